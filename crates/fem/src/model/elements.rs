//! The reference elements of a model, all 4-node or all 9-node ([`Elements`]), and
//! [`with_elements!`](crate::with_elements) to run one generic body on either kind.

use super::*;

/// The reference elements of a model: all 4-node or all 9-node.
#[derive(Clone, Debug)]
pub enum Elements {
    Quad4(Vec<RefElement<4>>),
    Quad9(Vec<RefElement<9>>),
}

/// Run `$body` with `$v` bound to the element vector of either kind (the body is compiled once
/// per kind, so generic kernels are monomorphized for both).
#[macro_export]
macro_rules! with_elements {
    ($els:expr, $v:ident => $body:expr) => {
        match $els {
            $crate::model::Elements::Quad4($v) => $body,
            $crate::model::Elements::Quad9($v) => $body,
        }
    };
}

impl Elements {
    pub fn len(&self) -> usize {
        with_elements!(self, v => v.len())
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The nodes of element `e` (4 or 9).
    pub fn nodes(&self, e: usize) -> &[usize] {
        with_elements!(self, v => &v[e].nodes[..])
    }
    /// The corner nodes of element `e`.
    pub fn corners(&self, e: usize) -> [usize; 4] {
        let n = self.nodes(e);
        [n[0], n[1], n[2], n[3]]
    }
    /// The nodes of each element: 4 or 9.
    pub fn nodes_per_element(&self) -> usize {
        match self {
            Elements::Quad4(_) => 4,
            Elements::Quad9(_) => 9,
        }
    }
    /// Element `e`'s nodal weights ∫N_a dA0, in node order.
    pub fn nodal_weights(&self, e: usize) -> Vec<f64> {
        with_elements!(self, v => v[e].nodal.iter().map(|p| p.w).collect())
    }
    pub fn kind(&self) -> ElementKind {
        match self {
            Elements::Quad4(_) => ElementKind::Quad4,
            Elements::Quad9(_) => ElementKind::Quad9,
        }
    }
}
