//! What the factorization examples (`subtree_split`, `supernode_bound`, `factor_drivers`)
//! share: the whole capped tube's pattern (the mesh's node graph expanded to 3 unknowns per
//! node, no constraint taken out), a matrix on it, and the timing of faer's numeric LDLᵀ.

// each example uses a part of these helpers
#![allow(dead_code)]
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Par, Side};
use std::time::Instant;
use tubemem_mesh::Mesh;

/// The unknowns and the lower triangle's (row, column) pairs of `mesh`'s 4-node elements, 3
/// unknowns per node, sorted.
pub fn pairs(mesh: &Mesh) -> (usize, Vec<(usize, usize)>) {
    let n = 3 * mesh.nodes.len();
    let mut pairs = Vec::new();
    for q in &mesh.quads {
        for &a in q {
            for &b in q {
                for ca in 0..3 {
                    for cb in 0..3 {
                        let (r, c) = (3 * a + ca, 3 * b + cb);
                        if r >= c {
                            pairs.push((r, c));
                        }
                    }
                }
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    (n, pairs)
}

/// An SPD matrix on `pairs`, diagonally dominant by 1e-3 only, permuted by `perm` (the unknown
/// eliminated k-th is `perm[k]`); its lower triangle. Its factor's entries decay slowly (a
/// strongly dominant diagonal makes them decay to subnormal numbers, which the dense kernels
/// process many times slower). Off the diagonal −1 between equal components and −0.1 (1 + a b)
/// between components a ≠ b (three unknowns of a node with equal couplings would make a ring's
/// Schur complement singular); on it the sum of the row's magnitudes plus 10⁻³.
pub fn dominant_matrix(
    n: usize,
    pairs: &[(usize, usize)],
    perm: &[usize],
) -> SparseColMat<usize, f64> {
    let mut inv = vec![0usize; n];
    for (k, &p) in perm.iter().enumerate() {
        inv[p] = k;
    }
    let triplets: Vec<Triplet<usize, usize, f64>> = pairs
        .iter()
        .zip(dominant_values(n, pairs))
        .map(|(&(r, c), v)| {
            let (pr, pc) = (inv[r], inv[c]);
            Triplet::new(pr.max(pc), pr.min(pc), v)
        })
        .collect();
    SparseColMat::try_new_from_triplets(n, n, &triplets).expect("matrix")
}

/// The values of [`dominant_matrix`], one per pair (unpermuted).
pub fn dominant_values(n: usize, pairs: &[(usize, usize)]) -> Vec<f64> {
    let off = |r: usize, c: usize| {
        let (a, b) = (r % 3, c % 3);
        if a == b {
            -1.0
        } else {
            -0.1 * (1 + a * b) as f64
        }
    };
    let mut diagonal = vec![1e-3; n];
    for &(r, c) in pairs {
        if r != c {
            diagonal[r] -= off(r, c);
            diagonal[c] -= off(r, c);
        }
    }
    pairs
        .iter()
        .map(|&(r, c)| if r == c { diagonal[r] } else { off(r, c) })
        .collect()
}

/// The mesh size from the command line: AROUND ALONG (default 448 × 560, the
/// million-unknown benchmark's).
pub fn around_along() -> (usize, usize) {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("AROUND ALONG"))
        .collect();
    (
        args.first().copied().unwrap_or(448),
        args.get(1).copied().unwrap_or(560),
    )
}

/// faer's matrix product C ← C + A B (n = 3000, best of 2) with `par`: GFLOP/s, the dense peak
/// as `dense_peak` measures it, for an example to take beside its own timing.
pub fn matmul_peak(par: Par) -> f64 {
    use faer::{linalg::matmul::matmul, Accum, Mat};
    let n = 3000;
    let a = Mat::<f64>::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.5);
    let b = Mat::<f64>::from_fn(n, n, |i, j| ((i * 5 + j * 13) % 17) as f64 / 17.0 - 0.5);
    let mut c = Mat::<f64>::zeros(n, n);
    let best = (0..2)
        .map(|_| {
            let t = Instant::now();
            matmul(c.as_mut(), Accum::Add, a.as_ref(), b.as_ref(), 1.0, par);
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);
    assert!(c.norm_l2().is_finite());
    2.0 * (n as f64).powi(3) / best / 1e9
}

/// The median of `v` (the upper one of an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The rounds a timing example repeats its measure (`ROUNDS`, default 5).
pub fn rounds() -> usize {
    std::env::var("ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(5)
}

/// The whole capped tube of the command line's size ([`around_along`]; R = 1, L = 20, no
/// symmetry): its unknowns and [`pairs`].
pub fn tube_pairs() -> (usize, Vec<(usize, usize)>) {
    let (around, along) = around_along();
    let mesh =
        tubemem_mesh::tube::capped_tube(1.0, 20.0, around, along, tubemem_mesh::Symmetry::None)
            .expect("mesh");
    pairs(&mesh)
}

/// The supernode relaxations the examples compare (`RELAX=…`), each (columns, fraction of
/// explicit zeros allowed up to that many columns): faer's default, then two coarser ones
/// (more explicit zeros, wider supernodes).
pub const RELAXATIONS: [(&str, &[(usize, f64)]); 3] = [
    (
        "default",
        &[(4, 1.0), (16, 0.8), (48, 0.1), (usize::MAX, 0.05)],
    ),
    (
        "coarse",
        &[(8, 1.0), (32, 0.8), (96, 0.2), (usize::MAX, 0.1)],
    ),
    (
        "coarser",
        &[(16, 1.0), (64, 0.8), (192, 0.3), (usize::MAX, 0.15)],
    ),
];

/// The relaxation of [`RELAXATIONS`] named `name`.
pub fn relaxation(name: &str) -> &'static [(usize, f64)] {
    RELAXATIONS
        .iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("RELAX={name}: one of default, coarse, coarser"))
        .1
}

/// faer's supernodal symbolic factor of `m` (lower triangle, already ordered) with the
/// supernode relaxation `relax` (faer's default if None).
pub fn symbolic(
    m: &SparseColMat<usize, f64>,
    relax: Option<&[(usize, f64)]>,
) -> SymbolicCholesky<usize> {
    let mut params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        ..Default::default()
    };
    if let Some(relax) = relax {
        params.supernodal_params = SymbolicSupernodalParams { relax: Some(relax) };
    }
    // the identity as a custom ordering (faer 0.24's `Identity` with the lower triangle
    // analyses the diagonal alone)
    let id: Vec<usize> = (0..m.ncols()).collect();
    factorize_symbolic_cholesky(
        m.symbolic(),
        Side::Lower,
        SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(&id, &id, m.ncols())),
        params,
    )
    .expect("symbolic")
}

/// Seconds of a numeric LDLᵀ on `par` into a factor and a workspace that an earlier
/// factorization has touched (as the solver's, which keeps its factor's storage from one
/// factorization to the next): the best of `rounds` after a first; also the workspace's bytes.
/// With `ROUNDS` set in the environment, each round's seconds go to stderr (the first one
/// includes the first touch of the factor's and the workspace's pages).
pub fn factor_seconds(
    m: &SparseColMat<usize, f64>,
    s: &SymbolicCholesky<usize>,
    par: Par,
    rounds: usize,
) -> (f64, usize) {
    let (_, seconds, bytes) = factor(m, s, par, rounds);
    (seconds, bytes)
}

/// faer's numeric LDLᵀ of `m` (lower triangle, ordered) on `s` into `l`, with the workspace
/// `mem` (`s.factorize_numeric_ldlt_scratch` for `par`).
pub fn faer_ldlt(
    m: &SparseColMat<usize, f64>,
    s: &SymbolicCholesky<usize>,
    l: &mut [f64],
    par: Par,
    mem: &mut MemBuffer,
) {
    s.factorize_numeric_ldlt::<f64>(
        l,
        m.as_ref(),
        Side::Lower,
        LdltRegularization::default(),
        par,
        MemStack::new(mem),
        Default::default(),
    )
    .expect("numeric");
}

/// [`factor_seconds`] with the factor's values.
pub fn factor(
    m: &SparseColMat<usize, f64>,
    s: &SymbolicCholesky<usize>,
    par: Par,
    rounds: usize,
) -> (Vec<f64>, f64, usize) {
    let mut l = vec![0.0; s.len_val()];
    let req = s.factorize_numeric_ldlt_scratch::<f64>(par, Default::default());
    let mut mem = MemBuffer::new(req);
    let mut best = f64::INFINITY;
    for round in 0..=rounds {
        let t = Instant::now();
        faer_ldlt(m, s, &mut l, par, &mut mem);
        if std::env::var("ROUNDS").is_ok() {
            eprintln!("round {round}: {:.3} s", t.elapsed().as_secs_f64());
        }
        if round > 0 {
            best = best.min(t.elapsed().as_secs_f64());
        }
    }
    (l, best, req.size_bytes())
}
