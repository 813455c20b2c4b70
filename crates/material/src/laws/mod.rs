//! The built-in laws, one file each.
//!
//! | law | type | parameters | derivatives |
//! |---|---|---|---|
//! | Anssari-Benam–Bucchi (the paper's) | [`AnssariBenamBucchi`] | μ, 𝒩 | analytic |
//! | Mooney–Rivlin, neo-Hookean | [`MooneyRivlin`], [`neo_hookean`] | μ, α | analytic |
//! | Yeoh (3 terms) | [`Yeoh`] | C10, C20, C30 | analytic |
//! | Gent | [`Gent`] | μ, Jm | analytic |
//! | Gent–Gent | [`GentGent`] | μ, Jm, C2 | analytic |
//! | Arruda–Boyce (8-chain) | [`ArrudaBoyce`] | μ, N | analytic, exact inverse Langevin |
//! | Ogden (N terms) | [`Ogden`] | μp, αp | principal stretches ([`crate::separable`]) |
//! | Saint-Venant–Kirchhoff, plane stress | [`SaintVenantKirchhoff`] | E, ν | analytic (compressible) |
//! | an energy written in the case file | [`expression::InvariantLaw`], [`expression::PrincipalLaw`] | named | automatic |
//!
//! Every law gives W(a, b)/μ and its derivatives with respect to (a, b) = (tr C, det C).

use crate::MaterialError;

pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), MaterialError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(MaterialError::InvalidParameter {
            name,
            value,
            requirement: "must be finite and > 0",
        })
    }
}

mod abb;
mod arruda_boyce;
pub mod expression;
mod gent;
pub mod langevin;
mod mooney_rivlin;
mod ogden;
mod svk;
mod yeoh;

pub use abb::{AnssariBenamBucchi, MAX_KUHN};
pub use arruda_boyce::ArrudaBoyce;
pub use gent::{Gent, GentGent};
pub use mooney_rivlin::{neo_hookean, MooneyRivlin};
pub use ogden::Ogden;
pub use svk::SaintVenantKirchhoff;
pub use yeoh::Yeoh;

/// W and its (a, b) derivatives for an energy of the invariants, W̄(I1, I2), given its partial
/// derivatives `f` = [W̄, W̄₁, W̄₂, W̄₁₁, W̄₁₂, W̄₂₂] at I1 = a + 1/b, I2 = a/b + b:
///
/// ```text
/// I1_a = 1, I1_b = −1/b², I1_bb = 2/b³;   I2_a = 1/b, I2_b = 1 − a/b², I2_ab = −1/b², I2_bb = 2a/b³
/// ```
pub(crate) fn from_invariants(f: [f64; 6], a: f64, b: f64) -> crate::EnergyDerivatives {
    let [w, w1, w2, w11, w12, w22] = f;
    let (b2, b3) = (b * b, b * b * b);
    let (i1a, i1b, i1bb) = (1.0, -1.0 / b2, 2.0 / b3);
    let (i2a, i2b, i2ab, i2bb) = (1.0 / b, 1.0 - a / b2, -1.0 / b2, 2.0 * a / b3);
    crate::EnergyDerivatives {
        w,
        w_a: w1 * i1a + w2 * i2a,
        w_b: w1 * i1b + w2 * i2b,
        w_aa: w11 * i1a * i1a + 2.0 * w12 * i1a * i2a + w22 * i2a * i2a,
        w_ab: w11 * i1a * i1b + w12 * (i1a * i2b + i2a * i1b) + w22 * i2a * i2b + w2 * i2ab,
        w_bb: w11 * i1b * i1b + 2.0 * w12 * i1b * i2b + w22 * i2b * i2b + w1 * i1bb + w2 * i2bb,
    }
}

/// The [`from_invariants`] of an energy of I1 alone: `f` = [W̄, W̄', W̄''].
pub(crate) fn from_i1(f: [f64; 3], a: f64, b: f64) -> crate::EnergyDerivatives {
    from_invariants([f[0], f[1], 0.0, f[2], 0.0, 0.0], a, b)
}
