//! The GPS free inflation of a capped tube in time, with a quasi-linear viscoelastic law
//! ([`tubemem_material::viscoelastic`]): the paper's "mixed algebraic-differential" problem
//! (Sec. 3.2). Every point of the section has the same stretch history, so the section stays
//! uniform and eqs. (66) hold at every instant with the hereditary stress:
//!
//! ```text
//! N_s = λs S_s/λz,  N_z = λz S_z/λs,  S = α S⁰(λs, λz) + B   (one step, Prony::step)
//! N_s = ϖ λs   (hoop)        N_s = 2 N_z   (caps, GPS; PS: λz = 1)
//! and the control: ϖ(t) given (creep when held), λs(t) given, or v = λs² λz given
//!   (the enclosed volume per unit reference length over πR²: relaxation at fixed volume)
//! ```
//! The load follows a program of segments, each ramping its control linearly in time to a
//! target (or holding it) over a duration (0: a jump, taken with Δt = 0, the instantaneous
//! response). Each segment takes equal steps; [`inflation_history`] doubles them until the
//! Richardson estimate of the error (the update is second order, [`ORDER`]) is below a
//! tolerance, and reports that estimate.

use crate::{newton, resultants, GpsError, Hypothesis};
use tubemem_material::viscoelastic::{History, Prony};
use tubemem_material::{MaterialError, MembraneLaw, Num};

/// What a segment controls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Control {
    /// the reduced pressure ϖ
    Pressure,
    /// the hoop stretch λs
    Stretch,
    /// the enclosed volume per unit reference length over πR², v = λs² λz
    Volume,
}

/// One segment of a load program.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Segment {
    pub control: Control,
    /// the controlled value at the segment's end (`None`: held at its value at the start)
    pub target: Option<f64>,
    /// in the Prony series' time unit; 0: a jump
    pub duration: f64,
}

/// A state of the history.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimePoint {
    pub time: f64,
    pub w: f64,
    pub lambda_s: f64,
    pub lambda_z: f64,
    pub n_s: f64,
    pub n_z: f64,
}

/// A computed history and its accuracy.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TimeHistory {
    /// the state at the start (unloaded) and at the end of every step
    pub points: Vec<TimePoint>,
    /// steps per segment of non-zero duration
    pub steps_per_segment: usize,
    /// the Richardson estimate of the largest error in ϖ, λs or λz over the segment ends,
    /// |y_n − y_2n|/(2^p − 1) with p = [`ORDER`]
    pub error_estimate: f64,
}

/// The update's order in Δt (`tubemem_material::viscoelastic`; measured by the tests).
pub const ORDER: i32 = 2;

/// The most steps per segment [`inflation_history`] takes before it gives up: 2^20.
pub const MAX_STEPS: usize = 1 << 20;

/// The unknowns and resultants at the end of a step.
struct Solved {
    ls: f64,
    lz: f64,
    ns: f64,
    nz: f64,
}

/// One step's equations: the law, the hypothesis, α and the history's stress B.
struct StepEquations<'a> {
    law: &'a dyn MembraneLaw,
    hyp: Hypothesis,
    alpha: f64,
    b: [f64; 3],
}

impl StepEquations<'_> {
    /// N_s, N_z at (λs, λz) and their Jacobian [[∂N_s/∂λs, ∂N_s/∂λz], [∂N_z/∂λs, ∂N_z/∂λz]].
    fn resultants(&self, ls: f64, lz: f64) -> Result<(f64, f64, [[f64; 2]; 2]), MaterialError> {
        let r = resultants::resultants(self.law, ls, lz)?;
        let (alpha, bs, bz) = (self.alpha, self.b[0], self.b[1]);
        let ns = alpha * r.ns + bs * ls / lz;
        let nz = alpha * r.nz + bz * lz / ls;
        let j = [
            [
                alpha * r.jac[0][0] + bs / lz,
                alpha * r.jac[0][1] - bs * ls / (lz * lz),
            ],
            [
                alpha * r.jac[1][0] - bz * lz / (ls * ls),
                alpha * r.jac[1][1] + bz / ls,
            ],
        ];
        Ok((ns, nz, j))
    }

    /// F = N_s − 2 N_z (the caps' balance), its partials in λs and λz.
    fn axial(&self, ls: f64, lz: f64) -> Result<(f64, f64, f64), MaterialError> {
        let (ns, nz, j) = self.resultants(ls, lz)?;
        Ok((
            ns - 2.0 * nz,
            j[0][0] - 2.0 * j[1][0],
            j[0][1] - 2.0 * j[1][1],
        ))
    }

    /// Solve the step for the controlled `value` from the guess (λs, λz).
    fn solve(
        &self,
        control: Control,
        value: f64,
        guess: [f64; 2],
        at: &str,
    ) -> Result<Solved, GpsError> {
        const STAGE: &str = "viscoelastic inflation (eqs. 66 in time)";
        let ftol = 1e-13;
        let fail = |f: newton::Failure| f.into_error(STAGE, at);
        let (ls, lz) = match (control, self.hyp) {
            (Control::Pressure, Hypothesis::Gps) => {
                let x = newton::system2(
                    |[ls, lz]| {
                        let (ns, nz, j) = self.resultants(ls, lz)?;
                        Ok((
                            [ns - value * ls, ns - 2.0 * nz],
                            [
                                [j[0][0] - value, j[0][1]],
                                [j[0][0] - 2.0 * j[1][0], j[0][1] - 2.0 * j[1][1]],
                            ],
                        ))
                    },
                    guess,
                    ftol,
                )
                .map_err(fail)?;
                (x[0], x[1])
            }
            (Control::Pressure, Hypothesis::Ps) => {
                let ls = newton::scalar(
                    |ls| {
                        let (ns, _, j) = self.resultants(ls, 1.0)?;
                        Ok((ns - value * ls, j[0][0] - value))
                    },
                    guess[0],
                    ftol,
                )
                .map_err(fail)?;
                (ls, 1.0)
            }
            (Control::Stretch, Hypothesis::Gps) => {
                let lz = newton::scalar(
                    |lz| self.axial(value, lz).map(|(f, _, d)| (f, d)),
                    guess[1],
                    ftol,
                )
                .map_err(fail)?;
                (value, lz)
            }
            (Control::Volume, Hypothesis::Gps) => {
                // λs = √(v/λz): dλs/dλz = −λs/(2λz)
                let lz = newton::scalar(
                    |lz| {
                        let ls = (value / lz).sqrt();
                        self.axial(ls, lz)
                            .map(|(f, ds, dz)| (f, dz - ds * ls / (2.0 * lz)))
                    },
                    guess[1],
                    ftol,
                )
                .map_err(fail)?;
                ((value / lz).sqrt(), lz)
            }
            (Control::Stretch, Hypothesis::Ps) => (value, 1.0),
            (Control::Volume, Hypothesis::Ps) => (value.sqrt(), 1.0),
        };
        let (ns, nz, _) = self
            .resultants(ls, lz)
            .map_err(|source| GpsError::Material {
                stage: STAGE,
                at: at.to_string(),
                source,
            })?;
        if ns.is_nan() || ns <= 0.0 {
            return Err(GpsError::Compressive {
                stage: "viscoelastic inflation",
                at: at.to_string(),
                n_s: ns,
                w: ns / ls,
            });
        }
        Ok(Solved { ls, lz, ns, nz })
    }
}

fn controlled(p: &TimePoint, c: Control) -> f64 {
    match c {
        Control::Pressure => p.w,
        Control::Stretch => p.lambda_s,
        Control::Volume => p.lambda_s * p.lambda_s * p.lambda_z,
    }
}

fn check_program(segments: &[Segment]) -> Result<(), GpsError> {
    if segments.is_empty() {
        return Err(crate::invalid(
            "segments",
            0.0,
            "a load program needs at least one segment",
        ));
    }
    for s in segments {
        if !(s.duration.is_finite() && s.duration >= 0.0) {
            return Err(crate::invalid(
                "duration",
                s.duration,
                "a segment's duration must be finite and ≥ 0",
            ));
        }
        if let Some(t) = s.target {
            let ok = match s.control {
                Control::Pressure => t.is_finite() && t > 0.0,
                Control::Stretch | Control::Volume => t.is_finite() && t >= 1.0,
            };
            if !ok {
                return Err(crate::invalid(
                    "target",
                    t,
                    "a target pressure must be finite and > 0, a target stretch or volume ≥ 1",
                ));
            }
        } else if s.duration == 0.0 {
            return Err(crate::invalid(
                "duration",
                0.0,
                "a hold needs a duration > 0",
            ));
        }
    }
    if segments[0].target.is_none() {
        return Err(crate::invalid(
            "target",
            f64::NAN,
            "the first segment loads the unloaded tube: give its target",
        ));
    }
    Ok(())
}

/// The history under `segments` with `steps` equal steps in each segment of non-zero duration
/// (a jump takes one step with Δt = 0). The tube starts unloaded at λs = λz = 1.
pub fn integrate(
    law: &dyn MembraneLaw,
    prony: &Prony,
    hyp: Hypothesis,
    segments: &[Segment],
    steps: usize,
) -> Result<Vec<TimePoint>, GpsError> {
    check_program(segments)?;
    if steps == 0 || steps > MAX_STEPS {
        return Err(crate::invalid(
            "steps",
            steps as f64,
            "steps per segment must be 1 to 2^20",
        ));
    }
    let mut hist = History::unloaded(prony.terms().len());
    let mut p = TimePoint {
        time: 0.0,
        w: 0.0,
        lambda_s: 1.0,
        lambda_z: 1.0,
        n_s: 0.0,
        n_z: 0.0,
    };
    let mut points = vec![p];
    for (k, seg) in segments.iter().enumerate() {
        let from = controlled(&p, seg.control);
        let to = seg.target.unwrap_or(from);
        let (n, dt) = if seg.duration == 0.0 {
            (1, 0.0)
        } else {
            (steps, seg.duration / steps as f64)
        };
        let step = prony.step(dt);
        let t0 = p.time;
        for i in 1..=n {
            let value = from + (to - from) * i as f64 / n as f64;
            let time = t0 + dt * i as f64;
            let at = format!("segment {}, t = {}", k + 1, Num(time));
            let eqs = StepEquations {
                law,
                hyp,
                alpha: step.alpha,
                b: hist.offset(&step),
            };
            let s = eqs.solve(seg.control, value, [p.lambda_s, p.lambda_z], &at)?;
            let r = law
                .principal(s.ls, s.lz)
                .map_err(|source| GpsError::Material {
                    stage: "viscoelastic inflation (eqs. 66 in time)",
                    at: at.clone(),
                    source,
                })?;
            hist = hist.advanced(&step, [r.grad[0] / s.ls, r.grad[1] / s.lz, 0.0]);
            p = TimePoint {
                time,
                w: s.ns / s.ls,
                lambda_s: s.ls,
                lambda_z: s.lz,
                n_s: s.ns,
                n_z: s.nz,
            };
            points.push(p);
        }
    }
    Ok(points)
}

/// The history with the steps per segment doubled from `start` until the Richardson estimate
/// of the error at the segments' ends is at most `tolerance` (see [`TimeHistory`]).
pub fn inflation_history(
    law: &dyn MembraneLaw,
    prony: &Prony,
    hyp: Hypothesis,
    segments: &[Segment],
    start: usize,
    tolerance: f64,
) -> Result<TimeHistory, GpsError> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(crate::invalid(
            "tolerance",
            tolerance,
            "must be finite and > 0",
        ));
    }
    let ends = |pts: &[TimePoint], n: usize| -> Vec<TimePoint> {
        // the segment ends: after each segment's steps (1 for a jump, n otherwise)
        let mut out = Vec::new();
        let mut i = 0;
        for s in segments {
            i += if s.duration == 0.0 { 1 } else { n };
            out.push(pts[i]);
        }
        out
    };
    let mut n = start.max(1);
    let mut coarse = integrate(law, prony, hyp, segments, n)?;
    loop {
        if 2 * n > MAX_STEPS {
            return Err(GpsError::NoConvergence {
                stage: "viscoelastic inflation: time steps",
                at: format!("{n} steps per segment, tolerance {}", Num(tolerance)),
                residual: f64::NAN,
                iterations: n,
            });
        }
        let fine = integrate(law, prony, hyp, segments, 2 * n)?;
        let est = ends(&coarse, n)
            .iter()
            .zip(ends(&fine, 2 * n))
            .map(|(a, b)| {
                (a.w - b.w)
                    .abs()
                    .max((a.lambda_s - b.lambda_s).abs())
                    .max((a.lambda_z - b.lambda_z).abs())
            })
            .fold(0.0, f64::max)
            / (2f64.powi(ORDER) - 1.0);
        n *= 2;
        if est <= tolerance {
            return Ok(TimeHistory {
                points: fine,
                steps_per_segment: n,
                error_estimate: est,
            });
        }
        coarse = fine;
    }
}
