//! Laws whose energy is written as text in the case file or in Python ([`crate::expr`]):
//!
//! * [`InvariantLaw`], `model = "invariants"`: W/(μH) as a function of the incompressible
//!   membrane's invariants I1 = λ1² + λ2² + 1/(λ1λ2)² and I2 = 1/λ1² + 1/λ2² + (λ1λ2)², with
//!   its named parameters; derivatives by the second-order dual numbers of
//!   [`crate::dual::HyperDual2`]. neo-Hookean is `(I1 - 3)/2`.
//! * [`PrincipalLaw`], `model = "principal"`: W/(μH) = w(λ1) + w(λ2) + w(λ3), w written in the
//!   stretch `l`; derivatives by Taylor jets through [`crate::separable`]. Ogden's one-term
//!   law with μ = 1 is `2/alpha^2 * (l^alpha - 1)` (μ1 α1 / 2 = 1 needs μ1 = 2/α).
//!
//! Both are checked when they are built: the energy and its derivatives must be finite at the
//! reference state, and its tangent there positive definite (a stable, stress-free reference;
//! the reference is stress-free for any energy of this form). The energy is shifted so that
//! it is 0 at the reference state.

use crate::dual::{HyperDual2, Real};
use crate::expr::Expr;
use crate::separable::{Separable, StretchEnergy, SERIES_TERMS};
use crate::taylor::Jet;
use crate::{EnergyDerivatives, MaterialError, MembraneLaw};
use std::collections::BTreeMap;

/// The variables of an invariant energy.
pub const INVARIANT_VARIABLES: [&str; 2] = ["I1", "I2"];
/// The variable of a principal-stretch energy.
pub const STRETCH_VARIABLE: [&str; 1] = ["l"];

fn parameters_text(p: &BTreeMap<String, f64>) -> String {
    if p.is_empty() {
        return String::new();
    }
    format!(
        "; {}",
        p.iter()
            .map(|(k, v)| format!("{k} = {}", crate::Num(*v)))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// Reference-state checks shared by both forms: finite derivatives and a positive definite
/// tangent at C = I.
fn check_reference(law: &dyn MembraneLaw) -> Result<(), MaterialError> {
    let inadmissible = |reason: String| MaterialError::Inadmissible {
        law: law.name().into(),
        reason: reason.into(),
    };
    let t = law.stress_tangent([1.0, 1.0, 0.0]).map_err(|e| {
        inadmissible(format!(
            "it cannot be evaluated at the reference state ({e})"
        ))
    })?;
    // ℂ at C = I in Voigt form: positive definite when its leading minors are; taken of
    // ℂ / max|ℂij| (the same signs), so that an energy of 1e150 does not overflow them
    let scale = t
        .tangent
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if !scale.is_finite() {
        return Err(inadmissible(
            "its tangent at the reference state is not finite".to_string(),
        ));
    }
    let s = if scale > 0.0 { scale } else { 1.0 };
    let c = t.tangent.map(|row| row.map(|v| v / s));
    let m1 = c[0][0];
    let m2 = c[0][0] * c[1][1] - c[0][1] * c[1][0];
    let m3 = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
        - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0])
        + c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
    if !(m1 > 0.0 && m2 > 0.0 && m3 > 0.0) {
        // the minors as they are, or of ℂ / max|ℂij| where they would overflow
        let whole = [m1 * s, m2 * s * s, m3 * s * s * s];
        let minors = if whole.iter().all(|m| m.is_finite()) {
            format!(
                "leading minors {:.3e}, {:.3e}, {:.3e}",
                whole[0], whole[1], whole[2]
            )
        } else {
            format!("leading minors of ℂ / {s:.3e}: {m1:.3e}, {m2:.3e}, {m3:.3e}")
        };
        return Err(inadmissible(format!(
            "its tangent at the reference state is not positive definite ({minors}): the unstretched membrane would not resist every small deformation (is the sign of the energy right, and its modulus positive?)"
        )));
    }
    Ok(())
}

/// An energy of the invariants I1, I2, written as text.
#[derive(Clone, Debug, PartialEq)]
pub struct InvariantLaw {
    expr: Expr,
    parameters: BTreeMap<String, f64>,
    shear_modulus: f64,
    /// the energy at the reference state, subtracted
    w0: f64,
}

impl InvariantLaw {
    pub fn new(
        energy: &str,
        parameters: &BTreeMap<String, f64>,
        shear_modulus: f64,
    ) -> Result<Self, MaterialError> {
        super::check_positive("shear_modulus", shear_modulus)?;
        let expr = Expr::parse(energy, &INVARIANT_VARIABLES, parameters)?;
        let w0 = expr.eval(&[3.0, 3.0]);
        let mut law = Self {
            expr,
            parameters: parameters.clone(),
            shear_modulus,
            w0: 0.0,
        };
        if !w0.is_finite() {
            return Err(MaterialError::Inadmissible {
                law: law.name().into(),
                reason: format!(
                    "its energy at the reference state (I1 = I2 = 3) is {w0}, not a finite number"
                )
                .into(),
            });
        }
        law.w0 = w0;
        check_reference(&law)?;
        Ok(law)
    }
}

/// An energy's text as a law's name quotes it: whole up to 160 characters, else its first 120
/// and the count (a run's header and every message name the law; a 50 KB energy had been
/// printed whole).
fn excerpt(text: &str) -> String {
    let n = text.chars().count();
    if n <= 160 {
        text.to_string()
    } else {
        format!(
            "{}… ({n} characters)",
            text.chars().take(120).collect::<String>()
        )
    }
}

impl MembraneLaw for InvariantLaw {
    fn name(&self) -> String {
        format!(
            "energy W = {}{}",
            excerpt(self.expr.text()),
            parameters_text(&self.parameters)
        )
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        let a = HyperDual2::variable(a, 0);
        let b = HyperDual2::variable(b, 1);
        let binv = b.recip();
        let w = self.expr.eval(&[a + binv, a * binv + b]);
        Ok(EnergyDerivatives {
            w: w.re - self.w0,
            w_a: w.g[0],
            w_b: w.g[1],
            w_aa: w.h[0],
            w_ab: w.h[1],
            w_bb: w.h[2],
        })
    }
}

/// w(l) of a principal-stretch energy, as the Taylor coefficients of g(x) = w(√x).
#[derive(Clone, Debug, PartialEq)]
struct StretchExpr {
    expr: Expr,
    name: String,
}

impl StretchExpr {
    fn jet<const N: usize>(&self, x: f64, t: &mut [f64]) {
        let w = self.expr.eval(&[Jet::<N>::variable(x).sqrt()]);
        t.copy_from_slice(&w.t[..t.len()]);
    }
}

impl StretchEnergy for StretchExpr {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn taylor(&self, x: f64, t: &mut [f64]) -> Result<(), MaterialError> {
        match t.len() {
            0 => {}
            1..=3 => self.jet::<3>(x, t),
            n if n <= SERIES_TERMS => self.jet::<SERIES_TERMS>(x, t),
            n => {
                return Err(MaterialError::InvalidState {
                    what: "Taylor order",
                    value: n as f64,
                    requirement: "at most the series' 15 coefficients",
                })
            }
        }
        Ok(())
    }
}

/// A separable principal-stretch energy w(λ1) + w(λ2) + w(λ3), w written as text in `l`.
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipalLaw {
    law: Separable<StretchExpr>,
}

impl PrincipalLaw {
    pub fn new(
        energy: &str,
        parameters: &BTreeMap<String, f64>,
        shear_modulus: f64,
    ) -> Result<Self, MaterialError> {
        super::check_positive("shear_modulus", shear_modulus)?;
        let expr = Expr::parse(energy, &STRETCH_VARIABLE, parameters)?;
        let name = format!(
            "energy W = Σ w(λi), w(l) = {}{}",
            excerpt(expr.text()),
            parameters_text(parameters)
        );
        let law = Self {
            law: Separable::new(StretchExpr { expr, name }, shear_modulus)?,
        };
        let mut t = [0.0; 3];
        law.law.energy.taylor(1.0, &mut t)?;
        if !t.iter().all(|v| v.is_finite()) {
            return Err(MaterialError::Inadmissible {
                law: law.name().into(),
                reason: "w and its derivatives at l = 1 must be finite numbers".into(),
            });
        }
        check_reference(&law)?;
        Ok(law)
    }
}

impl MembraneLaw for PrincipalLaw {
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
