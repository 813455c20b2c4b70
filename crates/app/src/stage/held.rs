//! The inflation between held plates (`plates = "held"`): the plates of the squeeze before the
//! stage stay where it left them while the pressure rises, under pressure control or by arc
//! length. The closed form is the section between plates at that half-gap and the FE's
//! pressure ([`tubemem_gps::regulated::between_plates`] when the plates are closer than the
//! stress-free tube's radius), and its critical pressure ϖc(ρ)
//! ([`tubemem_gps::regulated::critical_pressure`]) is the reference of a pressure maximum the
//! arc length locates.

use super::{closed_form::Supply, LoadParts, RangeInput, StageKind};
use crate::report::{ContactRecord, CriticalReference};
use crate::units::Dimension;
use tubemem_fem::contact::Contact;
use tubemem_fem::continuation::ArcLoading;
use tubemem_fem::model::{Load, Loading, Model, State};
use tubemem_fem::stepping::StepInfo;
use tubemem_gps::Hypothesis;
use tubemem_material::MembraneLaw;

/// An inflation to the reduced pressure `target` between the previous squeeze's plates.
#[derive(Clone, Copy, Debug)]
pub struct HeldPlates {
    pub target: f64,
}

impl HeldPlates {
    /// The held plates at the stage's half-gap, with its penalty, enforcement and points.
    fn contact(parts: &LoadParts) -> Contact {
        Contact::plates(parts.held_plates.unwrap_or(f64::NAN), parts.penalty)
            .with_enforcement(parts.enforcement)
            .with_points(parts.points)
    }
}

impl StageKind for HeldPlates {
    fn name(&self) -> &'static str {
        "inflate"
    }

    fn presses(&self) -> bool {
        true
    }

    fn supply(&self) -> Supply {
        Supply::HeldPlates
    }

    fn range(&self, input: &RangeInput) -> Result<(f64, f64, f64), String> {
        let Some(prev) = input.previous_squeeze else {
            return Err(
                "`plates = \"held\"` holds the plates of the squeeze just before it, which did not leave any"
                    .into(),
            );
        };
        let p = input.state.p;
        if self.target.is_nan() || self.target <= p {
            let show = |v: f64| input.units.show(Dimension::Pressure, v);
            return Err(format!(
                "`target_pressure` ({}) must be above the pressure the plates hold the tube at ({}): the stage raises the pressure",
                show(self.target),
                show(p)
            ));
        }
        Ok((p, self.target, prev.penalty))
    }

    fn load(&self, parts: &LoadParts) -> Box<dyn Fn(f64) -> Load> {
        let contact = Self::contact(parts);
        Box::new(move |v| Load::with_contact(Loading::Pressure(v), contact.clone()))
    }

    fn arc_monitor(&self, _model: &Model, _node: usize) -> Box<dyn Fn(&State) -> f64> {
        Box::new(|s: &State| s.p)
    }

    fn arc_loading(&self, parts: &LoadParts) -> ArcLoading {
        ArcLoading::Pressure(Some(Self::contact(parts)))
    }

    fn step_contact(
        &self,
        model: &Model,
        state: &State,
        info: &StepInfo<'_>,
        start: super::closed_form::ClosedFormStart,
    ) -> Option<ContactRecord> {
        super::squeeze::plates_contact(model, state, info, start)
    }

    fn limit_reference(
        &self,
        law: &dyn MembraneLaw,
        held_plates: Option<f64>,
    ) -> Option<CriticalReference> {
        let rho = held_plates?;
        let c = tubemem_gps::regulated::critical_pressure(law, Hypothesis::Gps, rho).ok()??;
        Some(CriticalReference {
            what: "GPS critical pressure between the plates".into(),
            w: c.w,
            lambda_s: c.lambda_s,
        })
    }
}
