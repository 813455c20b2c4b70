//! The Anssari-Benam–Bucchi law (the paper's).

use super::check_positive;
use crate::{EnergyDerivatives, MaterialError, MembraneLaw};
use serde::{Deserialize, Serialize};

/// Generalized neo-Hookean law of Anssari-Benam & Bucchi (2021), paper eqs. (19)–(23):
///
/// ```text
/// W̄ = K [ (I1 − 3)/(6𝒩) − ln((I1 − 3𝒩)/(3 − 3𝒩)) ],   K = 𝒩 (3 − 3𝒩)/(1 − 3𝒩)
/// W̄'(I1) = K [ 1/(6𝒩) − 1/(I1 − 3𝒩) ],   W̄''(I1) = K/(I1 − 3𝒩)²
/// ```
/// W̄'(3) = ½, so μ is the small-strain shear modulus; the chains lock at I1 → 3𝒩.
/// The largest Kuhn segment number the law takes, 1e6 (networks have tens to hundreds; the
/// paper's is 30). The energy's logarithm ln((I1 − 3𝒩)/(3 − 3𝒩)) is that of a ratio within
/// (I1 − 3)/(3𝒩) of 1, so its relative error is about 1.1e-16 · 3𝒩/(I1 − 3): 3e-4 at 𝒩 = 1e6
/// and I1 − 3 = 1e-6, and all of it beyond 𝒩 ≈ 1e10 there; at 𝒩 = 1e308, 3𝒩 overflows.
pub const MAX_KUHN: f64 = 1e6;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnssariBenamBucchi {
    shear_modulus: f64,
    kuhn: f64,
}

impl AnssariBenamBucchi {
    /// `shear_modulus` μ > 0 (any unit: the dimensionless functions do not use it) and Kuhn
    /// segment number 1 < 𝒩 ≤ [`MAX_KUHN`].
    pub fn new(shear_modulus: f64, kuhn: f64) -> Result<Self, MaterialError> {
        check_positive("shear_modulus", shear_modulus)?;
        if !(kuhn.is_finite() && kuhn > 1.0 && kuhn <= MAX_KUHN) {
            return Err(MaterialError::InvalidParameter {
                name: "kuhn",
                value: kuhn,
                requirement: "the Kuhn segment number must be > 1 and at most 1e6",
            });
        }
        Ok(Self {
            shear_modulus,
            kuhn,
        })
    }
    pub fn kuhn(&self) -> f64 {
        self.kuhn
    }
    /// (W̄, W̄', W̄'') as functions of I1.
    fn f(&self, i1: f64) -> Result<[f64; 3], MaterialError> {
        let n = self.kuhn;
        let limit = 3.0 * n;
        if i1.is_nan() || i1 >= limit {
            return Err(MaterialError::Locking {
                law: self.name(),
                i1,
                limit,
            });
        }
        let k = n * (3.0 - 3.0 * n) / (1.0 - 3.0 * n);
        let d = i1 - limit; // < 0
        Ok([
            k * ((i1 - 3.0) / (6.0 * n) - (d / (3.0 - 3.0 * n)).ln()),
            k * (1.0 / (6.0 * n) - 1.0 / d),
            k / (d * d),
        ])
    }
}

impl MembraneLaw for AnssariBenamBucchi {
    fn name(&self) -> String {
        format!("Anssari-Benam–Bucchi (𝒩 = {})", crate::Num(self.kuhn))
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn locking_limit(&self) -> Option<f64> {
        Some(3.0 * self.kuhn)
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        // W(a, b) = W̄(I1), I1 = a + 1/b.
        let i1 = a + 1.0 / b;
        let [f0, f1, f2] = self.f(i1)?;
        let (b2, b3) = (b * b, b * b * b);
        Ok(EnergyDerivatives {
            w: f0,
            w_a: f1,
            w_b: -f1 / b2,
            w_aa: f2,
            w_ab: -f2 / b2,
            w_bb: f2 / (b2 * b2) + 2.0 * f1 / b3,
        })
    }
}
