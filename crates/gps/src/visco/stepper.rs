//! The GPS section in time advanced one step at a time ([`Stepper`]), each step with its own
//! length and its own load: the DAE driven by another solver's steps (the FE's time steps,
//! at the FE's own pressure and plate position), and the step that [`super::integrate`] takes.

use super::step::{Fix, PlateFix, Section, StepEquations};
use super::{TimePoint, UNLOADED};
use crate::{GpsError, Hypothesis};
use tubemem_material::viscoelastic::{History, Prony};
use tubemem_material::{MembraneLaw, Num};

/// What loads one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepLoad {
    /// the free tube at the reduced pressure ϖ
    Pressure(f64),
    /// the free tube at the hoop stretch λs
    Stretch(f64),
    /// the free tube at the enclosed volume v = λs² λz
    Volume(f64),
    /// the free tube with the gas closed: ϖ λs² λz = `m`
    Gas(f64),
    /// two frictionless plates at ±ρ with the pressure ϖ given; the tube is free when it is
    /// narrower than the gap
    PlatesAtPressure { rho: f64, w: f64 },
    /// two plates at ±ρ with the gas closed: ϖ ρ (2λs − ρ) λz = `m` in contact, ϖ λs² λz = `m`
    /// free
    PlatesWithGas { rho: f64, m: f64 },
}

/// The section's state and its material history, advanced step by step from the unloaded
/// tube (a clone advances on its own: a prediction).
#[derive(Clone)]
pub struct Stepper<'a> {
    law: &'a dyn MembraneLaw,
    prony: &'a Prony,
    hyp: Hypothesis,
    history: History,
    point: TimePoint,
}

impl<'a> Stepper<'a> {
    /// The unloaded tube at t = 0.
    pub fn new(law: &'a dyn MembraneLaw, prony: &'a Prony, hyp: Hypothesis) -> Self {
        Self {
            law,
            prony,
            hyp,
            history: History::unloaded(prony.terms().len()),
            point: UNLOADED,
        }
    }

    /// The state at the end of the last step.
    pub fn state(&self) -> TimePoint {
        self.point
    }

    /// M = ϖ × the enclosed volume per unit reference length over πR² of the current state
    /// (ϖ ρ(2λs − ρ)λz in contact, ϖ λs² λz free): what a gas closed in now keeps.
    pub fn gas(&self) -> f64 {
        let p = &self.point;
        if p.chi > 0.0 {
            let rho = p.rho.unwrap_or(p.lambda_s);
            p.w * rho * (2.0 * p.lambda_s - rho) * p.lambda_z
        } else {
            p.w * p.lambda_s * p.lambda_s * p.lambda_z
        }
    }

    /// One step of length `dt` ≥ 0 (0: a jump) under `load`; the history advances.
    pub fn advance(&mut self, dt: f64, load: StepLoad) -> Result<TimePoint, GpsError> {
        self.advance_in(dt, load, "")
    }

    /// [`Stepper::advance`], its errors located with `place` before the time ("segment 2, ").
    pub(crate) fn advance_in(
        &mut self,
        dt: f64,
        load: StepLoad,
        place: &str,
    ) -> Result<TimePoint, GpsError> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(crate::invalid("time step", dt, "must be finite and ≥ 0"));
        }
        let step = self.prony.step(dt);
        let p = self.point;
        let time = p.time + dt;
        let at = format!("{place}t = {}", Num(time));
        let eqs = StepEquations {
            law: self.law,
            hyp: self.hyp,
            alpha: step.alpha,
            b: self.history.offset(&step),
        };
        let guess = [p.lambda_s, p.lambda_z];
        let free = |fix| eqs.solve(Section::Free(fix), guess, &at);
        let (s, rho) = match load {
            StepLoad::Pressure(w) => (free(Fix::Pressure(w))?, None),
            StepLoad::Stretch(v) => (free(Fix::Stretch(v))?, None),
            StepLoad::Volume(v) => (free(Fix::Volume(v))?, None),
            StepLoad::Gas(m) => (free(Fix::Gas(m))?, None),
            StepLoad::PlatesAtPressure { rho, w } => {
                // in contact if the free tube would be wider than the gap
                match free(Fix::Pressure(w)) {
                    Ok(f) if f.ls <= rho => (f, Some(rho)),
                    _ => (
                        eqs.solve(Section::Plates(rho, PlateFix::Pressure(w)), guess, &at)?,
                        Some(rho),
                    ),
                }
            }
            StepLoad::PlatesWithGas { rho, m } => match free(Fix::Gas(m)) {
                Ok(f) if f.ls <= rho => (f, Some(rho)),
                _ => (
                    eqs.solve(Section::Plates(rho, PlateFix::Gas(m)), guess, &at)?,
                    Some(rho),
                ),
            },
        };
        let r = self
            .law
            .principal(s.ls, s.lz)
            .map_err(|source| GpsError::Material {
                stage: "viscoelastic section in time",
                at: at.clone(),
                source,
            })?;
        self.history = self
            .history
            .advanced(&step, [r.grad[0] / s.ls, r.grad[1] / s.lz, 0.0]);
        let chi = rho.map_or(0.0, |rho| (s.ls - rho).max(0.0));
        self.point = TimePoint {
            time,
            w: s.w,
            lambda_s: s.ls,
            lambda_z: s.lz,
            n_s: s.ns,
            n_z: s.nz,
            rho,
            chi,
            force: s.w * chi,
        };
        Ok(self.point)
    }
}
