//! The inflation: the gas let in, under pressure, mid-span stretch or volume control.

use super::{LoadParts, RangeInput, StageKind};
use crate::case::StagePlan;
use tubemem_fem::model::{Load, Loading, Model, State};
use tubemem_fem::post::MidSpan;
use tubemem_gps::limits::Limits;
use tubemem_gps::{inflate, Hypothesis};
use tubemem_material::MembraneLaw;

/// What an inflation controls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// the reduced pressure ϖ
    Pressure(f64),
    /// the hoop stretch λs* at the mid-span node on the x axis (the pressure is its multiplier)
    Stretch(f64),
    /// the enclosed volume over its reference value
    VolumeRatio(f64),
}

/// An inflation stage.
#[derive(Clone, Copy, Debug)]
pub struct Inflate {
    pub control: Control,
}

impl StageKind for Inflate {
    fn name(&self) -> &'static str {
        "inflate"
    }

    fn target_pressure(&self) -> Option<f64> {
        match self.control {
            Control::Pressure(p) => Some(p),
            _ => None,
        }
    }

    fn warnings(
        &self,
        plan: &StagePlan,
        law: &dyn MembraneLaw,
        limits: Option<&Limits>,
    ) -> Vec<String> {
        let i = plan.index;
        let mut out = vec![];
        // a target the closed form has no state for: say so before the run meets it
        let beyond = match self.control {
            Control::Stretch(s) => inflate(law, Hypothesis::Gps, s).err(),
            Control::Pressure(p) if p > 0.0 && !plan.arc_length => limits
                .and_then(|l| l.max)
                .filter(|mx| p > mx.w)
                .map(|_| tubemem_gps::GpsError::InvalidInput {
                    name: "target_pressure",
                    value: p,
                    requirement: "above the pressure maximum of the GPS inflation curve: under pressure control there is no uniform equilibrium there (use volume control)",
                }),
            _ => None,
        };
        // a mid-span stretch on the falling branch of the GPS curve: no stable uniform tube there
        if let (Control::Stretch(s), Some(l)) = (self.control, limits) {
            if let Some(mx) = l.max.filter(|mx| s > mx.lambda_s) {
                if l.min.is_none_or(|mn| s < mn.lambda_s) {
                    out.push(format!(
                        "stage {i}: the target λs* = {s} lies past the GPS pressure maximum (ϖ = {:.6} at λs = {:.4}), on the falling branch where a uniform tube is unstable: expect a bulge; the comparison with GPS is marked not applicable wherever the tube is not uniform",
                        mx.w, mx.lambda_s
                    ));
                }
            }
        }
        if let Some(e) = beyond {
            out.push(format!(
                "stage {i}: the target lies outside the closed form's validity ({}); the run will stop where the law allows no further equilibrium",
                crate::error_chain(&e)
            ));
        }
        out
    }

    fn controlled_value(&self, model: &Model, state: &State, node: usize) -> Option<f64> {
        match self.control {
            Control::Pressure(_) => None,
            Control::Stretch(_) => Some(state.x[node][0]),
            Control::VolumeRatio(_) => Some(model.total_volume(&state.x)),
        }
    }

    fn pressure_estimate(&self, law: &dyn MembraneLaw) -> Option<f64> {
        match self.control {
            Control::Pressure(p) => Some(p),
            Control::Stretch(s) => inflate(law, Hypothesis::Gps, s).ok().map(|g| g.w),
            Control::VolumeRatio(r) => inflate(law, Hypothesis::Gps, r.cbrt()).ok().map(|g| g.w),
        }
    }

    fn first_step(&self, from: f64, steps: usize, v0: f64) -> f64 {
        match self.control {
            Control::Pressure(_) => f64::INFINITY,
            Control::Stretch(s) => from + (s - from) / steps as f64,
            Control::VolumeRatio(r) => from + (r * v0 - from) / steps as f64,
        }
    }

    fn range(&self, input: &RangeInput) -> Result<(f64, f64, f64), String> {
        let (model, state) = (input.model, input.state);
        Ok(match self.control {
            Control::Pressure(p) => (state.p, p, 0.0),
            Control::Stretch(s) => (state.x[input.node][0], s, 0.0),
            Control::VolumeRatio(r) => (
                model.multiplicity() * model.mesh().volume_at(&state.x),
                r * input.v0,
                0.0,
            ),
        })
    }

    fn load(&self, parts: &LoadParts) -> Box<dyn Fn(f64) -> Load> {
        let node = parts.node;
        match self.control {
            Control::Pressure(_) => Box::new(Load::pressure),
            Control::Stretch(_) => Box::new(move |v| {
                Load::new(Loading::Node {
                    node,
                    component: 0,
                    target: v,
                })
            }),
            Control::VolumeRatio(_) => Box::new(|v| Load::new(Loading::Volume(v))),
        }
    }

    fn arc_monitor(&self, model: &Model, node: usize) -> Box<dyn Fn(&State) -> f64> {
        match self.control {
            Control::Pressure(_) => Box::new(|s: &State| s.p),
            Control::Stretch(_) => Box::new(move |s: &State| s.x[node][0]),
            Control::VolumeRatio(_) => {
                let mesh = model.mesh().clone();
                let mult = model.multiplicity();
                Box::new(move |s: &State| mult * mesh.volume_at(&s.x))
            }
        }
    }

    fn unstable_note(&self, ms: &MidSpan, limits: Option<&Limits>) -> String {
        // an inflation past the closed form's pressure maximum: the uniform state is unstable
        limits
            .and_then(|l| l.max)
            .filter(|mx| ms.lambda_s > mx.lambda_s)
            .map(|mx| format!(
                "; the mid-span λs = {:.4} is past the GPS pressure maximum (ϖ = {:.6} at λs = {:.4}), where a uniform tube is unstable and a bulge forms",
                ms.lambda_s, mx.w, mx.lambda_s
            ))
            .unwrap_or_default()
    }
}
