//! The load program of `tubemem gps history` and Python's `gps_history`: a free inflation (a
//! ramp of the pressure, the hoop stretch or the volume, then a hold), then plates closing from
//! first contact at a speed, held, and released to where they first touched.

use super::{inflation_history, integrate, loop_area, Control, Segment, Supply, TimeHistory};
use crate::{GpsError, Hypothesis};
use tubemem_material::viscoelastic::Prony;
use tubemem_material::MembraneLaw;

/// The plates' part of a cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlatesLeg {
    pub supply: Supply,
    /// the half-gap the plates close to
    pub to: f64,
    /// the time they take (0: a jump); the release takes the same
    pub travel: f64,
    /// the time they are held at `to`
    pub hold: f64,
    /// then back to first contact
    pub release: bool,
}

/// A cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cycle {
    /// what the inflation ramps (not plates)
    pub control: Control,
    pub to: f64,
    pub ramp: f64,
    pub hold: f64,
    pub plates: Option<PlatesLeg>,
}

/// How the steps are chosen: doubled to a tolerance, or fixed per segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Steps {
    Tolerance(f64),
    Fixed(usize),
}

/// A computed cycle.
#[derive(Clone, Debug, PartialEq)]
pub struct CycleResult {
    /// the history (its error estimate NaN with fixed steps)
    pub history: TimeHistory,
    /// where the plates first touched (the inflated λs), with plates
    pub touch: Option<f64>,
    /// the plates' work over the cycle, with a release ([`loop_area`])
    pub loop_area: Option<f64>,
}

fn history(
    law: &dyn MembraneLaw,
    prony: &Prony,
    hyp: Hypothesis,
    program: &[Segment],
    steps: Steps,
) -> Result<TimeHistory, GpsError> {
    match steps {
        Steps::Tolerance(t) => inflation_history(law, prony, hyp, program, 16, t),
        Steps::Fixed(n) => integrate(law, prony, hyp, program, n).map(|points| TimeHistory {
            points,
            steps_per_segment: n,
            error_estimate: f64::NAN,
        }),
    }
}

/// Run a cycle.
pub fn run_cycle(
    law: &dyn MembraneLaw,
    prony: &Prony,
    hyp: Hypothesis,
    c: &Cycle,
    steps: Steps,
) -> Result<CycleResult, GpsError> {
    if matches!(c.control, Control::Plates(_)) {
        return Err(crate::invalid(
            "control",
            f64::NAN,
            "a cycle inflates first: its control is the pressure, the stretch or the volume",
        ));
    }
    for (name, v) in [("ramp", c.ramp), ("hold", c.hold)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(crate::invalid(name, v, "a duration must be finite and ≥ 0"));
        }
    }
    let mut program = vec![Segment {
        control: c.control,
        target: Some(c.to),
        duration: c.ramp,
    }];
    if c.hold > 0.0 {
        program.push(Segment {
            control: c.control,
            target: None,
            duration: c.hold,
        });
    }
    let Some(p) = c.plates else {
        let history = history(law, prony, hyp, &program, steps)?;
        return Ok(CycleResult {
            history,
            touch: None,
            loop_area: None,
        });
    };
    for (name, v) in [("plates travel", p.travel), ("plates hold", p.hold)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(crate::invalid(
                if name == "plates travel" {
                    "squeeze_time"
                } else {
                    "plates_hold"
                },
                v,
                "a duration must be finite and ≥ 0",
            ));
        }
    }
    // where the plates first touch: the inflated λs (to the same steps)
    let first = history(law, prony, hyp, &program, steps)?;
    let touch = first.end().lambda_s;
    if !(p.to.is_finite() && p.to > 0.0 && p.to < touch) {
        return Err(GpsError::PlatesOutside { rho: p.to, touch });
    }
    let plates = Control::Plates(p.supply);
    program.push(Segment {
        control: plates,
        target: Some(p.to),
        duration: p.travel,
    });
    if p.hold > 0.0 {
        program.push(Segment {
            control: plates,
            target: None,
            duration: p.hold,
        });
    }
    if p.release {
        program.push(Segment {
            control: plates,
            target: Some(touch),
            duration: p.travel,
        });
    }
    let history = history(law, prony, hyp, &program, steps)?;
    let area = p.release.then(|| loop_area(&history.points));
    Ok(CycleResult {
        history,
        touch: Some(touch),
        loop_area: area,
    })
}
