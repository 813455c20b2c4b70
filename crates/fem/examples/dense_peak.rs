//! This machine's dense peak, measured with faer's own matrix product (the kernel the
//! supernodal factorization spends its time in):
//!
//! ```text
//! cargo run --release -p tubemem-fem --example dense_peak
//! ```
//! C ← C + A B with n × n matrices (2n³ flops), n = 2000 and 3000, best of 5, on 1 thread and on
//! every thread of the machine. Prints one line per thread count, and a JSON line for scripts.
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
    println!(
        "{{\"threads\": {threads}, \"gflops\": {{{}}}}}",
        json.join(", ")
    );
}
