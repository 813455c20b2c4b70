//! A stage's set-up at its start, the same for every kind: the pre-stress from a stress-free
//! state, the load parameter's range, and for closed gas the gas constant ϖV.

use super::{RangeInput, StageKind};
use crate::case::StagePlan;
use crate::checkpoint::StageContext;
use crate::observer::BoxError;
use crate::report::*;
use crate::units::Dimension;
use crate::{AppError, Result};
use tubemem_fem::model::{Model, State};
use tubemem_fem::post::midspan;
use tubemem_fem::stepping::{Stage, StageError, StepSettings};
use tubemem_gps::limits::Limits;
use tubemem_material::MembraneLaw;

/// What the set-up of every stage shares: fixed for the run.
pub struct SetupInput<'a> {
    pub stages: usize,
    pub law: &'a dyn MembraneLaw,
    pub limits: Option<&'a Limits>,
    /// the node whose hoop stretch a stretch control holds
    pub node: usize,
    /// the reference volume of the whole tube
    pub v0: f64,
    /// the stage's steps start from a coarse run's states (`[solver] mesh_sequencing`), which
    /// are loaded: no pre-stress
    pub guided: bool,
    /// the case's units, for what the set-up says
    pub units: crate::units::Units,
}

/// Set up a stage of `kind` at its start. A precondition that fails is recorded in the report
/// as the stage's failure.
pub(crate) fn setup_stage(
    kind: &dyn StageKind,
    plan: &StagePlan,
    run: &SetupInput,
    model: &mut Model,
    state: &mut State,
    report: &mut RunReport,
) -> Result<StageContext> {
    let i = plan.index;
    let (node, v0) = (run.node, run.v0);
    // the squeeze this stage continues, if the previous stage was one
    let previous_squeeze: Option<FinalContact> = match report.stages.last().map(|s| &s.outcome) {
        Some(StageOutcome::Finished(s)) => s.final_state.contact,
        _ => None,
    };
    // the λs* of the confine stage this one continues, if the previous stage was one
    let previous_confine: Option<f64> = match report.stages.last().map(|s| &s.outcome) {
        Some(StageOutcome::Finished(s)) if kind.planes().is_some() => s.initial_stretch,
        _ => None,
    };
    report
        .warnings
        .extend(kind.warnings(plan, run.law, run.limits));
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
    let from_before = kind.controlled_value(model, state, node);
    let closed_gas = kind.closed_gas();
    if state.p == 0.0 && !kind.presses() && !run.guided {
        let estimate = kind.pressure_estimate(run.law);
        let mut pre = settings;
        // an arc-length stage always starts pre-stressed: its first tangent needs the
        // geometric stiffness
        let target_pressure = kind.target_pressure().is_some() && !plan.arc_length;
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
                        stages: run.stages,
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
            let now = kind.controlled_value(model, state, node).unwrap_or(state.p);
            let first = from_before.map_or(f64::INFINITY, |f0| kind.first_step(f0, plan.steps, v0));
            if target_pressure || now >= first {
                prestressed_from = Some(now);
            }
        }
    }
    // for a squeeze: the inflated mid-span stretch λs* and the gas constant at its start
    let start = midspan(model, state).map_err(|source| AppError::Post { stage: i, source })?;
    let pv = state.p * model.multiplicity() * model.mesh().volume_at(&state.x);
    let range = kind.range(&RangeInput {
        model,
        state,
        node,
        v0,
        start: &start,
        previous_squeeze,
        continues_confine: previous_confine.is_some(),
        penalty: plan.penalty,
        units: &run.units,
    });
    let (mut from, to, penalty) = match range {
        Ok(r) => r,
        Err(message) => {
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
            return Err(AppError::StageInput { stage: i, message });
        }
    };
    let held_plates = previous_squeeze.map(|c| c.rho).filter(|_| plan.held_plates);
    if let (Some(c), crate::case::Target::Pressure(t), false) = (
        kind.limit_reference(run.law, held_plates),
        plan.target,
        plan.arc_length,
    ) {
        if t > c.w {
            report.warnings.push(format!(
                "stage {i}: the target {} is above the {} ({} at λs = {:.4}): under pressure control the section snaps there, and the run stops near it (control = \"arc-length\" locates the FE's own maximum)",
                run.units.show(Dimension::Pressure, t),
                c.what,
                run.units.show(Dimension::Pressure, c.w),
                c.lambda_s
            ));
        }
    }
    match (prestressed_from, from_before) {
        (Some(f), _) | (None, Some(f)) => from = f,
        _ => {}
    }
    Ok(StageContext {
        stage: i,
        from,
        to,
        pv: if closed_gas { pv } else { 0.0 },
        start_pressure: state.p,
        gas_closed_at: if closed_gas && kind.presses() && kind.planes().is_none() {
            gas_closed_at(report)
        } else {
            None
        },
        held_plates,
        penalty,
        // a squeeze that continues a squeeze compares with the flattening from the same λs*
        // and a confine that continues a confine from the same λs* too
        start_lambda_s: previous_squeeze
            .map(|c| c.initial_stretch)
            .or(previous_confine)
            .unwrap_or(start.lambda_s),
    })
}

/// Where the gas of a closed-gas squeeze was closed in, if the squeezes just before it began
/// with a regulated one (the mixed path): that stage's final half-gap and pressure. `None`: the
/// gas was closed in the free tube (the paper's squeeze).
fn gas_closed_at(report: &RunReport) -> Option<[f64; 2]> {
    for s in report.stages.iter().rev() {
        let StageOutcome::Finished(f) = &s.outcome else {
            return None;
        };
        let (crate::case::Target::Rho(_), Some(c)) = (s.plan.target, f.final_state.contact) else {
            return None;
        };
        if let crate::case::GasControl::Regulated { .. } = s.plan.gas {
            return Some([c.rho, f.final_state.midspan.w]);
        }
    }
    None
}
