//! Measure first: what factorizing the elimination tree's independent subtrees on two threads
//! would gain on the whole capped tube's pattern (parallelism across the elimination tree),
//! before writing a layer over faer's supernodal kernels.
//!
//! ```text
//! cargo run --release -p tubemem-fem --example subtree_split -- AROUND ALONG
//! ORDER=ring cargo run --release -p tubemem-fem --example subtree_split -- AROUND ALONG
//! ```
//! (default 448 × 560: the million-unknown benchmark's 4-node mesh, 3 unknowns per node, no
//! constraint taken out.) The pattern is the mesh's node graph expanded to 3 unknowns per node,
//! ordered by the project's nested dissection ([`tubemem_fem::ordering::nested_dissection`]),
//! or with `ORDER=ring` by the mid-span ring of nodes (z = 0) as the top separator and nested
//! dissection inside each half. The values are symmetric and diagonally dominant by 10⁻³ only: LDLᵀ
//! without pivoting does the same flops whatever the values, but a strongly dominant diagonal
//! would make the factor's far entries subnormal, and the dense kernels slow down many times on
//! those.
//! It prints:
//!
//! 1. from faer's supernodal symbolic factor: the supernodal elimination tree's top, the flops
//!    of each subtree (Σ over columns of (entries below the diagonal)²), and the split a
//!    subtree-to-thread mapping would make — the subtrees shared between two threads largest
//!    first, the largest opened (its root to the sequential top) while that shortens
//!    top + the longer share; the ideal speed-up is total / (top + longer share);
//! 2. measured, each the second of two factorizations into storage the first touched (as the
//!    solver's factor keeps its storage): the numeric LDLᵀ of the whole matrix on 1 thread and
//!    on 2 (faer's parallelism inside supernodes), and of the two shares' principal submatrices
//!    (each on one thread) one after the other and side by side (`rayon::join`). A share's
//!    submatrix leaves out its updates of the rows above it (the top's), so its flops are
//!    printed next to the share's;
//! 3. with `ORDER=ring`, the layer itself, on the ring: the bordered matrices [A_i B_i; B_iᵀ 0]
//!    of the two halves (the ring last) factorized side by side, each on one thread; the
//!    ring's Schur complement S = C − Σ B_iᵀ A_i⁻¹ B_i from their factors' trailing blocks
//!    (−B_iᵀ A_i⁻¹ B_i = (L D Lᵀ)_ring) and its dense Cholesky; ln det K = Σ ln det A_i +
//!    ln det S against the whole factor's, which shows that the split factorizes the same
//!    matrix.
mod tube_pattern;

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Par, Side};
use std::time::Instant;
use tube_pattern::factor_seconds;
use tubemem_mesh::{tube::capped_tube, Symmetry};

fn symbolic(m: &SparseColMat<usize, f64>) -> SymbolicCholesky<usize> {
    tube_pattern::symbolic(m, None)
}

/// Σ over columns of (entries below the diagonal)², faer's supernodal layout.
fn flops_of(s: &SymbolicCholesky<usize>) -> f64 {
    let SymbolicCholeskyRaw::Supernodal(sn) = s.raw() else {
        panic!("supernodal layout forced")
    };
    let (b, e) = (sn.supernode_begin(), sn.supernode_end());
    (0..sn.n_supernodes())
        .map(|k| {
            let (c, r) = (e[k] - b[k], sn.supernode(k).pattern().len());
            (0..c)
                .map(|j| ((c - 1 - j + r) as f64).powi(2))
                .sum::<f64>()
        })
        .sum()
}

/// The numeric LDLᵀ's values and seconds (the second of two, as in [`factor_seconds`]).
fn factor_values(m: &SparseColMat<usize, f64>, s: &SymbolicCholesky<usize>) -> (Vec<f64>, f64) {
    let (l, seconds, _) = tube_pattern::factor(m, s, Par::Seq, 1);
    (l, seconds)
}

/// Σ ln D_jj over the first `upto` columns of a supernodal LDLᵀ factor (with the count of
/// negative pivots).
fn log_pivots(s: &SymbolicCholesky<usize>, l: &[f64], upto: usize) -> (f64, usize) {
    let SymbolicCholeskyRaw::Supernodal(sn) = s.raw() else {
        panic!("supernodal layout forced")
    };
    let ptr = sn.col_ptr_for_val();
    let (mut sum, mut negative) = (0.0, 0);
    for k in 0..sn.n_supernodes() {
        let (b, e) = (sn.supernode_begin()[k], sn.supernode_end()[k]);
        let rows = e - b + sn.supernode(k).pattern().len();
        let val = faer::MatRef::from_column_major_slice(&l[ptr[k]..ptr[k + 1]], rows, e - b);
        for j in 0..(e - b) {
            if b + j < upto {
                sum += val[(j, j)].abs().ln();
                negative += usize::from(val[(j, j)] < 0.0);
            }
        }
    }
    (sum, negative)
}

/// The trailing `k` × `k` block of L D Lᵀ from a supernodal LDLᵀ factor whose last `k`
/// columns lie in its last supernode (None otherwise): there L's diagonal block is unit lower
/// with D on its diagonal.
fn trailing_block(s: &SymbolicCholesky<usize>, l: &[f64], k: usize) -> Option<faer::Mat<f64>> {
    let SymbolicCholeskyRaw::Supernodal(sn) = s.raw() else {
        return None;
    };
    let last = sn.n_supernodes() - 1;
    let (b, e) = (sn.supernode_begin()[last], sn.supernode_end()[last]);
    if e - b < k || !sn.supernode(last).pattern().is_empty() {
        return None;
    }
    let ptr = sn.col_ptr_for_val();
    let c = e - b;
    let val = faer::MatRef::from_column_major_slice(&l[ptr[last]..ptr[last + 1]], c, c);
    let block = val.submatrix(c - k, c - k, k, k);
    let mut unit = faer::Mat::<f64>::zeros(k, k);
    let mut scaled = faer::Mat::<f64>::zeros(k, k);
    for j in 0..k {
        let d = block[(j, j)];
        unit[(j, j)] = 1.0;
        scaled[(j, j)] = d;
        for i in j + 1..k {
            unit[(i, j)] = block[(i, j)];
            scaled[(i, j)] = block[(i, j)] * d;
        }
    }
    Some(&scaled * unit.transpose())
}

/// The principal submatrix of `m` on the columns `cols` (ascending) with the block of its
/// last `k` columns set to zero: [A B; Bᵀ 0].
fn bordered(m: &SparseColMat<usize, f64>, cols: &[usize], k: usize) -> SparseColMat<usize, f64> {
    let mut at = vec![usize::MAX; m.ncols()];
    for (j, &c) in cols.iter().enumerate() {
        at[c] = j;
    }
    let first = cols.len() - k;
    let mut t = Vec::new();
    for &c in cols {
        let rows = m.as_ref().row_idx_of_col_raw(c);
        let vals = m.as_ref().val_of_col(c);
        for (&r, &v) in rows.iter().zip(vals) {
            if at[r] != usize::MAX {
                let zero = at[r] >= first && at[c] >= first;
                t.push(Triplet::new(at[r], at[c], if zero { 0.0 } else { v }));
            }
        }
    }
    SparseColMat::try_new_from_triplets(cols.len(), cols.len(), &t).expect("submatrix")
}

/// The principal submatrix of `m` (lower triangle) on the columns `cols` (ascending).
fn principal(m: &SparseColMat<usize, f64>, cols: &[usize]) -> SparseColMat<usize, f64> {
    let mut at = vec![usize::MAX; m.ncols()];
    for (k, &c) in cols.iter().enumerate() {
        at[c] = k;
    }
    let mut t = Vec::new();
    for &c in cols {
        let rows = m.as_ref().row_idx_of_col_raw(c);
        let vals = m.as_ref().val_of_col(c);
        for (&r, &v) in rows.iter().zip(vals) {
            if at[r] != usize::MAX {
                t.push(Triplet::new(at[r], at[c], v));
            }
        }
    }
    SparseColMat::try_new_from_triplets(cols.len(), cols.len(), &t).expect("submatrix")
}

fn main() {
    let (around, along) = tube_pattern::around_along();
    let mesh = capped_tube(1.0, 20.0, around, along, Symmetry::None).expect("mesh");
    let (n, pairs) = tube_pattern::pairs(&mesh);
    let nd = tubemem_fem::ordering::nested_dissection(n, &pairs).expect("ordering");
    // the tube's own top separator: the ring of nodes at mid-length (z = 0), each half ordered
    // by nested dissection, the ring last
    let side = |k: usize| {
        let z = mesh.nodes[k / 3][2];
        if z.abs() < 1e-9 {
            2
        } else {
            usize::from(z > 0.0)
        }
    };
    let mut ring_split = Vec::with_capacity(n);
    for half in 0..2 {
        let members: Vec<usize> = (0..n).filter(|&k| side(k) == half).collect();
        let mut local = vec![usize::MAX; n];
        for (i, &k) in members.iter().enumerate() {
            local[k] = i;
        }
        let sub: Vec<(usize, usize)> = pairs
            .iter()
            .filter(|&&(r, c)| local[r] != usize::MAX && local[c] != usize::MAX)
            .map(|&(r, c)| (local[r], local[c]))
            .collect();
        let order =
            tubemem_fem::ordering::nested_dissection(members.len(), &sub).expect("ordering");
        ring_split.extend(order.iter().map(|&i| members[i]));
    }
    let halves = [
        (0..n).filter(|&k| side(k) == 0).count(),
        (0..n).filter(|&k| side(k) == 1).count(),
    ];
    ring_split.extend((0..n).filter(|&k| side(k) == 2));
    let which = std::env::var("ORDER").unwrap_or_default();
    println!(
        "ordering: {}",
        if which == "ring" {
            "ring split"
        } else {
            "nested dissection"
        }
    );
    let perm = if which == "ring" { ring_split } else { nd };
    let m = tube_pattern::dominant_matrix(n, &pairs, &perm);
    let sym = symbolic(&m);
    let SymbolicCholeskyRaw::Supernodal(sn) = sym.raw() else {
        panic!("supernodal layout forced")
    };
    let (b, e) = (sn.supernode_begin(), sn.supernode_end());
    let ns = sn.n_supernodes();
    let mut of_col = vec![0usize; n];
    for k in 0..ns {
        of_col[b[k]..e[k]].fill(k);
    }
    let parent: Vec<Option<usize>> = (0..ns)
        .map(|k| sn.supernode(k).pattern().first().map(|&r| of_col[r]))
        .collect();
    let own: Vec<f64> = (0..ns)
        .map(|k| {
            let (c, r) = (e[k] - b[k], sn.supernode(k).pattern().len());
            (0..c)
                .map(|j| ((c - 1 - j + r) as f64).powi(2))
                .sum::<f64>()
        })
        .collect();
    let mut children = vec![Vec::new(); ns];
    let mut sub = own.clone();
    let mut roots = Vec::new();
    for k in 0..ns {
        match parent[k] {
            Some(p) => {
                assert!(p > k, "postordered");
                children[p].push(k);
                let s = sub[k];
                sub[p] += s;
            }
            None => roots.push(k),
        }
    }
    let total: f64 = roots.iter().map(|&r| sub[r]).sum();
    // the split: subtrees shared between two threads, largest first (LPT); the largest
    // subtree is opened (its root joins the sequential top, its children the frontier) while
    // that shortens top + the longer share
    let lpt = |frontier: &[usize]| {
        let mut f = frontier.to_vec();
        f.sort_by(|a, b| sub[*b].total_cmp(&sub[*a]).then(a.cmp(b)));
        let mut share = [Vec::new(), Vec::new()];
        let mut load = [0.0f64; 2];
        for &k in &f {
            let t = usize::from(load[1] < load[0]);
            load[t] += sub[k];
            share[t].push(k);
        }
        (share, load)
    };
    let mut frontier = roots.clone();
    let mut top = 0.0;
    let mut top_nodes = Vec::new();
    loop {
        let (_, load) = lpt(&frontier);
        let (i, &big) = frontier
            .iter()
            .enumerate()
            .max_by(|a, b| sub[*a.1].total_cmp(&sub[*b.1]))
            .expect("a subtree");
        let mut opened = frontier.clone();
        opened.swap_remove(i);
        opened.extend(&children[big]);
        let (_, after) = lpt(&opened);
        if own[big] + after[0].max(after[1]) >= load[0].max(load[1]) {
            break;
        }
        top += own[big];
        top_nodes.push(big);
        frontier = opened;
    }
    let (share, load) = lpt(&frontier);
    for &k in &top_nodes {
        println!("top supernode {k}: {} columns, pattern {}, own {:.2} GFLOP, children subtrees {:?} GFLOP", e[k] - b[k], sn.supernode(k).pattern().len(), own[k] / 1e9, children[k].iter().map(|&c| (sub[c] / 1e8).round() / 10.0).collect::<Vec<_>>());
    }
    let top_cols: usize = top_nodes.iter().map(|&k| e[k] - b[k]).sum();
    println!(
        "{n} unknowns, {ns} supernodes, {:.1} GFLOP (Σ col²); top: {} supernodes, {top_cols} columns, {:.2} GFLOP ({:.1} %); shares {:.1} + {:.1} GFLOP in {} + {} subtrees",
        total / 1e9,
        top_nodes.len(),
        top / 1e9,
        100.0 * top / total,
        load[0] / 1e9,
        load[1] / 1e9,
        share[0].len(),
        share[1].len()
    );
    println!(
        "ideal speed-up on 2 threads: {:.2}",
        total / (top + load[0].max(load[1]))
    );
    // the columns of each share
    let cols: Vec<Vec<usize>> = share
        .iter()
        .map(|roots| {
            let mut inside = vec![false; ns];
            for &r in roots {
                inside[r] = true;
            }
            for k in (0..ns).rev() {
                if let Some(p) = parent[k] {
                    if inside[p] {
                        inside[k] = true;
                    }
                }
            }
            (0..n).filter(|&c| inside[of_col[c]]).collect()
        })
        .collect();
    let subs: Vec<SparseColMat<usize, f64>> = cols.iter().map(|c| principal(&m, c)).collect();
    let subsym: Vec<SymbolicCholesky<usize>> = subs.iter().map(symbolic).collect();
    for (i, s) in subsym.iter().enumerate() {
        println!(
            "share {i}: {} columns, submatrix factor {:.1} GFLOP (the share's subtrees: {:.1})",
            cols[i].len(),
            flops_of(s) / 1e9,
            load[i] / 1e9
        );
    }
    for round in 0..2 {
        let (whole1, bytes) = factor_seconds(&m, &sym, Par::Seq, 1);
        let (whole2, _) = factor_seconds(&m, &sym, Par::rayon(2), 1);
        let seq: Vec<f64> = (0..2)
            .map(|i| factor_seconds(&subs[i], &subsym[i], Par::Seq, 1).0)
            .collect();
        let (a, b) = rayon::join(
            || factor_seconds(&subs[0], &subsym[0], Par::Seq, 1).0,
            || factor_seconds(&subs[1], &subsym[1], Par::Seq, 1).0,
        );
        println!(
            "round {round}: whole 1 thread {whole1:.3} s (workspace {:.0} MiB), whole 2 threads {whole2:.3} s; shares one after the other {:.3} + {:.3} = {:.3} s, side by side {a:.3} and {b:.3} s ({:.2}× the sequential shares)",
            bytes as f64 / 1048576.0,
            seq[0],
            seq[1],
            seq[0] + seq[1],
            (seq[0] + seq[1]) / a.max(b)
        );
    }
    if which == "ring" {
        // the layer's factorization: [A_i B_i; B_iᵀ 0] (half i, the ring last) on a thread
        // each, then the ring's Schur complement S = C − Σ B_iᵀ A_i⁻¹ B_i, whose terms are the
        // trailing blocks −(L D Lᵀ)_ring of the two factors, and its dense Cholesky
        let ring = n - halves[0] - halves[1];
        let cols: Vec<Vec<usize>> = (0..2)
            .map(|h| {
                let start = if h == 0 { 0 } else { halves[0] };
                (start..start + halves[h]).chain(n - ring..n).collect()
            })
            .collect();
        let ms: Vec<SparseColMat<usize, f64>> =
            cols.iter().map(|c| bordered(&m, c, ring)).collect();
        let syms: Vec<SymbolicCholesky<usize>> = ms.iter().map(symbolic).collect();
        let c = principal(&m, &(n - ring..n).collect::<Vec<_>>());
        for round in 0..2 {
            let t = Instant::now();
            let ((l0, s0), (l1, s1)) = rayon::join(
                || factor_values(&ms[0], &syms[0]),
                || factor_values(&ms[1], &syms[1]),
            );
            let joined = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let (Some(t0), Some(t1)) = (
                trailing_block(&syms[0], &l0, ring),
                trailing_block(&syms[1], &l1, ring),
            ) else {
                println!("the ring's columns are not all in the last supernode");
                return;
            };
            let mut schur = &t0 + &t1;
            for j in 0..ring {
                for (&r, &v) in c
                    .as_ref()
                    .row_idx_of_col_raw(j)
                    .iter()
                    .zip(c.as_ref().val_of_col(j))
                {
                    schur[(r, j)] += v;
                    if r != j {
                        schur[(j, r)] += v;
                    }
                }
            }
            let llt = schur.llt(Side::Lower);
            let dense = t.elapsed().as_secs_f64();
            let spd = llt.is_ok();
            // ln det K = ln det A_0 + ln det A_1 + ln det S, against the whole factor's
            let ring_log = llt.map_or(f64::NAN, |f| {
                (0..ring).map(|j| 2.0 * f.L()[(j, j)].ln()).sum::<f64>()
            });
            let (whole_log, whole_negative) = log_pivots(&sym, &factor_values(&m, &sym).0, n);
            let (a0, n0) = log_pivots(&syms[0], &l0, halves[0]);
            let (a1, n1) = log_pivots(&syms[1], &l1, halves[1]);
            let split_log = a0 + a1 + ring_log;
            println!(
                "split at the ring ({ring} columns), round {round}: halves [A B; Bᵀ 0] side by side {:.3} and {:.3} s (wall of both calls, two factorizations each and their allocations, {joined:.3} s), flops {:.1} + {:.1} GFLOP; the ring's Schur complement and its Cholesky {dense:.3} s (positive definite: {spd}); ln det K {split_log:.9e} against the whole factor's {whole_log:.9e} (relative {:.1e}), negative pivots {} against {whole_negative}; the split's factorization {:.3} s (the longer half and the ring's dense part)",
                s0,
                s1,
                flops_of(&syms[0]) / 1e9,
                flops_of(&syms[1]) / 1e9,
                (split_log - whole_log).abs() / whole_log.abs(),
                n0 + n1,
                s0.max(s1) + dense,
            );
        }
    }
}
