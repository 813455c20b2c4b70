//! The sparse LDLᵀ split at the top separator of the elimination tree, so that its two halves
//! factorize on two threads (parallelism across the tree rather than inside supernodes).
//!
//! With the unknowns in three sets, half 0, half 1 and the separator S (METIS's vertex
//! separator on the node graph, [`crate::ordering::bisection`]: no entry couples the halves),
//!
//! ```text
//!     K = [ A₀  0   B₀ ]        M_i = [ A_i   B_i ]      T_i = C/2 − B_iᵀ A_i⁻¹ B_i
//!         [ 0   A₁  B₁ ]              [ B_iᵀ  C/2 ]      S   = T₀ + T₁ = C − Σ B_iᵀ A_i⁻¹ B_i
//!         [ B₀ᵀ B₁ᵀ C  ]
//! ```
//!
//! Each bordered half M_i (its unknowns in nested-dissection order, S last) is factorized
//! partially on faer's supernodal symbolic factor by the sequential multifrontal driver
//! ([`crate::linsolve::multifrontal`]; measured faster than faer's own driver on these
//! halves), the two on their own threads (`rayon::join`): A_i's columns are eliminated, and
//! what is left where S's columns would be is M_i's Schur complement T_i, the last supernode's
//! trailing block (S's columns are all in the last supernode of a half whose T_i is dense; the
//! split is not made where they are not). S = T₀ + T₁ is factorized by dense LDLᵀ. Every
//! piece is sequential and summed in a fixed order, so the factor is bitwise the same whether
//! the halves run side by side or one after the other: the thread count changes the time,
//! not the bits.
//!
//! Sylvester's law over the block elimination gives the inertia: the negative pivots of K are
//! those of A₀ (the first pivots of M₀'s factor), of A₁ and of S.
//!
//! With L_SA, S's rows of M_i's factor in A_i's columns (L_SA D_A L_Aᵀ = B_iᵀ), a solve of
//! K x = b takes one forward and one backward sweep over each half's A_i columns (the halves
//! side by side):
//! 1. the forward sweep on [b_i; 0] leaves y_i = L_A⁻¹ b_i in A_i's place and −q_i in S's,
//!    q_i = L_SA y_i = B_iᵀ A_i⁻¹ b_i;
//! 2. x_S = S⁻¹ (b_S − q₀ − q₁);
//! 3. the backward sweep on [D_A⁻¹ y_i; x_S] gives x_i = L_A⁻ᵀ (D_A⁻¹ y_i − L_SAᵀ x_S)
//!    = A_i⁻¹ (b_i − B_i x_S).
//!
//! Measured on the whole capped tube (`crates/fem/examples/subtree_split.rs`, `ORDER=ring`): the
//! halves' flops equal the whole nested-dissection factor's within 1 %, and side by side they
//! factorize in 0.5–0.6 of the whole factor's time on this 2-core machine, where faer's
//! parallelism inside supernodes is slower than one thread.

use crate::linsolve::multifrontal::Multifrontal;
use crate::linsolve::FactorizationError;
use crate::FemError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::supernodal::{SupernodalLdltRef, SymbolicSupernodalCholesky};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{FaerError, SymbolicSparseColMat};
use faer::{Accum, Conj, Mat, MatMut, MatRef, Par, Side};

/// LDLᵀ without pivoting and without regularization: a zero pivot is an error.
const NO_REGULARIZATION: LdltRegularization<'static, f64> = LdltRegularization {
    dynamic_regularization_signs: None,
    dynamic_regularization_delta: 0.0,
    dynamic_regularization_epsilon: 0.0,
};

/// One bordered half M_i = [A_i B_i; B_iᵀ C/2] with its symbolic and numeric factor.
struct Half {
    /// the half's unknowns (global indices) in elimination order; S follows them
    members: Vec<usize>,
    pattern: SymbolicSparseColMat<usize>,
    /// the indices of the values of K that M_i's entries take, by their position in
    /// `pattern` (32 bits: the pattern of a million unknowns has some 10⁷ entries, and half
    /// the bytes matter at that size); a position takes more than one where K's pattern
    /// repeats an entry (they are summed in K's order)
    source: Vec<u32>,
    /// per position of `pattern`, where its values start in `source` (the last: its length)
    start: Vec<u32>,
    /// the values from this one on in `source` are S × S: they take half of K's value, the
    /// two halves sharing C
    halved_from: usize,
    symbolic: SymbolicCholesky<usize>,
    /// A_i's columns of M_i's factor and, where S's would be, T_i (its lower triangle), in
    /// faer's supernodal layout (the last supernode holds all of S's columns)
    l_values: Vec<f64>,
    /// A_i's pivots (the first of M_i's), in elimination order
    pivots: Vec<f64>,
    /// M_i's values at the last factorization
    vals: Vec<f64>,
    /// the numeric factorization's driver (built at the first factorization, then kept with
    /// its workspace)
    driver: Option<Multifrontal>,
}

/// The supernodal structure of a half's symbolic factor (`Half::new` makes no half of another
/// layout, so the simplicial arm cannot be reached).
fn supernodal_of(symbolic: &SymbolicCholesky<usize>) -> &SymbolicSupernodalCholesky<usize> {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(sn) => sn,
        SymbolicCholeskyRaw::Simplicial(_) => unreachable!("supernodal layout forced"),
    }
}

/// `m` as an `s` × `s` matrix of zeros, in its own storage when it has that size.
fn zeroed(mut m: Mat<f64>, s: usize) -> Mat<f64> {
    if m.nrows() == s && m.ncols() == s {
        m.fill(0.0);
        m
    } else {
        Mat::zeros(s, s)
    }
}

/// K's LDLᵀ as two bordered halves and the separator's dense Schur complement.
pub(crate) struct TreeSplit {
    n: usize,
    /// the separator's unknowns (global), ascending
    separator: Vec<usize>,
    halves: [Half; 2],
    /// LDLᵀ of S: L strictly below the diagonal, D on it
    schur: Mat<f64>,
    /// run the halves side by side (on the current rayon pool; the default)
    parallel: bool,
}

impl Half {
    /// The bordered half `side` of the pattern `pairs` (row ≥ col) on `n` unknowns, with the
    /// separator `separator` last; `None` where S's columns of its factor are not all in its
    /// last supernode (the partial factorization's condition, [`Multifrontal::partial`]:
    /// where T_i is dense, as on a connected half, they are).
    fn new(
        sides: &[u8],
        side: u8,
        separator: &[usize],
        pairs: &[(usize, usize)],
    ) -> Result<Option<Self>, FemError> {
        let n = sides.len();
        let own: Vec<usize> = (0..n).filter(|&k| sides[k] == side).collect();
        let mut local = vec![usize::MAX; n];
        for (i, &k) in own.iter().enumerate() {
            local[k] = i;
        }
        let inner: Vec<(usize, usize)> = pairs
            .iter()
            .filter(|&&(r, c)| sides[r] == side && sides[c] == side)
            .map(|&(r, c)| (local[r], local[c]))
            .collect();
        let order = crate::ordering::nested_dissection(own.len(), &inner)
            .map_err(FactorizationError::Ordering)?;
        let members: Vec<usize> = order.iter().map(|&i| own[i]).collect();
        let mut at = vec![usize::MAX; n];
        for (i, &k) in members.iter().chain(separator).enumerate() {
            at[k] = i;
        }
        let m = members.len() + separator.len();
        // M_i's entries: the values they take (K's entries of the half and of S) and their
        // row and column in M_i
        let mut entries: Vec<(u32, usize, usize)> = Vec::new();
        let too_large =
            |_| FactorizationError::Ordering(crate::ordering::OrderingError::TooLarge(n));
        for (e, &(r, c)) in pairs.iter().enumerate() {
            let (sr, sc) = (sides[r], sides[c]);
            if (sr == side || sr == 2) && (sc == side || sc == 2) {
                let (a, b) = (at[r].max(at[c]), at[r].min(at[c]));
                entries.push((u32::try_from(e).map_err(too_large)?, a, b));
            }
        }
        // the pattern: by column, rows ascending, without duplicates
        let mut cells: Vec<(usize, usize)> = entries.iter().map(|&(_, r, c)| (c, r)).collect();
        cells.sort_unstable();
        cells.dedup();
        let mut col_ptr = vec![0usize; m + 1];
        for &(c, _) in &cells {
            col_ptr[c + 1] += 1;
        }
        for c in 0..m {
            col_ptr[c + 1] += col_ptr[c];
        }
        let row_idx: Vec<usize> = cells.iter().map(|&(_, r)| r).collect();
        drop(cells);
        // each entry's position in the pattern; K's values by position (a stable sort, so a
        // repeated entry's values keep K's order): the gather then writes M_i's values in
        // order, each once, and reads K's where they are
        let mut placed = Vec::with_capacity(entries.len());
        for &(e, r, c) in &entries {
            let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            placed.push((col_ptr[c] + rows.partition_point(|&x| x < r), e));
        }
        drop(entries);
        // `start` counts them in 32 bits
        u32::try_from(placed.len()).map_err(too_large)?;
        placed.sort_by_key(|&(at, _)| at);
        let mut start = vec![0u32; row_idx.len() + 1];
        for &(at, _) in &placed {
            start[at + 1] += 1;
        }
        for at in 0..row_idx.len() {
            start[at + 1] += start[at];
        }
        let source: Vec<u32> = placed.iter().map(|&(_, e)| e).collect();
        drop(placed);
        // S × S (the entries both of whose unknowns are S's) is the columns from S's first
        let halved_from = start[col_ptr[members.len()]] as usize;
        let pattern = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
        // the order is the one built here: the identity as a custom ordering (faer 0.24's
        // `Identity` with the lower triangle analyses the diagonal alone); supernodal, so that
        // S's rows of the factor are dense blocks
        let id: Vec<usize> = (0..m).collect();
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Custom(PermRef::new_checked(&id, &id, m)),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(FactorizationError::Symbolic)?;
        // the layout forced above, with S's columns all in the last supernode; else no split
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else {
            return Ok(None);
        };
        if sn.supernode_begin().last().copied().unwrap_or(0) > members.len() {
            return Ok(None);
        }
        Ok(Some(Self {
            members,
            pattern,
            source,
            start,
            halved_from,
            l_values: Vec::new(),
            symbolic,
            pivots: Vec::new(),
            vals: Vec::new(),
            driver: None,
        }))
    }

    fn dim(&self) -> usize {
        self.pattern.nrows()
    }

    /// M_i's values in its pattern from K's `values` (duplicates summed; S × S halved).
    fn values(&self, values: &[f64]) -> Vec<f64> {
        let mut vals = Vec::new();
        // a non-finite value is the caller's to find (it is taken into the sum as it is)
        let _finite = self.values_into(values, &mut vals);
        vals
    }

    /// [`Half::values`] into `vals`' storage; whether every value it took was finite.
    fn values_into(&self, values: &[f64], vals: &mut Vec<f64>) -> bool {
        vals.clear();
        let mut finite = true;
        vals.extend(self.start.windows(2).map(|w| {
            let (from, to) = (w[0] as usize, w[1] as usize);
            let mut sum = 0.0;
            for k in from..to {
                let v = values[self.source[k] as usize];
                finite &= v.is_finite();
                sum += if k < self.halved_from { v } else { 0.5 * v };
            }
            sum
        }));
        finite
    }

    /// out += M_i x in K's unknowns (M_i's lower triangle `vals`, both triangles applied).
    fn apply(&self, separator: &[usize], vals: &[f64], x: &[f64], out: &mut [f64]) {
        let global: Vec<usize> = self.members.iter().chain(separator).copied().collect();
        let xl: Vec<f64> = global.iter().map(|&k| x[k]).collect();
        let mut yl = vec![0.0; xl.len()];
        crate::linsolve::apply_lower(
            self.pattern.col_ptr(),
            self.pattern.row_idx(),
            vals,
            &xl,
            &mut yl,
        );
        for (&k, y) in global.iter().zip(yl) {
            out[k] += y;
        }
    }

    /// The supernodal structure of M_i's factor (the layout `new` forces).
    fn supernodal(&self) -> &SymbolicSupernodalCholesky<usize> {
        supernodal_of(&self.symbolic)
    }

    /// M_i's values from K's `values` ([`Half::values`]), in the last factorization's storage
    /// (a million unknowns: 55 MB a half, allocated anew at every factorization before).
    /// Returns whether every value it took was finite.
    fn gather(&mut self, values: &[f64]) -> bool {
        let mut vals = std::mem::take(&mut self.vals);
        let finite = self.values_into(values, &mut vals);
        self.vals = vals;
        finite
    }

    /// Add `delta` to the diagonal of the gathered values as a shift of K's diagonal would
    /// reach them: the half's own unknowns take all of it, S's each half (M₀ + M₁ = K).
    fn shift(&mut self, delta: f64) {
        let n = self.members.len();
        let (ptr, rows) = (self.pattern.col_ptr(), self.pattern.row_idx());
        for c in 0..self.dim() {
            // rows ascend in a column of the lower triangle: the diagonal comes first
            if ptr[c] < ptr[c + 1] && rows[ptr[c]] == c {
                self.vals[ptr[c]] += if c < n { delta } else { 0.5 * delta };
            }
        }
    }

    /// The partial LDLᵀ of M_i from its gathered values ([`Half::gather`]): A_i's columns
    /// eliminated, T_i left in S's place ([`Half::trailing`]); returns the negative pivots of
    /// A_i. A zero pivot names its unknown of K (`separator`: S's, in M_i's order).
    fn factorize(&mut self, separator: &[usize]) -> Result<usize, FemError> {
        let n = self.members.len();
        let driver = match &mut self.driver {
            Some(driver) => driver,
            None => self.driver.insert(Multifrontal::partial(
                self.supernodal(),
                self.pattern.as_ref(),
                n,
            )?),
        };
        let vals = std::mem::take(&mut self.vals);
        if self.l_values.len() != self.symbolic.len_val() {
            self.l_values = vec![0.0; self.symbolic.len_val()];
        }
        let global = |local: usize| {
            if local < n {
                self.members[local]
            } else {
                separator[local - n]
            }
        };
        let factorized = driver
            .factorize(
                supernodal_of(&self.symbolic),
                &vals,
                &mut self.l_values,
                None,
            )
            .map_err(|e| match e {
                LdltError::ZeroPivot { index } => FemError::ZeroPivot {
                    index: global(index),
                    value: 0.0,
                },
            });
        self.vals = vals;
        factorized?;
        // A_i's pivots, in elimination order
        let mut pivots = std::mem::take(&mut self.pivots);
        pivots.clear();
        let mut negative = 0;
        let sn = self.supernodal();
        let (begin, end, ptr) = (
            sn.supernode_begin(),
            sn.supernode_end(),
            sn.col_ptr_for_val(),
        );
        for k in 0..sn.n_supernodes() {
            let (b, e) = (begin[k], end[k]);
            let rows = (ptr[k + 1] - ptr[k]) / (e - b);
            for j in 0..e.min(n).saturating_sub(b) {
                let d = self.l_values[ptr[k] + j * rows + j];
                if !d.is_finite() || d == 0.0 {
                    return Err(FemError::ZeroPivot {
                        index: self.members[b + j],
                        value: d,
                    });
                }
                negative += usize::from(d < 0.0);
                pivots.push(d);
            }
        }
        self.pivots = pivots;
        Ok(negative)
    }

    /// T_i = C/2 − B_iᵀ A_i⁻¹ B_i from the last factorization: its lower triangle (the
    /// entries above the diagonal are not part of it).
    fn trailing(&self) -> MatRef<'_, f64> {
        match &self.driver {
            Some(driver) => driver.trailing(self.supernodal(), &self.l_values),
            None => MatRef::from_column_major_slice(&[], 0, 0),
        }
    }

    /// Supernode k of the factor of A_i's columns: its eliminated columns' diagonal block,
    /// the block below it, and the unknowns (of M_i) of that block's rows. The last supernode
    /// eliminates its columns before S's, and S's rows are below them.
    fn eliminated<'a>(
        &self,
        factor: &SupernodalLdltRef<'a, usize, f64>,
        k: usize,
    ) -> (
        usize,
        MatRef<'a, f64>,
        MatRef<'a, f64>,
        impl Iterator<Item = usize> + Clone + 'a,
    ) {
        let node = factor.supernode(k);
        let (start, c) = (node.start(), node.val().ncols());
        let ce = c.min(self.members.len().saturating_sub(start));
        let rows = (start + ce..start + c).chain(node.pattern().iter().copied());
        let (top, bottom) = node.val().get(.., ..ce).split_at_row(ce);
        (start, top, bottom, rows)
    }

    /// The forward sweep y = L⁻¹ y in place over A_i's columns (L: M_i's unit lower factor),
    /// supernode by supernode, as faer's supernodal LDLᵀ solve does its first sweep (faer
    /// exposes the whole solve only). On [b_i; 0] it leaves L_A⁻¹ b_i in A_i's unknowns and
    /// −B_iᵀ A_i⁻¹ b_i in S's.
    fn forward(&self, y: &mut [f64]) {
        let sn = self.supernodal();
        let factor = SupernodalLdltRef::<'_, usize, f64>::new(sn, &self.l_values);
        let mut tmp = Vec::new();
        for k in 0..sn.n_supernodes() {
            let (start, top, bottom, rows) = self.eliminated(&factor, k);
            let mut x = MatMut::from_column_major_slice_mut(
                &mut y[start..start + top.ncols()],
                top.ncols(),
                1,
            );
            faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place(
                top,
                x.as_mut(),
                Par::Seq,
            );
            tmp.clear();
            tmp.resize(bottom.nrows(), 0.0);
            faer::linalg::matmul::matmul(
                MatMut::from_column_major_slice_mut(&mut tmp, bottom.nrows(), 1),
                Accum::Replace,
                bottom,
                x.as_ref(),
                1.0,
                Par::Seq,
            );
            for (i, &t) in rows.zip(&tmp) {
                y[i] -= t;
            }
        }
    }

    /// The backward sweep over A_i's columns, y_A = L_A⁻ᵀ (y_A − L_SAᵀ y_S) in place, with
    /// S's entries y_S given.
    fn backward(&self, y: &mut [f64]) {
        let sn = self.supernodal();
        let factor = SupernodalLdltRef::<'_, usize, f64>::new(sn, &self.l_values);
        let mut tmp = Vec::new();
        for k in (0..sn.n_supernodes()).rev() {
            let (start, top, bottom, rows) = self.eliminated(&factor, k);
            tmp.clear();
            tmp.extend(rows.map(|i| y[i]));
            let mut x = MatMut::from_column_major_slice_mut(
                &mut y[start..start + top.ncols()],
                top.ncols(),
                1,
            );
            faer::linalg::matmul::matmul(
                x.as_mut(),
                Accum::Add,
                bottom.transpose(),
                MatRef::from_column_major_slice(&tmp, bottom.nrows(), 1),
                -1.0,
                Par::Seq,
            );
            faer::linalg::triangular_solve::solve_unit_upper_triangular_in_place(
                top.transpose(),
                x.as_mut(),
                Par::Seq,
            );
        }
    }
}

impl TreeSplit {
    /// The split of the pattern `pairs` (row, col; one per value given to
    /// [`TreeSplit::factorize`]) on `n` unknowns at METIS's top separator; `None` when METIS
    /// leaves a half empty.
    pub(crate) fn new(n: usize, pairs: &[(usize, usize)]) -> Result<Option<Self>, FemError> {
        let Some(sides) =
            crate::ordering::bisection(n, pairs).map_err(FactorizationError::Ordering)?
        else {
            return Ok(None);
        };
        if (0..2).any(|h| !sides.contains(&h))
            || pairs
                .iter()
                .any(|&(r, c)| sides[r] != 2 && sides[c] != 2 && sides[r] != sides[c])
        {
            return Ok(None);
        }
        let separator: Vec<usize> = (0..n).filter(|&k| sides[k] == 2).collect();
        // one after the other: METIS, which orders each half, is not reentrant
        let Some(h0) = Half::new(&sides, 0, &separator, pairs)? else {
            return Ok(None);
        };
        let Some(h1) = Half::new(&sides, 1, &separator, pairs)? else {
            return Ok(None);
        };
        let s = separator.len();
        Ok(Some(Self {
            n,
            separator,
            halves: [h0, h1],
            schur: Mat::zeros(s, s),
            parallel: true,
        }))
    }

    /// Factorize (and solve) the two halves side by side (`true`, the default) or one after the
    /// other: the bits are the same.
    #[cfg(test)]
    pub(crate) fn set_parallel(&mut self, parallel: bool) {
        self.parallel = parallel;
    }

    /// The separator's size.
    pub(crate) fn separator_len(&self) -> usize {
        self.separator.len()
    }

    /// The flops of one factorization, counted as [`crate::linsolve::SparseLdlt::factor_flops`]
    /// counts them: the two halves' partial factors (A_i's columns, their update of T_i
    /// included) and S's dense LDLᵀ, that is, the flops of the whole factor in this order.
    pub(crate) fn flops(&self) -> f64 {
        let s = self.separator.len() as f64;
        let dense: f64 = (0..self.separator.len())
            .map(|j| {
                let c = s - 1.0 - j as f64;
                c * (c + 2.0)
            })
            .sum();
        self.halves
            .iter()
            .map(|h| crate::linsolve::supernodal_flops(h.supernodal(), h.members.len()))
            .sum::<f64>()
            + dense
    }

    /// The entries of the factor: the halves' in A_i's columns and S's lower triangle.
    pub(crate) fn nnz(&self) -> usize {
        let s = self.separator.len();
        self.halves
            .iter()
            .map(|h| crate::linsolve::supernodal_entries(h.supernodal(), h.members.len()))
            .sum::<usize>()
            + s * (s + 1) / 2
    }

    /// Numeric LDLᵀ of K with the values `values` (one per pair given to `new`); returns the
    /// number of negative pivots.
    pub(crate) fn factorize(&mut self, values: &[f64]) -> Result<usize, FemError> {
        self.gather(values);
        self.factorize_gathered()
    }

    /// The two halves' values from K's `values` (one per pair given to `new`), kept for
    /// [`TreeSplit::factorize_gathered`]: after this the split needs K's values no more.
    /// Returns whether every value was finite (each value reaches at least one half).
    pub(crate) fn gather(&mut self, values: &[f64]) -> bool {
        let [h0, h1] = &mut self.halves;
        let (f0, f1) = if self.parallel {
            rayon::join(|| h0.gather(values), || h1.gather(values))
        } else {
            (h0.gather(values), h1.gather(values))
        };
        f0 && f1
    }

    /// Add `delta` to K's diagonal in the gathered values ([`TreeSplit::gather`]).
    pub(crate) fn shift(&mut self, delta: f64) {
        for h in &mut self.halves {
            h.shift(delta);
        }
    }

    /// Numeric LDLᵀ of the gathered values ([`TreeSplit::gather`]); returns the number of
    /// negative pivots.
    pub(crate) fn factorize_gathered(&mut self) -> Result<usize, FemError> {
        let [h0, h1] = &mut self.halves;
        let (n0, n1) = if self.parallel {
            let sep = &self.separator;
            rayon::join(|| h0.factorize(sep), || h1.factorize(sep))
        } else {
            (h0.factorize(&self.separator), h1.factorize(&self.separator))
        };
        let (n0, n1) = (n0?, n1?);
        let s = self.separator.len();
        // S = T₀ + T₁ (lower triangles; the dense LDLᵀ reads no other) in the last
        // factorization's storage
        let mut schur = zeroed(std::mem::replace(&mut self.schur, Mat::new()), s);
        let (t0, t1) = (self.halves[0].trailing(), self.halves[1].trailing());
        for j in 0..s {
            for i in j..s {
                schur[(i, j)] = t0[(i, j)] + t1[(i, j)];
            }
        }
        let req = faer::linalg::cholesky::ldlt::factor::cholesky_in_place_scratch::<f64>(
            s,
            Par::Seq,
            Default::default(),
        );
        let mut mem = MemBuffer::try_new(req)
            .map_err(|e| FactorizationError::Workspace(FaerError::from(e)))?;
        faer::linalg::cholesky::ldlt::factor::cholesky_in_place(
            schur.as_mut(),
            NO_REGULARIZATION,
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .map_err(|e| match e {
            LdltError::ZeroPivot { index } => FemError::ZeroPivot {
                index: self.separator[index],
                value: 0.0,
            },
        })?;
        let mut negative = n0 + n1;
        for j in 0..s {
            let d = schur[(j, j)];
            if !d.is_finite() || d == 0.0 {
                return Err(FemError::ZeroPivot {
                    index: self.separator[j],
                    value: d,
                });
            }
            negative += usize::from(d < 0.0);
        }
        self.schur = schur;
        Ok(negative)
    }

    /// K with the values `values` (one per pair given to `new`) as the two halves' matrices,
    /// M₀ + M₁ = K (their S × S entries halved), without K's own pattern.
    pub(crate) fn matrix(&self, values: &[f64]) -> SplitMatrix<'_> {
        SplitMatrix {
            split: self,
            values: [self.halves[0].values(values), self.halves[1].values(values)],
        }
    }

    /// The pivots: A₀'s, A₁'s (each in its elimination order), then S's.
    pub(crate) fn pivots(&self) -> Vec<f64> {
        let mut d = Vec::with_capacity(self.n);
        for h in &self.halves {
            d.extend(&h.pivots);
        }
        d.extend((0..self.separator.len()).map(|j| self.schur[(j, j)]));
        d
    }

    /// Solve K x = rhs in place with the last factorization (see the module's steps).
    pub(crate) fn solve(&self, rhs: &mut [f64]) {
        let s = self.separator.len();
        // 1. the forward sweep over A_i's columns on [b_i; 0]: y_i = L_A⁻¹ b_i, and in S's
        //    place −q_i = −B_iᵀ A_i⁻¹ b_i
        let first = |h: &Half| {
            let mut y: Vec<f64> = h.members.iter().map(|&k| rhs[k]).collect();
            y.resize(h.dim(), 0.0);
            h.forward(&mut y);
            y
        };
        let (mut y0, mut y1) = self.join(|| first(&self.halves[0]), || first(&self.halves[1]));
        // 2. x_S = S⁻¹ (b_S − q₀ − q₁)
        let (n0, n1) = (self.halves[0].members.len(), self.halves[1].members.len());
        let mut x = Mat::<f64>::from_fn(s, 1, |i, _| {
            rhs[self.separator[i]] + y0[n0 + i] + y1[n1 + i]
        });
        faer::linalg::cholesky::ldlt::solve::solve_in_place_with_conj(
            self.schur.as_ref(),
            self.schur.diagonal(),
            Conj::No,
            x.as_mut(),
            Par::Seq,
            MemStack::new(&mut MemBuffer::new(faer::dyn_stack::StackReq::EMPTY)),
        );
        // 3. x_i = L_A⁻ᵀ (D_A⁻¹ y_i − L_SAᵀ x_S) = A_i⁻¹ (b_i − B_i x_S)
        let second = |h: &Half, y: &mut Vec<f64>| {
            let n = h.members.len();
            for (v, d) in y[..n].iter_mut().zip(&h.pivots) {
                *v /= d;
            }
            for (v, i) in y[n..].iter_mut().zip(0..s) {
                *v = x[(i, 0)];
            }
            h.backward(y);
        };
        self.join(
            || second(&self.halves[0], &mut y0),
            || second(&self.halves[1], &mut y1),
        );
        for (h, y) in self.halves.iter().zip([y0, y1]) {
            for (&k, &value) in h.members.iter().zip(&y) {
                rhs[k] = value;
            }
        }
        for (i, &k) in self.separator.iter().enumerate() {
            rhs[k] = x[(i, 0)];
        }
    }

    /// `a` and `b`, side by side when the split runs in parallel.
    fn join<A: Send, B: Send>(
        &self,
        a: impl FnOnce() -> A + Send,
        b: impl FnOnce() -> B + Send,
    ) -> (A, B) {
        if self.parallel {
            rayon::join(a, b)
        } else {
            (a(), b())
        }
    }
}

/// K as the sum of the split's two bordered halves ([`TreeSplit::matrix`]).
pub(crate) struct SplitMatrix<'a> {
    split: &'a TreeSplit,
    values: [Vec<f64>; 2],
}

impl SplitMatrix<'_> {
    /// out = K x: M₀ x, then M₁ x, each column by column (sequential, a fixed order).
    pub(crate) fn apply(&self, x: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        for (h, vals) in self.split.halves.iter().zip(&self.values) {
            h.apply(&self.split.separator, vals, x, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linsolve::{Factor, Layout, SparseLdlt};
    use crate::ordering::Ordering;

    /// n, the pairs, their values, a solution x, b = K x and the negative eigenvalues.
    type Problem = (
        usize,
        Vec<(usize, usize)>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        usize,
    );

    /// A `k` × `k` grid's pattern (3 unknowns per node, bilinear couplings) with an indefinite,
    /// diagonally dominant matrix on it: every 7th diagonal entry negative, |d| ≥ 2 against
    /// off-diagonal row sums ≤ 1.75 (Gershgorin: no eigenvalue within 0.25 of zero, and the
    /// negative eigenvalues are as many as the negative diagonal entries, which the off-diagonal
    /// part, switched on continuously, cannot change). Some entries are given twice, halved
    /// (duplicates are summed). Returns n, the pairs, their values, a solution x and b = K x.
    fn problem(k: usize) -> Problem {
        let (n, grid) = crate::ordering::grid(k);
        let d = |i: usize| {
            if i % 7 == 3 {
                -2.0 - 0.001 * i as f64
            } else {
                2.0 + 0.001 * i as f64
            }
        };
        let off = |r: usize, c: usize| 0.05 * (((r * 31 + c * 17) % 11) as f64 / 10.0 - 0.5);
        let mut pairs = Vec::new();
        let mut vals = Vec::new();
        for (e, &(r, c)) in grid.iter().enumerate() {
            let v = if r == c { d(r) } else { off(r, c) };
            if e % 5 == 0 {
                pairs.extend([(r, c), (r, c)]);
                vals.extend([0.5 * v, 0.5 * v]);
            } else {
                pairs.push((r, c));
                vals.push(v);
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos()).collect();
        let mut b = vec![0.0; n];
        for (&(r, c), &v) in pairs.iter().zip(&vals) {
            b[r] += v * x[c];
            if r != c {
                b[c] += v * x[r];
            }
        }
        let negative = (0..n).filter(|&i| d(i) < 0.0).count();
        (n, pairs, vals, x, b, negative)
    }

    #[test]
    fn the_split_solves_the_matrix_and_keeps_its_inertia() {
        let (n, pairs, vals, x, b, negative) = problem(24);
        let mut t = TreeSplit::new(n, &pairs).unwrap().expect("a split");
        // a separator, and two halves that together with it hold every unknown once
        let sizes = [t.halves[0].members.len(), t.halves[1].members.len()];
        assert!(t.separator_len() > 0 && sizes[0] > 0 && sizes[1] > 0);
        assert_eq!(sizes[0] + sizes[1] + t.separator_len(), n);
        // a 24-node grid's separator is a line of about 24 nodes, not the whole
        assert!(t.separator_len() <= 3 * 2 * 24, "{}", t.separator_len());
        assert_eq!(t.factorize(&vals).unwrap(), negative);
        assert_eq!(
            t.pivots().iter().filter(|&&d| d < 0.0).count(),
            negative,
            "the pivots' signs"
        );
        let mut y = b.clone();
        t.solve(&mut y);
        // condition number ≤ 3.75 / 0.25 = 15 (Gershgorin), a backward-stable solve: exact to
        // about 15 × 1e-16 per unit of |x| ≤ 1
        for i in 0..n {
            assert!(
                (y[i] - x[i]).abs() < 1e-12,
                "x[{i}]: {} against {}",
                y[i],
                x[i]
            );
        }
        // the split's operator (M₀ + M₁, the S × S entries halved) is K: K x = b to the
        // rounding of a row's sum, summed in another order than b's (some 30 terms, each
        // |K_ij x_j| ≤ 3.7, |b_i| ≤ 5.5: at most 30 × 5.5 × 2.2e-16 ≈ 4e-14)
        let mut kx = vec![0.0; n];
        t.matrix(&vals).apply(&x, &mut kx);
        for i in 0..n {
            assert!(
                (kx[i] - b[i]).abs() < 1e-13,
                "(Kx)[{i}]: {} against {}",
                kx[i],
                b[i]
            );
        }
    }

    #[test]
    fn the_split_is_bitwise_the_same_side_by_side_and_one_after_the_other() {
        let (n, pairs, vals, _, b, _) = problem(24);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let run = |parallel: bool| {
            pool.install(|| {
                let mut t = TreeSplit::new(n, &pairs).unwrap().expect("a split");
                t.set_parallel(parallel);
                t.factorize(&vals).unwrap();
                let mut y = b.clone();
                t.solve(&mut y);
                (t.pivots(), y)
            })
        };
        let (one, two) = (run(false), run(true));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&one.0), bits(&two.0));
        assert_eq!(bits(&one.1), bits(&two.1));
    }

    /// A factorization in the storage of an earlier one (the halves' values, the driver's
    /// workspace, the dense blocks, all kept from one factorization to the next) gives the bits of a
    /// fresh split's, and so does one after a failed factorization.
    #[test]
    fn the_split_reuses_its_storage_without_changing_a_bit() {
        let (n, pairs, vals, _, b, _) = problem(24);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let result = |t: &mut TreeSplit| {
            t.factorize(&vals).unwrap();
            let mut y = b.clone();
            t.solve(&mut y);
            (bits(&t.pivots()), bits(&y))
        };
        let fresh = result(&mut TreeSplit::new(n, &pairs).unwrap().expect("a split"));
        let mut t = TreeSplit::new(n, &pairs).unwrap().expect("a split");
        // other values first (the matrix doubled: other pivots in the storage), then K's
        let doubled: Vec<f64> = vals.iter().map(|v| 2.0 * v).collect();
        t.factorize(&doubled).unwrap();
        assert_ne!(bits(&t.pivots()), fresh.0);
        assert_eq!(result(&mut t), fresh);
        // a singular matrix between (a zero pivot part-way), then K's again
        assert!(t.factorize(&vec![0.0; pairs.len()]).is_err());
        assert_eq!(result(&mut t), fresh);
    }

    /// A shift of the gathered values is the shift of K's diagonal: the halves' own unknowns
    /// take all of it, S's half in each half. Against a fresh split of K with the diagonal
    /// shifted before gathering: the same inertia, and solutions equal to the rounding of the
    /// two summation orders (|d| ≥ 2 against row sums ≤ 1.75 bound the condition number by
    /// 15; 1e-12 leaves room for 15 × a few ulp).
    #[test]
    fn a_shift_of_the_gathered_values_shifts_the_diagonal() {
        let (n, pairs, vals, _, b, _) = problem(24);
        let delta = 0.7;
        let mut shifted = vals.clone();
        let mut seen = vec![false; n];
        for (v, &(r, c)) in shifted.iter_mut().zip(&pairs) {
            if r == c && !seen[r] {
                seen[r] = true;
                *v += delta;
            }
        }
        assert!(seen.iter().all(|&s| s), "a diagonal entry for each unknown");
        let mut fresh = TreeSplit::new(n, &pairs).unwrap().expect("a split");
        let expected = fresh.factorize(&shifted).unwrap();
        let mut t = TreeSplit::new(n, &pairs).unwrap().expect("a split");
        t.gather(&vals);
        t.shift(delta);
        assert_eq!(t.factorize_gathered().unwrap(), expected);
        let (mut y, mut z) = (b.clone(), b.clone());
        t.solve(&mut y);
        fresh.solve(&mut z);
        for i in 0..n {
            assert!(
                (y[i] - z[i]).abs() < 1e-12,
                "x[{i}]: {} against {}",
                y[i],
                z[i]
            );
        }
    }

    #[test]
    fn a_singular_matrix_is_a_zero_pivot_of_the_split() {
        let (n, pairs, _, _, _, _) = problem(12);
        let mut t = TreeSplit::new(n, &pairs).unwrap().expect("a split");
        let zeros = vec![0.0; pairs.len()];
        assert!(matches!(
            t.factorize(&zeros),
            Err(FemError::ZeroPivot { .. })
        ));
    }

    #[test]
    fn a_large_nested_dissection_factor_is_split_and_agrees_with_the_whole_one() {
        // 183² nodes × 3 = 100,467 unknowns, just above the split's threshold
        let (n, pairs, vals, x, b, negative) = problem(183);
        assert!(n >= crate::linsolve::SPLIT_MIN_UNKNOWNS);
        let mut split =
            SparseLdlt::with_options(n, &pairs, Layout::Auto, Ordering::NestedDissection).unwrap();
        let mut whole = SparseLdlt::with_options(n, &pairs, Layout::Auto, Ordering::Amd).unwrap();
        let s = split.split_separator().expect("split");
        // a grid's separator is a line of nodes, about √(n/3) of them
        assert!(s <= 3 * 2 * 183, "separator {s}");
        assert_eq!(whole.split_separator(), None, "AMD keeps the whole factor");
        assert_eq!(split.factorize(&vals).unwrap(), negative);
        assert_eq!(whole.factorize(&vals).unwrap(), negative);
        let (mut y, mut z) = (b.clone(), b.clone());
        split.solve(&mut y);
        whole.solve(&mut z);
        for i in 0..n {
            assert!((y[i] - x[i]).abs() < 1e-12, "split x[{i}]");
            assert!((y[i] - z[i]).abs() < 1e-12, "split against whole x[{i}]");
        }
        // a matrix that needs two shifts: diagonal, −1 at the even unknowns and 0 at the odd
        // (one entry of each diagonal), with shifts 1 (still singular: the even ones at 0) and
        // 3 (2 at the even, 3 at the odd); each factor takes the values by value, the split
        // drops them before its numeric factorization. The solution is b_i/2 and b_i/3: a
        // division or a reciprocal's product, within 2 ulp of the quotient.
        let mut diagonal = vec![usize::MAX; n];
        for (e, &(r, c)) in pairs.iter().enumerate() {
            if r == c && diagonal[r] == usize::MAX {
                diagonal[r] = e;
            }
        }
        let mut values = vec![0.0; pairs.len()];
        for (i, &d) in diagonal.iter().enumerate() {
            values[d] = if i % 2 == 0 { -1.0 } else { 0.0 };
        }
        for ldlt in [&mut split, &mut whole] {
            assert_eq!(
                ldlt.factorize_shifted(values.clone(), &diagonal, &[1.0, 3.0])
                    .unwrap(),
                (0, 3.0)
            );
            let mut y = b.clone();
            ldlt.solve(&mut y);
            for i in 0..n {
                let q = b[i] / if i % 2 == 0 { 2.0 } else { 3.0 };
                assert!(
                    (y[i] - q).abs() <= 4.5e-16 * q.abs(),
                    "x[{i}]: {} against {q}",
                    y[i]
                );
            }
            // no shift that factorizes: the first failure
            assert!(matches!(
                ldlt.factorize_shifted(values.clone(), &diagonal, &[1.0]),
                Err(FemError::ZeroPivot { .. })
            ));
        }
        // a non-finite value is named by its entry, split or whole (the split's halves see it
        // as they gather; an entry of S × S is halved, an infinity stays one)
        let in_separator = pairs
            .iter()
            .position(|&(r, c)| r != c && split_sides_are_separator(&split, r, c))
            .expect("an entry coupling two unknowns of S");
        for (entry, bad) in [(7, f64::NAN), (in_separator, f64::INFINITY)] {
            let mut values = vals.clone();
            values[entry] = bad;
            for ldlt in [&mut split, &mut whole] {
                assert!(matches!(
                    ldlt.factorize_shifted(values.clone(), &diagonal, &[1.0]),
                    Err(FemError::NonFiniteEntry { entry: e }) if e == entry
                ));
            }
        }
    }

    /// Whether unknowns `r` and `c` are both in the split's separator.
    fn split_sides_are_separator(ldlt: &SparseLdlt, r: usize, c: usize) -> bool {
        let Factor::Split(t) = &ldlt.factor else {
            return false;
        };
        t.separator.binary_search(&r).is_ok() && t.separator.binary_search(&c).is_ok()
    }
}
