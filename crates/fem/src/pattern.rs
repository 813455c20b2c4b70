//! The sparsity pattern of the global tangent, built once per mesh: for every element, the
//! positions of its 3N × 3N entries (N = 4 or 9 nodes) in the lower triangle of the global matrix (in pattern
//! order), and the position of every diagonal entry (for shifts). The global (row, col) of
//! each value is built with it and handed to the symbolic factorization, not kept: 16 bytes a
//! value, some 400 MB at a million unknowns.

use crate::dofs::DofMap;

#[derive(Clone, Debug)]
pub struct Pattern {
    /// per element: (local row, local col) of each entry it contributes, in pattern order
    entries: Vec<Vec<(u8, u8)>>,
    /// the number of values
    len: usize,
    /// the position in `pairs` of one entry of each diagonal
    diag: Vec<usize>,
}

impl Pattern {
    /// The pattern of elements given by their node lists (in element order), and the (row, col)
    /// of every value, row ≥ col, in the order values are given (duplicates included).
    pub fn new<'a>(
        dofs: &DofMap,
        elements: impl IntoIterator<Item = &'a [usize]>,
    ) -> (Self, Vec<(usize, usize)>) {
        let mut entries = Vec::new();
        let mut pairs = Vec::new();
        let mut diag = vec![usize::MAX; dofs.len()];
        for nodes in elements {
            let mut list = Vec::new();
            let d = 3 * nodes.len();
            for i in 0..d {
                for j in 0..d {
                    if let (Some(a), Some(b)) =
                        (dofs.eq(nodes[i / 3], i % 3), dofs.eq(nodes[j / 3], j % 3))
                    {
                        if a >= b {
                            if a == b && diag[a] == usize::MAX {
                                diag[a] = pairs.len();
                            }
                            pairs.push((a, b));
                            list.push((i as u8, j as u8));
                        }
                    }
                }
            }
            entries.push(list);
        }
        let pattern = Self {
            entries,
            len: pairs.len(),
            diag,
        };
        (pattern, pairs)
    }

    /// The local (row, col) entries of element `e`, in pattern order.
    pub fn element_entries(&self, e: usize) -> &[(u8, u8)] {
        &self.entries[e]
    }

    /// The number of values.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The value positions of the diagonal entries (one each; `usize::MAX` for an equation that
    /// no element reaches, which [`crate::model::Model::new`] rejects).
    pub fn diagonal(&self) -> &[usize] {
        &self.diag
    }
}
