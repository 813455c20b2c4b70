//! The confinement: the gas closed in, the tube pressed by any frictionless planes n·x ≤ d,
//! each moved from its `offset` to its `target` as the load parameter t goes from 0 to 1.

use super::{
    closed_form, penalty_of, planes_load, LoadParts, RangeInput, StageComparison, StageKind,
    MAX_PENETRATION_FRACTION,
};
use crate::case::{GasControl, PlaneSpec};
use crate::observer::BoxError;
use crate::report::{
    rel, ClosedFormState, ContactRecord, RelativeErrors, StepClosedForm, StepRecord,
};
use crate::{AppError, Result};
use tubemem_fem::contact::{Contact, MovingPlanes};
use tubemem_fem::continuation::ArcLoading;
use tubemem_fem::model::{Load, Model, State};
use tubemem_fem::post::{MidSpan, WallValues};
use tubemem_fem::stepping::StepInfo;
use tubemem_gps::confine::{confine, confine_at_pressure, ConfineState, WallContact};
use tubemem_gps::Hypothesis;
use tubemem_material::MembraneLaw;

/// A confine stage by its planes.
#[derive(Clone, Debug)]
pub struct Confine {
    pub planes: Vec<PlaneSpec>,
    pub gas: GasControl,
}

impl StageKind for Confine {
    fn name(&self) -> &'static str {
        "confine"
    }

    fn closed_gas(&self) -> bool {
        self.gas == GasControl::Closed
    }

    fn presses(&self) -> bool {
        true
    }

    fn supply(&self) -> closed_form::Supply {
        self.gas.into()
    }

    fn range(&self, input: &RangeInput) -> std::result::Result<(f64, f64, f64), String> {
        let (model, state, planes) = (input.model, input.state, &self.planes);
        if state.p.is_nan() || state.p <= 0.0 {
            return Err(format!(
                "the tube holds no gas pressure to confine (ϖ = {})",
                state.p
            ));
        }
        // no plane may start inside the tube; one that continues a confine stage may touch it
        // as that stage's contact left it, by up to the penetration a step accepts
        // (MAX_PENETRATION_FRACTION of its distance from the axis)
        let touch = if input.continues_confine {
            MAX_PENETRATION_FRACTION
        } else {
            0.0
        };
        for (k, p) in planes.iter().enumerate() {
            let len = p.normal[0].hypot(p.normal[1]);
            let reach = state
                .x
                .iter()
                .map(|x| (p.normal[0] * x[0] + p.normal[1] * x[1]) / len)
                .fold(f64::NEG_INFINITY, f64::max);
            if reach > p.offset / len + touch * (p.offset / len).abs() {
                return Err(format!(
                    "plane {}: `offset` = {} cuts the tube, which reaches n·x = {reach:.6} along its normal: start it further out",
                    k + 1,
                    p.offset
                ));
            }
        }
        // the planes must press the tube: some plane moves in, and ends inside the tube's
        // present reach along its normal (walls that never touch it would leave a stage with
        // no contact, compared with a confinement the FE never had)
        if !input.continues_confine && !planes.iter().any(|p| p.target < p.offset) {
            return Err(
                "no plane moves in (every `target` ≥ its `offset`): a confine stage presses the tube; a plane moving out releases it, which a later stage after a confine stage may do"
                    .to_string(),
            );
        }
        let reaches: Vec<f64> = planes
            .iter()
            .map(|p| {
                let len = p.normal[0].hypot(p.normal[1]);
                let reach = state
                    .x
                    .iter()
                    .map(|x| (p.normal[0] * x[0] + p.normal[1] * x[1]) / len)
                    .fold(f64::NEG_INFINITY, f64::max);
                reach - p.target / len
            })
            .collect();
        if !input.continues_confine && reaches.iter().all(|&d| d <= 0.0) {
            return Err(format!(
                "no plane's `target` reaches the tube: the nearest stays {:.6} R outside it along its normal, so the planes would never touch it; move a target inside the tube's present surface",
                -reaches.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            ));
        }
        // the planes must have the model's symmetry
        let sym = model.mesh().symmetry.planes();
        for (axis, name) in [(0usize, "x = 0"), (1usize, "y = 0")] {
            if !sym.contains(&axis) {
                continue;
            }
            for (k, p) in planes.iter().enumerate() {
                if !p.mirrored_in(planes, axis) {
                    return Err(format!(
                        "plane {} has no mirror image across {name}, a symmetry plane of the model (symmetry = {:?}): give its mirror plane too, or use a model without that symmetry",
                        k + 1,
                        model.mesh().symmetry
                    ));
                }
            }
        }
        Ok((0.0, 1.0, penalty_of(input.penalty, state, input.start)))
    }

    fn load(&self, parts: &LoadParts) -> Box<dyn Fn(f64) -> Load> {
        let planes = self.planes.clone();
        planes_load(parts, self.gas, move |t, penalty| {
            fe_planes(&planes, t, penalty)
        })
    }

    fn arc_monitor(&self, _model: &Model, _node: usize) -> Box<dyn Fn(&State) -> f64> {
        // closed gas: the planes' parameter t
        Box::new(|s: &State| s.planes)
    }

    fn arc_loading(&self, parts: &LoadParts) -> ArcLoading {
        ArcLoading::ClosedGas {
            pv: parts.pv,
            planes: fe_moving_planes(&self.planes, parts.penalty)
                .with_enforcement(parts.enforcement)
                .with_points(parts.points),
        }
    }

    /// Each wall's values, the penetration guard (as a fraction of the nearest wall's
    /// distance from the axis), and the closed form for the same walls: GPS from the stage's
    /// start, and the section at the FE's pressure.
    fn step_closed_form(
        &self,
        model: &Model,
        state: &State,
        info: &StepInfo<'_>,
        law: &dyn MembraneLaw,
        ms: &MidSpan,
        _contact: Option<&ContactRecord>,
        start: closed_form::ClosedFormStart,
        stage: usize,
    ) -> std::result::Result<(StepClosedForm, Vec<WallValues>), BoxError> {
        let start_lambda_s = start.lambda_s;
        let mut cf = closed_form::step_closed_form(law, ms, None, start.supply);
        let Some(c) = info.load.contact.as_ref() else {
            return Ok((cf, vec![]));
        };
        let w = tubemem_fem::post::midspan_walls(model, state, c);
        let d_min = self
            .planes
            .iter()
            .map(|p| {
                (p.offset + info.value * (p.target - p.offset)).abs()
                    / p.normal[0].hypot(p.normal[1])
            })
            .fold(f64::INFINITY, f64::min);
        let pen = w.iter().map(|v| v.penetration).fold(0.0, f64::max);
        if pen.is_nan() || pen > MAX_PENETRATION_FRACTION * d_min {
            return Err(Box::new(AppError::ContactUnresolved {
                stage,
                step: info.step,
                penetration: pen,
                rho: d_min,
                penalty: c.penalty,
            }) as BoxError);
        }
        if let Ok(gw) = self
            .planes
            .iter()
            .map(|p| p.wall_at(info.value))
            .collect::<std::result::Result<Vec<_>, _>>()
        {
            cf.gps_inflation = None;
            cf.local_confine = confine_at_pressure(law, Hypothesis::Gps, &gw, ms.w).ok();
            cf.gps_confine = match self.gas {
                GasControl::Closed => confine(law, Hypothesis::Gps, &gw, start_lambda_s).ok(),
                // regulated: the confinement at the prescribed pressure is the section at
                // the FE's pressure
                GasControl::Regulated { .. } => cf.local_confine.clone(),
            };
        }
        Ok((cf, w))
    }

    /// GPS and PS for the same walls at the last step's t, the section at the FE's pressure,
    /// and each wall's force against both.
    fn stage_comparison(
        &self,
        law: &dyn MembraneLaw,
        ms: &MidSpan,
        contact: Option<&ContactRecord>,
        last: Option<&StepRecord>,
        start: closed_form::ClosedFormStart,
    ) -> Result<StageComparison> {
        let start_lambda_s = start.lambda_s;
        let mut out = closed_form::stage_closed_form(
            law,
            ms,
            contact,
            last.map(|l| &l.closed_form),
            start.supply,
        )?;
        let Some(last) = last else {
            return Ok(out);
        };
        let walls = self
            .planes
            .iter()
            .map(|p| p.wall_at(last.load))
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| AppError::gps("the confine stage's planes", e))?;
        let errors = |c: &ConfineState| RelativeErrors {
            w: Some(rel(ms.w, c.w)),
            lambda_s: Some(rel(ms.lambda_s, c.lambda_s)),
            lambda_z: Some(rel(ms.lambda_z, c.lambda_z)),
            ..Default::default()
        };
        let closed_or_regulated = |hyp: Hypothesis| match self.gas {
            GasControl::Closed => confine(law, hyp, &walls, start_lambda_s),
            GasControl::Regulated { .. } => confine_at_pressure(law, hyp, &walls, ms.w),
        };
        let g = match &last.closed_form.gps_confine {
            Some(g) => g.clone(),
            None => closed_or_regulated(Hypothesis::Gps)
                .map_err(|e| AppError::gps("GPS for the confine stage's walls", e))?,
        };
        let p = closed_or_regulated(Hypothesis::Ps)
            .map_err(|e| AppError::gps("PS for the confine stage's walls", e))?;
        out.gps_errors = errors(&g);
        out.ps_errors = errors(&p);
        let local = last.closed_form.local_confine.clone();
        out.local_errors = local.as_ref().map(|l| RelativeErrors {
            w: None,
            ..errors(l)
        });
        out.walls = last
            .walls
            .iter()
            .enumerate()
            .map(|(k, fe)| {
                let gk = g.walls.get(k).copied();
                let lk = local.as_ref().and_then(|l| l.walls.get(k).copied());
                let err = |c: Option<WallContact>| {
                    c.filter(|c| c.force > 0.0).map(|c| rel(fe.force, c.force))
                };
                crate::report::WallSummary {
                    fe: *fe,
                    gps: gk,
                    local: lk,
                    force_error_vs_gps: err(gk),
                    force_error_vs_gps_at_fe_pressure: err(lk),
                }
            })
            .collect();
        out.gps = ClosedFormState::Confine(Box::new(g));
        out.ps = ClosedFormState::Confine(Box::new(p));
        Ok(out)
    }

    fn planes(&self) -> Option<&[PlaneSpec]> {
        Some(&self.planes)
    }
}

/// The planes of a confine stage as functions of its load parameter t (for arc length):
/// [`fe_planes`] at t, the offsets linear in t.
pub(crate) fn fe_moving_planes(planes: &[PlaneSpec], penalty: f64) -> MovingPlanes {
    MovingPlanes {
        at_zero: fe_planes(planes, 0.0, penalty),
        rates: planes
            .iter()
            .map(|p| -(p.target - p.offset) / p.normal[0].hypot(p.normal[1]))
            .collect(),
    }
}

/// The FE contact of a confine stage at load parameter `t`: each wall n·x ≤ d as the kernel's
/// plane with gap −n·x + d ≥ 0 (unit normal, in the cross-section plane).
pub(crate) fn fe_planes(planes: &[PlaneSpec], t: f64, penalty: f64) -> Contact {
    Contact {
        planes: planes
            .iter()
            .map(|p| {
                let len = p.normal[0].hypot(p.normal[1]);
                let d = p.offset + t * (p.target - p.offset);
                tubemem_fem::contact::Plane {
                    normal: [-p.normal[0] / len, -p.normal[1] / len, 0.0],
                    offset: -d / len,
                }
            })
            .collect(),
        penalty,
        enforcement: tubemem_fem::contact::Enforcement::Penalty,
        points: Default::default(),
    }
}
