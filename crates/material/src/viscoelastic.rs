//! Quasi-linear viscoelasticity (Fung's QLV) with a Prony series, in the normalization Abaqus
//! users have data for: the base law's second Piola–Kirchhoff stress S⁰(C) = 2 ∂W/∂C (its μ
//! the *instantaneous* modulus) relaxed by a Prony series (issue #63):
//!
//! ```text
//! S(t) = g∞ S⁰(C(t)) + Σᵢ hᵢ(t),    ḣᵢ + hᵢ/τᵢ = gᵢ Ṡ⁰(C(t)),    g∞ = 1 − Σᵢ gᵢ > 0
//! instantaneous response: S⁰ (every hᵢ takes gᵢ ΔS⁰ of a jump);  long-term: g∞ S⁰
//! ```
//!
//! The update over a step Δt is exact for S⁰ linear in time within the step
//! (Taylor–Pister–Goudreau 1970, Simo 1987):
//!
//! ```text
//! hᵢⁿ⁺¹ = eᵢ hᵢⁿ + gᵢ γᵢ (S⁰ⁿ⁺¹ − S⁰ⁿ),   eᵢ = exp(−Δt/τᵢ),   γᵢ = (1 − eᵢ)/(Δt/τᵢ)  (γᵢ = 1 at Δt = 0)
//! Sⁿ⁺¹ = g∞ S⁰ⁿ⁺¹ + Σᵢ hᵢⁿ⁺¹ = α S⁰ⁿ⁺¹ + B,    α = g∞ + Σᵢ gᵢ γᵢ,   B = Σᵢ (eᵢ hᵢⁿ − gᵢ γᵢ S⁰ⁿ)
//! algorithmic tangent: ∂Sⁿ⁺¹/∂Cⁿ⁺¹ = α ∂S⁰/∂C
//! ```
//! so a step's stress is the base law's scaled by α plus a stress B fixed by the history, and its
//! tangent the base law's scaled by α. Its error over a history is second order in Δt where S⁰
//! is smooth in time (the recursion integrates the linear interpolant of S⁰ exactly).

use crate::{MaterialError, MembraneLaw, Num, StressTangent};

/// The most Prony terms a law takes: 32 (measured data rarely support more than 4–6).
pub const MAX_TERMS: usize = 32;

/// One Prony term: the relative modulus `g` that relaxes with time constant `tau` (in the
/// case's time unit).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PronyTerm {
    pub g: f64,
    pub tau: f64,
}

/// A validated Prony series: every gᵢ > 0, every τᵢ finite and > 0, g∞ = 1 − Σ gᵢ > 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Prony {
    terms: Vec<PronyTerm>,
}

/// A Prony series refused, naming the term (counted from 0) and the key.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PronyError {
    #[error("prony[{term}].{key} = {}: {requirement}", Num(*value))]
    Term {
        term: usize,
        key: &'static str,
        value: f64,
        requirement: &'static str,
    },
    #[error("the Prony series' Σ g = {}: must be < 1 (g∞ = 1 − Σ g, the long-term fraction of the instantaneous modulus, must be > 0)", Num(*sum))]
    NoLongTerm { sum: f64 },
    #[error("the Prony series has {count} terms: give 1 to {MAX_TERMS}")]
    Count { count: usize },
}

impl Prony {
    pub fn new(terms: Vec<PronyTerm>) -> Result<Self, PronyError> {
        if terms.is_empty() || terms.len() > MAX_TERMS {
            return Err(PronyError::Count { count: terms.len() });
        }
        for (i, t) in terms.iter().enumerate() {
            if !(t.g.is_finite() && t.g > 0.0 && t.g < 1.0) {
                return Err(PronyError::Term {
                    term: i,
                    key: "g",
                    value: t.g,
                    requirement: "a relative modulus must be in (0, 1)",
                });
            }
            if !(t.tau.is_finite() && t.tau > 0.0) {
                return Err(PronyError::Term {
                    term: i,
                    key: "tau",
                    value: t.tau,
                    requirement: "a relaxation time must be finite and > 0",
                });
            }
        }
        let sum: f64 = terms.iter().map(|t| t.g).sum();
        if sum >= 1.0 {
            return Err(PronyError::NoLongTerm { sum });
        }
        Ok(Self { terms })
    }

    pub fn terms(&self) -> &[PronyTerm] {
        &self.terms
    }

    /// g∞ = 1 − Σ gᵢ, the long-term fraction of the instantaneous stress.
    pub fn g_infinity(&self) -> f64 {
        1.0 - self.terms.iter().map(|t| t.g).sum::<f64>()
    }

    /// The relaxation function G(t)/G(0) = g∞ + Σ gᵢ exp(−t/τᵢ) (t ≥ 0).
    pub fn relaxation(&self, t: f64) -> f64 {
        self.g_infinity()
            + self
                .terms
                .iter()
                .map(|p| p.g * (-t / p.tau).exp())
                .sum::<f64>()
    }

    /// The factors of a step of length `dt` ≥ 0: per term (eᵢ, gᵢ γᵢ), and α.
    pub fn step(&self, dt: f64) -> Step {
        let factors: Vec<(f64, f64)> = self
            .terms
            .iter()
            .map(|p| {
                let x = dt / p.tau;
                let gamma = if x == 0.0 { 1.0 } else { -(-x).exp_m1() / x };
                ((-x).exp(), p.g * gamma)
            })
            .collect();
        let alpha = self.g_infinity() + factors.iter().map(|f| f.1).sum::<f64>();
        Step { factors, alpha }
    }
}

/// The factors of one step ([`Prony::step`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// per term: (eᵢ = exp(−Δt/τᵢ), gᵢ γᵢ)
    pub factors: Vec<(f64, f64)>,
    /// α = g∞ + Σ gᵢ γᵢ: the scale of the base law's stress and tangent in the step
    pub alpha: f64,
}

/// The history of one material point: the base law's stress at the last converged state and
/// each term's hᵢ, symmetric tensors in Voigt order (11, 22, 12) in the reference frame of
/// [`MembraneLaw::stress_tangent`]. The unstretched, unloaded point has all zero.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct History {
    pub s0: [f64; 3],
    pub h: Vec<[f64; 3]>,
}

impl History {
    /// The history of a point that has never been loaded (`terms` Prony terms).
    pub fn unloaded(terms: usize) -> Self {
        Self {
            s0: [0.0; 3],
            h: vec![[0.0; 3]; terms],
        }
    }

    /// B = Σᵢ (eᵢ hᵢⁿ − gᵢ γᵢ S⁰ⁿ), the stress a step adds to α S⁰ⁿ⁺¹.
    pub fn offset(&self, step: &Step) -> [f64; 3] {
        let mut b = [0.0; 3];
        for (h, &(e, gg)) in self.h.iter().zip(&step.factors) {
            for k in 0..3 {
                b[k] += e * h[k] - gg * self.s0[k];
            }
        }
        b
    }

    /// The history after the step that ends with base-law stress `s0_new`.
    pub fn advanced(&self, step: &Step, s0_new: [f64; 3]) -> Self {
        let h = self
            .h
            .iter()
            .zip(&step.factors)
            .map(|(h, &(e, gg))| std::array::from_fn(|k| e * h[k] + gg * (s0_new[k] - self.s0[k])))
            .collect();
        Self { s0: s0_new, h }
    }

    /// S = g∞ S⁰ + Σ hᵢ at this (converged) state.
    pub fn stress(&self, prony: &Prony) -> [f64; 3] {
        let gi = prony.g_infinity();
        std::array::from_fn(|k| gi * self.s0[k] + self.h.iter().map(|h| h[k]).sum::<f64>())
    }
}

/// The stress and algorithmic tangent at the end of a step: the base law's at C scaled by α,
/// plus the history's offset ([`History::offset`]). The energy field is the base law's (a QLV
/// law has no stored energy of its own; it is reported for information only).
pub fn step_stress_tangent(
    law: &dyn MembraneLaw,
    step: &Step,
    history: &History,
    c: [f64; 3],
) -> Result<StressTangent, MaterialError> {
    let base = law.stress_tangent(c)?;
    let b = history.offset(step);
    Ok(StressTangent {
        w: base.w,
        s: std::array::from_fn(|k| step.alpha * base.s[k] + b[k]),
        tangent: base.tangent.map(|row| row.map(|v| step.alpha * v)),
    })
}

/// A material point's nominal stress P₁ = μ λ₁ S₁ (force per reference area, in the law's
/// modulus units) along a history of stretches λ₁(tₖ) in a uniaxial test (the width free:
/// S₂ = 0 at every step, solved by Newton for λ₂) or an equibiaxial one (λ₂ = λ₁), the membrane
/// in plane stress through the law's incompressibility. The point starts unloaded at t₀; each
/// interval is one step of [`Prony::step`] (exact for S⁰ linear in time; a zero interval is a
/// jump). `equibiaxial` false: uniaxial.
pub fn nominal_history(
    law: &dyn MembraneLaw,
    prony: &Prony,
    equibiaxial: bool,
    time: &[f64],
    stretch: &[f64],
) -> Result<Vec<f64>, MaterialError> {
    let mu = law.shear_modulus();
    let mut hist = History::unloaded(prony.terms().len());
    let mut out = Vec::with_capacity(time.len());
    let mut l2 = 1.0;
    let mut t_prev = time.first().copied().unwrap_or(0.0);
    for (&t, &l1) in time.iter().zip(stretch) {
        let step = prony.step((t - t_prev).max(0.0));
        t_prev = t;
        let b = hist.offset(&step);
        if equibiaxial {
            l2 = l1;
        } else {
            // S₂ = α grad₂/λ₂ + B₂ = 0 in λ₂, from the last width (or λ₁^−½ at the start)
            if out.is_empty() {
                l2 = 1.0 / l1.sqrt();
            }
            let mut converged = false;
            for _ in 0..60 {
                let p = law.principal(l1, l2)?;
                let f = step.alpha * p.grad[1] / l2 + b[1];
                let df = step.alpha * (p.hess[1][1] / l2 - p.grad[1] / (l2 * l2));
                let mut d = -f / df;
                if !d.is_finite() {
                    break;
                }
                // keep the width positive
                while l2 + d <= 0.0 {
                    d *= 0.5;
                }
                l2 += d;
                if d.abs() <= 1e-14 * l2 {
                    converged = true;
                    break;
                }
            }
            if !converged {
                return Err(MaterialError::InvalidState {
                    what: "uniaxial width λ₂ (S₂ = 0 not reached)",
                    value: l2,
                    requirement: "Newton must converge on the free width at every step",
                });
            }
        }
        let p = law.principal(l1, l2)?;
        let s0 = [p.grad[0] / l1, p.grad[1] / l2, 0.0];
        let s1 = step.alpha * s0[0] + b[0];
        hist = hist.advanced(&step, s0);
        out.push(mu * l1 * s1);
    }
    Ok(out)
}
