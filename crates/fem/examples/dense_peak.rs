//! This machine's dense peak, measured with faer's own matrix product (the kernel the
//! supernodal factorization spends its time in):
//!
//! ```text
//! cargo run --release -p tubemem-fem --example dense_peak
//! ```
//! C ← C + A B with n × n matrices (2n³ flops), n = 2000 and 3000, best of 5, on 1 thread and on
//! every thread of the machine. Beside it, the memory bandwidth that the factorization's
//! memory-bound parts (zeroing, gathering, extend-add) meet: a ← a + b over two arrays of
//! 256 MiB each (24 bytes moved per entry: a and b read, a written), best of 5, on 1 thread
//! and split across every thread. Prints one line per measure and thread count, and a JSON
//! line for scripts.
use faer::{linalg::matmul::matmul, Accum, Mat, Par};
use std::time::Instant;

fn best_gflops(n: usize, par: Par) -> f64 {
    let a = Mat::<f64>::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.5);
    let b = Mat::<f64>::from_fn(n, n, |i, j| ((i * 5 + j * 13) % 17) as f64 / 17.0 - 0.5);
    let mut c = Mat::<f64>::zeros(n, n);
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        matmul(c.as_mut(), Accum::Add, a.as_ref(), b.as_ref(), 1.0, par);
        best = best.min(t.elapsed().as_secs_f64());
    }
    // keep the product alive (and checked) so that it is not optimized away
    assert!(c.norm_l2().is_finite());
    2.0 * (n as f64).powi(3) / best / 1e9
}

/// a ← a + b over `a`'s chunks, one per thread of `threads`: GB/s (24 bytes an entry).
fn bandwidth(a: &mut [f64], b: &[f64], threads: usize) -> f64 {
    let chunk = a.len().div_ceil(threads);
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        rayon::scope(|s| {
            for (x, y) in a.chunks_mut(chunk).zip(b.chunks(chunk)) {
                s.spawn(move |_| {
                    for (u, v) in x.iter_mut().zip(y) {
                        *u += v;
                    }
                });
            }
        });
        best = best.min(t.elapsed().as_secs_f64());
    }
    24.0 * a.len() as f64 / best / 1e9
}

fn main() {
    let threads = rayon::current_num_threads();
    let mut json = vec![];
    for (label, par) in [("1", Par::Seq), ("all", Par::rayon(0))] {
        let g = [2000, 3000]
            .iter()
            .map(|&n| best_gflops(n, par))
            .fold(0.0, f64::max);
        println!(
            "faer matmul peak on {} thread(s): {g:.1} GFLOP/s",
            if label == "1" { 1 } else { threads }
        );
        json.push(format!("\"{label}\": {g}"));
    }
    let entries = 32 << 20;
    let mut a = vec![1.0; entries];
    let b = vec![1e-3; entries];
    let mut bw = vec![];
    for (label, t) in [("1", 1), ("all", threads)] {
        let g = bandwidth(&mut a, &b, t);
        println!("memory bandwidth (a ← a + b) on {t} thread(s): {g:.1} GB/s");
        bw.push(format!("\"{label}\": {g}"));
    }
    assert!(a.iter().all(|v| v.is_finite()));
    println!(
        "{{\"threads\": {threads}, \"gflops\": {{{}}}, \"bandwidth_gb_s\": {{{}}}}}",
        json.join(", "),
        bw.join(", ")
    );
}
