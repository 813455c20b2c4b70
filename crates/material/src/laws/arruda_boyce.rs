//! The Arruda–Boyce eight-chain law (Arruda & Boyce 1993, *J. Mech. Phys. Solids* 41), in its
//! exact form with the inverse Langevin function evaluated to round-off ([`super::langevin`]):
//!
//! ```text
//! W/μ = N [ β λr + ln(β / sinh β) ] − (the same at I1 = 3),   λr = √(I1/(3N)),  β = L⁻¹(λr)
//! W̄'(I1) = β/(6 λr),    W̄''(I1) = (λr β'(λr) − β) / (36 N λr³)
//! ```
//! N is the number of Kuhn segments per chain; the chains lock at λr → 1, I1 → 3N. The
//! small-strain shear modulus is μ β₀ √N / 3 with β₀ = L⁻¹(1/√N) (μ (1 + 3/(5N) + …), as for
//! Abaqus's Arruda–Boyce μ).

use super::check_positive;
use super::langevin::inverse_langevin;
use crate::{EnergyDerivatives, MaterialError, MembraneLaw, Num};

/// The largest N the law takes, 1e6.
pub const MAX_SEGMENTS: f64 = 1e6;

/// The eight-chain law.
#[derive(Clone, Debug, PartialEq)]
pub struct ArrudaBoyce {
    shear_modulus: f64,
    n: f64,
    /// the energy's value at I1 = 3, subtracted
    w0: f64,
}

impl ArrudaBoyce {
    /// μ > 0 and 1 < N ≤ 1e6.
    pub fn new(shear_modulus: f64, n: f64) -> Result<Self, MaterialError> {
        check_positive("shear_modulus", shear_modulus)?;
        if !(n.is_finite() && n > 1.0 && n <= MAX_SEGMENTS) {
            return Err(MaterialError::InvalidParameter {
                name: "kuhn",
                value: n,
                requirement: "the number of Kuhn segments per chain N must be > 1 and at most 1e6 (the chains lock at λ = √N)",
            });
        }
        let mut law = Self {
            shear_modulus,
            n,
            w0: 0.0,
        };
        law.w0 = law.f(3.0)?[0];
        Ok(law)
    }

    /// The small-strain shear modulus over μ: β₀ √N / 3.
    pub fn small_strain_factor(&self) -> f64 {
        inverse_langevin(1.0 / self.n.sqrt()).map_or(f64::NAN, |b| b[0] * self.n.sqrt() / 3.0)
    }

    /// (W̄, W̄', W̄'') at I1.
    fn f(&self, i1: f64) -> Result<[f64; 3], MaterialError> {
        let n = self.n;
        let lr = (i1 / (3.0 * n)).sqrt();
        let locked = || MaterialError::Locking {
            law: self.name(),
            i1,
            limit: 3.0 * n,
        };
        if i1.is_nan() || i1 <= 0.0 {
            return Err(locked());
        }
        let [b, db, _] = inverse_langevin(lr).ok_or_else(locked)?;
        // ln(β/sinh β) without overflow at large β or cancellation at small β:
        // ln β − β − ln((1 − e^{−2β})/2), with 1 − e^{−2β} = −expm1(−2β)
        let ln_b_over_sinh = if b < 1e-8 {
            -b * b / 6.0
        } else {
            b.ln() - b - (-(-2.0 * b).exp_m1()).ln() + std::f64::consts::LN_2
        };
        let w = n * (b * lr + ln_b_over_sinh) - self.w0;
        let w1 = b / (6.0 * lr);
        let w2 = (lr * db - b) / (36.0 * n * lr * lr * lr);
        Ok([w, w1, w2])
    }
}

impl MembraneLaw for ArrudaBoyce {
    fn name(&self) -> String {
        format!("Arruda–Boyce (N = {})", Num(self.n))
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn locking_limit(&self) -> Option<f64> {
        Some(3.0 * self.n)
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        Ok(super::from_i1(self.f(a + 1.0 / b)?, a, b))
    }
}
