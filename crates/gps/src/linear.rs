//! Appendix F: the small-strain slopes of the pressure–strain relations for a Hooke membrane
//! (Young's modulus E, Poisson ratio ν):
//!
//! ```text
//! GPS (eq. 100):  pR/(EH) = ε_s / (1 − ν/2)
//! PS  (eq. 102):  pR/(EH) = ε_s / (1 − ν²)
//! ```
//! In the paper's reduced pressure ϖ = pR/(μH), with E = 2μ(1 + ν), the slopes dϖ/dε_s are
//! 2(1 + ν)/(1 − ν/2) and 2(1 + ν)/(1 − ν²): both equal 4 for an incompressible membrane
//! (ν = ½), which is why the GPS and PS curves of Fig. 5 coincide at small stretch.
use crate::Hypothesis;

/// pR/(EH) per unit hoop strain (eqs. 100 and 102).
pub fn slope_over_young(hyp: Hypothesis, nu: f64) -> f64 {
    match hyp {
        Hypothesis::Gps => 1.0 / (1.0 - nu / 2.0),
        Hypothesis::Ps => 1.0 / (1.0 - nu * nu),
    }
}

/// dϖ/dε_s with ϖ = pR/(μH) and E = 2μ(1 + ν).
pub fn slope_over_shear(hyp: Hypothesis, nu: f64) -> f64 {
    2.0 * (1.0 + nu) * slope_over_young(hyp, nu)
}
