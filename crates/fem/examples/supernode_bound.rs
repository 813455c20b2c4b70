//! The measured reason the factorization of the million-unknown tube stays below the dense
//! peak: the rate faer's own dense kernels reach on the shapes this pattern's supernodes give
//! them.
//!
//! ```text
//! cargo run --release -p tubemem-fem --example supernode_bound -- [AROUND ALONG]
//! ```
//! (default 448 × 560: the million-unknown benchmark's 4-node mesh, 3 unknowns per node, no
//! constraint taken out, ordered by the project's nested dissection, as `subtree_split`.)
//!
//! faer's supernodal LDLᵀ is left-looking: for each supernode s (c columns, r rows below its
//! diagonal block) it applies, one matrix product each, the update of every descendant d
//! whose rows reach s (an m × n block of s, lower triangular at its top, from d's m rows at
//! or below s times d's n rows inside s, of depth k = d's columns, scaled by d's pivots); then
//! it factorizes s's c × c diagonal block (dense LDLᵀ) and solves its r × c block against it.
//! The example lists every such piece of work from faer's symbolic factor and its flops, then
//! times faer's dense kernels on each shape (rounded to 1/8 of a power of two; a matrix product
//! m × k × n with `matmul`, the diagonal block with `cholesky_in_place`, the solve with
//! `solve_unit_lower_triangular_in_place`; on one thread, in storage touched before, best of
//! three batches of at least 0.2 ms). Σ flops / rate(shape) is the time the factorization
//! would take if every piece ran at its dense kernel's rate on its shape and nothing else cost
//! anything (no gathering, no scattering into the parent, no index work): a bound on the rate
//! faer can reach on this symbolic factor. The example prints it against the dense peak and
//! against the measured numeric factorization of the same symbolic factor, for faer's default
//! supernode relaxation and for coarser ones (`RELAX=…`: more explicit zeros, wider
//! supernodes), and the flops by the depth k of the products. `PROFILE=N` only repeats the
//! numeric factorization N times (for `perf record`; `ROUNDS=1` prints each round's seconds).
mod tube_pattern;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{cholesky_in_place, LdltParams, LdltRegularization};
use faer::linalg::matmul::matmul;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::{Accum, Mat, Par, Spec};
use std::collections::BTreeMap;
use std::time::Instant;
use tubemem_mesh::{tube::capped_tube, Symmetry};

/// A size rounded to 1/8 of its power of two (exact up to 16).
fn round(x: usize) -> usize {
    if x <= 16 {
        return x;
    }
    let step = 1usize << (usize::BITS - 1 - x.leading_zeros() - 3);
    (x + step / 2) / step * step
}

/// One kind of dense work on one shape.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Debug)]
enum Work {
    /// C (m × n) += A (m × k) Bᵀ (k × n)
    Product { m: usize, n: usize, k: usize },
    /// the dense LDLᵀ of a c × c block
    Diagonal { c: usize },
    /// an r × c block solved against a unit lower c × c one
    Solve { r: usize, c: usize },
}

impl Work {
    /// Seconds of one piece of this work with faer's dense kernel on one thread: the best of
    /// three batches of at least 0.2 ms.
    fn seconds(self) -> f64 {
        let fill = |r: usize, c: usize, s: usize| {
            Mat::<f64>::from_fn(r, c, |i, j| ((i * 7 + j * 3 + s) % 11) as f64 / 11.0 - 0.5)
        };
        let mut run: Box<dyn FnMut()> = match self {
            Work::Product { m, n, k } => {
                let (a, b, mut c) = (fill(m, k, 1), fill(k, n, 2), fill(m, n, 3));
                Box::new(move || {
                    matmul(
                        c.as_mut(),
                        Accum::Add,
                        a.as_ref(),
                        b.as_ref(),
                        -1e-3,
                        Par::Seq,
                    )
                })
            }
            Work::Diagonal { c } => {
                // diagonally dominant, refreshed each time (the factorization overwrites it)
                let a = Mat::<f64>::from_fn(c, c, |i, j| {
                    if i == j {
                        c as f64 + 1.0
                    } else {
                        ((i + j) % 5) as f64 / 10.0
                    }
                });
                let mut w = a.clone();
                let req = faer::linalg::cholesky::ldlt::factor::cholesky_in_place_scratch::<f64>(
                    c,
                    Par::Seq,
                    Spec::<LdltParams, f64>::default(),
                );
                let mut mem = MemBuffer::new(req);
                Box::new(move || {
                    w.copy_from(&a);
                    cholesky_in_place(
                        w.as_mut(),
                        LdltRegularization::default(),
                        Par::Seq,
                        MemStack::new(&mut mem),
                        Default::default(),
                    )
                    .expect("dominant");
                })
            }
            Work::Solve { r, c } => {
                let l = Mat::<f64>::from_fn(c, c, |i, j| {
                    if i == j {
                        1.0
                    } else if i > j {
                        0.5 / c as f64
                    } else {
                        0.0
                    }
                });
                let mut b = fill(c, r, 4);
                Box::new(move || {
                    faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place(
                        l.as_ref(),
                        b.as_mut(),
                        Par::Seq,
                    )
                })
            }
        };
        run();
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let (t, mut reps) = (Instant::now(), 0usize);
            while reps == 0 || t.elapsed().as_secs_f64() < 2e-4 {
                run();
                reps += 1;
            }
            best = best.min(t.elapsed().as_secs_f64() / reps as f64);
        }
        best
    }
}

/// The work of faer's supernodal LDLᵀ on `sym`: (shape, flops) for every piece, in the order
/// faer does them (see the module documentation).
fn pieces(sym: &SymbolicCholesky<usize>) -> Vec<(Work, f64)> {
    let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else {
        panic!("supernodal layout forced")
    };
    let (begin, end) = (sn.supernode_begin(), sn.supernode_end());
    let ns = sn.n_supernodes();
    // the descendants d whose patterns reach each supernode s
    let mut of_col = vec![0usize; sym.nrows()];
    for s in 0..ns {
        of_col[begin[s]..end[s]].fill(s);
    }
    let mut updates: Vec<Vec<usize>> = vec![Vec::new(); ns];
    for d in 0..ns {
        let mut last = usize::MAX;
        for &row in sn.supernode(d).pattern() {
            let s = of_col[row];
            if s != last {
                updates[s].push(d);
                last = s;
            }
        }
    }
    let mut out = Vec::new();
    for s in 0..ns {
        let (s_start, s_end) = (begin[s], end[s]);
        for &d in &updates[s] {
            let pattern = sn.supernode(d).pattern();
            let start = pattern.partition_point(|&r| r < s_start);
            let mid = pattern[start..].partition_point(|&r| r < s_end);
            let (m, n, k) = (pattern.len() - start, mid, end[d] - begin[d]);
            // the top n × n block is lower triangular
            let entries = (n * (n + 1) / 2 + (m - n) * n) as f64;
            out.push((Work::Product { m, n, k }, 2.0 * k as f64 * entries));
        }
        let (c, r) = (s_end - s_start, sn.supernode(s).pattern().len());
        out.push((Work::Diagonal { c }, (c as f64).powi(3) / 3.0));
        if r > 0 {
            out.push((Work::Solve { r, c }, (r * c * c) as f64));
        }
    }
    out
}

fn main() {
    let (around, along) = tube_pattern::around_along();
    let mesh = capped_tube(1.0, 20.0, around, along, Symmetry::None).expect("mesh");
    let (n, pairs) = tube_pattern::pairs(&mesh);
    let perm = tubemem_fem::ordering::nested_dissection(n, &pairs).expect("ordering");
    let m = tube_pattern::dominant_matrix(n, &pairs, &perm);
    if let Some(times) = std::env::var("PROFILE")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        // only the numeric factorization, `times` times after a first, for a profiler
        let sym = tube_pattern::symbolic(&m, None);
        let (best, _) = tube_pattern::factor_seconds(&m, &sym, Par::Seq, times);
        println!("numeric LDLᵀ, 1 thread, best of {times}: {best:.3} s");
        return;
    }
    let peak = {
        // faer's matmul on 2000 × 2000 and 3000 × 3000, one thread, as `dense_peak`
        let best = |n: usize| {
            let w = Work::Product { m: n, n, k: n };
            2.0 * (n as f64).powi(3) / w.seconds() / 1e9
        };
        best(2000).max(best(3000))
    };
    println!("{n} unknowns (nested dissection); faer matmul peak on 1 thread: {peak:.1} GFLOP/s");
    // faer's default relaxation, then coarser ones
    let which = std::env::var("RELAX").unwrap_or_else(|_| "default,coarse,coarser".into());
    let mut rates: BTreeMap<Work, f64> = BTreeMap::new();
    for (name, relax) in tube_pattern::RELAXATIONS {
        if !which.split(',').any(|w| w == name) {
            continue;
        }
        let sym = tube_pattern::symbolic(&m, Some(relax));
        let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else {
            panic!("supernodal layout forced")
        };
        let work = pieces(&sym);
        let flops: f64 = work.iter().map(|w| w.1).sum();
        // the time of every piece at its shape's rate
        let mut bound = 0.0;
        let mut by_depth: BTreeMap<usize, (f64, f64)> = BTreeMap::new();
        for &(w, f) in &work {
            let key = match w {
                Work::Product { m, n, k } => Work::Product {
                    m: round(m),
                    n: round(n),
                    k: round(k),
                },
                Work::Diagonal { c } => Work::Diagonal { c: round(c) },
                Work::Solve { r, c } => Work::Solve {
                    r: round(r),
                    c: round(c),
                },
            };
            let rate = *rates.entry(key).or_insert_with(|| {
                let rf = match key {
                    Work::Product { m, n, k } => 2.0 * (m * n * k) as f64,
                    Work::Diagonal { c } => (c as f64).powi(3) / 3.0,
                    Work::Solve { r, c } => (r * c * c) as f64,
                };
                rf / key.seconds()
            });
            bound += f / rate;
            if let Work::Product { k, .. } = w {
                let e = by_depth.entry(round(k).min(256)).or_default();
                e.0 += f;
                e.1 += f / rate;
            }
        }
        let (actual, _) = tube_pattern::factor_seconds(&m, &sym, Par::Seq, 2);
        println!(
            "\nrelaxation {name} {relax:?}: {} supernodes, nnz(L) {:.1} M, {:.1} GFLOP counted piece by piece; \
             {} shapes timed so far",
            sn.n_supernodes(),
            sym.len_val() as f64 / 1e6,
            flops / 1e9,
            rates.len()
        );
        println!(
            "  bound (every piece at its dense kernel's rate, nothing else): {bound:.3} s = {:.1} GFLOP/s = {:.0} % of the 1-thread peak",
            flops / bound / 1e9,
            100.0 * flops / bound / 1e9 / peak
        );
        println!(
            "  measured numeric LDLᵀ, 1 thread (best of 2): {actual:.3} s = {:.1} GFLOP/s = {:.0} % of the peak ({:.0} % of the bound's rate)",
            flops / actual / 1e9,
            100.0 * flops / actual / 1e9 / peak,
            100.0 * bound / actual
        );
        println!("  the products by their depth k (d's columns): share of the flops, rate at their shapes");
        for (k, (f, t)) in by_depth {
            if f / flops >= 0.01 {
                println!(
                    "    k ≈ {k:>4}{}: {:5.1} % of the flops, {:5.1} GFLOP/s ({:3.0} % of the peak)",
                    if k == 256 { "+" } else { " " },
                    100.0 * f / flops,
                    f / t / 1e9,
                    100.0 * f / t / 1e9 / peak
                );
            }
        }
    }
}
