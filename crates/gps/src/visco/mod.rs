//! The GPS section of a capped tube in time, with a quasi-linear viscoelastic law
//! ([`tubemem_material::viscoelastic`]): the paper's "mixed algebraic-differential" problem
//! (Sec. 3.2). Every point of the section has the same stretch history (N_s is uniform around
//! the section at every instant, frictionless plates or none), so the section stays uniform and
//! eqs. (66) (free) or (76)–(77) (between plates) hold at every instant with the hereditary
//! stress of the step (the private module `step`).
//!
//! A load program is a list of segments, each ramping its control linearly in time to a target
//! (or holding it) over a duration (0: a jump, taken with Δt = 0, the instantaneous response):
//! the pressure ϖ (creep when held), the hoop stretch λs, the enclosed volume v = λs² λz
//! (relaxation at fixed volume when held), or the plates' half-gap ρ with the pressure held or
//! the gas closed at the segment's start (a squeeze at a plate speed, a hold, a release; the
//! plates start where they touch the tube, and leave it where it is narrower than the gap). Each
//! segment takes equal steps; [`inflation_history`] doubles them until the estimate of the
//! error, |y_n − y_2n| between the two last step counts, is below a tolerance, and reports
//! it. The update is second order on a smooth history ([`ORDER`]); where contact begins or
//! ends inside a step the history has a kink there and the observed order falls to between 1
//! and 2 (measured 1.3 to 2.2 over a squeeze–hold–release cycle), so the estimate takes the
//! whole difference, which bounds the finer history's error for any order of at least 1
//! (the Richardson estimate |y_n − y_2n|/(2^p − 1) would assume p).

pub mod cycle;
mod step;
mod stepper;

use crate::{GpsError, Hypothesis};
pub use stepper::{StepLoad, Stepper};
use tubemem_material::viscoelastic::Prony;
use tubemem_material::{MembraneLaw, Num};

/// How the gas is supplied while the plates move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Supply {
    /// the pressure held at its value at the segment's start (a regulator)
    Pressure,
    /// the gas closed in at the segment's start (Boyle, eq. 77₂)
    Gas,
}

/// What a segment controls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Control {
    /// the reduced pressure ϖ of the free tube
    Pressure,
    /// the hoop stretch λs of the free tube
    Stretch,
    /// the free tube's enclosed volume per unit reference length over πR², v = λs² λz
    Volume,
    /// the half-gap ρ of two frictionless plates y = ±ρR
    Plates(Supply),
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
    /// the plates' half-gap (None before any plates segment)
    pub rho: Option<f64>,
    /// χ = λs − ρ, the reduced contact length (0 without contact)
    pub chi: f64,
    /// the reduced force ϖχ on each plate (eq. 80; 0 without contact)
    pub force: f64,
}

/// A computed history and its accuracy.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TimeHistory {
    /// the state at the start (unloaded) and at the end of every step
    pub points: Vec<TimePoint>,
    /// steps per segment of non-zero duration
    pub steps_per_segment: usize,
    /// the estimate of the largest error in ϖ, λs, λz or the force over the
    /// segment ends, or in the plates' work ([`loop_area`]),
    /// |y_n − y_2n| (see the module docs)
    pub error_estimate: f64,
}

impl TimeHistory {
    /// The last state (the unloaded tube for a history without steps).
    pub fn end(&self) -> TimePoint {
        self.points.last().copied().unwrap_or(UNLOADED)
    }
}

/// The unloaded tube every history starts from.
pub const UNLOADED: TimePoint = TimePoint {
    time: 0.0,
    w: 0.0,
    lambda_s: 1.0,
    lambda_z: 1.0,
    n_s: 0.0,
    n_z: 0.0,
    rho: None,
    chi: 0.0,
    force: 0.0,
};

/// The update's order in Δt on a smooth history (`tubemem_material::viscoelastic`; measured
/// by the tests).
pub const ORDER: i32 = 2;

/// The most steps per segment [`inflation_history`] takes before it gives up: 2^20.
pub const MAX_STEPS: usize = 1 << 20;

fn controlled(p: &TimePoint, c: Control) -> f64 {
    match c {
        Control::Pressure => p.w,
        Control::Stretch => p.lambda_s,
        Control::Volume => p.lambda_s * p.lambda_s * p.lambda_z,
        // plates not yet there start where they touch the tube
        Control::Plates(_) => p.rho.unwrap_or(p.lambda_s),
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
    let mut plates = false;
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
                Control::Pressure | Control::Plates(_) => t.is_finite() && t > 0.0,
                Control::Stretch | Control::Volume => t.is_finite() && t >= 1.0,
            };
            if !ok {
                return Err(crate::invalid(
                    "target",
                    t,
                    "a target pressure or half-gap must be finite and > 0, a target stretch or volume ≥ 1",
                ));
            }
        } else if s.duration == 0.0 {
            return Err(crate::invalid(
                "duration",
                0.0,
                "a hold needs a duration > 0",
            ));
        }
        match s.control {
            Control::Plates(_) => plates = true,
            _ if plates => return Err(crate::invalid(
                "control",
                f64::NAN,
                "after a plates segment the plates stay: every later segment moves or holds them",
            )),
            _ => {}
        }
    }
    if segments[0].target.is_none() || matches!(segments[0].control, Control::Plates(_)) {
        return Err(crate::invalid(
            "target",
            f64::NAN,
            "the first segment inflates the unloaded tube: give its pressure, stretch or volume target",
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
    let mut stepper = Stepper::new(law, prony, hyp);
    let mut points = vec![stepper.state()];
    for (k, seg) in segments.iter().enumerate() {
        let p = stepper.state();
        let from = controlled(&p, seg.control);
        let to = seg.target.unwrap_or(from);
        // the gas closed at the segment's start, and the pressure held there
        let (m, held) = (stepper.gas(), p.w);
        let (n, dt) = if seg.duration == 0.0 {
            (1, 0.0)
        } else {
            (steps, seg.duration / steps as f64)
        };
        for i in 1..=n {
            let value = from + (to - from) * i as f64 / n as f64;
            let load = match seg.control {
                Control::Pressure => StepLoad::Pressure(value),
                Control::Stretch => StepLoad::Stretch(value),
                Control::Volume => StepLoad::Volume(value),
                Control::Plates(Supply::Pressure) => StepLoad::PlatesAtPressure {
                    rho: value,
                    w: held,
                },
                Control::Plates(Supply::Gas) => StepLoad::PlatesWithGas { rho: value, m },
            };
            let point = stepper.advance_in(dt, load, &format!("segment {}, ", k + 1))?;
            points.push(point);
        }
    }
    Ok(points)
}

/// The history with the steps per segment doubled from `start` until the estimate
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
                    .max((a.force - b.force).abs())
            })
            .fold((loop_area(&coarse) - loop_area(&fine)).abs(), f64::max);
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

/// The work the plates do on the tube, per plate and unit length, over the steps with plates:
/// ∫ force d(−ρ) in πμHR (trapezoids between consecutive steps; the step where the plates
/// arrive starts from first contact, ρ = λs, with no force). Over a squeeze and a release back
/// to first contact it is the force–gap loop's area, the energy the law dissipated.
pub fn loop_area(points: &[TimePoint]) -> f64 {
    points
        .windows(2)
        .filter_map(|q| {
            let a = q[0].rho.unwrap_or(q[0].lambda_s);
            q[1].rho.map(|b| 0.5 * (q[0].force + q[1].force) * (a - b))
        })
        .sum()
}
