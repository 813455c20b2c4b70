//! The FE run of a case: plan → mesh → model → stepping → [`RunReport`], with observers called
//! at every converged step (writers, progress displays, interrupt checks).

use crate::case::{Case, PenaltySpec, StagePlan, Target};
use crate::checkpoint::{checkpoint_edges, Checkpoint, StageContext};
use crate::model_setup::{check_memory, equations_estimate, sideways_planes};
use crate::observer::{BoxError, Observer, StepView};
use crate::report::*;
use crate::{AppError, Result};
use tubemem_fem::contact::{penalty_for, Contact, Enforcement, MovingPlanes};
use tubemem_fem::continuation::{run_arc_stage, ArcLoading, Critical, CriticalKind};
use tubemem_fem::model::{nearest_node, Load, Loading, Model, State};
use tubemem_fem::post::{cell_values, midspan, midspan_contact, ring_profile, Regime};
use tubemem_fem::stepping::{run_stage_refitted, Stage, StageError, StepInfo, StepSettings};
use tubemem_fem::NewtonSettings;
use tubemem_gps::{flatten, inflate, section_at_pressure, Hypothesis};
use tubemem_material::MembraneLaw;

/// The largest penetration of the plates, as a fraction of the plate half-gap ρ, that a squeeze
/// step accepts: 5 %. Beyond it the contact is not resolved (the shipped squeezes penetrate
/// 0.2 % of ρ at the default tolerance), and the results would be the penalty's, not the
/// membrane's.
pub const MAX_PENETRATION_FRACTION: f64 = 0.05;

/// After a pressure-controlled stage failed below its target: follow the path by arc length from
/// the last converged `state` towards `target` and return the first pressure maximum located on
/// the way (ϖmax and the mid-span λs there), or `None` when the path reaches the target or the
/// probe fails (the Newton failure is then the whole story). The model's state is not changed.
///
/// The probe looks where the closed form puts the maximum: it aims at no more than twice the
/// GPS inflation maximum of `law` (a finite tube's maximum lies within a few per cent of it),
/// and a law whose GPS inflation has no maximum is not probed. It takes at most
/// [`PROBE_STEPS`] steps. (Aimed at a target of 1e308 it had walked for over ten minutes.)
fn pressure_maximum_below(
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
struct PendingCritical {
    record: CriticalRecord,
    state: State,
    mode: Option<Vec<[f64; 3]>>,
}

/// The record of a located critical point (its mid-span values, the closed form's limit point
/// of the same kind, and for a bifurcation the critical mode), queued in `pending`.
#[allow(clippy::too_many_arguments)]
fn critical_record(
    model: &mut Model,
    c: &Critical<State>,
    load: &Load,
    stage: usize,
    limits: Option<&tubemem_gps::limits::Limits>,
    polygon: Option<f64>,
    last_limit: &std::cell::Cell<Option<f64>>,
    pending: &mut Vec<PendingCritical>,
) -> std::result::Result<(), tubemem_fem::FemError> {
    let ms = midspan(model, &c.state)?;
    let reference = limits.and_then(|l| match c.kind {
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

/// The closed form at one step (see [`StepClosedForm`]).
fn step_closed_form(
    law: &dyn MembraneLaw,
    ms: &tubemem_fem::post::MidSpan,
    squeeze: Option<(&tubemem_fem::post::ContactValues, f64)>,
) -> StepClosedForm {
    match squeeze {
        None => StepClosedForm {
            gps_inflation: inflate(law, Hypothesis::Gps, ms.lambda_s).ok(),
            gps_flattening: None,
            local: None,
            gps_confine: None,
            local_confine: None,
        },
        Some((c, ls0)) => {
            let g = flatten(law, Hypothesis::Gps, ls0, c.rho).ok();
            let local = g.map(|g| {
                section_at_pressure(law, c.rho, ms.w, [g.lambda_s, g.lambda_z])
                    .map_err(|e| e.to_string())
            });
            StepClosedForm {
                gps_inflation: None,
                gps_flattening: g,
                local,
                gps_confine: None,
                local_confine: None,
            }
        }
    }
}

/// Distance (in R) from the cap junction (or plug) at which λs comes within `tol` of its
/// mid-span value and stays there all the way to mid-span; `None` if it never does.
pub fn boundary_layer(
    rings: &[tubemem_fem::post::RingValues],
    half_length: f64,
    mid: f64,
    tol: f64,
) -> Option<f64> {
    let mut side: Vec<_> = rings.iter().filter(|r| r.z_ref >= -1e-12).collect();
    side.sort_by(|a, b| b.z_ref.total_cmp(&a.z_ref)); // from the junction inwards
    let within =
        |r: &&tubemem_fem::post::RingValues| ((r.values.lambda_s - mid) / mid).abs() <= tol;
    let first_inside = side.iter().position(within)?;
    if side[first_inside..].iter().all(within) {
        Some(half_length - side[first_inside].z_ref)
    } else {
        None
    }
}

/// Where the membrane is wrinkled or slack at the end of a stage.
fn wrinkle_report(model: &Model, state: &State, stage: usize) -> Result<Wrinkling> {
    let cells = cell_values(model, state).map_err(|source| AppError::Post { stage, source })?;
    let mesh = model.mesh();
    let extent = |regime: Regime| {
        let zs: Vec<f64> = cells
            .iter()
            .zip(&mesh.quads)
            .filter(|(c, _)| c.regime() == regime)
            .map(|(_, q)| q.iter().map(|&i| mesh.nodes[i][2]).sum::<f64>() / 4.0)
            .collect();
        let (lo, hi) = zs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &z| {
                (a.min(z), b.max(z))
            });
        RegimeExtent {
            elements: zs.len(),
            z_ref_min: (!zs.is_empty()).then_some(lo),
            z_ref_max: (!zs.is_empty()).then_some(hi),
        }
    };
    Ok(Wrinkling {
        wrinkled: extent(Regime::Wrinkled),
        slack: extent(Regime::Slack),
    })
}

/// The closed-form comparison of a stage's final state: GPS and PS, and for a squeeze the
/// section at the FE's pressure. GPS and the section are the last step's (solved once, for its
/// steps.csv row); only PS is solved here.
#[allow(clippy::type_complexity)]
fn stage_closed_form(
    law: &dyn MembraneLaw,
    ms: &tubemem_fem::post::MidSpan,
    contact: Option<&ContactRecord>,
    last: Option<&StepClosedForm>,
) -> Result<(
    [(ClosedFormState, RelativeErrors); 2],
    Option<LocalSection>,
    Option<RelativeErrors>,
)> {
    let local = last.and_then(|l| l.local.as_ref());
    let one = |hyp: Hypothesis| -> Result<(ClosedFormState, RelativeErrors)> {
        Ok(match contact {
            None => {
                let known = last
                    .and_then(|l| l.gps_inflation)
                    .filter(|_| hyp == Hypothesis::Gps);
                let s = match known {
                    Some(s) => s,
                    None => inflate(law, hyp, ms.lambda_s).map_err(|e| {
                        AppError::gps(format!("{} inflation at the FE's λs", hyp.label()), e)
                    })?,
                };
                (
                    ClosedFormState::Inflation(s),
                    RelativeErrors {
                        w: Some(rel(ms.w, s.w)),
                        lambda_z: Some(rel(ms.lambda_z, s.lambda_z)),
                        n_s: Some(rel(ms.n_s, s.n_s)),
                        n_z: Some(rel(ms.n_z, s.n_z)),
                        ..Default::default()
                    },
                )
            }
            Some(c) => {
                let known = last
                    .and_then(|l| l.gps_flattening)
                    .filter(|_| hyp == Hypothesis::Gps);
                let s = match known {
                    Some(s) => s,
                    None => flatten(law, hyp, c.initial_stretch, c.values.rho).map_err(|e| {
                        AppError::gps(format!("{} flattening at the FE's ρ", hyp.label()), e)
                    })?,
                };
                (
                    ClosedFormState::Flattening(s),
                    RelativeErrors {
                        w: Some(rel(ms.w, s.w)),
                        lambda_s: Some(rel(ms.lambda_s, s.lambda_s)),
                        lambda_z: Some(rel(ms.lambda_z, s.lambda_z)),
                        chi: Some(rel(c.values.chi, s.chi)),
                        force: Some(rel(c.values.force, s.force)),
                        ..Default::default()
                    },
                )
            }
        })
    };
    let both = [one(Hypothesis::Gps)?, one(Hypothesis::Ps)?];
    let (section, errors) = match (contact, local) {
        (Some(c), Some(Ok(l))) => (
            Some(LocalSection::Solved(*l)),
            Some(RelativeErrors {
                w: None,
                lambda_s: Some(rel(ms.lambda_s, l.lambda_s)),
                lambda_z: Some(rel(ms.lambda_z, l.lambda_z)),
                chi: Some(rel(c.values.chi, l.chi)),
                force: Some(rel(c.values.force, l.force)),
                ..Default::default()
            }),
        ),
        (Some(_), Some(Err(e))) => (Some(LocalSection::Failed { error: e.clone() }), None),
        _ => (None, None),
    };
    Ok((both, section, errors))
}

/// How a run is driven from outside.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// continue from this checkpoint (its case hash must be the case's)
    pub resume: Option<Checkpoint>,
    /// skip the memory guard (a model estimated larger than the available memory is tried)
    pub force: bool,
    /// once set (by a signal handler, or Python's Ctrl-C), the run stops at the next Newton
    /// iteration with [`AppError::Interrupted`], keeping every converged step
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// Set up a stage at its start: the pre-stress from a stress-free state, the load parameter's
/// range, and for a squeeze the gas constant and the penalty. A precondition that fails is
/// recorded in the report.
#[allow(clippy::too_many_arguments)]
fn setup_stage(
    plan: &StagePlan,
    planes: &[crate::case::PlaneSpec],
    stages: usize,
    model: &mut Model,
    state: &mut State,
    report: &mut RunReport,
    closed_form_law: &dyn MembraneLaw,
    limits: Option<&tubemem_gps::limits::Limits>,
    node: usize,
    v0: f64,
) -> Result<StageContext> {
    let i = plan.index;
    // the squeeze this stage continues, if the previous stage was one
    let previous_squeeze: Option<FinalContact> = match report.stages.last().map(|s| &s.outcome) {
        Some(StageOutcome::Finished(s)) => s.final_state.contact,
        _ => None,
    };
    // a target the closed form has no state for: say so before the run meets it
    let beyond = match plan.target {
        Target::Stretch(s) => inflate(closed_form_law, Hypothesis::Gps, s).err(),
        Target::Pressure(p) if p > 0.0 && !plan.arc_length => limits
            .and_then(|l| l.max)
        .filter(|mx| p > mx.w)
        .map(|_| {
            tubemem_gps::GpsError::InvalidInput {
                name: "target_pressure",
                value: p,
                requirement: "above the pressure maximum of the GPS inflation curve: under pressure control there is no uniform equilibrium there (use volume control)",
            }
        }),
        _ => None,
    };
    // a mid-span stretch on the falling branch of the GPS curve: no stable uniform tube there
    if let Target::Stretch(s) = plan.target {
        if let Some(l) = limits {
            if let Some(mx) = l.max.filter(|mx| s > mx.lambda_s) {
                if l.min.is_none_or(|mn| s < mn.lambda_s) {
                    report.warnings.push(format!(
                        "stage {i}: the target λs* = {s} lies past the GPS pressure maximum (ϖ = {:.6} at λs = {:.4}), on the falling branch where a uniform tube is unstable: expect a bulge; the comparison with GPS is marked not applicable wherever the tube is not uniform",
                        mx.w, mx.lambda_s
                    ));
                }
            }
        }
    }
    if let Some(e) = beyond {
        report.warnings.push(format!(
            "stage {i}: the target lies outside the closed form's validity ({}); the run will stop where the law allows no further equilibrium",
            crate::error_chain(&e)
        ));
    }
    // A stage from the stress-free state first takes a small pressure step (the pre-stress,
    // ϖ = 0.01, `StepSettings::prestress`): a stress-free membrane has no stiffness against
    // its inextensional modes. When the target's own pressure (GPS, eq. 66) is not well
    // above that, the pre-stress is half of it, so that the stage runs from the
    // pre-stressed state up to the target; a pressure target below it is approached from
    // above, and a first step that would undo the pre-stress starts from it instead.
    let settings = StepSettings {
        initial_steps: plan.steps,
        ..StepSettings::default()
    };
    let mut prestressed_from: Option<f64> = None;
    // the controlled value before any pre-stress: where the stage's steps are measured from
    let from_before = match plan.target {
        Target::Stretch(_) => Some(state.x[node][0]),
        Target::VolumeRatio(_) => Some(model.total_volume(&state.x)),
        _ => None,
    };
    let closed_gas = matches!(plan.target, Target::Rho(_) | Target::Confine(_));
    if state.p == 0.0 && !closed_gas {
        let estimate = match plan.target {
            Target::Pressure(p) => Some(p),
            Target::Stretch(s) => inflate(closed_form_law, Hypothesis::Gps, s)
                .ok()
                .map(|g| g.w),
            Target::VolumeRatio(r) => inflate(closed_form_law, Hypothesis::Gps, r.cbrt())
                .ok()
                .map(|g| g.w),
            Target::Rho(_) | Target::Confine(_) => None,
        };
        let mut pre = settings;
        // an arc-length stage always starts pre-stressed: its first tangent needs the
        // geometric stiffness
        let target_pressure = matches!(plan.target, Target::Pressure(_)) && !plan.arc_length;
        if let Some(w) = estimate.filter(|w| *w > 0.0 && 0.5 * w < settings.prestress) {
            if !target_pressure {
                pre.prestress = 0.5 * w;
                pre.min_prestress = pre.min_prestress.min(0.5 * pre.prestress);
            }
        } else if target_pressure {
            pre.prestress = 0.0; // a pressure stage from zero needs none
        }
        if pre.prestress > 0.0 && estimate.is_some_and(|w| w > 0.0) {
            let stage = Stage {
                index: i,
                from: 0.0,
                to: 1.0,
                settings: pre,
            };
            tubemem_fem::stepping::prestress::<BoxError>(model, state, &stage).map_err(
                |e| match e {
                    StageError::Solve(tubemem_fem::FemError::Interrupted) => {
                        AppError::Interrupted { stage: i, steps: 0 }
                    }
                    StageError::Solve(source) => AppError::Stage {
                        stage: i,
                        stages,
                        unstable: None,
                        source,
                    },
                    StageError::Observer { step, source, .. } => AppError::Observer {
                        stage: i,
                        step,
                        source,
                    },
                },
            )?;
            let now = match plan.target {
                Target::Stretch(_) => state.x[node][0],
                Target::VolumeRatio(_) => model.total_volume(&state.x),
                _ => state.p,
            };
            let first = match (plan.target, from_before) {
                (Target::Stretch(s), Some(f0)) => f0 + (s - f0) / plan.steps as f64,
                (Target::VolumeRatio(r), Some(f0)) => f0 + (r * v0 - f0) / plan.steps as f64,
                _ => f64::INFINITY,
            };
            if target_pressure || now >= first {
                prestressed_from = Some(now);
            }
        }
    }
    // for a squeeze: the inflated mid-span stretch λs* and the gas constant at its start
    let start = midspan(model, state).map_err(|source| AppError::Post { stage: i, source })?;
    let pv = state.p * model.multiplicity() * model.mesh().volume_at(&state.x);
    let fail_input = |report: &mut RunReport, message: String| {
        report.stages.push(StageReport {
            plan: *plan,
            steps: vec![],
            outcome: StageOutcome::Failed(StageFailure {
                index: i,
                error: format!("[[stage]] {i}: {message}"),
                last_converged: None,
                critical_points: vec![],
            }),
            profile: vec![],
        });
        AppError::StageInput { stage: i, message }
    };
    let (mut from, to, penalty): (f64, f64, f64) = match plan.target {
        Target::Pressure(p) => (state.p, p, 0.0),
        Target::Stretch(s) => (state.x[node][0], s, 0.0),
        Target::VolumeRatio(r) => (
            model.multiplicity() * model.mesh().volume_at(&state.x),
            r * v0,
            0.0,
        ),
        Target::Rho(rho) => {
            if state.p.is_nan() || state.p <= 0.0 {
                return Err(fail_input(
                    report,
                    format!(
                        "the tube holds no gas pressure to squeeze (ϖ = {})",
                        state.p
                    ),
                ));
            }
            let h0 = state.x.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
            if rho >= h0 {
                return Err(fail_input(report, format!("`target_rho` = {rho} must be below the current half-height {h0:.6} of the tube")));
            }
            let penalty = match (plan.penalty, previous_squeeze) {
                (Some(PenaltySpec::Value(k)), _) => k,
                // a squeeze that continues a squeeze keeps its plates' penalty
                (_, Some(prev)) => prev.penalty,
                (Some(PenaltySpec::Tolerance(t)), None) => {
                    penalty_for(state.p, start.lambda_s * start.lambda_z, t)
                }
                (None, None) => penalty_for(
                    state.p,
                    start.lambda_s * start.lambda_z,
                    crate::case::DEFAULT_PENETRATION_TOLERANCE,
                ),
            };
            (h0, rho, penalty)
        }
        Target::Confine(_) => {
            if state.p.is_nan() || state.p <= 0.0 {
                return Err(fail_input(
                    report,
                    format!(
                        "the tube holds no gas pressure to confine (ϖ = {})",
                        state.p
                    ),
                ));
            }
            // no plane may start inside the tube
            for (k, p) in planes.iter().enumerate() {
                let len = p.normal[0].hypot(p.normal[1]);
                let reach = state
                    .x
                    .iter()
                    .map(|x| (p.normal[0] * x[0] + p.normal[1] * x[1]) / len)
                    .fold(f64::NEG_INFINITY, f64::max);
                if reach > p.offset / len {
                    return Err(fail_input(report, format!(
                        "plane {}: `offset` = {} cuts the tube, which reaches n·x = {reach:.6} along its normal: start it further out",
                        k + 1,
                        p.offset
                    )));
                }
            }
            // the planes must have the model's symmetry
            let sym = model.mesh().symmetry.planes();
            for (axis, name) in [(0usize, "x = 0"), (1usize, "y = 0")] {
                if !sym.contains(&axis) {
                    continue;
                }
                for (k, p) in planes.iter().enumerate() {
                    if !p.mirrored_in(planes, axis) {
                        return Err(fail_input(report, format!(
                            "plane {} has no mirror image across {name}, a symmetry plane of the model (symmetry = {:?}): give its mirror plane too, or use a model without that symmetry",
                            k + 1,
                            model.mesh().symmetry
                        )));
                    }
                }
            }
            let penalty = match plan.penalty {
                Some(PenaltySpec::Value(k)) => k,
                Some(PenaltySpec::Tolerance(t)) => {
                    penalty_for(state.p, start.lambda_s * start.lambda_z, t)
                }
                None => penalty_for(
                    state.p,
                    start.lambda_s * start.lambda_z,
                    crate::case::DEFAULT_PENETRATION_TOLERANCE,
                ),
            };
            (0.0, 1.0, penalty)
        }
    };
    match (prestressed_from, from_before) {
        (Some(f), _) | (None, Some(f)) => from = f,
        _ => {}
    }
    Ok(StageContext {
        stage: i,
        from,
        to,
        pv: if closed_gas { pv } else { 0.0 },
        penalty,
        // a squeeze that continues a squeeze compares with the flattening from the same λs*
        start_lambda_s: previous_squeeze.map_or(start.lambda_s, |c| c.initial_stretch),
    })
}

/// The planes of a confine stage as functions of its load parameter t (for arc length):
/// [`fe_planes`] at t, the offsets linear in t.
pub fn fe_moving_planes(planes: &[crate::case::PlaneSpec], penalty: f64) -> MovingPlanes {
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
pub fn fe_planes(planes: &[crate::case::PlaneSpec], t: f64, penalty: f64) -> Contact {
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

/// Build the mesh a case asks for.
pub fn build_mesh(case: &Case) -> Result<tubemem_mesh::Mesh> {
    build_mesh_with_fit(case, None).map(|(m, _)| m)
}

/// [`build_mesh`], with where its node line was fitted to the contact edge (`[mesh]
/// fit_contact_edge`, [`crate::edge_fit`]: a locating run of the case on a coarse mesh, which
/// `interrupt` stops as it stops the run, [`RunOptions::interrupt`]).
pub fn build_mesh_with_fit(
    case: &Case,
    interrupt: Option<&std::sync::Arc<std::sync::atomic::AtomicBool>>,
) -> Result<(tubemem_mesh::Mesh, Option<ContactEdgeFit>)> {
    let options = RunOptions {
        interrupt: interrupt.cloned(),
        ..Default::default()
    };
    crate::model_setup::mesh_of(case, &mut |coarse| {
        run_with(coarse, "contact-edge locator", &options, &mut [])
    })
}

/// Run a validated case; `label` names it in the report. Observers see every converged step as
/// it comes. The outcome always carries the report (every converged step) and, if the run
/// failed, the error, which every observer has also been told of.
pub fn run(case: &Case, label: &str, observers: &mut [&mut dyn Observer]) -> RunOutcome {
    run_with(case, label, &RunOptions::default(), observers)
}

/// [`run`] with options.
pub fn run_with(
    case: &Case,
    label: &str,
    options: &RunOptions,
    observers: &mut [&mut dyn Observer],
) -> RunOutcome {
    let mut report = None;
    let error = run_inner(case, label, options, observers, &mut report).err();
    let report = report.unwrap_or_else(|| RunReport {
        case: label.to_string(),
        mesh: MeshInfo {
            nodes: 0,
            elements: 0,
            equations: 0,
            symmetry: String::new(),
            element: String::new(),
            factor_nnz: 0,
            factor_flops: 0.0,
            contact_edge_fit: None,
        },
        material: String::new(),
        material_spec: case.material,
        geometry: GeometryInfo {
            radius: case.geometry.radius,
            length: case.geometry.length,
            thickness: case.geometry.thickness,
            caps: String::new(),
        },
        units: UNITS.into(),
        case_hash: case.hash().to_string(),
        scales: case.scales(),
        stages: vec![],
        warnings: vec![],
    });
    if let Some(e) = &error {
        for o in observers.iter_mut() {
            o.failed(&report, e);
        }
    }
    RunOutcome { report, error }
}

fn run_inner(
    case: &Case,
    label: &str,
    options: &RunOptions,
    observers: &mut [&mut dyn Observer],
    slot: &mut Option<RunReport>,
) -> Result<()> {
    let g = &case.geometry;
    let half = 0.5 * g.length / g.radius;
    // the memory guard, before anything large is built
    if let Some(n) = equations_estimate(case) {
        check_memory(n, options.force)?;
    }
    let (mesh, contact_edge_fit) = build_mesh_with_fit(case, options.interrupt.as_ref())?;
    if case.mesh.file.is_some() {
        check_memory(3 * mesh.nodes.len(), options.force)?;
    }
    let symmetry = mesh.symmetry;
    let law = case.material.build_with(case.solver.wrinkling)?;
    let closed_form_law = case.material.build()?;
    // the closed form's limit points, for the warnings, the critical points' references and the
    // stage-end notes (one scan per run)
    let gps_limits =
        tubemem_gps::limits::limit_points(closed_form_law.as_ref(), Hypothesis::Gps).ok();
    let mut model = Model::new(mesh, law).map_err(AppError::Model)?;
    // planes that move the tube sideways: the rigid-mode pins on the axis would hold the caps'
    // poles against them, so springs hold those modes instead
    let soft = sideways_planes(case);
    if soft.iter().any(|s| *s) {
        model
            .soften_rigid_pins(soft, tubemem_fem::dofs::SOFT_PIN_STIFFNESS)
            .map_err(AppError::Model)?;
    }
    model.set_interrupt(options.interrupt.clone());
    model.set_settings(NewtonSettings {
        rtol: case.solver.rtol,
        max_iterations: case.solver.max_iterations,
        ..NewtonSettings::default()
    });
    model.set_factor_threads(case.solver.factor_threads);
    model.set_iteration_log(case.output.iterations);
    let mut state = model.reference_state();
    // `[mesh] track_contact_edge`: the tube the tracker refits, and the edges it is fitted to
    let tracking = case.mesh.track_contact_edge;
    let tube = match (tracking, case.mesh.around, case.mesh.along) {
        (true, Some(around), Some(along)) => Some(crate::edge_track::TubeSpec {
            kind: case.mesh.element,
            length: g.length / g.radius,
            around,
            along,
            cap_rows: case.mesh.cap_rows.unwrap_or(around / 8),
            symmetry: case.mesh.symmetry,
        }),
        _ => None,
    };
    let tracked_edges: crate::edge_track::Edges = Default::default();
    let v0 = model.multiplicity() * model.mesh().volume();
    let node = nearest_node(model.mesh(), [1.0, 0.0, 0.0]);
    let report = slot.insert(RunReport {
        case: label.to_string(),
        mesh: MeshInfo {
            nodes: model.mesh().nodes.len(),
            elements: model.mesh().quads.len(),
            equations: model.n_eq(),
            symmetry: format!("{symmetry:?}").to_lowercase(),
            element: model.mesh().element().name().into(),
            factor_nnz: model.factor_nnz(),
            factor_flops: model.factor_flops(),
            contact_edge_fit,
        },
        material: model.law().name(),
        material_spec: case.material,
        geometry: GeometryInfo {
            radius: g.radius,
            length: g.length,
            thickness: g.thickness,
            caps: format!("{:?}", g.caps).to_lowercase(),
        },
        units: UNITS.into(),
        case_hash: case.hash().to_string(),
        scales: case.scales(),
        stages: vec![],
        warnings: vec![],
    });
    if let Some(ck) = &options.resume {
        if let Some(message) = ck.mismatch(case.hash(), Some(state.x.len())) {
            return Err(AppError::Folder {
                path: std::path::PathBuf::from(label),
                message,
            });
        }
        *report = ck.report.clone();
        state.x.clone_from(&ck.x);
        state.p = ck.p;
        state.multipliers.clone_from(&ck.multipliers);
        // a tracked mesh: fitted where the checkpoint's step had it
        if let (Some(tube), Some(edges)) = (tube, checkpoint_edges(ck)) {
            let nodes = tube.nodes(&edges).map_err(AppError::Mesh)?;
            let n = nodes.len();
            model
                .move_reference(
                    nodes,
                    &tubemem_mesh::hoop::Transfer::identity(n),
                    None,
                    &mut [],
                )
                .map_err(AppError::Model)?;
            *tracked_edges.borrow_mut() = edges;
        }
    }
    for o in observers.iter_mut() {
        o.started(report, &model, &state)
            .map_err(|source| AppError::Observer {
                stage: 0,
                step: 0,
                source,
            })?;
    }
    let stages = case.plan().len();
    for plan in case.plan() {
        let i = plan.index;
        let resume_here = options.resume.as_ref().filter(|c| c.context.stage == i);
        if options.resume.as_ref().is_some_and(|c| i < c.context.stage) {
            continue; // finished before the restart: in the restored report
        }
        for o in observers.iter_mut() {
            o.stage_started(plan, stages);
        }
        let (context, progress, restored, restored_critical) = match resume_here {
            Some(ck) => (
                ck.context,
                Some((
                    ck.progress,
                    ck.previous.as_ref().map(|(x, p)| State {
                        x: x.clone(),
                        p: *p,
                        planes: 0.0,
                        multipliers: Vec::new(),
                    }),
                )),
                ck.steps.clone(),
                ck.critical_points.clone(),
            ),
            None => {
                let ctx = setup_stage(
                    plan,
                    &case.stages[i - 1].plane,
                    stages,
                    &mut model,
                    &mut state,
                    report,
                    closed_form_law.as_ref(),
                    gps_limits.as_ref(),
                    node,
                    v0,
                )?;
                (ctx, None, vec![], vec![])
            }
        };
        let settings = StepSettings {
            initial_steps: plan.steps,
            ..StepSettings::default()
        };
        let start_lambda_s = context.start_lambda_s;
        let (pv, penalty) = (context.pv, context.penalty);
        let enforcement = plan.enforcement.unwrap_or(Enforcement::Penalty);
        let points = plan.contact_points;
        let load: Box<dyn Fn(f64) -> Load> = match plan.target {
            Target::Pressure(_) => Box::new(Load::pressure),
            Target::Stretch(_) => Box::new(move |v| {
                Load::new(Loading::Node {
                    node,
                    component: 0,
                    target: v,
                })
            }),
            Target::VolumeRatio(_) => Box::new(|v| Load::new(Loading::Volume(v))),
            Target::Rho(_) => Box::new(move |h| {
                Load::with_contact(
                    Loading::Gas { pv },
                    Contact::plates(h, penalty)
                        .with_enforcement(enforcement)
                        .with_points(points),
                )
            }),
            Target::Confine(_) => {
                let planes = case.stages[i - 1].plane.clone();
                Box::new(move |t| {
                    Load::with_contact(
                        Loading::Gas { pv },
                        fe_planes(&planes, t, penalty)
                            .with_enforcement(enforcement)
                            .with_points(points),
                    )
                })
            }
        };
        let stage = Stage {
            index: i,
            from: context.from,
            to: context.to,
            settings,
        };
        let mut steps: Vec<StepRecord> = restored;
        let every_profile = case.output.profiles == crate::case::ProfileFrames::Every;
        let confine_planes =
            matches!(plan.target, Target::Confine(_)).then(|| case.stages[i - 1].plane.clone());
        let finished: &RunReport = report;
        // critical points located by an arc-length stage, reported to the observers with the
        // step that follows them on the path
        let pending: std::cell::RefCell<Vec<PendingCritical>> = Default::default();
        // a squeeze or confine stage compares with a closed form that starts from a uniform
        // tube: not applicable after a stage that ended with a tube that was not uniform
        let started_uniform: Option<usize> = match plan.target {
            Target::Rho(_) | Target::Confine(_) => {
                report.stages.last().and_then(|s| match &s.outcome {
                    StageOutcome::Finished(f) if !f.gps_applicable => Some(f.index),
                    _ => None,
                })
            }
            _ => None,
        };
        // a resumed arc-length stage goes on in the direction its last two steps went (in ϖ,
        // or in the planes' parameter with the gas closed)
        let closed_gas = matches!(plan.target, Target::Rho(_) | Target::Confine(_));
        let direction = match steps.as_slice() {
            [.., a, b] if closed_gas && b.load < a.load => -1.0,
            [.., a, b] if !closed_gas && b.midspan.w < a.midspan.w => -1.0,
            _ => 1.0,
        };
        let mut criticals: Vec<CriticalRecord> = restored_critical;
        // a closed-gas arc-length stage: the planes where the stage starts, or where its last
        // converged step left them
        let planes_start = steps.last().map_or(context.from, |r| r.load);
        // the last limit point before a restart, for the ripple test of the next one
        let last_limit_w0 = criticals
            .iter()
            .rev()
            .find(|c| matches!(c.kind, CriticalKind::LimitMax | CriticalKind::LimitMin))
            .map(|c| c.midspan.w);
        let mut on_step = |m: &Model, st: &State, info: &StepInfo| {
            let mut critical_here = None;
            for p in pending.borrow_mut().drain(..) {
                for o in observers.iter_mut() {
                    o.critical(&p.record, m, &p.state, p.mode.as_deref())?;
                }
                critical_here = Some(p.record.kind);
                criticals.push(p.record);
            }
            {
                let ms = midspan(m, st).map_err(|e| Box::new(e) as BoxError)?;
                let plates = if confine_planes.is_some() {
                    None
                } else {
                    info.load.contact.as_ref()
                };
                let contact = plates.and_then(|c| {
                    midspan_contact(m, st, c).map(|values| ContactRecord {
                        values,
                        displacement: start_lambda_s - values.rho,
                        initial_stretch: start_lambda_s,
                        penalty: c.penalty,
                    })
                });

                let mut vals = vec![
                    ms.w,
                    ms.lambda_s,
                    ms.lambda_z,
                    ms.n_s,
                    ms.n_z,
                    ms.n_sz,
                    ms.volume,
                ];
                if let Some(c) = &contact {
                    let c = &c.values;
                    vals.extend([c.chi, c.force, c.contact_pressure, c.penetration]);
                }
                if let Some(c) = &contact {
                    let (pen, rho) = (c.values.penetration, c.values.rho);
                    if pen.is_nan() || pen > MAX_PENETRATION_FRACTION * rho {
                        return Err(Box::new(AppError::ContactUnresolved {
                            stage: i,
                            step: info.step,
                            penetration: pen,
                            rho,
                            penalty: c.penalty,
                        }) as BoxError);
                    }
                }
                if vals.iter().any(|v| !v.is_finite()) {
                    return Err(Box::new(AppError::NonFinite {
                        stage: i,
                        step: info.step,
                        values: vals,
                    }) as BoxError);
                }
                let mut closed_form = step_closed_form(
                    closed_form_law.as_ref(),
                    &ms,
                    contact.as_ref().map(|c| (&c.values, start_lambda_s)),
                );
                // a confine stage: each wall, and the closed form for the same walls
                let walls = match (&confine_planes, info.load.contact.as_ref()) {
                    (Some(planes), Some(c)) => {
                        let w = tubemem_fem::post::midspan_walls(m, st, c);
                        let d_min = planes
                            .iter()
                            .map(|p| {
                                (p.offset + info.value * (p.target - p.offset)).abs()
                                    / p.normal[0].hypot(p.normal[1])
                            })
                            .fold(f64::INFINITY, f64::min);
                        let pen = w.iter().map(|v| v.penetration).fold(0.0, f64::max);
                        if pen.is_nan() || pen > MAX_PENETRATION_FRACTION * d_min {
                            return Err(Box::new(AppError::ContactUnresolved {
                                stage: i,
                                step: info.step,
                                penetration: pen,
                                rho: d_min,
                                penalty: c.penalty,
                            }) as BoxError);
                        }
                        if let Ok(gw) = planes
                            .iter()
                            .map(|p| p.wall_at(info.value))
                            .collect::<Result<Vec<_>, _>>()
                        {
                            let law = closed_form_law.as_ref();
                            closed_form.gps_inflation = None;
                            closed_form.gps_confine = tubemem_gps::confine::confine(
                                law,
                                Hypothesis::Gps,
                                &gw,
                                start_lambda_s,
                            )
                            .ok();
                            closed_form.local_confine = tubemem_gps::confine::confine_at_pressure(
                                law,
                                Hypothesis::Gps,
                                &gw,
                                ms.w,
                            )
                            .ok();
                        }
                        w
                    }
                    _ => vec![],
                };
                let profile = if every_profile {
                    ring_profile(m, st, info.load.contact.as_ref())
                        .map_err(|e| Box::new(e) as BoxError)?
                } else {
                    vec![]
                };
                let step_nonuniformity = nonuniformity(&profile, half);
                let step_fronts = bulge_fronts(&profile);
                let record = StepRecord {
                    stage: i,
                    step: info.step,
                    load: info.value,
                    midspan: ms,
                    newton_iterations: info.newton.iterations,
                    negative_pivots: info.newton.inertia.negative_pivots,
                    residuals: info.newton.history.clone(),
                    contact,
                    walls,
                    closed_form,
                    profile,
                    arc: plan.arc_length.then_some(ArcValues {
                        arc_length: info.progress.lambda,
                        dw_ds: info.dw_ds,
                    }),
                    critical: critical_here,
                    nonuniformity: step_nonuniformity,
                    gps_applicable: step_nonuniformity
                        .map(|u| u <= NONUNIFORM && started_uniform.is_none()),
                    negative_pivots_volume: info.negative_conjugate,
                    fronts: step_fronts,
                    augmentation: matches!(plan.enforcement, Some(Enforcement::Augmented { .. }))
                        .then_some(info.newton.augmentation),
                    edge_tracking: (tracking && closed_gas).then(|| crate::report::EdgeTracking {
                        edges: tracked_edges.borrow().clone(),
                        refits: info.refits,
                    }),
                };
                steps.push(record);
                let view = StepView {
                    report: finished,
                    stage_steps: &steps,
                    stage_critical_points: &criticals,
                    context: &context,
                    progress: info.progress,
                    model: m,
                    state: st,
                    load: info.load,
                    plan,
                    stages,
                    record: steps.last().expect("just pushed"),
                    fraction: info.fraction,
                    previous: info.previous,
                };
                for o in observers.iter_mut() {
                    o.step(&view)?;
                }
                Ok::<(), BoxError>(())
            }
        };
        let result = if plan.arc_length {
            let mesh = model.mesh().clone();
            let mult = model.multiplicity();
            let monitor: Box<dyn Fn(&State) -> f64> = match plan.target {
                Target::Pressure(_) => Box::new(|s: &State| s.p),
                Target::Stretch(_) => Box::new(move |s: &State| s.x[node][0]),
                Target::VolumeRatio(_) => Box::new(move |s: &State| mult * mesh.volume_at(&s.x)),
                // closed gas: the planes' own parameter (the half-gap h, or t of a confine)
                Target::Rho(_) | Target::Confine(_) => Box::new(|s: &State| s.planes),
            };
            let loading = match plan.target {
                Target::Rho(_) => ArcLoading::ClosedGas {
                    pv,
                    planes: MovingPlanes::plates(penalty)
                        .with_enforcement(enforcement)
                        .with_points(points),
                },
                Target::Confine(_) => ArcLoading::ClosedGas {
                    pv,
                    planes: fe_moving_planes(&case.stages[i - 1].plane, penalty)
                        .with_enforcement(enforcement)
                        .with_points(points),
                },
                _ => ArcLoading::Pressure(None),
            };
            if let ArcLoading::ClosedGas { .. } = loading {
                state.planes = planes_start;
            }
            let limits = gps_limits.as_ref();
            let polygon = case.mesh.polygon_factor();
            let last_limit = std::cell::Cell::new(last_limit_w0);
            let found = run_arc_stage(
                &mut model,
                &mut state,
                &stage,
                progress.map(|(p, _)| p),
                loading.clone(),
                &*monitor,
                direction,
                plan.follow_stable.then_some(BRANCH_SWITCH_FRACTION),
                &mut on_step,
                |m: &mut Model, c: &Critical<State>| {
                    critical_record(
                        m,
                        c,
                        &loading.load_at(&c.state),
                        i,
                        limits,
                        polygon,
                        &last_limit,
                        &mut pending.borrow_mut(),
                    )
                    .map_err(|e| Box::new(e) as BoxError)
                },
            );
            found.map(|_| ())
        } else {
            let mut tracker = tube
                .filter(|_| closed_gas)
                .map(|tube| crate::edge_track::Tracker {
                    tube,
                    law: closed_form_law.as_ref(),
                    pressing: match &confine_planes {
                        Some(planes) => crate::edge_track::Pressing::Walls(planes.clone()),
                        None => crate::edge_track::Pressing::Plates,
                    },
                    edges: tracked_edges.clone(),
                });
            run_stage_refitted(
                &mut model,
                &mut state,
                &stage,
                progress,
                &load,
                &mut on_step,
                tracker
                    .as_mut()
                    .map(|t| t as &mut dyn tubemem_fem::stepping::Refit),
            )
        };
        if let Err(e) = result {
            let error = match e {
                StageError::Solve(tubemem_fem::FemError::Interrupted) => AppError::Interrupted {
                    stage: i,
                    steps: steps.len(),
                },
                StageError::Solve(source) => {
                    // the last converged state of the stage, or of the run before it
                    let last_negative = steps.last().map(|r| r.negative_pivots).or_else(|| {
                        report
                            .stages
                            .last()
                            .filter(|s| !s.plan.arc_length)
                            .and_then(|s| s.steps.last())
                            .map(|r| r.negative_pivots)
                    });
                    let unstable = last_negative.filter(|&n| n > 0 && !plan.arc_length);
                    match (plan.target, plan.arc_length) {
                        // a pressure target the path cannot reach: say where its maximum is
                        (Target::Pressure(target), false) if state.p < target => {
                            match pressure_maximum_below(
                                &mut model,
                                &state,
                                target,
                                closed_form_law.as_ref(),
                            ) {
                                Some((w_max, lambda_s)) => AppError::BeyondLimit {
                                    stage: i,
                                    stages,
                                    target,
                                    w_max,
                                    lambda_s,
                                    source: Box::new(source),
                                },
                                None => AppError::Stage {
                                    stage: i,
                                    stages,
                                    unstable,
                                    source,
                                },
                            }
                        }
                        _ => AppError::Stage {
                            stage: i,
                            stages,
                            unstable,
                            source,
                        },
                    }
                }
                StageError::Observer { step, source, .. } => match source.downcast::<AppError>() {
                    Ok(app) => *app,
                    Err(source) => AppError::Observer {
                        stage: i,
                        step,
                        source,
                    },
                },
            };
            let last_converged = steps.last().map(|s| s.midspan);
            report.stages.push(StageReport {
                plan: *plan,
                steps,
                outcome: StageOutcome::Failed(StageFailure {
                    index: i,
                    error: error.chain(),
                    last_converged,
                    critical_points: criticals,
                }),
                profile: vec![],
            });
            return Err(error);
        }
        let (ms, contact, its, neg, last_cf) = match steps.last() {
            Some(l) => (
                l.midspan,
                l.contact,
                l.newton_iterations,
                l.negative_pivots,
                Some(l.closed_form.clone()),
            ),
            None => (
                midspan(&model, &state).map_err(|source| AppError::Post { stage: i, source })?,
                None,
                0,
                0,
                None,
            ),
        };
        // the stage end's profile: the last step's, or computed for it (with its plates)
        let rings = match steps.last() {
            Some(l) if !l.profile.is_empty() => l.profile.clone(),
            _ => {
                let plates = contact.map(|c| {
                    Contact::plates(c.values.rho, c.penalty)
                        .with_enforcement(enforcement)
                        .with_points(points)
                });
                ring_profile(&model, &state, plates.as_ref())
                    .map_err(|source| AppError::Post { stage: i, source })?
            }
        };
        let layer = boundary_layer(&rings, half, ms.lambda_s, 1e-3);
        let stage_nonuniformity = nonuniformity(&rings, half);
        // an inflation past the closed form's pressure maximum: the uniform state is unstable
        let unstable_note = match plan.target {
            Target::Pressure(_) | Target::Stretch(_) | Target::VolumeRatio(_) => {
                gps_limits
                    .as_ref()
                    .and_then(|l| l.max)
                    .filter(|mx| ms.lambda_s > mx.lambda_s)
                    .map(|mx| format!(
                        "; the mid-span λs = {:.4} is past the GPS pressure maximum (ϖ = {:.6} at λs = {:.4}), where a uniform tube is unstable and a bulge forms",
                        ms.lambda_s, mx.w, mx.lambda_s
                    ))
                    .unwrap_or_default()
            }
            _ => String::new(),
        };
        let wrinkling = wrinkle_report(&model, &state, i)?;
        let ([(mut gps, mut gps_err), (mut ps, mut ps_err)], local_section, mut local_err) =
            stage_closed_form(
                closed_form_law.as_ref(),
                &ms,
                contact.as_ref(),
                last_cf.as_ref(),
            )?;
        // a confine stage: the closed form for the same walls, GPS and PS, and each wall
        let mut wall_summary = vec![];
        if let (Some(planes), Some(last)) = (&confine_planes, steps.last()) {
            let law = closed_form_law.as_ref();
            let walls = planes
                .iter()
                .map(|p| p.wall_at(last.load))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| AppError::gps("the confine stage's planes", e))?;
            let errors = |c: &tubemem_gps::confine::ConfineState| RelativeErrors {
                w: Some(rel(ms.w, c.w)),
                lambda_s: Some(rel(ms.lambda_s, c.lambda_s)),
                lambda_z: Some(rel(ms.lambda_z, c.lambda_z)),
                ..Default::default()
            };
            let g = match &last.closed_form.gps_confine {
                Some(g) => g.clone(),
                None => tubemem_gps::confine::confine(law, Hypothesis::Gps, &walls, start_lambda_s)
                    .map_err(|e| AppError::gps("GPS for the confine stage's walls", e))?,
            };
            let p = tubemem_gps::confine::confine(law, Hypothesis::Ps, &walls, start_lambda_s)
                .map_err(|e| AppError::gps("PS for the confine stage's walls", e))?;
            gps_err = errors(&g);
            ps_err = errors(&p);
            let local = last.closed_form.local_confine.clone();
            local_err = local.as_ref().map(|l| RelativeErrors {
                w: None,
                ..errors(l)
            });
            wall_summary = last
                .walls
                .iter()
                .enumerate()
                .map(|(k, fe)| {
                    let gk = g.walls.get(k).copied();
                    let lk = local.as_ref().and_then(|l| l.walls.get(k).copied());
                    let err = |c: Option<tubemem_gps::confine::WallContact>| {
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
            gps = ClosedFormState::Confine(Box::new(g));
            ps = ClosedFormState::Confine(Box::new(p));
        }
        let summary = StageSummary {
            index: i,
            kind: if confine_planes.is_some() {
                "confine".into()
            } else if contact.is_some() {
                "squeeze".into()
            } else {
                "inflate".into()
            },
            control: plan.control().map(String::from),
            target: plan.target,
            final_state: StageFinal {
                midspan: ms,
                newton_iterations: its,
                stage_steps: steps.len(),
                stage_newton_iterations: steps.iter().map(|s| s.newton_iterations).sum(),
                negative_pivots: neg,
                contact: contact.map(|c| FinalContact {
                    rho: c.values.rho,
                    chi: c.values.chi,
                    chi_geometric: c.values.chi_geometric,
                    force: c.values.force,
                    displacement: c.displacement,
                    contact_pressure: c.values.contact_pressure,
                    penetration: c.values.penetration,
                    total_plate_force: c.values.total_force,
                    penalty: c.penalty,
                    initial_stretch: c.initial_stretch,
                }),
            },
            cap_boundary_layer: layer,
            wrinkling,
            profile: format!("profiles/stage{i}_final.csv"),
            gps,
            ps,
            relative_error_vs_gps: gps_err,
            relative_error_vs_ps: ps_err,
            gps_at_fe_pressure: local_section,
            relative_error_vs_gps_at_fe_pressure: local_err,
            walls: wall_summary,
            planes: confine_planes.clone().unwrap_or_default(),
            critical_points: criticals,
            nonuniformity: stage_nonuniformity,
            gps_applicable: stage_nonuniformity.is_none_or(|u| u <= NONUNIFORM)
                && started_uniform.is_none(),
            gps_not_applicable: match (stage_nonuniformity.filter(|u| *u > NONUNIFORM), started_uniform) {
                (Some(u), _) => Some(format!(
                    "the tube is not uniform: λs varies by {:.1} % over the central half of the cylinder (more than {} %){}",
                    100.0 * u,
                    100.0 * NONUNIFORM,
                    unstable_note
                )),
                (None, Some(k)) => Some(format!(
                    "the stage starts from the end of stage {k}, where the tube was not uniform, and the closed form starts from a uniform tube"
                )),
                (None, None) => None,
            },
        };
        report.stages.push(StageReport {
            plan: *plan,
            steps,
            outcome: StageOutcome::Finished(Box::new(summary)),
            profile: rings,
        });
        for o in observers.iter_mut() {
            o.stage_finished(report)
                .map_err(|source| AppError::Output {
                    what: format!("the results of stage {i}"),
                    source,
                })?;
        }
    }
    for o in observers.iter_mut() {
        o.finished(report).map_err(|source| AppError::Output {
            what: "the run's results".into(),
            source,
        })?;
    }
    Ok(())
}
