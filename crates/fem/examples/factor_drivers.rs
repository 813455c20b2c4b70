//! faer's left-looking numeric LDLᵀ against the multifrontal driver
//! (`tubemem_fem::linsolve::multifrontal`) on the whole tube's nested-dissection pattern, one
//! thread, the two interleaved round by round (this machine's speed drifts by 10–25 % over
//! minutes, so they are timed side by side), each into storage an earlier round touched.
//!
//! ```text
//! cargo run --release -p tubemem-fem --example factor_drivers -- [AROUND ALONG]
//! ```
//! (default 448 × 560, the million-unknown benchmark's mesh; `ROUNDS=N`, default 5.) Prints
//! each driver's median seconds and GFLOP/s, the largest difference between the two factors,
//! the entries of the update matrices the multifrontal driver forms against the factor's,
//! the multifrontal driver's time by phase (the dense kernels — diagonal blocks and update
//! products — against zeroing, assembling, extend-adding and copying, which move memory) and
//! the memory each keeps beside the factor.
mod tube_pattern;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use faer::{Par, Side};
use std::time::Instant;
use tubemem_fem::linsolve::multifrontal::{Multifrontal, Phases};
use tubemem_mesh::{tube::capped_tube, Symmetry};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let (around, along) = tube_pattern::around_along();
    let rounds: usize = std::env::var("ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(5);
    let mesh = capped_tube(1.0, 20.0, around, along, Symmetry::None).expect("mesh");
    let (n, pairs) = tube_pattern::pairs(&mesh);
    let perm = tubemem_fem::ordering::nested_dissection(n, &pairs).expect("ordering");
    let m = tube_pattern::dominant_matrix(n, &pairs, &perm);
    let sym = tube_pattern::symbolic(&m, None);
    let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else {
        panic!("supernodal layout forced")
    };
    // flops as the solver counts them: Σ over columns of c (c + 2), c the entries below
    let flops: f64 = (0..sn.n_supernodes())
        .map(|s| {
            let cols = sn.supernode_end()[s] - sn.supernode_begin()[s];
            let rows = (sn.col_ptr_for_val()[s + 1] - sn.col_ptr_for_val()[s]) / cols;
            (0..cols)
                .map(|j| {
                    let c = (rows - j - 1) as f64;
                    c * (c + 2.0)
                })
                .sum::<f64>()
        })
        .sum();
    let req = sym.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default());
    let mut mem = MemBuffer::new(req);
    let mut driver = Multifrontal::new(sn, m.symbolic()).expect("driver");
    let mut theirs = vec![0.0; sym.len_val()];
    let mut ours = vec![0.0; sym.len_val()];
    let (mut t_faer, mut t_ours) = (Vec::new(), Vec::new());
    let mut phases = Phases::default();
    for round in 0..=rounds {
        let t = Instant::now();
        sym.factorize_numeric_ldlt::<f64>(
            &mut theirs,
            m.as_ref(),
            Side::Lower,
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .expect("faer");
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
    let (a, b) = (median(t_faer), median(t_ours));
    println!(
        "{n} unknowns, nested dissection, {} supernodes, {:.1} GFLOP per factorization, one thread, medians of {rounds}:",
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
    let Phases {
        matrix,
        extend_own,
        diagonal,
        copy,
        update,
        extend_update,
    } = phases;
    let total = matrix + extend_own + diagonal + copy + update + extend_update;
    println!("  multifrontal by phase (its fastest round, {total:.3} s):");
    for (name, s) in [
        ("diagonal blocks (dense LDLᵀ, solve)", diagonal),
        ("update products", update),
        ("zeroing, taking the matrix", matrix),
        ("extend-add into own columns", extend_own),
        ("extend-add into update matrices", extend_update),
        ("W copy and scaling", copy),
    ] {
        println!("    {name:38} {s:.3} s ({:.0} %)", 100.0 * s / total);
    }
}
