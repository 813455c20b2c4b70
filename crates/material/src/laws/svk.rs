//! The Saint-Venant–Kirchhoff law in plane stress: a compressible sheet, Green–Lagrange
//! strain E = (C − I)/2, second Piola–Kirchhoff stress S = D E with the plane-stress matrix of
//! Young's modulus E and Poisson's ratio ν (the law of Kratos's `MembraneElement3D4N`):
//!
//! ```text
//! W H⁻¹ = E/(2(1 − ν²)) [(1 − ν) tr(E²) + ν (tr E)²] = μ [tr(E²) + ν/(1 − ν) (tr E)²],
//! μ = E/(2(1 + ν));   with a = tr C, b = det C:  tr E = (a − 2)/2, det E = (b − a + 1)/4,
//! tr(E²) = (tr E)² − 2 det E, so  W/μ = (1 + k)(a − 2)²/4 − (b − a + 1)/2,  k = ν/(1 − ν)
//! W_a = (1 + k)(a − 2)/2 + ½,  W_b = −½,  W_aa = (1 + k)/2,  W_ab = W_bb = 0
//! ```
//! The thickness does not change (the membrane's H is its reference thickness, as in Kratos).

use crate::{EnergyDerivatives, MaterialError, MembraneLaw, Num};

/// The plane-stress Saint-Venant–Kirchhoff law.
#[derive(Clone, Debug, PartialEq)]
pub struct SaintVenantKirchhoff {
    young_modulus: f64,
    poisson_ratio: f64,
}

impl SaintVenantKirchhoff {
    /// E > 0 and −1 < ν ≤ ½ (the 3D law's range; ν = ½ is the incompressible limit, which
    /// plane stress keeps finite).
    pub fn new(young_modulus: f64, poisson_ratio: f64) -> Result<Self, MaterialError> {
        super::check_positive("young_modulus", young_modulus)?;
        if !(poisson_ratio.is_finite() && poisson_ratio > -1.0 && poisson_ratio <= 0.5) {
            return Err(MaterialError::InvalidParameter {
                name: "poisson_ratio",
                value: poisson_ratio,
                requirement: "Poisson's ratio ν must lie in (−1, 0.5]",
            });
        }
        Ok(Self {
            young_modulus,
            poisson_ratio,
        })
    }
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }
}

impl MembraneLaw for SaintVenantKirchhoff {
    fn name(&self) -> String {
        format!(
            "Saint-Venant–Kirchhoff, plane stress (E = {}, ν = {})",
            Num(self.young_modulus),
            Num(self.poisson_ratio)
        )
    }
    fn shear_modulus(&self) -> f64 {
        self.young_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        let nu = self.poisson_ratio;
        let k1 = 1.0 + nu / (1.0 - nu);
        Ok(EnergyDerivatives {
            w: 0.25 * k1 * (a - 2.0) * (a - 2.0) - 0.5 * (b - a + 1.0),
            w_a: 0.5 * k1 * (a - 2.0) + 0.5,
            w_b: -0.5,
            w_aa: 0.5 * k1,
            w_ab: 0.0,
            w_bb: 0.0,
        })
    }
}
