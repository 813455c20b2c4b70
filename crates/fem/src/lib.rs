//! # tubemem-fem — nonlinear membrane finite elements
//!
//! A 3D membrane solver on quadrilateral surface meshes that assumes nothing about translation
//! invariance: hyperelastic incompressible membrane ([`element`]), exact enclosed volume
//! ([`volume`]) for pressure, volume and closed-gas loading, assembled in parallel into a faer
//! sparse matrix and solved by Newton with a sparse LDLᵀ factorization ([`linsolve`]).
//!
//! Kernels, assembly and solver are apart: an element kernel reads nodal positions and writes a
//! local vector and matrix; only [`model`] touches global structures.
//! All quantities are per unit μH (energies, forces, resultants), with lengths in units of R.

// Kernels index nodes, components and Gauss points explicitly, as the formulas are written;
// `!(a > b)` is deliberate where NaN must fail the test.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod contact;
pub mod element;
pub mod linsolve;
pub mod model;
pub mod post;
pub mod volume;

use thiserror::Error;
use tubemem_material::MaterialError;
use tubemem_mesh::MeshError;

/// What went wrong, and where.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FemError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error("element {element} is degenerate at Gauss point {gauss_point} of the reference configuration")]
    DegenerateElement { element: usize, gauss_point: usize },
    #[error("element {element}, Gauss point {gauss_point}: {source}")]
    Material {
        element: usize,
        gauss_point: usize,
        #[source]
        source: MaterialError,
    },
    #[error("sparse factorization failed: {reason}")]
    Factorization { reason: String },
    #[error("invalid parameter `{name}` = {value}: {requirement}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        requirement: &'static str,
    },
    /// Writing the results of a converged step failed (the run stops; earlier steps are kept).
    #[error("stage {stage}, step {step}: writing results failed: {reason}")]
    Output {
        stage: usize,
        step: usize,
        reason: String,
    },
    #[error("stage {stage}, step {step}: Newton did not converge after {iterations} iterations (residual {residual:.3e}, tolerance {tolerance:.1e}) even with {cuts} step cut-backs")]
    NoConvergence {
        stage: usize,
        step: usize,
        iterations: usize,
        residual: f64,
        tolerance: f64,
        cuts: usize,
    },
}

#[cfg(test)]
mod tests;
