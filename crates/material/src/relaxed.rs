//! Tension-field (relaxed) membrane energy: membranes carry no compression.
//!
//! A membrane cannot sustain a compressive principal resultant: it wrinkles. Pipkin's relaxed
//! energy replaces W by its quasiconvexification, which for an isotropic membrane is
//!
//! ```text
//! taut      N2(λ1, λ2) ≥ 0                 W_r = W(λ1, λ2)
//! wrinkled  N2 ≤ 0 < N1(λ1, μ(λ1))         W_r = w(λ1) = W(λ1, μ(λ1)),  ∂W/∂λ2(λ1, μ) = 0
//! slack     otherwise (λ1 ≤ 1)             W_r = 0
//! ```
//! with λ1 ≥ λ2 the principal stretches and μ(λ1) the natural width (for neo-Hookean
//! μ = λ1^(−1/2)). In the wrinkled regime the energy depends on λ1 only, and
//! λ1² = a/2 + √(a²/4 − b) is again a function of the invariants (a, b) = (tr C, det C), so the
//! relaxed law is a [`MembraneLaw`] like any other:
//!
//! ```text
//! w'(λ1) = W_1(λ1, μ)      w''(λ1) = W_11 + W_12 μ',   μ' = −W_12 / W_22
//! q = λ1² = a/2 + √D, D = a²/4 − b:  q_a = ½ + a/(4√D), q_b = −1/(2√D)
//! q_aa = 1/(4√D) − a²/(16 D^{3/2}),  q_ab = a/(8 D^{3/2}),  q_bb = −1/(4 D^{3/2})
//! ```
//! The relaxed energy is C¹ across the taut/wrinkled boundary (N2 = 0 there), so Newton sees
//! continuous forces and a tangent that jumps, and the tangent is never negative in compression.
//! In taut states it is the law itself, bit for bit.

use crate::{EnergyDerivatives, MaterialError, MembraneLaw};

/// The round-off allowance on the taut cone's boundary N2 = 0 (per μH).
pub const N2_ROUNDOFF: f64 = 1e-14;

/// The tension-field relaxation of a law.
#[derive(Debug, Clone)]
pub struct Relaxed<L> {
    pub law: L,
}

/// Which regime a state is in.
#[derive(schemars::JsonSchema, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    Taut,
    Wrinkled,
    Slack,
}

impl<L: MembraneLaw> Relaxed<L> {
    pub fn new(law: L) -> Self {
        Self { law }
    }

    /// Natural width μ(λ1): ∂W/∂λ2(λ1, μ) = 0, by Newton from the neo-Hookean λ1^(−1/2).
    pub fn natural_width(&self, l1: f64) -> Result<f64, MaterialError> {
        let mut mu = l1.powf(-0.5);
        for _ in 0..50 {
            let p = self.law.principal(l1, mu)?;
            let step = p.grad[1] / p.hess[1][1];
            let mut next = mu - step;
            if next.is_nan() || next <= 0.0 {
                next = 0.5 * mu;
            }
            let done = (next - mu).abs() <= 1e-15 * mu;
            mu = next;
            if done {
                return Ok(mu);
            }
        }
        Ok(mu)
    }

    /// The regime of the state with invariants (a, b).
    pub fn regime(&self, a: f64, b: f64) -> Result<Regime, MaterialError> {
        let disc = (0.25 * a * a - b).max(0.0).sqrt();
        let l1 = (0.5 * a + disc).sqrt();
        let l2 = (0.5 * a - disc).max(0.0).sqrt();
        if l2 > 0.0 {
            // N2 = 0 (the stress-free state C = I included) is the boundary of the taut cone,
            // where the relaxed energy is C¹: take the taut branch there, so that Newton sees
            // the law's stiffness when it starts from the reference configuration. The
            // boundary is taken with a round-off allowance, N2 ≥ −1e-14 (per μH): a reference
            // state's C = I computed from positions has N2 of ±1e-16, and on the slack branch
            // such a point would have no stiffness at all (a flat sheet started from rest
            // failed its first Newton step so).
            let [_, n2] = self.law.resultants(l1, l2)?;
            if n2 >= -N2_ROUNDOFF {
                return Ok(Regime::Taut);
            }
            // equal stretches (to round-off: C's round-off of 1e-16 makes √D about 1e-8, so
            // within 1e-6 of a) have equal resultants, and the wrinkled branch's
            // derivatives need λ1 > λ2 (they divide by λ1² − λ2²): shrunk equally the state is
            // slack; at or above the reference state a compressive N2 is round-off, and the
            // state is taut (the law's stiffness, which a sheet started from rest needs). Found
            // by the fuzz run: a law 100 times stiffer than its declared μ (an energy written
            // as a sum of 100 terms) has round-off beyond N2_ROUNDOFF at C = I, which had gone
            // to the wrinkled branch with equal stretches and divided by zero.
            if disc <= 1e-6 * a {
                return Ok(if l1 < 1.0 - 1e-12 {
                    Regime::Slack
                } else {
                    Regime::Taut
                });
            }
        }
        if l1 > 1.0 {
            let mu = self.natural_width(l1)?;
            if self.law.resultants(l1, mu)?[0] > 0.0 {
                return Ok(Regime::Wrinkled);
            }
        }
        Ok(Regime::Slack)
    }
}

impl<L: MembraneLaw> MembraneLaw for Relaxed<L> {
    fn name(&self) -> String {
        format!("{} with tension-field relaxation", self.law.name())
    }
    fn shear_modulus(&self) -> f64 {
        self.law.shear_modulus()
    }
    fn locking_limit(&self) -> Option<f64> {
        self.law.locking_limit()
    }
    fn stable_limit(&self) -> Option<f64> {
        self.law.stable_limit()
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        match self.regime(a, b)? {
            Regime::Taut => self.law.derivatives_ab(a, b),
            Regime::Slack => Ok(EnergyDerivatives {
                w: 0.0,
                w_a: 0.0,
                w_b: 0.0,
                w_aa: 0.0,
                w_ab: 0.0,
                w_bb: 0.0,
            }),
            Regime::Wrinkled => {
                let d = 0.25 * a * a - b;
                let sd = d.sqrt();
                let q = 0.5 * a + sd;
                let l1 = q.sqrt();
                let mu = self.natural_width(l1)?;
                let p = self.law.principal(l1, mu)?;
                let w0 = p.w;
                let w1 = p.grad[0];
                let dmu = -p.hess[0][1] / p.hess[1][1];
                let w2 = p.hess[0][0] + p.hess[0][1] * dmu;
                // s = √q
                let (qa, qb) = (0.5 + 0.25 * a / sd, -0.5 / sd);
                let d32 = d * sd;
                let (qaa, qab, qbb) = (
                    0.25 / sd - a * a / (16.0 * d32),
                    a / (8.0 * d32),
                    -0.25 / d32,
                );
                let (sa, sb) = (qa / (2.0 * l1), qb / (2.0 * l1));
                let l3 = l1 * l1 * l1;
                let saa = qaa / (2.0 * l1) - qa * qa / (4.0 * l3);
                let sab = qab / (2.0 * l1) - qa * qb / (4.0 * l3);
                let sbb = qbb / (2.0 * l1) - qb * qb / (4.0 * l3);
                Ok(EnergyDerivatives {
                    w: w0,
                    w_a: w1 * sa,
                    w_b: w1 * sb,
                    w_aa: w2 * sa * sa + w1 * saa,
                    w_ab: w2 * sa * sb + w1 * sab,
                    w_bb: w2 * sb * sb + w1 * sbb,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::{neo_hookean, AnssariBenamBucchi};

    fn ab(l1: f64, l2: f64) -> (f64, f64) {
        (l1 * l1 + l2 * l2, l1 * l1 * l2 * l2)
    }

    #[test]
    fn relaxed_law_is_the_law_when_taut_and_tension_free_across_wrinkles() {
        let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
        let r = Relaxed::new(law.clone());
        // taut: identical
        let (a, b) = ab(1.4, 1.1);
        assert_eq!(r.regime(a, b).unwrap(), Regime::Taut);
        assert_eq!(r.derivatives(a, b).unwrap(), law.derivatives(a, b).unwrap());
        // wrinkled: λ2 below the natural width; N2 = 0 and N1 the uniaxial value
        let l1 = 1.5;
        let mu = r.natural_width(l1).unwrap();
        assert!((law.resultants(l1, mu).unwrap()[1]).abs() < 1e-12);
        let (a, b) = ab(l1, 0.7 * mu);
        assert_eq!(r.regime(a, b).unwrap(), Regime::Wrinkled);
        let [n1, n2] = r.resultants(l1, 0.7 * mu).unwrap();
        // N = (1/λ) ∂W_r/∂λ with W_r = w(λ1): N2 = 0, N1 = w'(λ1)/λ2 (per current length in the
        // compressed direction) — w'(λ1) = W_1(λ1, μ).
        assert!(n2.abs() < 1e-12, "{n2}");
        let w1 = law.principal(l1, mu).unwrap().grad[0];
        assert!((n1 - w1 / (0.7 * mu)).abs() < 1e-10 * n1);
        // slack
        let (a, b) = ab(0.95, 0.9);
        assert_eq!(r.regime(a, b).unwrap(), Regime::Slack);
        assert_eq!(r.derivatives(a, b).unwrap().w, 0.0);
        // neo-Hookean natural width: λ1^(−1/2)
        let nh = Relaxed::new(neo_hookean(1.0).unwrap());
        assert!((nh.natural_width(2.0).unwrap() - 2f64.powf(-0.5)).abs() < 1e-14);
    }

    /// FD checks of the relaxed derivatives inside the wrinkled regime (away from its boundary,
    /// where the second derivatives jump). Tolerances as in the law tests.
    #[test]
    fn relaxed_derivatives_match_finite_differences_when_wrinkled() {
        let r = Relaxed::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap());
        let h = 1e-6;
        for (l1, f) in [(1.3, 0.6), (2.0, 0.5), (3.5, 0.8)] {
            let mu = r.natural_width(l1).unwrap();
            let (a, b) = ab(l1, f * mu);
            assert_eq!(r.regime(a, b).unwrap(), Regime::Wrinkled);
            let d = r.derivatives(a, b).unwrap();
            let g = |a: f64, b: f64| r.derivatives(a, b).unwrap();
            let close = |x: f64, y: f64| (x - y).abs() <= 1e-6 * x.abs().max(y.abs()) + 1e-9;
            assert!(close(d.w_a, (g(a + h, b).w - g(a - h, b).w) / (2.0 * h)));
            assert!(close(d.w_b, (g(a, b + h).w - g(a, b - h).w) / (2.0 * h)));
            assert!(close(
                d.w_aa,
                (g(a + h, b).w_a - g(a - h, b).w_a) / (2.0 * h)
            ));
            assert!(close(
                d.w_ab,
                (g(a, b + h).w_a - g(a, b - h).w_a) / (2.0 * h)
            ));
            assert!(close(
                d.w_bb,
                (g(a, b + h).w_b - g(a, b - h).w_b) / (2.0 * h)
            ));
            // the relaxed tangent is positive semi-definite in C (no negative stiffness)
            let c = [l1 * l1, (f * mu).powi(2), 0.0];
            let t = r.stress_tangent(c).unwrap().tangent;
            for i in 0..3 {
                assert!(t[i][i] >= -1e-12, "{t:?}");
            }
        }
    }
}
