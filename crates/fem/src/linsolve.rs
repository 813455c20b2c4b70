//! Sparse symmetric LDLᵀ on faer: the pattern and the symbolic analysis (AMD ordering,
//! elimination tree, supernodes) are computed once per mesh; each Newton iteration only
//! refills the values (`new_from_argsort`) and refactorizes numerically.
//!
//! LDLᵀ rather than LLᵀ: the tangent of a pressurized membrane is indefinite past a limit point
//! (volume control) and may be singular in flat, unstressed states. The number of negative
//! pivots D_kk < 0 is the inertia index of the matrix (Sylvester), reported at every converged
//! step as a stability indicator: 0 means the equilibrium is stable under the loading control
//! used. faer's LDLᵀ does not pivot; a zero pivot is reported as an error and the Newton driver
//! reacts (shift, cut-back).

use crate::ordering::Ordering;
pub mod multifrontal;
pub mod tree_split;
use crate::FemError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltError;
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::SymmetricOrdering;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{CreationError, FaerError};
use tree_split::TreeSplit;

/// Storage of the factor: faer's choice by flop ratio, or forced (for tests and benchmarks).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Layout {
    #[default]
    Auto,
    Simplicial,
    Supernodal,
}
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

/// How the sparse factorization failed, with faer's error as the source. A zero pivot of the
/// numeric LDLᵀ is not one of these: it is [`FemError::ZeroPivot`], with its index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FactorizationError {
    #[error("cannot build the sparsity pattern")]
    Pattern(#[source] CreationError),
    #[error("the symbolic analysis failed")]
    Symbolic(#[source] FaerError),
    #[error("cannot fill the matrix")]
    Fill(#[source] FaerError),
    #[error("no memory for the factorization's workspace")]
    Workspace(#[source] FaerError),
    #[error("cannot compute the fill-reducing ordering")]
    Ordering(#[source] crate::ordering::OrderingError),
    #[error(
        "a partial factorization up to column {stop} needs the columns from there on in the \
         last supernode, which begins at column {begin}"
    )]
    Trailing { stop: usize, begin: usize },
}

/// The flops of one numeric factorization with the symbolic structure `symbolic` of an `n` × `n`
/// matrix ([`SparseLdlt::factor_flops`]).
pub(crate) fn symbolic_flops(symbolic: &SymbolicCholesky<usize>, n: usize) -> f64 {
    let col = |c: f64| c * (c + 2.0);
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let p = s.col_ptr();
            (0..n).map(|k| col((p[k + 1] - p[k]) as f64 - 1.0)).sum()
        }
        SymbolicCholeskyRaw::Supernodal(s) => supernodal_flops(s, n),
    }
}

/// The entries of the factor in the columns before `stop` of the supernodal structure `s`
/// (all of its values for `stop` = n; a partial factorization's factor otherwise).
pub(crate) fn supernodal_entries(
    s: &faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize>,
    stop: usize,
) -> usize {
    let (begin, end, val) = (s.supernode_begin(), s.supernode_end(), s.col_ptr_for_val());
    (0..s.n_supernodes())
        .map(|k| {
            let ncols = end[k] - begin[k];
            (val[k + 1] - val[k]) / ncols * ncols.min(stop.saturating_sub(begin[k]))
        })
        .sum()
}

/// The flops of eliminating the columns before `stop` of the supernodal structure `s` (all
/// of them for `stop` = n; a partial factorization's, [`multifrontal::Multifrontal::partial`],
/// otherwise), counted as [`symbolic_flops`] counts them.
pub(crate) fn supernodal_flops(
    s: &faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize>,
    stop: usize,
) -> f64 {
    let col = |c: f64| c * (c + 2.0);
    let (begin, end) = (s.supernode_begin(), s.supernode_end());
    let val = s.col_ptr_for_val();
    (0..s.n_supernodes())
        .map(|k| {
            let ncols = end[k] - begin[k];
            let nrows = (val[k + 1] - val[k]) / ncols;
            (0..ncols.min(stop.saturating_sub(begin[k])))
                .map(|j| col((nrows - j - 1) as f64))
                .sum::<f64>()
        })
        .sum()
}

/// The factor: faer's supernodal or simplicial LDLᵀ of the whole matrix, or the split at the
/// top separator ([`crate::linsolve::tree_split`]).
/// A whole factor keeps K's pattern (lower triangle, duplicates merged) and the map from the
/// values given to it; a split factor does not need them (its halves have their own), which at
/// a million unknowns saves some 300 MB.
enum Factor {
    Whole {
        symbolic: Box<SymbolicCholesky<usize>>,
        l_values: Vec<f64>,
        pattern: SymbolicSparseColMat<usize>,
        argsort: Argsort<usize>,
    },
    Split(Box<TreeSplit>),
}

/// The fewest unknowns for which a nested-dissection factorization is split at its top
/// separator ([`crate::linsolve::tree_split`]); with `auto`, the split is kept when its flops are fewer
/// than AMD's whole factor's. Below, a factorization takes under about 0.1 s (61,158 unknowns of
/// the whole tube: 0.13 s on one thread, `examples/subtree_split.rs`) and the split's setup (a
/// third METIS call and two more symbolic analyses) is not repaid; every shipped case is below
/// it and keeps its whole factor bit for bit.
pub const SPLIT_MIN_UNKNOWNS: usize = 100_000;

/// A symmetric sparse matrix pattern (lower triangle) with its symbolic factorization.
pub struct SparseLdlt {
    n: usize,
    entries: usize,
    factor: Factor,
    factorized: bool,
    /// the parallelism of the numeric factorization and the solves
    par: Par,
    /// the ordering the symbolic analysis used (`Auto` resolved to the one it kept)
    ordering: Ordering,
}

/// `attempt(0)`, then where it fails `attempt(s − s_prev)` for each shift s of `shifts` in turn
/// (each attempt adds its argument to the diagonal, so the k-th one factorizes with shift
/// `shifts[k]`): the negative pivots and the shift of the first that factorizes, or the first
/// failure.
fn with_shifts(
    shifts: &[f64],
    mut attempt: impl FnMut(f64) -> Result<usize, FemError>,
) -> Result<(usize, f64), FemError> {
    let first = match attempt(0.0) {
        Ok(neg) => return Ok((neg, 0.0)),
        Err(e) => e,
    };
    let mut applied = 0.0;
    for &s in shifts {
        let result = attempt(s - applied);
        applied = s;
        if let Ok(neg) = result {
            return Ok((neg, s));
        }
    }
    Err(first)
}

impl SparseLdlt {
    /// `pairs`: the (row, col) positions, row ≥ col, in the order in which values will be given
    /// (duplicates are summed).
    pub fn new(n: usize, pairs: &[(usize, usize)]) -> Result<Self, FemError> {
        Self::with_layout(n, pairs, Layout::Auto)
    }

    /// As [`SparseLdlt::new`], with the factor layout chosen.
    pub fn with_layout(
        n: usize,
        pairs: &[(usize, usize)],
        layout: Layout,
    ) -> Result<Self, FemError> {
        Self::with_options(n, pairs, layout, Ordering::Amd)
    }

    /// As [`SparseLdlt::new`], with the factor layout and the fill-reducing ordering chosen.
    pub fn with_options(
        n: usize,
        pairs: &[(usize, usize)],
        layout: Layout,
        ordering: Ordering,
    ) -> Result<Self, FemError> {
        // K's pattern (lower triangle, duplicates merged) and the map from the values
        let merged = || -> Result<_, FactorizationError> {
            let idx: Vec<Pair<usize, usize>> = pairs
                .iter()
                .map(|&(r, c)| Pair::new(r.max(c), r.min(c)))
                .collect();
            SymbolicSparseColMat::try_new_from_indices(n, n, &idx)
                .map_err(FactorizationError::Pattern)
        };
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: match layout {
                Layout::Auto => SupernodalThreshold::AUTO,
                Layout::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
                Layout::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
            },
            ..Default::default()
        };
        let amd = |pattern: &SymbolicSparseColMat<usize>| {
            factorize_symbolic_cholesky(
                pattern.as_ref(),
                Side::Lower,
                SymmetricOrdering::Amd,
                params,
            )
            .map_err(FactorizationError::Symbolic)
        };
        let nested = |pattern: &SymbolicSparseColMat<usize>| -> Result<SymbolicCholesky<usize>, FactorizationError> {
            let perm = crate::ordering::nested_dissection(n, pairs)
                .map_err(FactorizationError::Ordering)?;
            let inverse = crate::ordering::inverse(&perm);
            factorize_symbolic_cholesky(
                pattern.as_ref(),
                Side::Lower,
                SymmetricOrdering::Custom(PermRef::new_checked(&perm, &inverse, n)),
                params,
            )
            .map_err(FactorizationError::Symbolic)
        };
        let whole =
            |symbolic: SymbolicCholesky<usize>,
             (pattern, argsort): (SymbolicSparseColMat<usize>, Argsort<usize>)| {
                Factor::Whole {
                    l_values: vec![0.0; symbolic.len_val()],
                    symbolic: Box::new(symbolic),
                    pattern,
                    argsort,
                }
            };
        // nested dissection on a large matrix: its top split as two halves factorized side by
        // side ([`crate::linsolve::tree_split`]); METIS's top separator is the one its nested dissection
        // of the whole would start from, so the flops are the same within about 1 %
        let split = if ordering != Ordering::Amd && n >= SPLIT_MIN_UNKNOWNS {
            TreeSplit::new(n, pairs)?
        } else {
            None
        };
        let (factor, ordering) = match (ordering, split) {
            (Ordering::Amd, _) => {
                let m = merged()?;
                (whole(amd(&m.0)?, m), Ordering::Amd)
            }
            (Ordering::NestedDissection, Some(t)) => {
                (Factor::Split(Box::new(t)), Ordering::NestedDissection)
            }
            (Ordering::NestedDissection, None) => {
                let m = merged()?;
                (whole(nested(&m.0)?, m), Ordering::NestedDissection)
            }
            (Ordering::Auto, Some(t)) => {
                // the split against AMD, by flops
                let m = merged()?;
                let a = amd(&m.0)?;
                if t.flops() < symbolic_flops(&a, n) {
                    (Factor::Split(Box::new(t)), Ordering::NestedDissection)
                } else {
                    (whole(a, m), Ordering::Amd)
                }
            }
            (Ordering::Auto, None) => {
                // both analyses, and the one whose factorization costs fewer flops (AMD on a
                // tie, so a pattern where nested dissection gains nothing keeps AMD's factor)
                let m = merged()?;
                let (a, d) = (amd(&m.0)?, nested(&m.0)?);
                if symbolic_flops(&d, n) < symbolic_flops(&a, n) {
                    (whole(d, m), Ordering::NestedDissection)
                } else {
                    (whole(a, m), Ordering::Amd)
                }
            }
        };
        Ok(Self::unfactorized(n, pairs.len(), factor, ordering))
    }

    /// The tree split of the pattern `pairs` on `n` unknowns whatever its size (runs use it from
    /// [`SPLIT_MIN_UNKNOWNS`] up): the halves' multifrontal LDLᵀ, our own numeric layer, on any
    /// pattern, to check it against faer's own factorization of the whole
    /// ([`SparseLdlt::with_options`] with nested dissection) on small patterns too. `None`
    /// where METIS leaves a half empty.
    pub fn split_of(n: usize, pairs: &[(usize, usize)]) -> Result<Option<Self>, FemError> {
        Ok(TreeSplit::new(n, pairs)?.map(|t| {
            Self::unfactorized(
                n,
                pairs.len(),
                Factor::Split(Box::new(t)),
                Ordering::NestedDissection,
            )
        }))
    }

    /// A factor of `n` unknowns and `entries` values, before its first numeric factorization.
    fn unfactorized(n: usize, entries: usize, factor: Factor, ordering: Ordering) -> Self {
        Self {
            n,
            entries,
            factor,
            factorized: false,
            par: Par::Seq,
            ordering,
        }
    }

    /// The threads of the numeric factorization of a whole factor, inside its supernodes: 1
    /// sequential (the default), n on n threads of the current rayon pool (0: all of them).
    /// faer parallelizes inside each supernode's dense kernels (the supernodes are eliminated in
    /// a fixed order, and each output block of a parallel product is summed by one thread in a
    /// fixed order), so the factor does not depend on the thread count:
    /// `factor_is_bitwise_the_same_on_1_and_2_threads`; its solves stay sequential (see
    /// [`SparseLdlt::solve`]). A split factor ([`crate::linsolve::tree_split`]) factorizes and solves its
    /// two halves side by side on the current rayon pool whatever this says (one after the other
    /// on a pool of one thread), each half sequential inside, with the same bits either way.
    pub fn set_threads(&mut self, threads: usize) {
        self.par = if threads == 1 {
            Par::Seq
        } else {
            Par::rayon(threads)
        };
    }

    /// The separator's unknowns when the factorization is split at the top separator
    /// ([`crate::linsolve::tree_split`]), `None` for a whole factor.
    pub fn split_separator(&self) -> Option<usize> {
        match &self.factor {
            Factor::Split(t) => Some(t.separator_len()),
            Factor::Whole { .. } => None,
        }
    }

    /// The ordering the symbolic analysis used: `Amd` or `NestedDissection` (what `Auto` kept).
    pub fn ordering(&self) -> Ordering {
        self.ordering
    }

    /// The threads of the numeric factorization, as [`SparseLdlt::set_threads`] takes them.
    pub fn threads(&self) -> usize {
        match self.par {
            Par::Seq => 1,
            Par::Rayon(n) => n.get(),
        }
    }

    /// The floating-point operations of one numeric factorization, from the symbolic structure:
    /// Σ_k c_k (c_k + 2) with c_k the number of entries of column k of L below the diagonal (the
    /// c_k(c_k + 1)/2 multiply–adds of the rank-one update of column k, multiplications and
    /// additions counted apart, plus its c_k scalings and c_k products with D). The usual count
    /// of sparse Cholesky (George & Liu), the one dense LDLᵀ's n³/3 comes from.
    /// A split factor counts its halves, the trailing products and the separator's dense
    /// LDLᵀ ([`crate::linsolve::tree_split`]).
    pub fn factor_flops(&self) -> f64 {
        match &self.factor {
            Factor::Whole { symbolic, .. } => symbolic_flops(symbolic, self.n),
            Factor::Split(t) => t.flops(),
        }
    }

    pub fn dim(&self) -> usize {
        self.n
    }

    /// Number of nonzeros in the factor (a memory measure).
    pub fn factor_nnz(&self) -> usize {
        match &self.factor {
            Factor::Whole { l_values, .. } => l_values.len(),
            Factor::Split(t) => t.nnz(),
        }
    }

    /// Numeric LDLᵀ of the matrix whose values (one per pair given to `new`) are `values`.
    /// Returns the number of negative pivots.
    pub fn factorize(&mut self, values: &[f64]) -> Result<usize, FemError> {
        self.factorized = false;
        let negative = match &mut self.factor {
            Factor::Split(t) => {
                Self::check_finite(values, self.entries)?;
                t.factorize(values)?
            }
            Factor::Whole {
                symbolic,
                l_values,
                pattern,
                argsort,
            } => {
                let mat = Self::fill(pattern, argsort, self.entries, values)?;
                let par = self.par;
                let req = symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default());
                let mut mem = MemBuffer::try_new(req)
                    .map_err(|e| FactorizationError::Workspace(FaerError::from(e)))?;
                let reg = LdltRegularization {
                    dynamic_regularization_signs: None,
                    dynamic_regularization_delta: 0.0,
                    dynamic_regularization_epsilon: 0.0,
                };
                symbolic
                    .factorize_numeric_ldlt::<f64>(
                        l_values,
                        mat.as_ref(),
                        Side::Lower,
                        reg,
                        par,
                        MemStack::new(&mut mem),
                        Default::default(),
                    )
                    .map_err(|e| match e {
                        LdltError::ZeroPivot { index } => FemError::ZeroPivot { index, value: 0.0 },
                    })?;
                let d = self.pivots();
                if let Some(index) = d.iter().position(|v| !v.is_finite() || *v == 0.0) {
                    return Err(FemError::ZeroPivot {
                        index,
                        value: d[index],
                    });
                }
                d.iter().filter(|&&v| v < 0.0).count()
            }
        };
        self.factorized = true;
        Ok(negative)
    }

    /// Numeric LDLᵀ of `values` (one per pair given to `new`), taken: a split factor drops
    /// them once its halves have gathered theirs, before its numeric factorization (at a
    /// million unknowns, 0.2 GB less at the peak). Where it fails, the diagonal is shifted by
    /// each of `shifts` in turn (absolute, ascending; `diagonal`: the position in `values` of
    /// one entry of each diagonal) and factorized again. Returns the negative pivots and the
    /// shift that factorized (0 without one), or the first failure.
    ///
    /// A whole factor adds the shift to `values` at `diagonal`, a split one to its halves'
    /// gathered sums (so a shifted split factor may differ from a whole one in the last bits
    /// of the shifted diagonal; unshifted, each is what [`SparseLdlt::factorize`] gives).
    pub fn factorize_shifted(
        &mut self,
        mut values: Vec<f64>,
        diagonal: &[usize],
        shifts: &[f64],
    ) -> Result<(usize, f64), FemError> {
        if let Factor::Split(t) = &mut self.factor {
            self.factorized = false;
            assert_eq!(values.len(), self.entries, "one value per pattern entry");
            // the halves see every value as they gather: a non-finite one is looked for (and
            // named) only when they saw one
            if !t.gather(&values) {
                Self::check_finite(&values, self.entries)?;
            }
            drop(values);
            let result = with_shifts(shifts, |delta| {
                if delta != 0.0 {
                    t.shift(delta);
                }
                t.factorize_gathered()
            });
            self.factorized = result.is_ok();
            return result;
        }
        with_shifts(shifts, |delta| {
            if delta != 0.0 {
                for &d in diagonal {
                    values[d] += delta;
                }
            }
            self.factorize(&values)
        })
    }

    /// The pivots D_kk of the last factorization (in elimination order; a split factor's: the
    /// two halves', then the separator's).
    pub fn pivots(&self) -> Vec<f64> {
        let (symbolic, l_values) = match &self.factor {
            Factor::Whole {
                symbolic, l_values, ..
            } => (symbolic, l_values),
            Factor::Split(t) => return t.pivots(),
        };
        match symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                s.col_ptr()[..self.n].iter().map(|&p| l_values[p]).collect()
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let begin = s.supernode_begin();
                let end = s.supernode_end();
                let val = s.col_ptr_for_val();
                let mut d = Vec::with_capacity(self.n);
                for k in 0..s.n_supernodes() {
                    let ncols = end[k] - begin[k];
                    let nrows = (val[k + 1] - val[k]) / ncols;
                    for j in 0..ncols {
                        d.push(l_values[val[k] + j * nrows + j]);
                    }
                }
                d
            }
        }
    }

    /// Whether the last numeric factorization succeeded (a solve may follow).
    pub fn is_factorized(&self) -> bool {
        self.factorized
    }

    /// The symmetric matrix whose values (one per pair given to `new`, duplicates summed)
    /// are `values`, as an operator ([`SymmetricMatrix::apply`]).
    pub fn matrix(&self, values: &[f64]) -> Result<SymmetricMatrix<'_>, FemError> {
        Ok(SymmetricMatrix(match &self.factor {
            Factor::Whole {
                pattern, argsort, ..
            } => Operator::Lower(Self::fill(pattern, argsort, self.entries, values)?),
            Factor::Split(t) => {
                Self::check_finite(values, self.entries)?;
                Operator::Split(t.matrix(values))
            }
        }))
    }

    /// [`SparseLdlt::filled`] from the pattern's parts.
    fn fill(
        pattern: &SymbolicSparseColMat<usize>,
        argsort: &Argsort<usize>,
        entries: usize,
        values: &[f64],
    ) -> Result<SparseColMat<usize, f64>, FemError> {
        Self::check_finite(values, entries)?;
        Ok(
            SparseColMat::new_from_argsort(pattern.clone(), argsort, values)
                .map_err(FactorizationError::Fill)?,
        )
    }

    /// One value per pattern entry, each finite.
    fn check_finite(values: &[f64], entries: usize) -> Result<(), FemError> {
        assert_eq!(values.len(), entries, "one value per pattern entry");
        match values.iter().position(|v| !v.is_finite()) {
            Some(entry) => Err(FemError::NonFiniteEntry { entry }),
            None => Ok(()),
        }
    }

    /// Solve A y = rhs in place with the last factorization.
    pub fn solve(&self, rhs: &mut [f64]) {
        assert!(self.factorized, "solve after a successful factorize");
        let (symbolic, l_values) = match &self.factor {
            Factor::Whole {
                symbolic, l_values, ..
            } => (symbolic, l_values),
            Factor::Split(t) => return t.solve(rhs),
        };
        // sequential whatever the factorization's threads: faer's parallel triangular solve
        // sums in an order that depends on the thread count (measured: the solution differs in
        // the last bits on 2 threads), and a solve is O(nnz(L)), a small part of an iteration
        let par = Par::Seq;
        let req = symbolic.solve_in_place_scratch::<f64>(1, par);
        let mut mem = MemBuffer::new(req);
        let n = self.n;
        let ldlt = LdltRef::<'_, usize, f64>::new(symbolic, l_values);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            par,
            MemStack::new(&mut mem),
        );
    }
}

/// A symmetric sparse matrix as an operator ([`SparseLdlt::matrix`]): by its lower triangle,
/// or, for a split factor, as the sum of the split's two halves.
pub struct SymmetricMatrix<'a>(Operator<'a>);

enum Operator<'a> {
    Lower(SparseColMat<usize, f64>),
    Split(tree_split::SplitMatrix<'a>),
}

impl SymmetricMatrix<'_> {
    /// out = A x, column by column in a fixed order (sequential: the sums do not depend on the
    /// number of threads).
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        match &self.0 {
            Operator::Lower(m) => {
                out.iter_mut().for_each(|v| *v = 0.0);
                let m = m.as_ref();
                apply_lower(
                    m.symbolic().col_ptr(),
                    m.symbolic().row_idx(),
                    m.val(),
                    x,
                    out,
                );
            }
            Operator::Split(m) => m.apply(x, out),
        }
    }
}

/// out += A x for the symmetric A whose lower triangle is (`ptr`, `rows`, `vals`) by column,
/// column by column in a fixed order.
pub(crate) fn apply_lower(ptr: &[usize], rows: &[usize], vals: &[f64], x: &[f64], out: &mut [f64]) {
    for j in 0..x.len() {
        let xj = x[j];
        let mut yj = 0.0;
        for k in ptr[j]..ptr[j + 1] {
            let (i, a) = (rows[k], vals[k]);
            out[i] += a * xj;
            if i != j {
                yj += a * x[i];
            }
        }
        out[j] += yj;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tridiagonal matrix with known inertia: diag(d) + 0.1 off-diagonals, solved and its
    /// negative pivots counted; reference: the solution of the dense system and the number of
    /// negative eigenvalues (Sylvester's law of inertia: equal to the negative pivot count).
    #[test]
    fn ldlt_solves_and_counts_negative_pivots() {
        for n in [7usize, 300] {
            let d: Vec<f64> = (0..n)
                .map(|i| {
                    if i % 5 == 2 {
                        -2.0 - i as f64 * 0.01
                    } else {
                        3.0 + i as f64 * 0.01
                    }
                })
                .collect();
            let mut pairs = vec![];
            let mut vals = vec![];
            for i in 0..n {
                pairs.push((i, i));
                vals.push(d[i]);
                if i + 1 < n {
                    // given twice, half each: duplicates must be summed
                    pairs.push((i + 1, i));
                    vals.push(0.05);
                    pairs.push((i, i + 1));
                    vals.push(0.05);
                }
            }
            let mut s = SparseLdlt::with_layout(n, &pairs, Layout::Simplicial).unwrap();
            let neg = s.factorize(&vals).unwrap();
            // Off-diagonals 0.1 ≪ |d| ≥ 2: Gershgorin keeps each eigenvalue's sign = sign(d_i).
            assert_eq!(neg, d.iter().filter(|&&v| v < 0.0).count());
            let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
            let mut b: Vec<f64> = (0..n)
                .map(|i| {
                    d[i] * x[i]
                        + if i > 0 { 0.1 * x[i - 1] } else { 0.0 }
                        + if i + 1 < n { 0.1 * x[i + 1] } else { 0.0 }
                })
                .collect();
            // the operator of the same values (duplicates summed, both triangles) gives b, to
            // the rounding of three products of size ≤ 7 (≈ 1e-15)
            let mut ax = vec![0.0; n];
            s.matrix(&vals).unwrap().apply(&x, &mut ax);
            for i in 0..n {
                assert!((ax[i] - b[i]).abs() < 1e-14, "(Ax)[{i}]");
            }
            s.solve(&mut b);
            for i in 0..n {
                assert!((b[i] - x[i]).abs() < 1e-12, "x[{i}]");
            }
        }
    }

    /// The ordering changes the factor, not what it says: on a 2D grid of nodes with 3 unknowns
    /// each (bilinear coupling), an indefinite matrix whose eigenvalue signs are those of its
    /// diagonal (Gershgorin: |d| ≥ 2 against off-diagonal row sums ≤ 35 × 0.05) factorized with
    /// AMD and with nested dissection gives the inertia of the diagonal and the same solution.
    #[test]
    fn the_ordering_changes_the_factor_not_the_inertia_or_the_solution() {
        let (n, grid) = crate::ordering::grid(20);
        let set: Vec<(usize, usize)> = grid.into_iter().filter(|&(r, c)| r > c).collect();
        let d: Vec<f64> = (0..n)
            .map(|i| {
                if i % 7 == 3 {
                    -2.0 - 0.001 * i as f64
                } else {
                    2.0 + 0.001 * i as f64
                }
            })
            .collect();
        let off = |r: usize, c: usize| 0.05 * (((r * 31 + c * 17) % 11) as f64 / 10.0 - 0.5);
        let mut pairs: Vec<(usize, usize)> = (0..n).map(|i| (i, i)).collect();
        let mut vals = d.clone();
        for &(r, c) in &set {
            pairs.push((r, c));
            vals.push(off(r, c));
        }
        let x: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos()).collect();
        let mut b: Vec<f64> = (0..n).map(|i| d[i] * x[i]).collect();
        for &(r, c) in &set {
            b[r] += off(r, c) * x[c];
            b[c] += off(r, c) * x[r];
        }
        let expected = d.iter().filter(|&&v| v < 0.0).count();
        let mut flops = Vec::new();
        let mut kept = Vec::new();
        for ordering in [Ordering::Amd, Ordering::NestedDissection, Ordering::Auto] {
            let mut s = SparseLdlt::with_options(n, &pairs, Layout::Auto, ordering).unwrap();
            kept.push(s.ordering());
            assert_eq!(s.factorize(&vals).unwrap(), expected, "{ordering:?}");
            let mut y = b.clone();
            s.solve(&mut y);
            // |d| ≥ 2 against row sums ≤ 1.75 bound the condition number by 3.75/0.25 = 15, so
            // the backward-stable solve is exact to about 15 × 1e-16
            for i in 0..n {
                assert!((y[i] - x[i]).abs() < 1e-12, "{ordering:?}: x[{i}]");
            }
            flops.push(s.factor_flops());
        }
        // the two orderings are different factorizations, and `auto` keeps the cheaper
        assert_ne!(flops[0], flops[1]);
        assert_eq!(flops[2], flops[0].min(flops[1]));
        let cheaper = if flops[1] < flops[0] {
            Ordering::NestedDissection
        } else {
            Ordering::Amd
        };
        assert_eq!(kept, [Ordering::Amd, Ordering::NestedDissection, cheaper]);
    }

    /// A wide-band matrix makes faer choose the supernodal layout, whose pivots are read from
    /// the diagonal of each supernode's block: the count must still equal the inertia.
    #[test]
    fn ldlt_counts_negative_pivots_in_supernodal_layout() {
        let (n, band) = (600usize, 40usize);
        let d: Vec<f64> = (0..n)
            .map(|i| if i % 7 == 3 { -100.0 } else { 100.0 })
            .collect();
        let mut pairs = vec![];
        let mut vals = vec![];
        for j in 0..n {
            for i in j..(j + band + 1).min(n) {
                pairs.push((i, j));
                vals.push(if i == j {
                    d[i]
                } else {
                    0.5 / (1.0 + (i - j) as f64)
                });
            }
        }
        let mut s = SparseLdlt::with_layout(n, &pairs, Layout::Supernodal).unwrap();
        assert!(
            matches!(&s.factor, Factor::Whole { symbolic, .. } if matches!(symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_))),
            "expected a supernodal factor"
        );
        // Off-diagonal row sums < 2·Σ 0.5/k ≈ 4.4 ≪ 100: eigenvalue signs follow d (Gershgorin).
        let neg = s.factorize(&vals).unwrap();
        assert_eq!(neg, d.iter().filter(|&&v| v < 0.0).count());
        assert_eq!(s.pivots().len(), n);
    }

    /// The factor and the solution are bitwise the same on 1 and 2 threads (a supernodal
    /// factor with large supernodes, where faer's dense kernels do split the work), and the flop
    /// count of a dense matrix is the dense LDLᵀ's: Σ_k (n−1−k)(n+1−k) = n³/3 + n²/2 − 5n/6.
    #[test]
    fn factor_is_bitwise_the_same_on_1_and_2_threads() {
        let n = 700usize;
        let mut pairs = vec![];
        let mut vals = vec![];
        for j in 0..n {
            for i in j..n {
                pairs.push((i, j));
                vals.push(if i == j {
                    n as f64
                } else {
                    ((i * 31 + j * 17) % 13) as f64 / 13.0 - 0.5
                });
            }
        }
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .unwrap()
                .install(|| {
                    let mut s = SparseLdlt::with_layout(n, &pairs, Layout::Supernodal).unwrap();
                    s.set_threads(threads);
                    s.factorize(&vals).unwrap();
                    let mut b: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
                    s.solve(&mut b);
                    let Factor::Whole { l_values, .. } = &s.factor else {
                        unreachable!("AMD's factor is whole")
                    };
                    (l_values.clone(), b, s.factor_flops())
                })
        };
        let (l1, b1, f1) = run(1);
        let (l2, b2, _) = run(2);
        let bits = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits());
        assert!(bits(&l1, &l2), "the factor depends on the thread count");
        assert!(bits(&b1, &b2), "the solution depends on the thread count");
        // Σ of 700 integers-valued terms up to 5e5 in f64: exact, so 1e-9 only covers the
        // closed form's own rounding
        let nf = n as f64;
        let dense = nf.powi(3) / 3.0 + nf * nf / 2.0 - 5.0 * nf / 6.0;
        assert!((f1 - dense).abs() < 1e-9 * dense, "{f1} vs {dense}");
    }

    #[test]
    fn ldlt_reports_a_singular_matrix() {
        let pairs = [(0, 0), (1, 0), (1, 1)];
        let mut s = SparseLdlt::new(2, &pairs).unwrap();
        assert!(s.factorize(&[1.0, 1.0, 1.0]).is_err()); // [[1,1],[1,1]]
        assert!(s.factorize(&[1.0, f64::NAN, 1.0]).is_err());
        assert_eq!(s.factorize(&[1.0, 2.0, 1.0]).unwrap(), 1); // eigenvalues 3, −1
    }
}
