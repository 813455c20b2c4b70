//! The solver's split factorization (`SparseLdlt` with nested dissection: the two halves'
//! partial multifrontal factorizations side by side, then the separator's dense LDLᵀ) on the
//! whole tube's pattern, timed against this machine's 2-core dense peak round by round (the
//! machine's speed drifts by 10–25 % over minutes, so the rate is measured against a peak
//! taken beside it, not once).
//!
//! ```text
//! cargo run --release -p tubemem-fem --example split_factor -- [AROUND ALONG]
//! ```
//! (default 448 × 560, the million-unknown benchmark's mesh, 3 unknowns per node, no
//! constraint taken out; `ROUNDS=N`, default 5.) Each round factorizes the matrix of
//! `tube_pattern::dominant_matrix` as the Newton solver does (its values taken by the split,
//! which gathers them into its halves), then times faer's matrix product on all threads
//! (n = 3000, C ← C + A B, best of 2, as `dense_peak`). Prints the factor's flops and entries,
//! each round's seconds and share of that round's peak, and their medians. The first round
//! touches the factor's pages and is not counted.
mod tube_pattern;

use faer::Par;
use std::time::Instant;
use tubemem_fem::linsolve::{Layout, SparseLdlt};
use tubemem_fem::ordering::Ordering;

fn main() {
    let rounds = tube_pattern::rounds();
    let (n, pairs) = tube_pattern::tube_pairs();
    let values = tube_pattern::dominant_values(n, &pairs);
    let diagonal: Vec<usize> = (0..pairs.len())
        .filter(|&e| pairs[e].0 == pairs[e].1)
        .collect();
    let mut ldlt = SparseLdlt::with_options(n, &pairs, Layout::Auto, Ordering::NestedDissection)
        .expect("symbolic analysis");
    let separator = ldlt
        .split_separator()
        .expect("a model of this size is split");
    let flops = ldlt.factor_flops();
    println!(
        "{n} unknowns, split at a separator of {separator}; factor {:.1} M entries, {:.1} GFLOP",
        ldlt.factor_nnz() as f64 / 1e6,
        flops / 1e9
    );
    let (mut seconds, mut peaks, mut shares) = (Vec::new(), Vec::new(), Vec::new());
    for round in 0..=rounds {
        let taken = values.clone();
        let t = Instant::now();
        ldlt.factorize_shifted(taken, &diagonal, &[])
            .expect("the matrix is positive definite");
        let s = t.elapsed().as_secs_f64();
        let g = tube_pattern::matmul_peak(Par::rayon(0));
        let share = flops / s / 1e9 / g;
        println!(
            "  round {round}: {s:.3} s = {:.1} GFLOP/s; dense peak {g:.1} GFLOP/s; {:.0} %{}",
            flops / s / 1e9,
            100.0 * share,
            if round == 0 { " (first touch)" } else { "" }
        );
        if round > 0 {
            seconds.push(s);
            peaks.push(g);
            shares.push(share);
        }
    }
    let s = tube_pattern::median(seconds);
    println!(
        "median of {rounds}: {s:.3} s = {:.1} GFLOP/s; dense peak {:.1} GFLOP/s; share {:.0} % (median of the rounds' shares)",
        flops / s / 1e9,
        tube_pattern::median(peaks),
        100.0 * tube_pattern::median(shares)
    );
}
