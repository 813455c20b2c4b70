//! Dimensional helpers: from the paper's reduced quantities back to units.
use crate::error::{invalid, GpsError};
use serde::{Deserialize, Serialize};

/// The range each SI scale and product of scales must lie in ([`Scales::new`]).
pub const SCALE_RANGE: (f64, f64) = (1e-100, 1e100);

/// Reference radius R, undeformed thickness H and shear modulus μ, in any consistent units
/// (e.g. m, m, Pa → pressures in Pa and forces per length in N/m).
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scales {
    pub radius: f64,
    pub thickness: f64,
    pub shear_modulus: f64,
}

impl Scales {
    pub fn new(radius: f64, thickness: f64, shear_modulus: f64) -> Result<Self, GpsError> {
        for (name, v) in [
            ("radius", radius),
            ("thickness", thickness),
            ("shear_modulus", shear_modulus),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "must be finite and > 0"));
            }
        }
        // Every dimensional output is a reduced value times one of these products; the reduced
        // values span many decades (a force of 1e-12 μHR at first contact, pressures of 1e3 ϖ
        // near a limit), so each product must leave that room inside f64's ±1e308: a scale
        // within 1e±100 does, for any physical tube (nm to km, mPa to TPa).
        let (r, h, mu) = (radius, thickness, shear_modulus);
        for (name, v) in [
            ("pressure scale mu*thickness/radius", mu * h / r),
            ("resultant scale mu*thickness", mu * h),
            ("force scale mu*thickness*radius", mu * h * r),
            ("stiffness scale mu*thickness/radius^2", mu * h / (r * r)),
            ("radius", r),
            ("shear_modulus", mu),
        ] {
            if !(SCALE_RANGE.0..=SCALE_RANGE.1).contains(&v) {
                return Err(invalid(
                    name,
                    v,
                    "must be within 1e-100 and 1e100 (SI units: every output is a reduced value times this scale, and must stay finite)",
                ));
            }
        }
        Ok(Self {
            radius,
            thickness,
            shear_modulus,
        })
    }
    /// p = ϖ μH/R (eq. 67).
    pub fn pressure(&self, w: f64) -> f64 {
        w * self.shear_modulus * self.thickness / self.radius
    }
    /// ϖ = pR/(μH).
    pub fn reduced_pressure(&self, p: f64) -> f64 {
        p * self.radius / (self.shear_modulus * self.thickness)
    }
    /// Force per unit tube length on each plate, p c = (ϖχ) π μH (eq. 80).
    pub fn force_per_length(&self, reduced_force: f64) -> f64 {
        reduced_force * std::f64::consts::PI * self.shear_modulus * self.thickness
    }
    /// Plate approach 2r* − 2r = 2R (λs* − ρ) (eq. 81).
    pub fn plate_approach(&self, reduced_displacement: f64) -> f64 {
        2.0 * self.radius * reduced_displacement
    }
    /// Resultant N = (N/μH) μH, force per unit current length.
    pub fn resultant(&self, reduced: f64) -> f64 {
        reduced * self.shear_modulus * self.thickness
    }
}
