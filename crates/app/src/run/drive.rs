//! One stage driven from its start to its end: by load steps (with the tracked mesh refitted
//! between them) or by arc length (with the critical points it locates), every converged step
//! recorded and shown to the observers; then the stage's report, or its failure's.

use super::runner::{Runner, StageStart};
use crate::case::{ProfileFrames, StagePlan};
use crate::observer::{BoxError, Observer, StepView};
use crate::report::Stiffness;
use crate::report::*;
use crate::stage::critical::{critical_record, PendingCritical, BRANCH_SWITCH_FRACTION};
use crate::stage::failure::{stage_error, FailureInput};
use crate::stage::record::{step_record, RecordInput};
use crate::stage::summary::stage_report;
use crate::stage::{LoadParts, StageKind};
use crate::{AppError, Result};
use std::cell::RefCell;
use tubemem_fem::continuation::{run_arc_stage, ArcLoading, Critical, CriticalKind};
use tubemem_fem::model::{Model, State};
use tubemem_fem::stepping::{run_stage_refitted, Stage, StageError, StepInfo, StepSettings};

/// What a converged step is handed to.
type OnStep<'s> = dyn FnMut(&Model, &State, &StepInfo) -> std::result::Result<(), BoxError> + 's;

/// Drive stage `plan` of `kind` from `start` and push its report (finished or failed) onto
/// `report`; the stage's failure is also the error returned.
pub(super) fn drive_stage(
    r: &mut Runner,
    kind: &dyn StageKind,
    plan: &StagePlan,
    stages: usize,
    start: StageStart,
    report: &mut RunReport,
    observers: &mut [&mut dyn Observer],
) -> Result<()> {
    let StageStart {
        context,
        progress,
        steps: restored,
        criticals: restored_critical,
    } = start;
    let i = plan.index;
    let parts = LoadParts {
        node: r.node,
        pv: context.pv,
        start_pressure: context.start_pressure,
        range: (context.from, context.to),
        penalty: context.penalty,
        held_plates: context.held_plates,
        enforcement: plan.contact_enforcement(),
        points: plan.contact_points,
    };
    let stage = Stage {
        index: i,
        from: context.from,
        to: context.to,
        settings: StepSettings {
            initial_steps: plan.steps,
            ..StepSettings::default()
        },
    };
    let mut steps: Vec<StepRecord> = restored;
    let mut criticals: Vec<CriticalRecord> = restored_critical;
    let closed_gas = kind.closed_gas();
    let presses = kind.presses();
    let record_input = RecordInput {
        kind,
        plan,
        law: r.law.as_ref(),
        start: crate::stage::closed_form::ClosedFormStart {
            lambda_s: context.start_lambda_s,
            supply: match (kind.supply(), context.gas_closed_at) {
                (crate::stage::closed_form::Supply::Closed, Some([rho, w])) => {
                    crate::stage::closed_form::Supply::ClosedAfterRegulated { rho, w }
                }
                (s, _) => s,
            },
        },
        half_length: 0.5 * r.case.geometry.length / r.case.geometry.radius,
        every_profile: r.case.output.profiles == ProfileFrames::Every,
        started_uniform: started_uniform(presses, report),
        tracked_edges: (r.case.mesh.track_contact_edge && presses).then_some(&r.tracked_edges),
    };
    // a resumed arc-length stage's path so far decides its direction and where its planes are
    let direction = arc_direction(closed_gas, &steps);
    let planes_start = steps.last().map_or(context.from, |s| s.load);
    let last_limit_w0 = last_limit(&criticals);
    // critical points located by an arc-length stage, reported to the observers with the
    // step that follows them on the path
    let pending: RefCell<Vec<PendingCritical>> = Default::default();
    let finished: &RunReport = report;
    let result = {
        let mut on_step = |m: &Model, st: &State, info: &StepInfo| {
            let mut critical_here = None;
            for p in pending.borrow_mut().drain(..) {
                for o in observers.iter_mut() {
                    o.critical(&p.record, m, &p.state, p.mode.as_deref())?;
                }
                critical_here = Some(p.record.kind);
                criticals.push(p.record);
            }
            let mut record = step_record(&record_input, m, st, info, critical_here)?;
            record.stiffness = steps
                .last()
                .and_then(|before| Stiffness::between(before, &record));
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
        };
        if plan.arc_length {
            let arc = ArcStage {
                kind,
                parts: &parts,
                stage: &stage,
                progress: progress.map(|(p, _)| p),
                direction,
                planes_start,
                last_limit_w0,
                follow_stable: plan.follow_stable,
                limits: r.limits.as_ref(),
                own_max: kind.limit_reference(r.law.as_ref(), context.held_plates),
                polygon: r.case.mesh.polygon_factor(),
                node: r.node,
                pending: &pending,
            };
            follow_arc(&arc, &mut r.model, &mut r.state, &mut on_step)
        } else {
            let mut tracker = r
                .tube
                .filter(|_| presses)
                .map(|tube| crate::edge_track::Tracker {
                    tube,
                    law: r.law.as_ref(),
                    pressing: match (kind.planes(), context.held_plates) {
                        (Some(planes), _) => crate::edge_track::Pressing::Walls(planes.to_vec()),
                        (None, Some(h)) => crate::edge_track::Pressing::HeldPlates(h),
                        (None, None) => crate::edge_track::Pressing::Plates,
                    },
                    edges: r.tracked_edges.clone(),
                });
            // mesh sequencing: the coarse run's steps of this stage lead (a resumed stage from
            // where it stopped)
            let load = kind.load(&parts);
            let guide = match &r.coarse {
                Some(c) => c.guide(i, &r.model).map_err(AppError::Model)?,
                None => None,
            };
            run_stage_refitted(
                &mut r.model,
                &mut r.state,
                &stage,
                progress,
                load,
                &mut on_step,
                tracker
                    .as_mut()
                    .map(|t| t as &mut dyn tubemem_fem::stepping::Refit),
                guide
                    .as_ref()
                    .map(|g| g as &dyn tubemem_fem::stepping::Guide),
            )
        }
    };
    // the coarse run's states of this stage are not needed again
    if let Some(c) = r.coarse.as_mut() {
        c.release(i);
    }
    if let Err(e) = result {
        let failed = Failed {
            kind,
            plan,
            stages,
            steps,
            criticals,
        };
        return Err(failed.record(e, r, report));
    }
    let done = stage_report(
        &record_input,
        r.limits.as_ref(),
        &r.model,
        &r.state,
        steps,
        criticals,
    )?;
    report.stages.push(done);
    Ok(())
}

/// A stage that failed, with what it had converged.
struct Failed<'a> {
    kind: &'a dyn StageKind,
    plan: &'a StagePlan,
    stages: usize,
    steps: Vec<StepRecord>,
    criticals: Vec<CriticalRecord>,
}

impl Failed<'_> {
    /// Push the failed stage onto `report` (its converged steps, critical points and error
    /// chain) and return the run's error for the stage's failure `e`.
    fn record(
        self,
        e: StageError<BoxError>,
        r: &mut Runner,
        report: &mut RunReport,
    ) -> crate::AppError {
        let error = stage_error(
            e,
            &FailureInput {
                kind: self.kind,
                plan: self.plan,
                stages: self.stages,
                law: r.law.as_ref(),
                steps: &self.steps,
                previous: report.stages.last(),
            },
            &mut r.model,
            &r.state,
        );
        let last_converged = self.steps.last().map(|s| s.midspan);
        report.stages.push(StageReport {
            plan: *self.plan,
            steps: self.steps,
            outcome: StageOutcome::Failed(StageFailure {
                index: self.plan.index,
                error: error.chain(),
                last_converged,
                critical_points: self.criticals,
            }),
            profile: vec![],
        });
        error
    }
}

/// A squeeze or confine stage compares with a closed form that starts from a uniform tube:
/// not applicable after a stage that ended with a tube that was not uniform (that stage's
/// index).
fn started_uniform(presses: bool, report: &RunReport) -> Option<usize> {
    if !presses {
        return None;
    }
    report.stages.last().and_then(|s| match &s.outcome {
        StageOutcome::Finished(f) if !f.gps_applicable => Some(f.index),
        _ => None,
    })
}

/// A resumed arc-length stage goes on in the direction its last two steps went (in ϖ, or in
/// the planes' parameter with the gas closed).
fn arc_direction(closed_gas: bool, steps: &[StepRecord]) -> f64 {
    match steps {
        [.., a, b] if closed_gas && b.load < a.load => -1.0,
        [.., a, b] if !closed_gas && b.midspan.w < a.midspan.w => -1.0,
        _ => 1.0,
    }
}

/// The pressure of the last limit point before a restart, for the ripple test of the next.
fn last_limit(criticals: &[CriticalRecord]) -> Option<f64> {
    criticals
        .iter()
        .rev()
        .find(|c| matches!(c.kind, CriticalKind::LimitMax | CriticalKind::LimitMin))
        .map(|c| c.midspan.w)
}

/// What an arc-length stage is followed with.
struct ArcStage<'a> {
    kind: &'a dyn StageKind,
    parts: &'a LoadParts,
    stage: &'a Stage,
    progress: Option<tubemem_fem::stepping::StepState>,
    direction: f64,
    /// a closed-gas stage: the planes where the stage starts, or where its last converged
    /// step left them
    planes_start: f64,
    last_limit_w0: Option<f64>,
    follow_stable: bool,
    limits: Option<&'a tubemem_gps::limits::Limits>,
    /// the stage's own pressure maximum (an inflation between held plates)
    own_max: Option<crate::report::CriticalReference>,
    polygon: Option<f64>,
    node: usize,
    pending: &'a RefCell<Vec<PendingCritical>>,
}

/// Follow an arc-length stage; every critical point located is recorded and left pending
/// for the step that follows it.
fn follow_arc(
    a: &ArcStage,
    model: &mut Model,
    state: &mut State,
    on_step: &mut OnStep,
) -> std::result::Result<(), StageError<BoxError>> {
    let monitor = a.kind.arc_monitor(model, a.node);
    let loading = a.kind.arc_loading(a.parts);
    if let ArcLoading::ClosedGas { .. } = loading {
        state.planes = a.planes_start;
    }
    let last_limit = std::cell::Cell::new(a.last_limit_w0);
    let index = a.stage.index;
    run_arc_stage(
        model,
        state,
        a.stage,
        a.progress,
        loading.clone(),
        &*monitor,
        a.direction,
        a.follow_stable.then_some(BRANCH_SWITCH_FRACTION),
        on_step,
        |m: &mut Model, c: &Critical<State>| {
            critical_record(
                m,
                c,
                &loading.load_at(&c.state),
                index,
                a.limits,
                a.own_max.as_ref(),
                a.polygon,
                &last_limit,
                &mut a.pending.borrow_mut(),
            )
            .map_err(|e| Box::new(e) as BoxError)
        },
    )
    .map(|_| ())
}
