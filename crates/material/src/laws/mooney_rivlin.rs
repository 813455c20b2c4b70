//! Mooney–Rivlin and neo-Hookean.

use super::check_positive;
use crate::{EnergyDerivatives, MaterialError, MembraneLaw};
use serde::{Deserialize, Serialize};

/// Mooney–Rivlin law, paper Appendix B eq. (83): W̄ = ½[(I1 − 3) + α (I2 − 3)], α ≥ 0.
///
/// Note on scaling: with eq. (83) as printed, the small-strain shear modulus is μ(1 + α), not μ
/// (the paper's remark that W̄ is scaled so that μ is the shear modulus holds for α = 0 only).
/// tubemem keeps the paper's scaling so that eqs. (86)–(87) hold verbatim, and reports
/// μ(1 + α) from [`MooneyRivlin::small_strain_shear_modulus`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MooneyRivlin {
    shear_modulus: f64,
    alpha: f64,
}

impl MooneyRivlin {
    pub fn new(shear_modulus: f64, alpha: f64) -> Result<Self, MaterialError> {
        check_positive("shear_modulus", shear_modulus)?;
        if !(alpha.is_finite() && alpha >= 0.0) {
            return Err(MaterialError::InvalidParameter {
                name: "alpha",
                value: alpha,
                requirement: "the Mooney–Rivlin hardening parameter must be finite and ≥ 0",
            });
        }
        Ok(Self {
            shear_modulus,
            alpha,
        })
    }
    pub fn alpha(&self) -> f64 {
        self.alpha
    }
    /// μ(1 + α): the shear modulus of eq. (83) at small strain.
    pub fn small_strain_shear_modulus(&self) -> f64 {
        self.shear_modulus * (1.0 + self.alpha)
    }
}

impl MembraneLaw for MooneyRivlin {
    fn name(&self) -> String {
        if self.alpha == 0.0 {
            "neo-Hookean".to_string()
        } else {
            format!("Mooney–Rivlin (α = {})", self.alpha)
        }
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        // I1 = a + 1/b, I2 = a/b + b.
        let al = self.alpha;
        let (b2, b3) = (b * b, b * b * b);
        Ok(EnergyDerivatives {
            w: 0.5 * ((a + 1.0 / b - 3.0) + al * (a / b + b - 3.0)),
            w_a: 0.5 * (1.0 + al / b),
            w_b: 0.5 * (-1.0 / b2 + al * (1.0 - a / b2)),
            w_aa: 0.0,
            w_ab: -0.5 * al / b2,
            w_bb: (1.0 + al * a) / b3,
        })
    }
}

/// The neo-Hookean law W̄ = ½(I1 − 3): Mooney–Rivlin with α = 0 (and the limit 𝒩 → ∞ of the
/// Anssari-Benam–Bucchi law).
pub fn neo_hookean(shear_modulus: f64) -> Result<MooneyRivlin, MaterialError> {
    MooneyRivlin::new(shear_modulus, 0.0)
}
