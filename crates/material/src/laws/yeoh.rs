//! Yeoh's law (Yeoh 1993, *Rubber Chem. Technol.* 66): W = C10 (I1 − 3) + C20 (I1 − 3)² +
//! C30 (I1 − 3)³, as Abaqus and FEBio write it. μ = 2 C10 is the small-strain shear modulus.

use crate::{EnergyDerivatives, MaterialError, MembraneLaw};

/// Yeoh's three-term law, with its coefficients in stress units.
#[derive(Clone, Debug, PartialEq)]
pub struct Yeoh {
    c: [f64; 3],
}

impl Yeoh {
    /// C10 > 0, and an energy that grows with I1 at every stretch (dW/dI1 > 0 for I1 ≥ 3):
    /// C30 ≥ 0, and where C20 < 0, C30 > 0 with C20² < 3 C10 C30 (the minimum of the quadratic
    /// dW/dI1 over I1 ≥ 3 is positive).
    pub fn new(c10: f64, c20: f64, c30: f64) -> Result<Self, MaterialError> {
        super::check_positive("c10", c10)?;
        for (name, v) in [("c20", c20), ("c30", c30)] {
            if !v.is_finite() {
                return Err(MaterialError::InvalidParameter {
                    name,
                    value: v,
                    requirement: "must be a finite number",
                });
            }
        }
        if c30 < 0.0 {
            return Err(MaterialError::InvalidParameter {
                name: "c30",
                value: c30,
                requirement: "must be ≥ 0 (with C30 < 0 the energy falls at large stretch)",
            });
        }
        if c20 < 0.0 && c20 * c20 >= 3.0 * c10 * c30 {
            return Err(MaterialError::InvalidParameter {
                name: "c20",
                value: c20,
                requirement: "with C20 < 0 the energy must still grow with I1 at every stretch: C20² < 3 C10 C30 is needed",
            });
        }
        Ok(Self { c: [c10, c20, c30] })
    }
}

impl MembraneLaw for Yeoh {
    fn name(&self) -> String {
        let [c10, c20, c30] = self.c;
        format!(
            "Yeoh (C10 = {}, C20 = {}, C30 = {})",
            crate::Num(c10),
            crate::Num(c20),
            crate::Num(c30)
        )
    }
    fn shear_modulus(&self) -> f64 {
        2.0 * self.c[0]
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        let mu = 2.0 * self.c[0];
        let [c10, c20, c30] = self.c.map(|c| c / mu);
        let x = a + 1.0 / b - 3.0;
        Ok(super::from_i1(
            [
                x * (c10 + x * (c20 + x * c30)),
                c10 + x * (2.0 * c20 + 3.0 * c30 * x),
                2.0 * c20 + 6.0 * c30 * x,
            ],
            a,
            b,
        ))
    }
}
