//! A multifrontal numeric LDLᵀ over faer's supernodal symbolic factor and its dense kernels:
//! the driver of the split factorization's two halves ([`crate::linsolve::tree_split`]).
//!
//! faer's numeric factorization is left-looking: a supernode gathers the update of every
//! descendant whose rows reach it, one matrix product of small depth per (descendant,
//! ancestor) pair, each formed in a workspace and scattered, and the descendant's block is
//! read from memory once per ancestor it updates. On the million-unknown tube that driver
//! reaches about half of what its dense products allow at their shapes
//! (`examples/supernode_bound.rs`). This driver does the same arithmetic in multifrontal
//! order, one product per supernode while its block is in cache. In a postorder of the
//! supernodal tree, supernode p (c columns, r rows below them):
//! 1. takes its columns of the matrix into its block of the factor (c + r rows, c columns);
//! 2. adds the children's update matrices (lower triangles) where their columns are p's
//!    ("extend-add", by runs of consecutive rows); steps 1 and 2 go a panel of columns at a
//!    time (about 1 MiB), so that the extend-add finds the panel in cache;
//! 3. factorizes its c × c diagonal block (faer's dense LDLᵀ) and solves the r × c block
//!    below it, which leaves L_B D there; a copy W = L_B D is kept and the block is scaled
//!    to L_B;
//! 4. forms its own update matrix U_p = −W L_Bᵀ (lower triangle, faer's triangular `matmul`);
//! 5. adds the children's update columns that fall in p's rows below, and drops the
//!    children's matrices; steps 4 and 5 go by the update matrix's panels, each taking the
//!    children's columns right after its product, while it is in cache.
//!
//! Every entry takes the same additions in the same order as it would column by column, so
//! the panels change no bit; they save the extend-add a trip to memory (measured with the
//! example `factor_drivers`: about 1.5 % of the factorization).
//!
//! A partial factorization ([`Multifrontal::partial`]) eliminates the columns before a given
//! one only; the columns from there on must all be in the last supernode, whose trailing
//! block then takes the eliminated columns' update (step 4 into the block itself instead of
//! an update matrix) and holds their Schur complement. The split factorization's halves are
//! factorized so, up to the separator.
//!
//! The update matrices live in one arena, stacked from both ends: a matrix goes to the end
//! that its depth's parity names, so a parent's matrix is never on the children's end and
//! nothing is moved. Each is its lower triangle stored by panels of 256 columns (a panel holds
//! the rows from its first column down), about half the square. The arena's size comes from
//! the symbolic factor. The result is in faer's supernodal layout (D on the diagonal of each
//! diagonal block, L strictly below it, zeros above), so faer's supernodal solve reads it.
//! Everything is sequential and in a fixed order: the bits do not depend on the thread count.
//! They differ from faer's driver's by round-off, because the updates are summed in another
//! order.
//!
//! The whole factor of a model (`SparseLdlt` without the split) keeps faer's driver: every
//! shipped case is far below the split's size, and its results stay bit for bit. The example
//! `factor_drivers` times the two drivers side by side, and [`Phases`] splits this one's time
//! into the dense kernels and the memory-bound rest.

use crate::linsolve::FactorizationError;
use crate::ordering::OrderingError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{
    cholesky_in_place, cholesky_in_place_scratch, LdltError, LdltRegularization,
};
use faer::linalg::matmul::triangular::{matmul, BlockStructure};
use faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::{FaerError, SymbolicSparseColMatRef};
use faer::{Accum, MatMut, MatRef, Par};
use std::time::Instant;

/// LDLᵀ without pivoting and without regularization: a zero pivot is an error.
const NO_REGULARIZATION: LdltRegularization<'static, f64> = LdltRegularization {
    dynamic_regularization_signs: None,
    dynamic_regularization_delta: 0.0,
    dynamic_regularization_epsilon: 0.0,
};

/// No place in the factor: an entry above the diagonal, which a lower-triangle input ignores.
const ABOVE: u32 = u32::MAX;

/// The multifrontal driver for one symbolic factor and one matrix pattern (the matrix's
/// lower triangle in the factor's elimination order, by column).
pub struct Multifrontal {
    /// the supernodes in the order they are factorized: a postorder of the supernodal tree
    order: Vec<usize>,
    /// per supernode: how many children it has in the tree
    n_children: Vec<usize>,
    /// per entry of the matrix (its pattern's order): its place in its supernode's block of
    /// the factor's values (32 bits: some 10⁷ entries at a million unknowns)
    place: Vec<u32>,
    /// the pattern's column starts (the entries of a supernode's columns are contiguous)
    col_ptr: Vec<usize>,
    /// per supernode: whether its update matrix goes to the arena's left end (else its right)
    left: Vec<bool>,
    /// the update matrices, stacked from both ends (at the size the postorder needs)
    arena: Vec<f64>,
    /// W = L_B D of the supernode being factorized (the largest r × c)
    work: Vec<f64>,
    /// faer's workspace for the largest diagonal block
    scratch: MemBuffer,
    /// an unknown's row in the current front (`usize::MAX` outside it)
    local: Vec<usize>,
    /// the rows of the supernode's children in its front, one child after the other
    /// ([`child_rows`])
    map: Vec<usize>,
    /// each child's runs of consecutive rows in `map`, one child after the other
    runs: Vec<Run>,
    /// the columns eliminated: all, or those before the trailing block
    /// ([`Multifrontal::partial`])
    stop: usize,
}

/// Rows `child..child + len` of a child's update matrix that go to the consecutive rows
/// `parent..parent + len` of its parent's front.
#[derive(Clone, Copy)]
struct Run {
    child: usize,
    parent: usize,
    len: usize,
}

/// Columns per panel of an update matrix's storage (narrow under test, so that the tests'
/// small matrices have many panels).
const PANEL: usize = if cfg!(test) { 16 } else { 256 };

/// The length of an r × r update matrix's lower triangle stored by panels: panel k holds the
/// rows from its first column's down, of its (at most [`PANEL`]) columns, column by column.
/// Against the whole square, that halves the arena up to a panel's width a matrix.
fn packed_len(r: usize) -> usize {
    (0..r)
        .step_by(PANEL)
        .map(|k| (r - k) * PANEL.min(r - k))
        .sum()
}

/// Where column j of an r × r update matrix stored by panels starts, and the row its first
/// entry holds (its panel's first column).
fn packed_column(r: usize, j: usize) -> (usize, usize) {
    let panels = j / PANEL;
    let k = panels * PANEL;
    // the full panels before: Σ_{q < panels} (r − q P) P
    let before = PANEL * (panels * r - PANEL * panels * panels.saturating_sub(1) / 2);
    (before + (j - k) * (r - k), k)
}

/// column += a child's column `from`, its rows `j..` (the lower triangle), through the runs
/// from the one holding row j; `from`'s first entry is the child's row `from_row`, the
/// column's is the front's row `offset`.
fn add_column(
    column: &mut [f64],
    offset: usize,
    from: &[f64],
    from_row: usize,
    j: usize,
    runs: &[Run],
) {
    for run in runs {
        let lo = run.child.max(j);
        let hi = run.child + run.len;
        let at = run.parent + (lo - run.child) - offset;
        for (d, &v) in column[at..at + hi - lo]
            .iter_mut()
            .zip(&from[lo - from_row..hi - from_row])
        {
            *d += v;
        }
    }
}

/// What the symbolic factor says of supernode `s`: its first column, column count and the
/// rows below them (ascending).
fn shape(sn: &SymbolicSupernodalCholesky<usize>, s: usize) -> (usize, usize, &[usize]) {
    let begin = sn.supernode_begin()[s];
    let end = sn.supernode_end()[s];
    let at = sn.col_ptr_for_row_idx()[s];
    let rows = &sn.row_idx()[at..at + sn.nnz_per_super()[s]];
    (begin, end - begin, rows)
}

/// The trailing columns that supernode `s` keeps in a factorization up to column `stop`
/// ([`Multifrontal::partial`]): the last supernode's from `stop` on (all of them are in it),
/// none elsewhere.
fn kept_columns(sn: &SymbolicSupernodalCholesky<usize>, stop: usize, s: usize) -> usize {
    if s + 1 == sn.n_supernodes() {
        sn.nrows() - stop
    } else {
        0
    }
}

/// Seconds spent in each part of [`Multifrontal::factorize`], summed over the supernodes
/// (for the example `factor_drivers`, which tells the dense kernels' time from the rest).
#[derive(Clone, Copy, Debug, Default)]
pub struct Phases {
    /// zeroing each block, taking the matrix's entries into it and adding the children's
    /// update columns that are its own columns (a panel of columns at a time)
    pub assembly: f64,
    /// the diagonal blocks' dense LDLᵀ and the solves below them
    pub diagonal: f64,
    /// W = L_B D copied and the blocks scaled to L_B
    pub copy: f64,
    /// the update matrices' products U = −W L_Bᵀ
    pub update: f64,
    /// the children's update columns added to the parents' update matrices
    pub extend_update: f64,
}

/// A stopwatch over [`Phases`]: each lap's seconds go to the phase it names.
struct Clock<'a>(Option<(&'a mut Phases, Instant)>);

impl Clock<'_> {
    fn lap(&mut self, phase: fn(&mut Phases) -> &mut f64) {
        if let Some((phases, since)) = &mut self.0 {
            let now = Instant::now();
            *phase(phases) += (now - *since).as_secs_f64();
            *since = now;
        }
    }
}

/// A child of the supernode being factorized: its update matrix (rc × rc, by panels), its
/// rows in the parent's front and their runs (ranges of the driver's `map` and `runs`,
/// [`child_rows`]), and how many of those rows are the parent's columns.
struct Child<'a> {
    u: &'a [f64],
    rc: usize,
    rows: std::ops::Range<usize>,
    runs: std::ops::Range<usize>,
    split: usize,
}

/// Entries of a front's panel of columns that the assembly keeps in cache together (1 MiB:
/// half of a core's 2 MiB L2 here).
const CACHED: usize = 1 << 17;

/// Appends a child's rows (`rows`, ascending) as rows of its parent's front to `map` (the
/// parent's own `c` columns from `begin` first, then the parent's rows below, `local`) and
/// their runs of consecutive rows to `runs`: a [`Child`] with `u` and `rc` to fill in.
fn child_rows<'a>(
    map: &mut Vec<usize>,
    runs: &mut Vec<Run>,
    rows: &[usize],
    begin: usize,
    c: usize,
    local: &[usize],
    u: &'a [f64],
) -> Child<'a> {
    let (m0, r0) = (map.len(), runs.len());
    map.extend(rows.iter().map(|&row| {
        if row < begin + c {
            row - begin
        } else {
            local[row]
        }
    }));
    for (i, &row) in map[m0..].iter().enumerate() {
        match runs[r0..].last_mut() {
            Some(run) if run.parent + run.len == row => run.len += 1,
            _ => runs.push(Run {
                child: i,
                parent: row,
                len: 1,
            }),
        }
    }
    Child {
        u,
        rc: rows.len(),
        rows: m0..map.len(),
        runs: r0..runs.len(),
        split: map[m0..].partition_point(|&t| t < c),
    }
}

/// Adds the `columns` of a child's update matrix `u` (rc × rc, by panels) to `target`, whose
/// front column t is `target[start..start + len]` with its first entry the front's row
/// `offset`, for `(start, len, offset) = place(t)`; `map` and `runs` from [`child_rows`].
fn extend_add(
    target: &mut [f64],
    place: impl Fn(usize) -> (usize, usize, usize),
    u: &[f64],
    rc: usize,
    map: &[usize],
    runs: &[Run],
    columns: std::ops::Range<usize>,
) {
    let mut first = runs.partition_point(|run| run.child + run.len <= columns.start);
    for j in columns {
        while runs[first].child + runs[first].len <= j {
            first += 1;
        }
        let (start, len, offset) = place(map[j]);
        let (at, row) = packed_column(rc, j);
        add_column(
            &mut target[start..start + len],
            offset,
            &u[at..at + rc - row],
            row,
            j,
            &runs[first..],
        );
    }
}

impl Multifrontal {
    /// The driver for `sn` and the lower-triangle `pattern` (rows ≥ column; an entry above
    /// the diagonal is ignored) whose values [`Multifrontal::factorize`] will take.
    pub fn new(
        sn: &SymbolicSupernodalCholesky<usize>,
        pattern: SymbolicSparseColMatRef<'_, usize>,
    ) -> Result<Self, FactorizationError> {
        Self::partial(sn, pattern, sn.nrows())
    }

    /// The driver of a partial factorization: the columns before `stop` are eliminated, and
    /// the trailing block from `stop` on is left as their Schur complement, that is, the
    /// matrix's trailing block minus the eliminated columns' updates (C − Bᵀ A⁻¹ B for the
    /// matrix [A B; Bᵀ C]). The trailing columns must all be in the last supernode, which
    /// holds the Schur complement's lower triangle where its columns' factor would be
    /// ([`Multifrontal::trailing`]); otherwise the driver is refused
    /// ([`FactorizationError::Trailing`]).
    pub fn partial(
        sn: &SymbolicSupernodalCholesky<usize>,
        pattern: SymbolicSparseColMatRef<'_, usize>,
        stop: usize,
    ) -> Result<Self, FactorizationError> {
        let n = sn.nrows();
        let last_begin = sn.supernode_begin().last().copied().unwrap_or(0);
        if stop > n || (stop < n && last_begin > stop) {
            return Err(FactorizationError::Trailing {
                stop,
                begin: last_begin,
            });
        }
        let ns = sn.n_supernodes();
        let mut owner = vec![0usize; n];
        for s in 0..ns {
            let (begin, c, _) = shape(sn, s);
            owner[begin..begin + c].fill(s);
        }
        // the tree: a supernode's parent owns the first row below its columns
        let parent: Vec<Option<usize>> = (0..ns)
            .map(|s| shape(sn, s).2.first().map(|&r| owner[r]))
            .collect();
        let mut n_children = vec![0usize; ns];
        let mut child_ptr = vec![0usize; ns + 1];
        for p in parent.iter().flatten() {
            child_ptr[p + 1] += 1;
        }
        for s in 0..ns {
            child_ptr[s + 1] += child_ptr[s];
            n_children[s] = child_ptr[s + 1] - child_ptr[s];
        }
        let mut children = vec![0usize; child_ptr[ns]];
        let mut next = child_ptr.clone();
        for (s, p) in parent.iter().enumerate() {
            if let Some(p) = *p {
                children[next[p]] = s;
                next[p] += 1;
            }
        }
        // postorder: each root's subtree, children in ascending order
        let mut order = Vec::with_capacity(ns);
        let mut pending: Vec<(usize, usize)> = Vec::new();
        for root in (0..ns).filter(|&s| parent[s].is_none()) {
            pending.push((root, child_ptr[root]));
            while let Some(&mut (s, ref mut k)) = pending.last_mut() {
                if *k < child_ptr[s + 1] {
                    let child = children[*k];
                    *k += 1;
                    pending.push((child, child_ptr[child]));
                } else {
                    order.push(s);
                    pending.pop();
                }
            }
        }
        // each update matrix goes to the end of the arena that its depth's parity names, so
        // that a parent's matrix never overlaps its children's (which are at the other end,
        // on top): each end is a stack in postorder, and no matrix is ever moved
        // (a parent comes after its children in faer's numbering: it owns a row below their
        // columns, and supernodes are disjoint ranges of columns)
        let mut left = vec![false; ns];
        for s in (0..ns).rev() {
            left[s] = parent[s].is_none_or(|p| !left[p]);
        }
        let mut frames: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        let mut tops = [0usize; 2];
        let (mut arena, mut work, mut widest, mut rows) = (0usize, 0, 0, 0);
        for &s in &order {
            let (_, c, below) = shape(sn, s);
            let r = below.len();
            let (own, kids) = if left[s] { (0, 1) } else { (1, 0) };
            arena = arena.max(tops[0] + tops[1] + packed_len(r));
            let from = frames[kids].len() - n_children[s];
            tops[kids] -= frames[kids].drain(from..).sum::<usize>();
            if r > 0 {
                frames[own].push(packed_len(r));
                tops[own] += packed_len(r);
            }
            // the last supernode of a partial factorization: its rows from `stop` on are
            // the ones below its eliminated columns
            let kept = kept_columns(sn, stop, s);
            work = work.max((r + kept) * (c - kept));
            widest = widest.max(c);
            rows = rows.max(r);
        }
        // each entry's place: column j of supernode s at s's values + (j − begin)(c + r),
        // row i at i − begin inside s's columns, else c + its position among the rows below
        let ptr = pattern.col_ptr();
        let mut place = vec![ABOVE; pattern.compute_nnz()];
        for (j, &s) in owner.iter().enumerate() {
            let (begin, c, below) = shape(sn, s);
            let base = (j - begin) * (c + below.len());
            let start = ptr[j];
            for (k, i) in pattern.row_idx_of_col(j).enumerate() {
                if i < j {
                    continue;
                }
                let row = if i < begin + c {
                    i - begin
                } else {
                    c + below.partition_point(|&x| x < i)
                };
                place[start + k] = u32::try_from(base + row)
                    .ok()
                    .filter(|&at| at != ABOVE)
                    .ok_or(FactorizationError::Ordering(OrderingError::TooLarge(n)))?;
            }
        }
        let scratch = MemBuffer::try_new(cholesky_in_place_scratch::<f64>(
            widest,
            Par::Seq,
            Default::default(),
        ))
        .map_err(|e| FactorizationError::Workspace(FaerError::from(e)))?;
        Ok(Self {
            order,
            n_children,
            left,
            place,
            col_ptr: ptr.to_vec(),
            arena: vec![0.0; arena],
            work: vec![0.0; work],
            scratch,
            local: vec![usize::MAX; n],
            map: Vec::with_capacity(rows),
            runs: Vec::new(),
            stop,
        })
    }

    /// The Schur complement a partial factorization ([`Multifrontal::partial`]) leaves in
    /// `l_values`, where the factor's trailing columns would be: its lower triangle (the
    /// entries above the diagonal are not part of it).
    pub fn trailing<'a>(
        &self,
        sn: &SymbolicSupernodalCholesky<usize>,
        l_values: &'a [f64],
    ) -> MatRef<'a, f64> {
        let Some(last) = sn.n_supernodes().checked_sub(1) else {
            return MatRef::from_column_major_slice(&[], 0, 0);
        };
        let (c, kept) = (shape(sn, last).1, kept_columns(sn, self.stop, last));
        let at = sn.col_ptr_for_val()[last];
        MatRef::from_column_major_slice(&l_values[at..at + c * c], c, c).submatrix(
            c - kept,
            c - kept,
            kept,
            kept,
        )
    }

    /// The entries of all the update matrices it forms in one factorization (their lower
    /// triangles, Σ r (r + 1)/2 over the supernodes that form one): the memory traffic of the
    /// extend-add, against the factor's own entries.
    pub fn update_entries(&self, sn: &SymbolicSupernodalCholesky<usize>) -> usize {
        (0..sn.n_supernodes())
            .map(|s| {
                // a partial factorization's last supernode updates its own trailing block
                let rows = shape(sn, s).2.len() + kept_columns(sn, self.stop, s);
                rows * (rows + 1) / 2
            })
            .sum()
    }

    /// The bytes this driver keeps beside the factor: its update-matrix arena, its entry map,
    /// W and the index arrays.
    pub fn workspace_bytes(&self) -> usize {
        8 * (self.arena.len() + self.work.len() + self.local.len() + self.order.len())
            + 4 * self.place.len()
            + 8 * (self.col_ptr.len() + self.n_children.len())
    }

    /// The LDLᵀ factor of the matrix with `values` (in the pattern's order) into `l_values`
    /// (faer's supernodal layout of `sn`, the symbolic factor [`Multifrontal::new`] took).
    /// A zero pivot is an error naming its column in elimination order. With `phases`, the
    /// seconds of each part are added to it.
    pub fn factorize(
        &mut self,
        sn: &SymbolicSupernodalCholesky<usize>,
        values: &[f64],
        l_values: &mut [f64],
        phases: Option<&mut Phases>,
    ) -> Result<(), LdltError> {
        let mut clock = Clock(phases.map(|p| (p, Instant::now())));
        let Self {
            order,
            n_children,
            left,
            place,
            col_ptr,
            arena,
            work,
            scratch,
            local,
            map,
            runs,
            stop,
        } = self;
        let size = arena.len();
        // each end's stacked update matrices, (offset, rows, supernode), and its top
        let mut frames: [Vec<(usize, usize, usize)>; 2] = [Vec::new(), Vec::new()];
        let mut tops = [0usize; 2];
        for &p in order.iter() {
            let (begin, c, below) = shape(sn, p);
            let r = below.len();
            let nr = c + r;
            let at = sn.col_ptr_for_val()[p];
            let block = &mut l_values[at..at + nr * c];
            for (i, &row) in below.iter().enumerate() {
                local[row] = c + i;
            }
            // p's update matrix at its end of the arena, the children's at the other: split
            // the arena between them
            let (own, kids) = if left[p] { (0, 1) } else { (1, 0) };
            let u_at = if own == 0 {
                tops[0]
            } else {
                size - tops[1] - packed_len(r)
            };
            let len = packed_len(r);
            let cut = if own == 0 { u_at + len } else { u_at };
            let (low, high) = arena.split_at_mut(cut);
            let (u_p, children_side, children_base): (&mut [f64], &[f64], usize) = if own == 0 {
                (&mut low[u_at..], &*high, cut)
            } else {
                (&mut high[..len], &*low, 0)
            };
            // the children: their update matrices and their rows in p's front
            map.clear();
            runs.clear();
            let from = frames[kids].len() - n_children[p];
            let children: Vec<Child<'_>> = frames[kids]
                .drain(from..)
                .map(|(offset, rc, child)| {
                    let u = &children_side[offset - children_base..][..packed_len(rc)];
                    child_rows(map, runs, shape(sn, child).2, begin, c, local, u)
                })
                .collect();
            // 1–2. p's columns of the matrix, then the children's columns that are p's, a
            //    panel of p's columns at a time
            let width = (CACHED / nr).clamp(1, c);
            for j0 in (0..c).step_by(width) {
                let j1 = (j0 + width).min(c);
                block[j0 * nr..j1 * nr].fill(0.0);
                for e in col_ptr[begin + j0]..col_ptr[begin + j1] {
                    if place[e] != ABOVE {
                        block[place[e] as usize] += values[e];
                    }
                }
                for child in &children {
                    let (map, runs) = (&map[child.rows.clone()], &runs[child.runs.clone()]);
                    let own = &map[..child.split];
                    let columns =
                        own.partition_point(|&t| t < j0)..own.partition_point(|&t| t < j1);
                    extend_add(
                        block,
                        |t| (t * nr, nr, 0),
                        child.u,
                        child.rc,
                        map,
                        runs,
                        columns,
                    );
                }
            }
            clock.lap(|p| &mut p.assembly);
            // 3. the diagonal block's LDLᵀ and the block below it: L_B D, kept in W, then L_B
            //    (the last supernode of a partial factorization eliminates its columns before
            //    `stop` only: its rows from there on are below them, and its trailing columns
            //    take their update in place of an update matrix)
            let kept = kept_columns(sn, *stop, p);
            let ce = c - kept;
            let below_e = nr - ce;
            let front = MatMut::from_column_major_slice_mut(block, nr, c);
            let (eliminated, trailing) = front.split_at_col_mut(ce);
            let (mut top_block, mut bottom) = eliminated.split_at_row_mut(ce);
            if ce > 0 {
                cholesky_in_place(
                    top_block.as_mut(),
                    NO_REGULARIZATION,
                    Par::Seq,
                    MemStack::new(scratch),
                    Default::default(),
                )
                .map_err(|LdltError::ZeroPivot { index }| {
                    LdltError::ZeroPivot {
                        index: index + begin,
                    }
                })?;
            }
            for j in 1..ce {
                for i in 0..j {
                    top_block[(i, j)] = 0.0;
                }
            }
            solve_unit_lower_triangular_in_place(
                top_block.as_ref(),
                bottom.as_mut().transpose_mut(),
                Par::Seq,
            );
            clock.lap(|p| &mut p.diagonal);
            if below_e > 0 && ce > 0 {
                // W = L_B D and L_B = W D⁻¹ in one pass over the block
                let w = &mut work[..below_e * ce];
                for j in 0..ce {
                    let d = top_block[(j, j)].recip();
                    for (i, wi) in w[j * below_e..(j + 1) * below_e].iter_mut().enumerate() {
                        let v = bottom[(i, j)];
                        *wi = v;
                        bottom[(i, j)] = v * d;
                    }
                }
                clock.lap(|p| &mut p.copy);
                let w = MatRef::from_column_major_slice(w, below_e, ce);
                let l_b = bottom.as_ref();
                if kept > 0 {
                    // 4'. the trailing block (the last supernode's, r = 0) += −W L_Bᵀ
                    let mut t = trailing.subrows_mut(ce, kept);
                    matmul(
                        t.as_mut(),
                        BlockStructure::TriangularLower,
                        Accum::Add,
                        w,
                        BlockStructure::Rectangular,
                        l_b.transpose(),
                        BlockStructure::Rectangular,
                        -1.0,
                        Par::Seq,
                    );
                    clock.lap(|p| &mut p.update);
                } else {
                    // 4–5. U_p = −W L_Bᵀ, lower triangle, panel by panel (its diagonal block's
                    //    lower triangle and the rectangle below it); each panel then takes the
                    //    children's columns below p's that fall in it
                    for k in (0..r).step_by(PANEL) {
                        let (width, height) = (PANEL.min(r - k), r - k);
                        let (at, _) = packed_column(r, k);
                        let panel = MatMut::from_column_major_slice_mut(
                            &mut u_p[at..at + height * width],
                            height,
                            width,
                        );
                        let (diagonal, below_it) = panel.split_at_row_mut(width);
                        let l_k = l_b.subrows(k, width).transpose();
                        matmul(
                            diagonal,
                            BlockStructure::TriangularLower,
                            Accum::Replace,
                            w.subrows(k, width),
                            BlockStructure::Rectangular,
                            l_k,
                            BlockStructure::Rectangular,
                            -1.0,
                            Par::Seq,
                        );
                        faer::linalg::matmul::matmul(
                            below_it,
                            Accum::Replace,
                            w.subrows(k + width, height - width),
                            l_k,
                            -1.0,
                            Par::Seq,
                        );
                        clock.lap(|p| &mut p.update);
                        let column = |t: usize| {
                            let (to, to_row) = packed_column(r, t - c);
                            (to, r - to_row, c + to_row)
                        };
                        for child in &children {
                            let (map, runs) = (&map[child.rows.clone()], &runs[child.runs.clone()]);
                            let columns = map.partition_point(|&t| t < c + k)
                                ..map.partition_point(|&t| t < c + k + width);
                            extend_add(u_p, column, child.u, child.rc, map, runs, columns);
                        }
                        clock.lap(|p| &mut p.extend_update);
                    }
                }
            }
            for &row in below {
                local[row] = usize::MAX;
            }
            tops[kids] -= children
                .iter()
                .map(|child| packed_len(child.rc))
                .sum::<usize>();
            if r > 0 {
                frames[own].push((u_at, r, p));
                tops[own] += len;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::prelude::Solve;
    use faer::sparse::linalg::cholesky::supernodal::SupernodalLdltRef;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
        SymmetricOrdering,
    };
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::{SparseColMat, Triplet};
    use faer::{Conj, Mat, Side};

    /// A `k` × `k` grid's matrix (3 unknowns per node, bilinear couplings) in nested-dissection
    /// order, lower triangle: every 7th diagonal entry −2, the others 2, off-diagonal entries
    /// of at most 0.025 in magnitude, at most 26 a row. Gershgorin: every eigenvalue is within
    /// 0.65 of a diagonal entry, so the matrix is regular with as many negative eigenvalues
    /// as negative diagonal entries. Returns it, the symbolic factor and that count.
    fn problem(k: usize) -> (SparseColMat<usize, f64>, SymbolicCholesky<usize>, usize) {
        let (n, pairs) = crate::ordering::grid(k);
        let perm = crate::ordering::nested_dissection(n, &pairs).unwrap();
        let mut inv = vec![0; n];
        for (i, &p) in perm.iter().enumerate() {
            inv[p] = i;
        }
        let d = |i: usize| if i % 7 == 3 { -2.0 } else { 2.0 };
        let triplets: Vec<_> = pairs
            .iter()
            .map(|&(r, c)| {
                let v = if r == c {
                    d(r)
                } else {
                    0.025 * (((r * 31 + c * 17) % 11) as f64 / 10.0 - 0.5) * 2.0
                };
                let (a, b) = (inv[r], inv[c]);
                Triplet::new(a.max(b), a.min(b), v)
            })
            .collect();
        let m = SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap();
        let id: Vec<usize> = (0..n).collect();
        let symbolic = factorize_symbolic_cholesky(
            m.symbolic(),
            Side::Lower,
            SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(&id, &id, n)),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .unwrap();
        (m, symbolic, (0..n).filter(|&i| d(i) < 0.0).count())
    }

    fn supernodal(s: &SymbolicCholesky<usize>) -> &SymbolicSupernodalCholesky<usize> {
        match s.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => sn,
            SymbolicCholeskyRaw::Simplicial(_) => unreachable!("supernodal forced"),
        }
    }

    /// The pivots D in elimination order.
    fn pivots(sn: &SymbolicSupernodalCholesky<usize>, l: &[f64]) -> Vec<f64> {
        let mut d = Vec::new();
        for s in 0..sn.n_supernodes() {
            let (_, c, below) = shape(sn, s);
            let at = sn.col_ptr_for_val()[s];
            d.extend((0..c).map(|j| l[at + j * (c + below.len()) + j]));
        }
        d
    }

    #[test]
    fn the_factor_is_faers_within_round_off_and_keeps_the_inertia() {
        let (m, symbolic, negative) = problem(40);
        let sn = supernodal(&symbolic);
        assert!(sn.n_supernodes() > 100, "a tree worth the name");
        let mut ours = vec![f64::NAN; symbolic.len_val()];
        let mut driver = Multifrontal::new(sn, m.symbolic()).unwrap();
        let mut phases = Phases::default();
        driver
            .factorize(sn, m.val(), &mut ours, Some(&mut phases))
            .unwrap();
        assert!(phases.diagonal > 0.0 && phases.update > 0.0);
        let mut theirs = vec![0.0; symbolic.len_val()];
        let req = symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default());
        let mut mem = MemBuffer::new(req);
        symbolic
            .factorize_numeric_ldlt::<f64>(
                &mut theirs,
                m.as_ref(),
                Side::Lower,
                NO_REGULARIZATION,
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .unwrap();
        // the same arithmetic summed in another order: entries of magnitude ≤ 2 built from at
        // most a few hundred products each, so a few hundred ulp of 2 (measured: 2.2e-15, 5 ulp)
        let worst = ours
            .iter()
            .zip(&theirs)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-13, "largest difference {worst:e}");
        let d = pivots(sn, &ours);
        assert_eq!(d.iter().filter(|&&x| x < 0.0).count(), negative);
        // faer's supernodal solve reads the factor: K x = b back to x
        let n = m.nrows();
        let x: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos()).collect();
        let mut b = faer::Mat::<f64>::zeros(n, 1);
        for j in 0..n {
            for (i, &v) in m.as_ref().row_idx_of_col(j).zip(m.as_ref().val_of_col(j)) {
                b[(i, 0)] += v * x[j];
                if i != j {
                    b[(j, 0)] += v * x[i];
                }
            }
        }
        let mut mem = MemBuffer::new(sn.solve_in_place_scratch::<f64>(1, Par::Seq));
        SupernodalLdltRef::new(sn, &ours).solve_in_place_with_conj(
            Conj::No,
            b.as_mut(),
            Par::Seq,
            MemStack::new(&mut mem),
        );
        // Gershgorin: |eigenvalues| ≥ 1.35, so the error is round-off times a condition of
        // at most 2.65/1.35 (measured: 1.2e-15)
        for i in 0..n {
            assert!((b[(i, 0)] - x[i]).abs() < 1e-13, "x[{i}]");
        }
    }

    #[test]
    fn a_partial_factorization_leaves_the_schur_complement_of_its_columns() {
        let (m, symbolic, _) = problem(24);
        let sn = supernodal(&symbolic);
        let n = m.nrows();
        let last = sn.n_supernodes() - 1;
        let (begin, c, _) = shape(sn, last);
        assert!(c > 20, "a last supernode wide enough to cut: {c}");
        // a column before the last supernode cannot be a stop
        assert!(matches!(
            Multifrontal::partial(sn, m.symbolic(), begin - 1),
            Err(FactorizationError::Trailing { .. })
        ));
        let dense = m.as_ref().to_dense();
        let full = Mat::from_fn(n, n, |i, j| dense[(i.max(j), i.min(j))]);
        let mut whole = vec![0.0; symbolic.len_val()];
        Multifrontal::new(sn, m.symbolic())
            .unwrap()
            .factorize(sn, m.val(), &mut whole, None)
            .unwrap();
        // inside the last supernode, and at its first column
        for stop in [begin + c / 3, begin] {
            let mut driver = Multifrontal::partial(sn, m.symbolic(), stop).unwrap();
            let mut ours = vec![f64::NAN; symbolic.len_val()];
            driver.factorize(sn, m.val(), &mut ours, None).unwrap();
            // T = C − Bᵀ A⁻¹ B, dense (A is regular: its Gershgorin discs are K's, |λ| ≥ 1.35)
            let (a, b) = (full.get(..stop, ..stop), full.get(..stop, stop..));
            let a_inv_b = a.partial_piv_lu().solve(b);
            let t = full.get(stop.., stop..) - b.transpose() * &a_inv_b;
            let trailing = driver.trailing(sn, &ours);
            assert_eq!((trailing.nrows(), trailing.ncols()), (n - stop, n - stop));
            let mut worst = 0.0f64;
            for j in 0..n - stop {
                for i in j..n - stop {
                    worst = worst.max((trailing[(i, j)] - t[(i, j)]).abs());
                }
            }
            // entries of magnitude ≤ 3 from two factorizations' round-off, times a condition
            // of at most 2.65/1.35 (measured: 4.4e-16 at both stops)
            assert!(worst < 1e-13, "stop {stop}: largest difference {worst:e}");
            // the eliminated columns are the whole factor's, to round-off: the same updates,
            // the last supernode's diagonal block factorized in two pieces instead of one
            // (entries ≤ 2, so the same few-hundred-ulp bound as the whole factor against
            // faer's; measured: 0 at the supernode's first column, 1.7e-18 inside it)
            let at = sn.col_ptr_for_val()[last];
            let eliminated = |l: &[f64]| -> Vec<f64> {
                let mut v = l[..at].to_vec();
                v.extend(&l[at..at + c * (stop - begin)]);
                v
            };
            let gap = eliminated(&ours)
                .iter()
                .zip(&eliminated(&whole))
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(gap < 1e-13, "stop {stop}: eliminated columns {gap:e} apart");
        }
    }

    #[test]
    fn a_second_factorization_in_the_same_storage_has_the_same_bits() {
        let (m, symbolic, _) = problem(24);
        let sn = supernodal(&symbolic);
        let mut driver = Multifrontal::new(sn, m.symbolic()).unwrap();
        let mut first = vec![0.0; symbolic.len_val()];
        driver.factorize(sn, m.val(), &mut first, None).unwrap();
        // other values in between, so that the arena and the factor hold something else
        let other: Vec<f64> = m.val().iter().map(|v| 3.0 * v).collect();
        let mut second = first.clone();
        driver.factorize(sn, &other, &mut second, None).unwrap();
        driver.factorize(sn, m.val(), &mut second, None).unwrap();
        assert!(first
            .iter()
            .zip(&second)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn a_zero_pivot_names_its_column() {
        let (m, symbolic, _) = problem(16);
        let sn = supernodal(&symbolic);
        let n = m.nrows();
        // a diagonal matrix on the same pattern, zero at column k (in elimination order)
        for k in [0, n / 2, n - 1] {
            let values: Vec<f64> = (0..n)
                .flat_map(|j| {
                    m.as_ref()
                        .row_idx_of_col(j)
                        .map(move |i| if i == j && j != k { 1.0 } else { 0.0 })
                })
                .collect();
            let mut driver = Multifrontal::new(sn, m.symbolic()).unwrap();
            let mut l = vec![0.0; symbolic.len_val()];
            assert!(matches!(
                driver.factorize(sn, &values, &mut l, None),
                Err(LdltError::ZeroPivot { index }) if index == k
            ));
        }
    }
}
