//! The fill-reducing ordering of the sparse LDLᵀ: faer's AMD, METIS's nested dissection, or
//! (the default) whichever of the two gives the factorization fewer flops.
//!
//! Measured (`mesh.factor_flops` of summary.json, and `scripts/bench-million.sh`): on the
//! shipped cases, long eighth and quarter models whose graphs are strips, nested dissection's
//! factor costs 20–56 % more flops than AMD's; on the whole capped tube of 244,608 equations
//! (`AROUND=224 ALONG=280`) it costs 34 % fewer. So neither is the better default, and the
//! symbolic analyses are cheap beside one numeric factorization: `auto` runs both.
//! On 100,000 unknowns or more, nested dissection's top split is taken apart
//! ([`bisection`], [`crate::linsolve::tree_split`]): its two halves factorize side by side, and `auto`
//! weighs that split against AMD.
//!
//! Nested dissection runs on the quotient graph of the matrix: the unknowns whose closed
//! neighbourhoods are equal (a node's three displacements, which every element couples together)
//! are one vertex, weighted by their count, so METIS sees the node graph and the factor keeps
//! each node's unknowns in one supernode. METIS (`METIS_NodeND`, through `metis-sys`, whose
//! bundled METIS the C compiler builds) tries [`SEPARATORS`] separators at each split and keeps
//! the smallest, from a fixed seed, so the ordering, and with it every result, is the same on
//! every run and for any thread count. Its order is then renumbered to a postorder of its
//! elimination tree (`postordered`): the same fill, and the supernodes whole.
//!
//! The ordering changes the factor's fill and flops, not the matrix: the solution agrees to
//! round-off and the inertia (the negative-pivot count, Sylvester's law) is the same
//! (`crates/fem/src/tests.rs`, `the_ordering_changes_the_flops_not_the_solution_or_the_inertia`).

use std::collections::HashMap;

/// Which fill-reducing ordering the symbolic analysis uses (`[solver] ordering`).
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum Ordering {
    /// both, and the one whose factorization costs fewer flops (the default: AMD on the long,
    /// strip-like symmetric models, nested dissection on whole tubes)
    #[default]
    Auto,
    /// approximate minimum degree (faer's)
    Amd,
    /// METIS nested dissection on the node graph
    NestedDissection,
}

/// Separators METIS tries at each bisection (`METIS_OPTION_NSEPS`); the smallest is kept.
/// Three cut the factor's flops on the capped tube's pattern by about a third against AMD,
/// against a fifth with one (measured on the million-unknown tube's pattern).
pub const SEPARATORS: i32 = 3;

/// The seed of METIS's randomized matching (`METIS_OPTION_SEED`): fixed, so the ordering is.
pub const SEED: i32 = 7;

/// METIS keeps global state (its random generator, its memory bookkeeping), so two calls at
/// once on two threads would race, and the ordering, with every result, would depend on the
/// timing: every call holds this lock.
static METIS: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Why the ordering could not be computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum OrderingError {
    #[error("the matrix has {0} unknowns, more than METIS's 32-bit indices can hold")]
    TooLarge(usize),
    #[error("METIS's nested dissection failed (status {0})")]
    Metis(i32),
}

/// The quotient graph of a symmetric pattern in METIS's CSR form: the unknowns with equal
/// closed neighbourhoods (supervariables) are one vertex, weighted by their count.
struct Quotient {
    /// each vertex's unknowns, ascending, vertices in order of first appearance
    groups: Vec<Vec<usize>>,
    xadj: Vec<metis_sys::idx_t>,
    adjncy: Vec<metis_sys::idx_t>,
    vwgt: Vec<metis_sys::idx_t>,
}

impl Quotient {
    /// The quotient graph of the pattern `pairs` (row, col) on `n` ≥ 1 unknowns.
    fn new(n: usize, pairs: &[(usize, usize)]) -> Result<Self, OrderingError> {
        // the adjacency of the unknowns (no self-loops), sorted
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
        for &(r, c) in pairs {
            if r != c {
                adj[r].push(c);
                adj[c].push(r);
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        let mut group_of = vec![0usize; n];
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut index: HashMap<Vec<usize>, usize> = HashMap::new();
        for (i, a) in adj.iter().enumerate() {
            let mut closed = a.clone();
            let at = closed.partition_point(|&j| j < i);
            closed.insert(at, i);
            let g = *index.entry(closed).or_insert_with(|| {
                groups.push(Vec::new());
                groups.len() - 1
            });
            groups[g].push(i);
            group_of[i] = g;
        }
        let too_large = |_| OrderingError::TooLarge(n);
        let mut xadj: Vec<metis_sys::idx_t> = Vec::with_capacity(groups.len() + 1);
        let mut adjncy: Vec<metis_sys::idx_t> = Vec::new();
        let mut vwgt: Vec<metis_sys::idx_t> = Vec::with_capacity(groups.len());
        xadj.push(0);
        for members in &groups {
            let mut nb: Vec<usize> = adj[members[0]]
                .iter()
                .map(|&j| group_of[j])
                .filter(|&h| h != group_of[members[0]])
                .collect();
            nb.sort_unstable();
            nb.dedup();
            for h in nb {
                adjncy.push(metis_sys::idx_t::try_from(h).map_err(too_large)?);
            }
            xadj.push(metis_sys::idx_t::try_from(adjncy.len()).map_err(too_large)?);
            vwgt.push(metis_sys::idx_t::try_from(members.len()).map_err(too_large)?);
        }
        Ok(Self {
            groups,
            xadj,
            adjncy,
            vwgt,
        })
    }

    /// METIS's options: [`SEPARATORS`] separators per split, the seed [`SEED`], 0-based.
    fn options() -> [metis_sys::idx_t; metis_sys::METIS_NOPTIONS as usize] {
        let mut options = [0 as metis_sys::idx_t; metis_sys::METIS_NOPTIONS as usize];
        // SAFETY: `options` has the METIS_NOPTIONS entries METIS writes.
        unsafe { metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr()) };
        options[metis_sys::moptions_et_METIS_OPTION_NSEPS as usize] = SEPARATORS;
        options[metis_sys::moptions_et_METIS_OPTION_SEED as usize] = SEED;
        options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        options
    }
}

/// The nested-dissection permutation of the symmetric pattern `pairs` (row, col) on `n`
/// unknowns: `perm[k]` is the unknown eliminated k-th. METIS's order, renumbered to a
/// postorder of its elimination tree (`postordered`): the same fill and flops, and the
/// supernodes that METIS's order splits are whole.
pub fn nested_dissection(n: usize, pairs: &[(usize, usize)]) -> Result<Vec<usize>, OrderingError> {
    Ok(postordered(n, pairs, &metis_order(n, pairs)?))
}

/// The elimination tree of the pattern `pairs` on `n` unknowns eliminated in the order `perm`
/// (`perm[k]` k-th), in elimination positions: `parent[k]`, or `usize::MAX` at a root (Liu's
/// algorithm with path compression).
pub(crate) fn elimination_tree(n: usize, pairs: &[(usize, usize)], perm: &[usize]) -> Vec<usize> {
    let inv = inverse(perm);
    // per position k, the positions i < k coupled to it (the rows of the lower triangle)
    let coupled = || {
        pairs
            .iter()
            .map(|&(r, c)| (inv[r].min(inv[c]), inv[r].max(inv[c])))
            .filter(|&(i, k)| i != k)
    };
    let mut start = vec![0usize; n + 1];
    for (_, k) in coupled() {
        start[k + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let mut below = vec![0usize; start[n]];
    for (i, k) in coupled() {
        below[next[k]] = i;
        next[k] += 1;
    }
    let mut parent = vec![usize::MAX; n];
    let mut ancestor = vec![usize::MAX; n];
    for k in 0..n {
        for &i0 in &below[start[k]..start[k + 1]] {
            // climb from i0 to its root so far, pointing the path at k
            let mut i = i0;
            while i < k {
                let up = ancestor[i];
                ancestor[i] = k;
                if up == usize::MAX {
                    parent[i] = k;
                }
                i = up;
            }
        }
    }
    parent
}

/// The inverse of the permutation `perm`: `inverse(perm)[perm[k]] = k`.
pub(crate) fn inverse(perm: &[usize]) -> Vec<usize> {
    let mut inv = vec![0usize; perm.len()];
    for (k, &p) in perm.iter().enumerate() {
        inv[p] = k;
    }
    inv
}

/// `perm` renumbered to a postorder of its elimination tree (each subtree's positions
/// contiguous, its root last; children in their order in `perm`). The postorder is an
/// equivalent order: the same factor's pattern up to the renumbering, so the same fill and
/// flops. faer's supernodal analysis takes a custom order as it is, and finds a supernode
/// only in consecutive columns, each the parent of the one before; METIS's order interleaves
/// subtrees, so on the million-unknown tube it left 173 k supernodes, most of one node (issue
/// #30's measurement), where the postorder gives 76,671 (faer's default relaxation; example
/// `supernode_bound`). The test below checks the drop on a grid.
pub(crate) fn postordered(n: usize, pairs: &[(usize, usize)], perm: &[usize]) -> Vec<usize> {
    let parent = elimination_tree(n, pairs, perm);
    // children lists in ascending order: pushed from the last
    let mut head = vec![usize::MAX; n];
    let mut sibling = vec![usize::MAX; n];
    for k in (0..n).rev() {
        if parent[k] != usize::MAX {
            sibling[k] = head[parent[k]];
            head[parent[k]] = k;
        }
    }
    let mut order = Vec::with_capacity(n);
    let mut pending: Vec<(usize, usize)> = Vec::new();
    for root in (0..n).filter(|&k| parent[k] == usize::MAX) {
        pending.push((root, head[root]));
        while let Some(&mut (k, ref mut child)) = pending.last_mut() {
            if *child == usize::MAX {
                order.push(perm[k]);
                pending.pop();
            } else {
                let c = *child;
                *child = sibling[c];
                pending.push((c, head[c]));
            }
        }
    }
    order
}

/// METIS's nested-dissection order of `pairs` on `n` unknowns (`perm[k]` k-th).
fn metis_order(n: usize, pairs: &[(usize, usize)]) -> Result<Vec<usize>, OrderingError> {
    if n == 0 {
        return Ok(Vec::new());
    }
    let mut q = Quotient::new(n, pairs)?;
    let m = q.groups.len();
    if m == 1 {
        return Ok(q.groups.swap_remove(0));
    }
    let mut nvtxs = metis_sys::idx_t::try_from(m).map_err(|_| OrderingError::TooLarge(n))?;
    let mut options = Quotient::options();
    let mut perm = vec![0 as metis_sys::idx_t; m];
    let mut iperm = vec![0 as metis_sys::idx_t; m];
    // SAFETY: every array has the length METIS reads (options METIS_NOPTIONS, xadj m + 1,
    // adjncy xadj[m], vwgt, perm and iperm m), the graph is symmetric without self-loops, and
    // METIS keeps no pointer past the call.
    let _metis = METIS.lock().unwrap_or_else(|e| e.into_inner());
    let status = unsafe {
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            q.xadj.as_mut_ptr(),
            q.adjncy.as_mut_ptr(),
            q.vwgt.as_mut_ptr(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(OrderingError::Metis(status));
    }
    // perm[k]: the quotient vertex eliminated k-th (METIS: row k of the permuted matrix is row
    // perm[k] of the original); each vertex's unknowns in ascending order
    Ok(perm
        .iter()
        .flat_map(|&g| q.groups[g as usize].iter().copied())
        .collect())
}

/// METIS's vertex separator of the symmetric pattern `pairs` (row, col) on `n` unknowns (the
/// top split of its nested dissection, on the same quotient graph, separators and seed): per
/// unknown 0 or 1, the half it lies in, or 2, the separator. No pair couples the two halves;
/// a node's unknowns stay together. `None` when the graph has fewer than two vertices.
pub fn bisection(n: usize, pairs: &[(usize, usize)]) -> Result<Option<Vec<u8>>, OrderingError> {
    if n == 0 {
        return Ok(None);
    }
    let mut q = Quotient::new(n, pairs)?;
    let m = q.groups.len();
    if m < 2 {
        return Ok(None);
    }
    let mut nvtxs = metis_sys::idx_t::try_from(m).map_err(|_| OrderingError::TooLarge(n))?;
    let mut options = Quotient::options();
    let mut sepsize: metis_sys::idx_t = 0;
    let mut part = vec![0 as metis_sys::idx_t; m];
    // SAFETY: as in `nested_dissection`; `part` has the m entries METIS writes.
    let _metis = METIS.lock().unwrap_or_else(|e| e.into_inner());
    let status = unsafe {
        metis_sys::METIS_ComputeVertexSeparator(
            &mut nvtxs,
            q.xadj.as_mut_ptr(),
            q.adjncy.as_mut_ptr(),
            q.vwgt.as_mut_ptr(),
            options.as_mut_ptr(),
            &mut sepsize,
            part.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(OrderingError::Metis(status));
    }
    let mut side = vec![2u8; n];
    for (g, members) in q.groups.iter().enumerate() {
        let s = u8::try_from(part[g]).ok().filter(|&s| s <= 2);
        let s = s.ok_or(OrderingError::Metis(metis_sys::rstatus_et_METIS_ERROR))?;
        for &i in members {
            side[i] = s;
        }
    }
    Ok(Some(side))
}

/// A 2D grid of `k` × `k` nodes with 3 unknowns each, coupled like bilinear elements: the
/// unknowns and the (row, col) pairs, row ≥ col (for the tests of orderings and factors).
#[cfg(test)]
pub(crate) fn grid(k: usize) -> (usize, Vec<(usize, usize)>) {
    let node = |i: usize, j: usize| i * k + j;
    let mut pairs = std::collections::BTreeSet::new();
    for i in 0..k - 1 {
        for j in 0..k - 1 {
            let q = [
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            ];
            for &a in &q {
                for &b in &q {
                    for ca in 0..3 {
                        for cb in 0..3 {
                            let (r, c) = (3 * a + ca, 3 * b + cb);
                            if r >= c {
                                pairs.insert((r, c));
                            }
                        }
                    }
                }
            }
        }
    }
    (3 * k * k, pairs.into_iter().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_dissection_is_a_permutation_that_keeps_a_nodes_unknowns_together() {
        let (n, pairs) = grid(12);
        let perm = nested_dissection(n, &pairs).unwrap();
        let mut seen = vec![false; n];
        for &p in &perm {
            assert!(!seen[p], "{p} twice");
            seen[p] = true;
        }
        assert!(seen.iter().all(|&s| s));
        for triple in perm.chunks(3) {
            assert_eq!(
                triple[0] / 3,
                triple[2] / 3,
                "a node's unknowns split: {triple:?}"
            );
            assert_eq!(triple, [triple[0], triple[0] + 1, triple[0] + 2]);
        }
        // the same on a second call (a fixed seed)
        assert_eq!(perm, nested_dissection(n, &pairs).unwrap());
    }

    /// Whether `parent` (positions) is a postorder's tree: each parent after its children,
    /// and each subtree's positions contiguous with its root last.
    fn is_postorder(parent: &[usize]) -> bool {
        let n = parent.len();
        let mut size = vec![1usize; n];
        for k in 0..n {
            if parent[k] != usize::MAX {
                if parent[k] <= k {
                    return false;
                }
                size[parent[k]] += size[k];
            }
        }
        // the subtree of k is k + 1 − size[k] ..= k: a child's lies inside its parent's
        (0..n)
            .all(|k| parent[k] == usize::MAX || k + 1 - size[k] >= parent[k] + 1 - size[parent[k]])
            && (0..n).all(|k| size[k] <= k + 1)
    }

    /// faer's symbolic factor of `pairs` eliminated in the order `perm`, simplicial or
    /// supernodal (faer's default relaxation).
    fn symbolic(
        n: usize,
        pairs: &[(usize, usize)],
        perm: &[usize],
        threshold: faer::sparse::linalg::SupernodalThreshold,
    ) -> faer::sparse::linalg::cholesky::SymbolicCholesky<usize> {
        use faer::sparse::linalg::cholesky::{
            factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
        };
        let inv = inverse(perm);
        let triplets: Vec<_> = pairs
            .iter()
            .map(|&(r, c)| faer::sparse::Triplet::new(inv[r].max(inv[c]), inv[r].min(inv[c]), 1.0))
            .collect();
        let m = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .unwrap();
        let id: Vec<usize> = (0..n).collect();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: threshold,
            ..Default::default()
        };
        factorize_symbolic_cholesky(
            m.symbolic(),
            faer::Side::Lower,
            SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(&id, &id, n)),
            params,
        )
        .unwrap()
    }

    /// The entries of the (simplicial) factor of `pairs` in the order `perm`.
    fn factor_entries(n: usize, pairs: &[(usize, usize)], perm: &[usize]) -> usize {
        use faer::sparse::linalg::SupernodalThreshold;
        symbolic(n, pairs, perm, SupernodalThreshold::FORCE_SIMPLICIAL).len_val()
    }

    /// faer's supernodes (default relaxation) of `pairs` in the order `perm`.
    fn supernodes(n: usize, pairs: &[(usize, usize)], perm: &[usize]) -> usize {
        use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
        use faer::sparse::linalg::SupernodalThreshold;
        match symbolic(n, pairs, perm, SupernodalThreshold::FORCE_SUPERNODAL).raw() {
            SymbolicCholeskyRaw::Supernodal(s) => s.n_supernodes(),
            SymbolicCholeskyRaw::Simplicial(_) => unreachable!("forced supernodal"),
        }
    }

    #[test]
    fn the_postorder_keeps_the_fill_and_makes_subtrees_contiguous() {
        let (n, pairs) = grid(30);
        let metis = metis_order(n, &pairs).unwrap();
        let post = nested_dissection(n, &pairs).unwrap();
        assert!(!is_postorder(&elimination_tree(n, &pairs, &metis)));
        assert!(is_postorder(&elimination_tree(n, &pairs, &post)));
        assert_eq!(
            factor_entries(n, &pairs, &post),
            factor_entries(n, &pairs, &metis)
        );
        // a postorder's postorder is itself
        assert_eq!(postordered(n, &pairs, &post), post);
        // faer finds supernodes in consecutive columns only: the postorder gives it fewer
        let (before, after) = (supernodes(n, &pairs, &metis), supernodes(n, &pairs, &post));
        assert!(
            after < before,
            "{after} supernodes against METIS's {before}"
        );
    }

    #[test]
    fn metis_gives_the_same_ordering_when_two_threads_call_it_at_once() {
        // METIS's random generator is global: without the lock, two calls at once interleave
        // their draws and the orderings change from run to run
        let (n, pairs) = grid(30);
        let alone = nested_dissection(n, &pairs).unwrap();
        let split = bisection(n, &pairs).unwrap();
        for _ in 0..8 {
            let (a, b) = std::thread::scope(|s| {
                let a = s.spawn(|| nested_dissection(n, &pairs).unwrap());
                let b = s.spawn(|| bisection(n, &pairs).unwrap());
                (a.join().unwrap(), b.join().unwrap())
            });
            assert_eq!(a, alone);
            assert_eq!(b, split);
        }
    }

    #[test]
    fn the_bisection_separates_the_halves() {
        let (n, pairs) = grid(20);
        let side = bisection(n, &pairs).unwrap().expect("a split");
        for &(r, c) in &pairs {
            assert!(
                side[r] == 2 || side[c] == 2 || side[r] == side[c],
                "{r} and {c} couple the halves"
            );
        }
        let count = |h: u8| side.iter().filter(|&&s| s == h).count();
        // balanced halves and a separator of about one line of the 20 × 20 grid's nodes
        assert!(
            count(0) > n / 4 && count(1) > n / 4,
            "{} {}",
            count(0),
            count(1)
        );
        assert!(count(2) <= 3 * 2 * 20, "separator {}", count(2));
        for k in (0..n).step_by(3) {
            assert!(
                side[k] == side[k + 1] && side[k] == side[k + 2],
                "node {}",
                k / 3
            );
        }
    }
}
