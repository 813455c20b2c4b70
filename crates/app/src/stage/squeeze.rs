//! The squeeze: the tube pressed between frictionless plates y = ±h, the gas closed in or
//! regulated.

use super::{closed_form::Supply, penalty_of, planes_load, LoadParts, RangeInput, StageKind};
use crate::case::GasControl;
use crate::report::ContactRecord;
use tubemem_fem::contact::{Contact, MovingPlanes};
use tubemem_fem::continuation::ArcLoading;
use tubemem_fem::model::{Load, Model, State};
use tubemem_fem::post::midspan_contact;
use tubemem_fem::stepping::StepInfo;

/// A squeeze to the plate half-gap ρ (in R).
#[derive(Clone, Copy, Debug)]
pub struct Squeeze {
    pub rho: f64,
    pub gas: GasControl,
}

impl StageKind for Squeeze {
    fn name(&self) -> &'static str {
        "squeeze"
    }

    fn closed_gas(&self) -> bool {
        self.gas == GasControl::Closed
    }

    fn presses(&self) -> bool {
        true
    }

    fn supply(&self) -> Supply {
        self.gas.into()
    }

    fn range(&self, input: &RangeInput) -> Result<(f64, f64, f64), String> {
        let state = input.state;
        if state.p.is_nan() || state.p <= 0.0 {
            return Err(format!(
                "the tube holds no gas pressure to squeeze (ϖ = {})",
                state.p
            ));
        }
        let h0 = state.x.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
        if self.rho >= h0 {
            return Err(format!(
                "`target_rho` = {} must be below the current half-height {h0:.6} of the tube",
                self.rho
            ));
        }
        let penalty = match (input.penalty, input.previous_squeeze) {
            (Some(crate::case::PenaltySpec::Value(k)), _) => k,
            // a squeeze that continues a squeeze keeps its plates' penalty
            (_, Some(prev)) => prev.penalty,
            (spec, None) => penalty_of(spec, state, input.start),
        };
        Ok((h0, self.rho, penalty))
    }

    fn load(&self, parts: &LoadParts) -> Box<dyn Fn(f64) -> Load> {
        planes_load(parts, self.gas, Contact::plates)
    }

    fn arc_monitor(&self, _model: &Model, _node: usize) -> Box<dyn Fn(&State) -> f64> {
        // closed gas: the plates' half-gap h
        Box::new(|s: &State| s.planes)
    }

    fn arc_loading(&self, parts: &LoadParts) -> ArcLoading {
        ArcLoading::ClosedGas {
            pv: parts.pv,
            planes: MovingPlanes::plates(parts.penalty)
                .with_enforcement(parts.enforcement)
                .with_points(parts.points),
        }
    }

    fn step_contact(
        &self,
        model: &Model,
        state: &State,
        info: &StepInfo<'_>,
        start: super::closed_form::ClosedFormStart,
    ) -> Option<ContactRecord> {
        plates_contact(model, state, info, start)
    }
}

/// The mid-span contact with the plates of a step's load (a squeeze, or an inflation between
/// held plates), its displacement measured from the free tube's λs* the closed form starts at.
pub(crate) fn plates_contact(
    model: &Model,
    state: &State,
    info: &StepInfo<'_>,
    start: super::closed_form::ClosedFormStart,
) -> Option<ContactRecord> {
    let start_lambda_s = start.lambda_s;
    info.load.contact.as_ref().and_then(|c| {
        midspan_contact(model, state, c).map(|values| ContactRecord {
            values,
            displacement: start_lambda_s - values.rho,
            initial_stretch: start_lambda_s,
            penalty: c.penalty,
        })
    })
}
