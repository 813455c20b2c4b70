//! Critical points of a stage: the record of a located one (with the closed form's limit
//! point of the same kind), and the probe for the pressure maximum a pressure-controlled stage
//! could not pass.

use crate::report::*;
use tubemem_fem::continuation::{ArcLoading, Critical, CriticalKind};
use tubemem_fem::model::{Load, Model, State};
use tubemem_fem::post::midspan;
use tubemem_gps::Hypothesis;
use tubemem_material::MembraneLaw;

/// After a pressure-controlled stage failed below its target: follow the path by arc length from
/// the last converged `state` towards `target` and return the first pressure maximum located on
/// the way (ϖmax and the mid-span λs there), or `None` when the path reaches the target or the
/// probe fails (the Newton failure is then the whole story). The model's state is not changed.
///
/// The probe looks where the closed form puts the maximum: it aims at no more than twice the
/// GPS inflation maximum of `law` (a finite tube's maximum lies within a few per cent of it),
/// and a law whose GPS inflation has no maximum is not probed. It takes at most
/// [`PROBE_STEPS`] steps. (Aimed at a target of 1e308 it had walked for over ten minutes.)
pub(crate) fn pressure_maximum_below(
    model: &mut Model,
    state: &State,
    target: f64,
    law: &dyn MembraneLaw,
) -> Option<(f64, f64)> {
    use tubemem_fem::continuation::{follow, ArcEvent, ArcSettings, MembranePath, Target};
    let w_max = tubemem_gps::limits::limit_points(law, Hypothesis::Gps)
        .ok()?
        .max?
        .w;
    let monitor = |s: &State| s.p;
    let goal = Target {
        name: "pressure",
        monitor: &monitor,
        value: target.min(2.0 * w_max),
    };
    let settings = ArcSettings {
        max_steps: PROBE_STEPS,
        ..ArcSettings::default()
    };
    let mut path = MembranePath::new(model, ArcLoading::Pressure(None));
    let mut found = None;
    let _ = follow(
        &mut path,
        state.clone(),
        &goal,
        &settings,
        |path, e| match e {
            ArcEvent::Critical(c) if c.kind == CriticalKind::LimitMax => {
                found = midspan(path.model, &c.state)
                    .ok()
                    .map(|m| (c.load, m.lambda_s));
                Err("located")
            }
            _ => Ok(()),
        },
    );
    found.filter(|(w, _)| *w < target)
}

/// The most steps the probe for a pressure maximum after a failed pressure stage takes: 200
/// (the shipped bulge's arc-length stage, `cases/inflate_abb30_ls6.0_bulge.toml`, locates its
/// maximum at step 6 and its minimum at step 24).
pub const PROBE_STEPS: usize = 200;

/// `branch = "follow-stable"`: the branch-switching step leaves the bifurcation point along the
/// critical mode by this fraction of the arc length of the step that crossed it (an RMS nodal
/// displacement of the same order as the path's own steps, so that the corrector lands on the
/// new branch rather than falling back onto the old one).
pub const BRANCH_SWITCH_FRACTION: f64 = 0.5;

/// A located critical point waiting for the step that follows it.
pub(crate) struct PendingCritical {
    pub(crate) record: CriticalRecord,
    pub(crate) state: State,
    pub(crate) mode: Option<Vec<[f64; 3]>>,
}

/// The record of a located critical point (its mid-span values, the closed form's limit point
/// of the same kind, and for a bifurcation the critical mode), queued in `pending`. A stage
/// whose path has its own pressure maximum (`own_max`, [`super::StageKind::limit_reference`])
/// compares its maxima with that, and nothing else with the free inflation's `limits`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn critical_record(
    model: &mut Model,
    c: &Critical<State>,
    load: &Load,
    stage: usize,
    limits: Option<&tubemem_gps::limits::Limits>,
    own_max: Option<&CriticalReference>,
    polygon: Option<f64>,
    last_limit: &std::cell::Cell<Option<f64>>,
    pending: &mut Vec<PendingCritical>,
) -> std::result::Result<(), tubemem_fem::FemError> {
    let ms = midspan(model, &c.state)?;
    let limits = limits.filter(|_| own_max.is_none());
    let own = own_max
        .filter(|_| c.kind == CriticalKind::LimitMax)
        .cloned();
    let reference = own.or_else(|| {
        limits.and_then(|l| match c.kind {
            // a mid-span past the uniform curve's minimum (λs beyond it) is in the upper phase of a
            // bulge, whose pressure is Maxwell's (a uniform tube cannot be there at a limit point)
            CriticalKind::Bifurcation | CriticalKind::Neutral => None,
            _ if l.min.is_some_and(|mn| ms.lambda_s > mn.lambda_s) && l.maxwell.is_some() => {
                l.maxwell.map(|mw| CriticalReference {
                    what: "Maxwell pressure".into(),
                    w: mw.w,
                    lambda_s: mw.lambda_s_upper,
                })
            }
            CriticalKind::LimitMax => l.max.map(|m| CriticalReference {
                what: "GPS limit point (maximum)".into(),
                w: m.w,
                lambda_s: m.lambda_s,
            }),
            CriticalKind::LimitMin => l.min.map(|m| CriticalReference {
                what: "GPS limit point (minimum)".into(),
                w: m.w,
                lambda_s: m.lambda_s,
            }),
        })
    });
    let (mode, mode_eigenvalue) =
        if matches!(c.kind, CriticalKind::Bifurcation | CriticalKind::Neutral) {
            let (v, mu) =
                model.smallest_mode(&c.state, load, tubemem_fem::continuation::MODE_ITERATIONS)?;
            let mut x = vec![[0.0; 3]; c.state.x.len()];
            model.free_update(&mut x, &v, 1.0);
            (Some(x), Some(mu))
        } else {
            (None, None)
        };
    let record = CriticalRecord {
        stage,
        step: c.step,
        kind: c.kind,
        arc_length: c.s,
        bracket: c.bracket,
        midspan: ms,
        negative_pivots_before: c.negative_before,
        negative_pivots_after: c.negative_after,
        w_error_over_polygon: match (&reference, polygon) {
            (Some(g), Some(f)) => Some(ms.w / (g.w * f) - 1.0),
            _ => None,
        },
        reference,
        polygon_factor: polygon,
        mode_eigenvalue,
        ripple: matches!(c.kind, CriticalKind::LimitMax | CriticalKind::LimitMin)
            && last_limit
                .replace(Some(ms.w))
                .is_some_and(|w0| (ms.w - w0).abs() <= RIPPLE * w0.abs()),
        mode_vtu: mode
            .as_ref()
            .map(|_| format!("vtu/critical_stage{stage}_step{}.vtu", c.step)),
        mode_png: mode
            .as_ref()
            .map(|_| format!("critical_stage{stage}_step{}_mode.png", c.step)),
    };
    pending.push(PendingCritical {
        record,
        state: c.state.clone(),
        mode,
    });
    Ok(())
}
