//! Cross-crate verification: the 3D membrane FE (`tubemem-fem`) against the closed form
//! (`tubemem-gps`, the paper's equations) and against analytic solutions. One test binary; each
//! module opens with the source of truth of its tests.
//!
//! The reference paper: *On the generalized plane strain assumption for pressurized membranes*
//! (README, "References"); equation numbers below are the paper's.

mod bulge;
mod sphere;
mod squeeze;
mod tube;
