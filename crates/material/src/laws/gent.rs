//! Gent's law (Gent 1996, *Rubber Chem. Technol.* 69), W = −(μ Jm/2) ln(1 − (I1 − 3)/Jm),
//! and the Gent–Gent law of Pucci & Saccomandi (2002, *Rubber Chem. Technol.* 75), which adds
//! C2 ln(I2/3). Both lock at I1 = 3 + Jm.

use super::check_positive;
use crate::{EnergyDerivatives, MaterialError, MembraneLaw, Num};

/// The largest Jm the Gent laws take, 1e6 (rubbers have tens to hundreds).
pub const MAX_JM: f64 = 1e6;

fn check_jm(jm: f64) -> Result<(), MaterialError> {
    if jm.is_finite() && jm > 0.0 && jm <= MAX_JM {
        Ok(())
    } else {
        Err(MaterialError::InvalidParameter {
            name: "jm",
            value: jm,
            requirement: "the locking parameter Jm must be > 0 and at most 1e6 (the chains lock at I1 = 3 + Jm)",
        })
    }
}

/// W̄(I1) = −(Jm/2) ln(1 − (I1 − 3)/Jm) and its first two derivatives, or the locking error.
fn gent_i1(law: &dyn MembraneLaw, jm: f64, i1: f64) -> Result<[f64; 3], MaterialError> {
    let r = 1.0 - (i1 - 3.0) / jm;
    if i1.is_nan() || r <= 0.0 {
        return Err(MaterialError::Locking {
            law: law.name(),
            i1,
            limit: 3.0 + jm,
        });
    }
    Ok([-0.5 * jm * r.ln(), 0.5 / r, 0.5 / (jm * r * r)])
}

/// Gent's law: μ the small-strain shear modulus, Jm the locking parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Gent {
    shear_modulus: f64,
    jm: f64,
}

impl Gent {
    pub fn new(shear_modulus: f64, jm: f64) -> Result<Self, MaterialError> {
        check_positive("shear_modulus", shear_modulus)?;
        check_jm(jm)?;
        Ok(Self { shear_modulus, jm })
    }
}

impl MembraneLaw for Gent {
    fn name(&self) -> String {
        format!("Gent (Jm = {})", Num(self.jm))
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn locking_limit(&self) -> Option<f64> {
        Some(3.0 + self.jm)
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        Ok(super::from_i1(gent_i1(self, self.jm, a + 1.0 / b)?, a, b))
    }
}

/// The Gent–Gent law: W/μ = −(Jm/2) ln(1 − (I1 − 3)/Jm) + (C2/μ) ln(I2/3). Its small-strain
/// shear modulus is μ (1 + 2 C2/(3μ)).
#[derive(Clone, Debug, PartialEq)]
pub struct GentGent {
    shear_modulus: f64,
    jm: f64,
    c2: f64,
}

impl GentGent {
    /// μ > 0, 0 < Jm ≤ 1e6, C2 ≥ 0 (in the units of μ).
    pub fn new(shear_modulus: f64, jm: f64, c2: f64) -> Result<Self, MaterialError> {
        check_positive("shear_modulus", shear_modulus)?;
        check_jm(jm)?;
        if !(c2.is_finite() && c2 >= 0.0) {
            return Err(MaterialError::InvalidParameter {
                name: "c2",
                value: c2,
                requirement: "the I2 modulus C2 must be finite and ≥ 0 (C2 < 0 softens the law in shear and can make it unstable)",
            });
        }
        Ok(Self {
            shear_modulus,
            jm,
            c2,
        })
    }
}

impl MembraneLaw for GentGent {
    fn name(&self) -> String {
        format!(
            "Gent–Gent (Jm = {}, C2/μ = {})",
            Num(self.jm),
            Num(self.c2 / self.shear_modulus)
        )
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn locking_limit(&self) -> Option<f64> {
        Some(3.0 + self.jm)
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        let [f0, f1, f11] = gent_i1(self, self.jm, a + 1.0 / b)?;
        let i2 = a / b + b;
        let c = self.c2 / self.shear_modulus;
        Ok(super::from_invariants(
            [
                f0 + c * (i2 / 3.0).ln(),
                f1,
                c / i2,
                f11,
                0.0,
                -c / (i2 * i2),
            ],
            a,
            b,
        ))
    }
}
