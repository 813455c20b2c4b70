//! # tubemem-fem — nonlinear membrane finite elements
//!
//! A 3D membrane solver on quadrilateral surface meshes that assumes nothing about translation
//! invariance. The crate is split along its seams:
//!
//! | module | what it owns |
//! |---|---|
//! | [`geometry`] | Gauss-point geometry: shape functions, reference frame, position, gradient, area ratio |
//! | [`element`] | the hyperelastic membrane kernel (residual, tangent) and the Gauss-point state |
//! | [`contact`] | rigid planes with their penalty ([`contact::Contact`]) and the contact kernel |
//! | [`dofs`] | equation numbering: symmetry planes, rigid-body pins, rigid plugs |
//! | [`pattern`] | the sparsity pattern, built once |
//! | [`linsolve`] | sparse LDLᵀ on faer (symbolic once, numeric per iteration), inertia |
//! | [`krylov`] | right-preconditioned GMRES, for a factor reused across linearizations |
//! | [`term`] | force terms: the public [`term::Term`] / [`term::ElementTerm`] interface, the membrane and contact terms |
//! | [`model`] | the model: assembly of the terms plus the enclosed volume, loads, solves, stability, the membrane problem |
//! | [`continuation`] | arc-length continuation with located critical points |
//! | [`manufactured`] | code verification: manufactured solutions, their body force and their errors |
//! | [`tension_field`] | wrinkling against a closed form: the annulus pulled at both rims |
//! | [`edge_load`] | a dead radial traction on the free edges of an open sheet |
//! | [`newton`] | a damped Newton driver that knows nothing of membranes |
//! | [`stepping`] | load stepping with cut-back and growth |
//! | [`post`] | mid-span values, profiles, contact values, cell values |
//! | [`slide`] | moving a whole tube's bulge by whole rows (the neutral family's members) |
//!
//! The enclosed volume with its gradient and Hessian is `tubemem_mesh::volume` (one
//! implementation for the mesh checks, the loading and the output).
//! All quantities are per unit μH (energies, forces, resultants), with lengths in units of R.

// Kernels index nodes, components and Gauss points explicitly, as the formulas are written;
// `!(a > b)` is deliberate where NaN must fail the test.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod contact;
pub mod continuation;
pub mod dofs;
pub mod edge_load;
pub mod element;
pub mod geometry;
pub mod heap;
pub mod krylov;
pub mod linsolve;
pub mod manufactured;
pub mod memory;
pub mod model;
pub mod newton;
pub mod ordering;
pub mod pattern;
pub mod post;
pub mod slide;
pub mod stepping;
pub mod tension_field;
pub mod term;

pub use newton::NewtonSettings;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_prolong;
#[cfg(test)]
mod tests_quad9;
#[cfg(test)]
mod tests_remap;
#[cfg(test)]
mod tests_reuse;

use thiserror::Error;
use tubemem_material::MaterialError;
use tubemem_mesh::MeshError;

/// What went wrong, and where. Wrapping variants keep their cause as `source()` and do not
/// repeat it in their own message; print the chain (e.g. `anyhow`'s `{:#}`) to see all of it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FemError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error("element {element} is degenerate at Gauss point {gauss_point} of the reference configuration")]
    DegenerateElement { element: usize, gauss_point: usize },
    #[error("element {element} is degenerate at its node {node} (of 0..N, in element order) in the reference configuration")]
    DegenerateNode { element: usize, node: usize },
    #[error("the state cannot be carried to the moved mesh: {reason}")]
    Remap { reason: String },
    /// A coarse mesh's state that cannot be carried to this mesh (mesh sequencing).
    #[error("the coarse mesh's state cannot be carried to this mesh: {reason}")]
    Prolong { reason: String },
    /// A load or problem the model cannot take (a pressure on an open sheet, a manufactured
    /// problem set up inconsistently).
    #[error("{reason}")]
    Setup { reason: String },
    #[error("the mesh cannot follow the contact edge: {reason}")]
    Refit { reason: String },
    #[error("element {element}, Gauss point {gauss_point}")]
    Material {
        element: usize,
        gauss_point: usize,
        #[source]
        source: MaterialError,
    },
    #[error("term `{term}` at element {element}")]
    Term {
        term: String,
        element: usize,
        #[source]
        source: Box<FemError>,
    },
    #[error("node {node} belongs to no element: every node must be a corner of a quad")]
    UnusedNode { node: usize },
    #[error("the controlled dof (node {node}, component {component}) is fixed by a constraint")]
    FixedControlDof { node: usize, component: usize },
    #[error("zero pivot {index} ({value:e}) in the LDLᵀ factorization: the tangent is singular")]
    ZeroPivot { index: usize, value: f64 },
    #[error("the enclosed volume of the modelled part is {} (not positive): the gas has been squeezed out, the plates are closer than the membrane allows", tubemem_material::Num(*volume))]
    GasVolume { volume: f64 },
    #[error("the residual is not finite at this state (an overflow in the {what})")]
    NonFiniteResidual { what: &'static str },
    #[error("tangent matrix entry {entry} is not finite")]
    NonFiniteEntry { entry: usize },
    /// A stage took more steps than allowed without reaching its end.
    #[error("stage {stage} took {steps} steps and is only {:.1} % done: the step limit (`StepSettings::max_steps`) stops it (a path that needs this many steps is stalling, and each step writes a frame)", 100.0 * fraction)]
    StepLimit {
        stage: usize,
        steps: usize,
        fraction: f64,
    },
    /// The run was asked to stop (SIGINT, SIGTERM, Ctrl-C in Python) between two Newton
    /// iterations.
    #[error("interrupted")]
    Interrupted,
    #[error("sparse factorization failed")]
    Factorization(#[from] linsolve::FactorizationError),
    #[error("invalid parameter `{name}` = {}: {requirement}", tubemem_material::Num(*value))]
    InvalidParameter {
        name: &'static str,
        value: f64,
        requirement: &'static str,
    },
    /// A stage could not reach its next step. `material` is the material error that rejected
    /// an earlier attempt at the same step (e.g. locking) when the last attempt failed
    /// otherwise: near a locking limit the cut-back attempts stop hitting the limit itself and
    /// fail to converge instead.
    #[error("step {step} (load parameter {value:.6}): no convergence even with {cuts} step cut-backs{}{}; last attempt",
        near_locking.as_ref().map(|l| format!(" — {l}")).unwrap_or_default(),
        material.as_ref().map(|m| format!(" (earlier attempts at this step were rejected: {})", error_chain(m.as_ref()))).unwrap_or_default())]
    Stage {
        stage: usize,
        step: usize,
        value: f64,
        cuts: usize,
        material: Option<Box<FemError>>,
        /// the last converged state's closest approach to the law's locking limit, when it is
        /// within [`model::NEAR_LOCKING`] of it
        near_locking: Option<model::LockingProximity>,
        #[source]
        source: Box<newton::NewtonError<FemError>>,
    },
    /// An arc-length stage could not take its next step.
    #[error("stage {stage}, arc-length step {step} from ϖ = {p:.9}: {what}{}", if source.is_some() { "; last attempt" } else { "" })]
    Arc {
        stage: usize,
        step: usize,
        p: f64,
        what: String,
        #[source]
        source: Option<Box<newton::NewtonError<FemError>>>,
    },
    /// The augmented Lagrangian's multipliers did not settle within their update limit.
    #[error("the contact multipliers did not settle: after {updates} augmentations a plane still pushes where the gap is {gap:.3e} R (penetration {penetration:.3e} R), above the gap tolerance {tolerance:.1e} R; the last update moved a multiplier by {change:.3e}, and the regularizing penalty κ = {penalty:.3e} sets how far an update moves one (raise `max_augmentations` or `gap_tolerance`, or give a larger `penalty` or a smaller `penetration_tolerance`)")]
    Augmentation {
        updates: usize,
        gap: f64,
        penetration: f64,
        change: f64,
        tolerance: f64,
        penalty: f64,
    },
    /// A bulge could not be moved along the tube ([`slide`]).
    #[error("cannot move the bulge: {what}")]
    Slide { what: String },
}

impl FemError {
    /// The element where a failed stage met the law's locking limit: a locking error, or a last
    /// converged state within [`model::NEAR_LOCKING`] of the limit.
    pub fn locking_element(&self) -> Option<usize> {
        if let Some((e, MaterialError::Locking { .. })) = self.material_cause() {
            return Some(e);
        }
        match self {
            FemError::Stage {
                near_locking: Some(l),
                ..
            } => Some(l.element),
            _ => None,
        }
    }

    /// The material error at the root of this one, if any (e.g. locking).
    pub fn material_cause(&self) -> Option<(usize, &MaterialError)> {
        match self {
            FemError::Material {
                element, source, ..
            } => Some((*element, source)),
            FemError::Stage {
                source, material, ..
            } => source
                .cause()
                .and_then(|e| e.material_cause())
                .or_else(|| material.as_ref().and_then(|m| m.material_cause())),
            _ => None,
        }
    }
}

/// The message of an error followed by its causes, ": "-separated, its numbers as a user reads
/// them ([`tubemem_material::tidy_numbers`]).
pub fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cur = c.source();
    }
    tubemem_material::tidy_numbers(&s)
}
