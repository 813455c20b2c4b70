//! Ogden's law (Ogden 1972, *Proc. R. Soc. A* 326), N terms:
//!
//! ```text
//! W = Σ_p μp/αp (λ1^αp + λ2^αp + λ3^αp − 3),   μ = ½ Σ_p μp αp  (the small-strain shear modulus)
//! ```
//! in principal stretches, evaluated through [`crate::separable`] with g(x) = w(√x) =
//! Σ_p (μp/αp)(x^(αp/2) − 1), whose Taylor coefficients are binomial:
//! t_n = Σ_p (μp/αp) C(αp/2, n) x^(αp/2 − n). (Abaqus writes the same law with
//! 2μᵢ/αᵢ² in place of μp/αp: μᵢ(Abaqus) = μp αp / 2.)

use crate::separable::{Separable, StretchEnergy};
use crate::{EnergyDerivatives, MaterialError, MembraneLaw, Num};

/// The most terms Ogden's law takes (Abaqus's N ≤ 6).
pub const MAX_TERMS: usize = 6;

/// w(λ) of Ogden's law, each term divided by μ.
#[derive(Clone, Debug, PartialEq)]
struct OgdenTerms {
    /// (μp/μ, αp)
    terms: Vec<(f64, f64)>,
    /// the name, with the parameters as given
    name: String,
}

impl StretchEnergy for OgdenTerms {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn taylor(&self, x: f64, t: &mut [f64]) -> Result<(), MaterialError> {
        t.iter_mut().for_each(|v| *v = 0.0);
        for &(m, alpha) in &self.terms {
            let c = m / alpha;
            let e = 0.5 * alpha;
            // C(e, n) x^(e − n), built up term by term
            let (mut coef, mut xp) = (1.0, x.powf(e));
            for (n, v) in t.iter_mut().enumerate() {
                if n > 0 {
                    coef *= (e - (n as f64 - 1.0)) / n as f64;
                    xp /= x;
                }
                *v += c * coef * xp;
            }
            t[0] -= c;
        }
        Ok(())
    }
}

/// Ogden's law with `mu` and `alpha` in the literature's form (μp in stress units).
#[derive(Clone, Debug, PartialEq)]
pub struct Ogden {
    law: Separable<OgdenTerms>,
}

impl Ogden {
    /// One to six terms; each αp ≠ 0 and μp αp > 0 (Ogden's sufficient condition for a stable
    /// law: every term stiffens in extension).
    pub fn new(mu: &[f64], alpha: &[f64]) -> Result<Self, MaterialError> {
        if mu.len() != alpha.len() || mu.is_empty() || mu.len() > MAX_TERMS {
            return Err(MaterialError::Inadmissible {
                law: "Ogden".into(),
                reason: format!(
                    "`mu` and `alpha` must be lists of the same length, 1 to {MAX_TERMS} terms (given {} and {})",
                    mu.len(),
                    alpha.len()
                )
                .into(),
            });
        }
        for (p, (&m, &a)) in mu.iter().zip(alpha).enumerate() {
            let named = |name: &str, value: f64, requirement: &str| MaterialError::Parameter {
                name: format!("{name}[{p}]").into(),
                value,
                requirement: requirement.into(),
            };
            if !m.is_finite() {
                return Err(named("mu", m, "must be a finite number"));
            }
            if !(a.is_finite() && a != 0.0 && a.abs() <= 100.0) {
                return Err(named("alpha", a, "must be finite, non-zero and |α| ≤ 100"));
            }
            if m * a <= 0.0 {
                return Err(named(
                    "mu",
                    m,
                    &format!(
                        "μp αp must be > 0 (Ogden's stability condition; α = {})",
                        Num(a)
                    ),
                ));
            }
        }
        let shear: f64 = 0.5 * mu.iter().zip(alpha).map(|(m, a)| m * a).sum::<f64>();
        let name = format!(
            "Ogden ({})",
            mu.iter()
                .zip(alpha)
                .map(|(m, a)| format!("μ = {}, α = {}", Num(*m), Num(*a)))
                .collect::<Vec<_>>()
                .join("; ")
        );
        Ok(Self {
            law: Separable::new(
                OgdenTerms {
                    terms: mu.iter().zip(alpha).map(|(m, a)| (m / shear, *a)).collect(),
                    name,
                },
                shear,
            )?,
        })
    }
}

impl MembraneLaw for Ogden {
    fn name(&self) -> String {
        self.law.name()
    }
    fn shear_modulus(&self) -> f64 {
        self.law.shear_modulus
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        self.law.derivatives_ab(a, b)
    }
}
