//! faer's left-looking numeric LDLᵀ against the multifrontal driver
//! (`tubemem_fem::linsolve::multifrontal`) on the whole tube's nested-dissection pattern, one
//! thread, the two interleaved round by round (this machine's speed drifts by 10–25 % over
//! minutes, so they are timed side by side), each into storage an earlier round touched.
//!
//! ```text
//! cargo run --release -p tubemem-fem --example factor_drivers -- [AROUND ALONG]
//! ```
//! (default 448 × 560, the million-unknown benchmark's mesh; `ROUNDS=N`, default 5;
//! `RELAX=default|coarse|coarser`, the supernode relaxation of `tube_pattern::RELAXATIONS`,
//! default faer's.) Prints the flops by kernel and by supernode width,
//! each driver's median seconds, GFLOP/s and the memory it keeps beside the factor, the
//! largest difference between the two factors, the entries of the update matrices the
//! multifrontal driver forms against the factor's, and the multifrontal driver's time by phase
//! — the dense kernels (diagonal blocks, update products; their rate is the flops over their
//! seconds, since every flop is spent there) against zeroing, assembling, extend-adding and
//! copying, which move memory — beside faer's matrix product on one thread. With `PAIR=1` it
//! also runs two multifrontal factorizations side by side, each on its own thread as the
//! split's halves run, and prints each one's phases against the product on both threads.
mod tube_pattern;

use faer::dyn_stack::MemBuffer;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use faer::Par;
use std::time::Instant;
use tubemem_fem::linsolve::multifrontal::{Multifrontal, Phases};

fn main() {
    let rounds = tube_pattern::rounds();
    let (n, pairs) = tube_pattern::tube_pairs();
    let perm = tubemem_fem::ordering::nested_dissection(n, &pairs).expect("ordering");
    let m = tube_pattern::dominant_matrix(n, &pairs, &perm);
    let relax = std::env::var("RELAX").unwrap_or_else(|_| "default".into());
    let sym = tube_pattern::symbolic(&m, Some(tube_pattern::relaxation(&relax)));
    let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else {
        panic!("supernodal layout forced")
    };
    // flops as the solver counts them: Σ over columns of c (c + 2), c the entries below
    let flops: f64 = (0..sn.n_supernodes())
        .map(|s| {
            let (cols, below) = shape(sn, s);
            let rows = cols + below;
            (0..cols)
                .map(|j| {
                    let c = (rows - j - 1) as f64;
                    c * (c + 2.0)
                })
                .sum::<f64>()
        })
        .sum();
    print_flops(sn);
    let req = sym.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default());
    let mut mem = MemBuffer::new(req);
    let mut driver = Multifrontal::new(sn, m.symbolic()).expect("driver");
    let mut theirs = vec![0.0; sym.len_val()];
    let mut ours = vec![0.0; sym.len_val()];
    let (mut t_faer, mut t_ours) = (Vec::new(), Vec::new());
    let mut phases = Phases::default();
    for round in 0..=rounds {
        let t = Instant::now();
        tube_pattern::faer_ldlt(&m, &sym, &mut theirs, Par::Seq, &mut mem);
        let a = t.elapsed().as_secs_f64();
        let mut p = Phases::default();
        let t = Instant::now();
        driver
            .factorize(sn, m.val(), &mut ours, Some(&mut p))
            .expect("multifrontal");
        let b = t.elapsed().as_secs_f64();
        eprintln!("round {round}: faer {a:.3} s, multifrontal {b:.3} s");
        // the first round touches the storage's pages
        if round > 0 {
            t_faer.push(a);
            t_ours.push(b);
            if b <= t_ours.iter().copied().fold(f64::INFINITY, f64::min) {
                phases = p;
            }
        }
    }
    let worst = ours
        .iter()
        .zip(&theirs)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let (a, b) = (tube_pattern::median(t_faer), tube_pattern::median(t_ours));
    println!(
        "{n} unknowns, nested dissection, relaxation {relax}: {} supernodes, {:.1} GFLOP per factorization, one thread, medians of {rounds}:",
        sn.n_supernodes(),
        flops / 1e9
    );
    println!(
        "  faer (left-looking): {a:.3} s = {:.1} GFLOP/s; workspace {:.0} MB",
        flops / a / 1e9,
        req.size_bytes() as f64 / 1e6
    );
    println!(
        "  multifrontal:        {b:.3} s = {:.1} GFLOP/s ({:+.1} %); workspace {:.0} MB",
        flops / b / 1e9,
        100.0 * (a / b - 1.0),
        driver.workspace_bytes() as f64 / 1e6
    );
    println!("  largest difference between the factors: {worst:.1e}");
    println!(
        "  the update matrices' entries (the extend-add's traffic): {:.1} M, against the factor's {:.1} M",
        driver.update_entries(sn) as f64 / 1e6,
        sym.len_val() as f64 / 1e6
    );
    print_phases("its fastest round", &phases, flops);
    println!(
        "  faer's matrix product on one thread: {:.1} GFLOP/s",
        tube_pattern::matmul_peak(Par::Seq)
    );
    if std::env::var("PAIR").is_ok() {
        // two factorizations side by side, each on its own thread, as the split's two halves
        // run: the dense kernels and the memory-bound phases with both cores busy
        let mut second = Multifrontal::new(sn, m.symbolic()).expect("driver");
        let mut other = vec![0.0; sym.len_val()];
        let mut best: Option<(f64, Phases, Phases)> = None;
        for round in 0..=rounds {
            let t = Instant::now();
            let (p, q) = rayon::join(
                || {
                    let mut p = Phases::default();
                    driver
                        .factorize(sn, m.val(), &mut ours, Some(&mut p))
                        .expect("multifrontal");
                    p
                },
                || {
                    let mut q = Phases::default();
                    second
                        .factorize(sn, m.val(), &mut other, Some(&mut q))
                        .expect("multifrontal");
                    q
                },
            );
            let s = t.elapsed().as_secs_f64();
            eprintln!("pair round {round}: {s:.3} s");
            if round > 0 && best.as_ref().is_none_or(|b| s < b.0) {
                best = Some((s, p, q));
            }
        }
        if let Some((s, p, q)) = best {
            println!(
                "  two side by side (PAIR), their fastest round {s:.3} s = {:.1} GFLOP/s together:",
                2.0 * flops / s / 1e9
            );
            print_phases("first", &p, flops);
            print_phases("second", &q, flops);
            println!(
                "  faer's matrix product on both threads: {:.1} GFLOP/s",
                tube_pattern::matmul_peak(Par::rayon(0))
            );
        }
    }
}

/// Supernode `s` of `sn`: its columns and the rows below its diagonal block.
fn shape(sn: &SymbolicSupernodalCholesky<usize>, s: usize) -> (usize, usize) {
    let c = sn.supernode_end()[s] - sn.supernode_begin()[s];
    (
        c,
        (sn.col_ptr_for_val()[s + 1] - sn.col_ptr_for_val()[s]) / c - c,
    )
}

/// The flops of `sn`'s supernodes (c columns, r rows below) by kernel, leading terms: the
/// diagonal blocks' LDLᵀ (c³/3), the solves below them (r c²) and the update products (r² c),
/// and by the supernodes' width (powers of two): the dense kernels' shapes.
fn print_flops(sn: &SymbolicSupernodalCholesky<usize>) {
    // [LDLᵀ, solve, update] per width band 2^b ≤ c < 2^(b+1), the last band c ≥ 128
    let mut bands = [[0.0f64; 3]; 8];
    let mut count = [0usize; 8];
    for s in 0..sn.n_supernodes() {
        let (c, r) = shape(sn, s);
        let (c, r, b) = (c as f64, r as f64, (c.ilog2() as usize).min(7));
        count[b] += 1;
        let band = &mut bands[b];
        band[0] += c * c * c / 3.0;
        band[1] += r * c * c;
        band[2] += r * r * c;
    }
    let total = |k: usize| bands.iter().map(|b| b[k]).sum::<f64>() / 1e9;
    println!(
        "  flops by kernel (leading terms): diagonal LDLᵀ {:.1}, solves {:.1}, update products {:.1} GFLOP",
        total(0),
        total(1),
        total(2)
    );
    println!("  by supernode width c: supernodes, GFLOP of LDLᵀ + solves, of update products");
    for (b, band) in bands.iter().enumerate() {
        let width = if b == 7 {
            "c ≥ 128".to_string()
        } else {
            format!("{} ≤ c < {}", 1 << b, 2 << b)
        };
        println!(
            "    {width:12} {:6} {:7.1} {:7.1}",
            count[b],
            (band[0] + band[1]) / 1e9,
            band[2] / 1e9
        );
    }
}

/// The multifrontal driver's `phases` (one factorization of `flops`) and the rate of its dense
/// kernels: the flops over the seconds of the diagonal blocks and the update products, where
/// every flop is spent.
fn print_phases(label: &str, phases: &Phases, flops: f64) {
    let Phases {
        assembly,
        diagonal,
        copy,
        update,
        extend_update,
    } = *phases;
    let total = assembly + diagonal + copy + update + extend_update;
    println!("  multifrontal by phase ({label}, {total:.3} s):");
    for (name, s) in [
        ("diagonal blocks (dense LDLᵀ, solve)", diagonal),
        ("update products", update),
        ("zeroing, matrix, extend-add into own", assembly),
        ("extend-add into update matrices", extend_update),
        ("W copy and scaling", copy),
    ] {
        println!("    {name:38} {s:.3} s ({:.0} %)", 100.0 * s / total);
    }
    println!(
        "    the dense kernels' rate: {:.1} GFLOP/s; the memory-bound phases: {:.3} s",
        flops / (diagonal + update) / 1e9,
        assembly + extend_update + copy
    );
}
