//! Force terms: what one element adds to the energy, the internal force and the stiffness.
//!
//! The assembly ([`crate::model::Model::assemble`]) sums, element by element, the built-in
//! terms — the membrane ([`MembraneTerm`]) and, when the load has planes, the
//! frictionless contact ([`ContactTerm`]) — and then every term added to the model with
//! [`Model::add_term`](crate::model::Model::add_term). The enclosed volume (the gas) is not a
//! term: the loading multiplies it by the pressure, a Lagrange multiplier or Boyle's law
//! ([`crate::model::Loading`]).
//!
//! A new term implements [`ElementTerm`] once, generic over the element's node count, and is
//! then a [`Term`] (the object-safe form the model stores) for both the 4-node and the 9-node
//! element:
//!
//! ```text
//! energy  E_e(x_e)                  returned
//! force   r_e += ∂E_e/∂x_e          3 dofs per node, node major (x, y, z of node 0, then node 1, …)
//! tangent k_e += ∂²E_e/∂x_e²        only when asked (Some), symmetric
//! ```
//!
//! The residual, the line search's energy, the tangent (so Newton's quadratic convergence), the
//! stability count and the arc-length driver all see the term through the assembly, with no
//! other change. Check a new term's tangent against finite differences of its force, as
//! `crates/fem/tests/term.rs` does for an elastic foundation.

use crate::contact::Contact;
use crate::element::membrane_kernel_in_step;
use crate::geometry::{RefElement, Vec3};
use crate::memory::Memory;
use crate::FemError;
use nalgebra::{SMatrix, SVector};
use tubemem_material::MembraneLaw;

/// One element as a term sees it: its index, its reference data (nodes, Gauss points with
/// shape functions, derivatives and area weights, the nodal points) and the current positions
/// of its nodes.
pub struct ElementAt<'a, const N: usize> {
    pub index: usize,
    pub reference: &'a RefElement<N>,
    /// the current positions of the element's nodes
    pub x: &'a [Vec3; N],
    /// the reference positions of every node of the mesh
    pub(crate) mesh_nodes: &'a [[f64; 3]],
}

impl<const N: usize> ElementAt<'_, N> {
    /// The reference positions of the element's nodes.
    pub fn x0(&self) -> [Vec3; N] {
        self.reference.gather(self.mesh_nodes)
    }
}

/// A force term written once for both element kinds (N = 4 or 9 nodes, D = 3N dofs). Every
/// `ElementTerm` is a [`Term`].
pub trait ElementTerm: Send + Sync {
    /// A short name, for error messages.
    fn name(&self) -> &str;
    /// Add element `el`'s force to `r` and, if `k` is given, its tangent to `k`; return its
    /// energy.
    fn add<const N: usize, const D: usize>(
        &self,
        el: &ElementAt<'_, N>,
        r: &mut SVector<f64, D>,
        k: Option<&mut SMatrix<f64, D, D>>,
    ) -> Result<f64, FemError>;
}

/// A shared term is a term (so that its owner can change it between solves, e.g. ramp a load
/// through an atomic scale, while the model holds it).
impl<T: ElementTerm> ElementTerm for std::sync::Arc<T> {
    fn name(&self) -> &str {
        (**self).name()
    }
    fn add<const N: usize, const D: usize>(
        &self,
        el: &ElementAt<'_, N>,
        r: &mut SVector<f64, D>,
        k: Option<&mut SMatrix<f64, D, D>>,
    ) -> Result<f64, FemError> {
        (**self).add(el, r, k)
    }
}

/// A force term as the model stores it (object safe: one method per element kind). Implement
/// [`ElementTerm`] instead; this follows.
pub trait Term: Send + Sync {
    fn name(&self) -> &str;
    fn add_quad4(
        &self,
        el: &ElementAt<'_, 4>,
        r: &mut SVector<f64, 12>,
        k: Option<&mut SMatrix<f64, 12, 12>>,
    ) -> Result<f64, FemError>;
    fn add_quad9(
        &self,
        el: &ElementAt<'_, 9>,
        r: &mut SVector<f64, 27>,
        k: Option<&mut SMatrix<f64, 27, 27>>,
    ) -> Result<f64, FemError>;
}

impl<T: ElementTerm> Term for T {
    fn name(&self) -> &str {
        ElementTerm::name(self)
    }
    fn add_quad4(
        &self,
        el: &ElementAt<'_, 4>,
        r: &mut SVector<f64, 12>,
        k: Option<&mut SMatrix<f64, 12, 12>>,
    ) -> Result<f64, FemError> {
        self.add(el, r, k)
    }
    fn add_quad9(
        &self,
        el: &ElementAt<'_, 9>,
        r: &mut SVector<f64, 27>,
        k: Option<&mut SMatrix<f64, 27, 27>>,
    ) -> Result<f64, FemError> {
        self.add(el, r, k)
    }
}

/// The membrane of a law ([`crate::element::membrane_kernel`]), hyperelastic or, with a
/// [`Memory`], in the current time step of a viscoelastic law: a law's failure at a Gauss point
/// is [`FemError::Material`] with the element and the point.
pub struct MembraneTerm<'a> {
    pub law: &'a dyn MembraneLaw,
    pub memory: Option<&'a Memory>,
}

impl ElementTerm for MembraneTerm<'_> {
    fn name(&self) -> &str {
        "membrane"
    }
    fn add<const N: usize, const D: usize>(
        &self,
        el: &ElementAt<'_, N>,
        r: &mut SVector<f64, D>,
        k: Option<&mut SMatrix<f64, D, D>>,
    ) -> Result<f64, FemError> {
        let step = self.memory.map(|m| m.at(el.index));
        membrane_kernel_in_step(self.law, step, el.reference, el.x, r, k).map_err(|(gp, source)| {
            FemError::Material {
                element: el.index,
                gauss_point: gp,
                source,
            }
        })
    }
}

/// Frictionless contact with rigid planes ([`Contact::kernel_on_branch`]), with the
/// multipliers of an augmented-Lagrangian contact.
pub struct ContactTerm<'a> {
    pub contact: &'a Contact,
    /// the contact multipliers of every element ([`crate::model::State::multipliers`]; empty:
    /// none)
    pub multipliers: &'a [f64],
    /// positions whose contact status selects the contact's branch
    /// ([`Contact::kernel_on_branch`]; none: the positions assembled)
    pub branch: Option<&'a [[f64; 3]]>,
}

impl ElementTerm for ContactTerm<'_> {
    fn name(&self) -> &str {
        "contact"
    }
    fn add<const N: usize, const D: usize>(
        &self,
        el: &ElementAt<'_, N>,
        r: &mut SVector<f64, D>,
        k: Option<&mut SMatrix<f64, D, D>>,
    ) -> Result<f64, FemError> {
        let c = self.contact;
        let lambda = c.element_history(self.multipliers, el.index, c.samples(el.reference).len());
        let branch = self.branch.map(|b| el.reference.gather(b));
        Ok(c.kernel_on_branch(el.reference, el.x, branch.as_ref(), lambda, r, k))
    }
}
