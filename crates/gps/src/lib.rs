//! # tubemem-gps — the closed form
//!
//! The algebraic equations of the generalized plane strain (GPS) and plane strain (PS) theories
//! of translation-invariant pressurized membranes (reference paper, Secs. 3.6, 3.7 and 4), for
//! **any** law of [`tubemem_material`]. Everything is dimensionless: R = 1, μH = 1, so
//! ϖ = pR/(μH) (eq. 67), ρ = r/R, χ = c/(πR) (eq. 72), resultants are N/(μH).
//!
//! * [`inflate`] / [`inflation_curve`]: free inflation at a given hoop stretch λs.
//!   GPS solves eq. (66), ϖλs = N_s and ϖλs/2 = N_z, for (ϖ, λz) by Newton (N_s = 2N_z is solved
//!   for λz, then ϖ = N_s/λs). Eq. (68) is **not** assumed: it holds only for laws whose two
//!   resultants share one factor (neo-Hookean, Anssari-Benam–Bucchi); tests check that it does
//!   and that it fails for Mooney–Rivlin. PS is eq. (69)–(70): λz = 1, ϖ = N_s(λs, 1)/λs.
//! * [`flatten`] / [`flattening_curve`]: squeezing between two parallel plates with a closed
//!   amount of gas, GPS eqs. (76)–(77) with the erratum of eq. (74) (N_z = (ϖρ/2)(ρ+2χ)/(ρ+χ)),
//!   PS eqs. (78)–(79), by continuation in ρ from the inflated state λs* with the previous point
//!   (linearly extrapolated) as the initial guess (Sec. 4.3) and automatic step cut-back.
//!   Unknowns (ϖ, λs, λz, χ): eq. (77)₁ gives χ = λs − ρ and eq. (76)₁ gives ϖ = N_s/ρ exactly,
//!   so Newton runs on the remaining two, (λs, λz) (one, λs, for PS).
//! * [`limits::limit_points`]: pressure maximum and minimum of the inflation curve and the
//!   Maxwell equal-area pressure on the (v, ϖ) curve, v = πλs²λz.
//! * [`linear`]: the small-strain slopes of Appendix F.
//! * [`Scales`]: back to dimensional pressure, force per unit length and plate travel.
//!
//! ```
//! use tubemem_gps::{inflate, flatten, Hypothesis};
//! use tubemem_material::laws::AnssariBenamBucchi;
//! let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
//! let s = inflate(&law, Hypothesis::Gps, 1.3).unwrap();
//! assert!((s.n_s - 2.0 * s.n_z).abs() < 1e-12);      // eq. (66): N_z = N_s/2
//! let f = flatten(&law, Hypothesis::Gps, 1.3, 1.0).unwrap();
//! assert!((f.lambda_s - f.rho - f.chi).abs() < 1e-12); // eq. (77)₁
//! ```

pub mod confine;
mod error;
pub mod limits;
pub mod linear;
mod newton;
pub mod regulated;
mod resultants;
mod scales;
pub mod visco;

use error::invalid;
pub use error::GpsError;
pub use scales::Scales;
use serde::{Deserialize, Serialize};
use tubemem_material::MembraneLaw;

/// Which kinematic hypothesis closes the cross-section problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Hypothesis {
    /// Generalized plane strain: a constant axial stretch λz set by the end-cap force.
    Gps,
    /// Plane strain (De Simone & Luongo): λz = 1.
    Ps,
}

impl Hypothesis {
    pub fn label(self) -> &'static str {
        match self {
            Hypothesis::Gps => "GPS",
            Hypothesis::Ps => "PS",
        }
    }
}

/// A free-inflation state (dimensionless).
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct InflationState {
    /// ϖ = pR/(μH)
    pub w: f64,
    pub lambda_s: f64,
    pub lambda_z: f64,
    /// N_s/(μH), hoop resultant
    pub n_s: f64,
    /// N_z/(μH), axial resultant (under PS: the reaction that keeps λz = 1)
    pub n_z: f64,
}

/// A flattening state (dimensionless).
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlatteningState {
    pub w: f64,
    pub lambda_s: f64,
    pub lambda_z: f64,
    pub n_s: f64,
    pub n_z: f64,
    /// ρ = r/R, the half-gap between the plates
    pub rho: f64,
    /// χ = c/(πR), the reduced contact length
    pub chi: f64,
    /// reduced force ϖχ (eq. 80)
    pub force: f64,
    /// reduced displacement λs* − ρ (eq. 81)
    pub displacement: f64,
}

/// A GPS cross-section squeezed under a given pressure ([`section_at_pressure`]).
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SectionState {
    pub w: f64,
    pub rho: f64,
    pub lambda_s: f64,
    pub lambda_z: f64,
    pub n_s: f64,
    pub n_z: f64,
    pub chi: f64,
    /// reduced force ϖχ (eq. 80)
    pub force: f64,
}

impl SectionState {
    /// The state as a flattening state, its displacement counted from the half-gap
    /// `initial_stretch` (λs* − ρ, eq. 81).
    pub fn as_flattening(&self, initial_stretch: f64) -> FlatteningState {
        FlatteningState {
            w: self.w,
            lambda_s: self.lambda_s,
            lambda_z: self.lambda_z,
            n_s: self.n_s,
            n_z: self.n_z,
            rho: self.rho,
            chi: self.chi,
            force: self.force,
            displacement: initial_stretch - self.rho,
        }
    }
}

const MAX_CUTS: usize = 30;

fn at_ls(ls: f64) -> String {
    format!("λs = {}", tubemem_material::Num(ls))
}

/// Neo-Hookean/GPS axial stretch of eq. (68), used only as an initial guess for other laws.
pub fn eq68_lambda_z(ls: f64) -> f64 {
    0.5 * (ls * ls + (ls.powi(4) + 8.0 / (ls * ls)).sqrt()).sqrt()
}

fn inflation_solve(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    ls: f64,
    lz_guess: f64,
) -> Result<InflationState, GpsError> {
    let material = |source| GpsError::Material {
        stage: "free inflation",
        at: at_ls(ls),
        source,
    };
    let lz = match hyp {
        Hypothesis::Ps => 1.0,
        Hypothesis::Gps => {
            let g = |lz: f64| {
                let r = resultants::resultants(law, ls, lz)?;
                Ok((r.ns - 2.0 * r.nz, r.jac[0][1] - 2.0 * r.jac[1][1]))
            };
            let scale = resultants::resultants(law, ls, lz_guess)
                .map(|r| r.ns.abs() + 2.0 * r.nz.abs())
                .unwrap_or(1.0);
            newton::scalar(g, lz_guess, 1e-9 * (1.0 + scale)).map_err(|f| match f.material {
                Some(e) => material(e),
                None => GpsError::NoConvergence {
                    stage: "free inflation (GPS, eq. 66)",
                    at: at_ls(ls),
                    residual: f.residual,
                    iterations: f.iterations,
                },
            })?
        }
    };
    let r = resultants::resultants(law, ls, lz).map_err(material)?;
    if r.ns < 0.0 {
        return Err(GpsError::Compressive {
            stage: "free inflation",
            at: at_ls(ls),
            n_s: r.ns,
            w: r.ns / ls,
        });
    }
    Ok(InflationState {
        w: r.ns / ls,
        lambda_s: ls,
        lambda_z: lz,
        n_s: r.ns,
        n_z: r.nz,
    })
}

/// The largest stretch the closed form takes: beyond 1e6 the invariants (λ² and 1/(λs λz)²)
/// approach overflow and underflow long before any law means anything there.
pub const MAX_STRETCH: f64 = 1e6;

fn check_stretch(ls: f64) -> Result<(), GpsError> {
    if ls.is_finite() && (1.0..=MAX_STRETCH).contains(&ls) {
        Ok(())
    } else {
        Err(invalid(
            "lambda_s",
            ls,
            "the hoop stretch of an inflated membrane must be ≥ 1 and at most 1e6",
        ))
    }
}

/// Free inflation to hoop stretch `lambda_s` (≥ 1).
pub fn inflate(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    lambda_s: f64,
) -> Result<InflationState, GpsError> {
    check_stretch(lambda_s)?;
    inflation_solve(law, hyp, lambda_s, eq68_lambda_z(lambda_s))
}

/// The most points a curve may have: 10 million (0.4 GB of inflation states, 0.7 GB of
/// flattening states, about 1 GB of CSV; a 10,000-point curve takes 2.5 ms, so this one about
/// 2.5 s). A request for more is refused before anything is allocated.
pub const MAX_CURVE_POINTS: usize = 10_000_000;

/// The one size guard of every curve and path: at least 2 points and at most
/// [`MAX_CURVE_POINTS`].
pub(crate) fn check_points(points: usize) -> Result<(), GpsError> {
    if points < 2 {
        return Err(invalid(
            "points",
            points as f64,
            "a curve needs at least 2 points",
        ));
    }
    if points > MAX_CURVE_POINTS {
        return Err(invalid(
            "points",
            points as f64,
            "a curve may have at most 10,000,000 points (about 1 GB of results)",
        ));
    }
    Ok(())
}

/// `points` states equally spaced in λs from `from` to `to` (both ≥ 1), each solved from the
/// previous one (Sec. 4.3).
pub fn inflation_curve(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    from: f64,
    to: f64,
    points: usize,
) -> Result<Vec<InflationState>, GpsError> {
    check_stretch(from)?;
    check_stretch(to)?;
    check_points(points)?;
    let mut out: Vec<InflationState> = Vec::with_capacity(points);
    for i in 0..points {
        let ls = from + (to - from) * i as f64 / (points - 1) as f64;
        let guess = match out.len() {
            0 => eq68_lambda_z(ls),
            1 => out[0].lambda_z,
            n => 2.0 * out[n - 1].lambda_z - out[n - 2].lambda_z,
        };
        let s = inflation_solve(law, hyp, ls, guess)
            .or_else(|_| inflation_solve(law, hyp, ls, eq68_lambda_z(ls)))?;
        out.push(s);
    }
    Ok(out)
}

/// The flattening problem from a given inflated state.
struct Flattening<'a> {
    law: &'a dyn MembraneLaw,
    hyp: Hypothesis,
    /// the state the gas is closed in
    initial: FlatteningState,
    /// Boyle's law constant: ϖ* λs*² λz* from a free inflation (eq. 77₂; λz* = 1 under PS,
    /// eq. 79₂), ϖρ(2λs − ρ)λz from a squeezed state
    gas: f64,
}

impl<'a> Flattening<'a> {
    fn new(
        law: &'a dyn MembraneLaw,
        hyp: Hypothesis,
        initial_stretch: f64,
    ) -> Result<Self, GpsError> {
        if !(initial_stretch.is_finite() && initial_stretch > 1.0) {
            return Err(invalid(
                "initial_stretch",
                initial_stretch,
                "flattening needs an inflated tube (λs* > 1) holding gas",
            ));
        }
        let s = inflate(law, hyp, initial_stretch)?;
        let gas = s.w * s.lambda_s.powi(2) * s.lambda_z;
        Ok(Self {
            law,
            hyp,
            initial: FlatteningState {
                w: s.w,
                lambda_s: s.lambda_s,
                lambda_z: s.lambda_z,
                n_s: s.n_s,
                n_z: s.n_z,
                rho: s.lambda_s,
                chi: 0.0,
                force: 0.0,
                displacement: 0.0,
            },
            gas,
        })
    }

    /// The gas closed in a squeezed section `s` (its displacement counted from `s.rho`).
    fn from_section(law: &'a dyn MembraneLaw, hyp: Hypothesis, s: SectionState) -> Self {
        let lz = match hyp {
            Hypothesis::Gps => s.lambda_z,
            Hypothesis::Ps => 1.0,
        };
        Self {
            law,
            hyp,
            initial: s.as_flattening(s.rho),
            gas: s.w * s.rho * (2.0 * s.lambda_s - s.rho) * lz,
        }
    }

    fn start(&self) -> FlatteningState {
        self.initial
    }

    /// Solve at half-gap `rho` from the guess (λs, λz).
    fn solve(&self, rho: f64, guess: [f64; 2]) -> Result<FlatteningState, GpsError> {
        let at = if self.initial.chi == 0.0 {
            format!("ρ = {rho} (λs* = {})", self.initial.lambda_s)
        } else {
            format!("ρ = {rho} (gas closed at ρ = {})", self.initial.rho)
        };
        let law = self.law;
        let m = self.gas;
        let fail = |f: newton::Failure, stage: &'static str| f.into_error(stage, &at);
        let (ls, lz) = match self.hyp {
            Hypothesis::Gps => {
                // F1 = N_s (2λs − ρ)/(2λs) − N_z        (eq. 76₂ with ϖρ = N_s, χ = λs − ρ)
                // F2 = λz N_s (2λs − ρ)/M − 1           (eq. 77₂, M = ϖ*λs*²λz*)
                let f = |x: [f64; 2]| {
                    let [ls, lz] = x;
                    let r = resultants::resultants(law, ls, lz)?;
                    let q = 1.0 - rho / (2.0 * ls);
                    let dq = rho / (2.0 * ls * ls);
                    let t = 2.0 * ls - rho;
                    let f1 = r.ns * q - r.nz;
                    let f2 = lz * r.ns * t / m - 1.0;
                    let j = [
                        [
                            r.jac[0][0] * q + r.ns * dq - r.jac[1][0],
                            r.jac[0][1] * q - r.jac[1][1],
                        ],
                        [
                            lz * (r.jac[0][0] * t + 2.0 * r.ns) / m,
                            (r.ns * t + lz * r.jac[0][1] * t) / m,
                        ],
                    ];
                    Ok((
                        [f1 / self.initial.n_s, f2],
                        [
                            [j[0][0] / self.initial.n_s, j[0][1] / self.initial.n_s],
                            j[1],
                        ],
                    ))
                };
                let x = newton::system2(f, guess, 1e-10)
                    .map_err(|e| fail(e, "flattening (GPS, eqs. 76–77)"))?;
                (x[0], x[1])
            }
            Hypothesis::Ps => {
                // h = N_s(λs, 1) (2λs − ρ)/M − 1     (eqs. 78–79, M = ϖ*λs*²)
                let h = |ls: f64| {
                    let r = resultants::resultants(law, ls, 1.0)?;
                    let t = 2.0 * ls - rho;
                    Ok((r.ns * t / m - 1.0, (r.jac[0][0] * t + 2.0 * r.ns) / m))
                };
                let ls = newton::scalar(h, guess[0], 1e-10)
                    .map_err(|e| fail(e, "flattening (PS, eqs. 78–79)"))?;
                (ls, 1.0)
            }
        };
        let r = resultants::resultants(law, ls, lz).map_err(|source| GpsError::Material {
            stage: "flattening",
            at: at.clone(),
            source,
        })?;
        let chi = contact_length(ls, rho, "flattening (negative contact length)", &at)?;
        let w = r.ns / rho;
        if r.ns < 0.0 {
            return Err(GpsError::Compressive {
                stage: "flattening",
                at,
                n_s: r.ns,
                w,
            });
        }
        Ok(FlatteningState {
            w,
            lambda_s: ls,
            lambda_z: lz,
            n_s: r.ns,
            n_z: r.nz,
            rho,
            chi,
            force: w * chi,
            displacement: self.initial.rho - rho,
        })
    }

    /// Continue from `prev` (with `prev2` for a linear predictor) to `rho`, cutting the step in
    /// half whenever Newton fails.
    fn continue_to(
        &self,
        prev: FlatteningState,
        prev2: Option<FlatteningState>,
        rho: f64,
    ) -> Result<FlatteningState, GpsError> {
        let predict = |a: &FlatteningState, b: Option<&FlatteningState>, rho: f64| match b {
            Some(b) if (a.rho - b.rho).abs() > 0.0 => {
                let t = (rho - a.rho) / (a.rho - b.rho);
                [
                    a.lambda_s + t * (a.lambda_s - b.lambda_s),
                    a.lambda_z + t * (a.lambda_z - b.lambda_z),
                ]
            }
            _ => [a.lambda_s, a.lambda_z],
        };
        let (mut cur, mut before) = (prev, prev2);
        let mut step = rho - prev.rho;
        let mut cuts = 0;
        loop {
            let target = if (rho - cur.rho).abs() <= step.abs() {
                rho
            } else {
                cur.rho + step
            };
            let guess = predict(&cur, before.as_ref(), target);
            match self
                .solve(target, guess)
                .or_else(|_| self.solve(target, [cur.lambda_s, cur.lambda_z]))
            {
                Ok(s) => {
                    before = Some(cur);
                    cur = s;
                    if target == rho {
                        return Ok(cur);
                    }
                }
                Err(e) => {
                    cuts += 1;
                    if cuts > MAX_CUTS {
                        return Err(e);
                    }
                    step *= 0.5;
                }
            }
        }
    }
}

/// χ = λs − ρ (the perimeter 2πλs = 2πρ + 2πχ); a negative one means the solve found a state
/// the plates do not touch.
fn contact_length(ls: f64, rho: f64, stage: &'static str, at: &str) -> Result<f64, GpsError> {
    let chi = ls - rho;
    if chi < -1e-10 {
        return Err(GpsError::NoConvergence {
            stage,
            at: at.to_string(),
            residual: chi,
            iterations: 0,
        });
    }
    Ok(chi)
}

fn check_rho(rho: f64, initial_stretch: f64) -> Result<(), GpsError> {
    if rho.is_finite() && rho > 0.0 && rho < initial_stretch {
        Ok(())
    } else {
        Err(invalid(
            "rho",
            rho,
            "the half-gap ρ must satisfy 0 < ρ < λs* (the plates start at the inflated radius)",
        ))
    }
}

/// The state at half-gap `rho` after inflating to `initial_stretch` and closing the gas in.
pub fn flatten(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    initial_stretch: f64,
    rho: f64,
) -> Result<FlatteningState, GpsError> {
    let fl = Flattening::new(law, hyp, initial_stretch)?;
    check_rho(rho, initial_stretch)?;
    fl.continue_to(fl.start(), None, rho)
}

/// The gas closed in the squeezed section `from`, then the plates moved on to `rho`
/// (continuation in ρ as [`flatten`]; the displacement counted from `from.rho`).
pub(crate) fn flatten_from(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    from: SectionState,
    rho: f64,
) -> Result<FlatteningState, GpsError> {
    let fl = Flattening::from_section(law, hyp, from);
    if rho == from.rho {
        return Ok(fl.start());
    }
    fl.continue_to(fl.start(), None, rho)
}

/// `points` states equally spaced in ρ from λs* (no contact) down to `rho_to`.
pub fn flattening_curve(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    initial_stretch: f64,
    rho_to: f64,
    points: usize,
) -> Result<Vec<FlatteningState>, GpsError> {
    let fl = Flattening::new(law, hyp, initial_stretch)?;
    check_rho(rho_to, initial_stretch)?;
    check_points(points)?;
    let mut out = Vec::with_capacity(points);
    out.push(fl.start());
    for i in 1..points {
        let rho = initial_stretch + (rho_to - initial_stretch) * i as f64 / (points - 1) as f64;
        let n = out.len();
        let prev2 = if n >= 2 { Some(out[n - 2]) } else { None };
        out.push(fl.continue_to(out[n - 1], prev2, rho)?);
    }
    Ok(out)
}

/// The GPS cross-section squeezed to half-gap `rho` under a *given* gas pressure `w` — eqs. (76)
/// without the gas law (77₂). This is the local, translation-invariant mechanics of the section:
/// a finite tube's mid-span obeys it whatever its total gas volume, so comparing the FE's mid-span
/// with it at the FE's own pressure separates the end effect that passes through the shared gas
/// (caps holding gas the plates do not squeeze) from the section's own mechanics.
///
/// Unknowns (λs, λz), with χ = λs − ρ:
/// N_s(λs, λz) = ϖρ and N_z(λs, λz) = (ϖρ/2)(2λs − ρ)/λs. Where the law has limit points
/// (ABB with 𝒩 = 30) several stretches carry the same pressure, so `guess` (λs, λz) picks the
/// branch: pass the Boyle flattening at the same ρ, or the previous state of a sequence.
pub fn section_at_pressure(
    law: &dyn MembraneLaw,
    rho: f64,
    w: f64,
    guess: [f64; 2],
) -> Result<SectionState, GpsError> {
    if !(rho.is_finite() && rho > 0.0) {
        return Err(invalid("rho", rho, "the half-gap ρ must be positive"));
    }
    if !(w.is_finite() && w > 0.0) {
        return Err(invalid("w", w, "the gas pressure ϖ must be positive"));
    }
    let at = format!("ρ = {rho}, ϖ = {w}");
    if !(guess.iter().all(|g| g.is_finite() && *g > 0.0)) {
        return Err(invalid(
            "guess",
            guess[0],
            "the initial (λs, λz) must be finite and positive",
        ));
    }
    let f = |x: [f64; 2]| {
        let [ls, lz] = x;
        let r = resultants::resultants(law, ls, lz)?;
        let q = 0.5 * w * rho * (2.0 - rho / ls);
        let dq = 0.5 * w * rho * rho / (ls * ls);
        let scale = w * rho;
        Ok((
            [(r.ns - w * rho) / scale, (r.nz - q) / scale],
            [
                [r.jac[0][0] / scale, r.jac[0][1] / scale],
                [(r.jac[1][0] - dq) / scale, r.jac[1][1] / scale],
            ],
        ))
    };
    let [ls, lz] = newton::system2(f, guess, 1e-12)
        .map_err(|e| e.into_error("GPS section at a given pressure (eq. 76)", &at))?;
    contact_length(
        ls,
        rho,
        "GPS section at a given pressure (negative contact length: ϖ too low for ρ)",
        &at,
    )?;
    let r = resultants::resultants(law, ls, lz).map_err(|source| GpsError::Material {
        stage: "GPS section at a given pressure",
        at,
        source,
    })?;
    Ok(section_state(w, rho, ls, lz, &r))
}

/// The section at half-gap `rho` under pressure `w` with stretches (λs, λz) and their
/// resultants `r` (χ = λs − ρ, the force ϖχ).
pub(crate) fn section_state(
    w: f64,
    rho: f64,
    ls: f64,
    lz: f64,
    r: &resultants::Resultants,
) -> SectionState {
    let chi = ls - rho;
    SectionState {
        w,
        rho,
        lambda_s: ls,
        lambda_z: lz,
        n_s: r.ns,
        n_z: r.nz,
        chi,
        force: w * chi,
    }
}

#[cfg(test)]
mod tests;
