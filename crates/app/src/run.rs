//! The FE run of a case: plan → mesh → model → stepping → [`RunReport`], with observers called
//! at every converged step (writers, progress displays, interrupt checks).

use crate::case::Case;
use crate::checkpoint::{checkpoint_edges, Checkpoint};
use crate::model_setup::{check_memory, equations_estimate, model_of};
use crate::observer::{BoxError, Observer, StepView};
use crate::report::*;
use crate::stage::critical::{critical_record, PendingCritical, BRANCH_SWITCH_FRACTION};
use crate::stage::failure::{stage_error, FailureInput};
use crate::stage::record::{step_record, RecordInput};
use crate::stage::setup::{setup_stage, SetupInput};
use crate::stage::summary::stage_report;
use crate::stage::LoadParts;
use crate::{AppError, Result};
use tubemem_fem::contact::Enforcement;
use tubemem_fem::continuation::{run_arc_stage, ArcLoading, Critical, CriticalKind};
use tubemem_fem::model::{nearest_node, Model, State};

use tubemem_fem::stepping::{run_stage_refitted, Stage, StepInfo, StepSettings};
use tubemem_gps::Hypothesis;

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
    let closed_form_law = case.material.build()?;
    // the closed form's limit points, for the warnings, the critical points' references and the
    // stage-end notes (one scan per run)
    let gps_limits =
        tubemem_gps::limits::limit_points(closed_form_law.as_ref(), Hypothesis::Gps).ok();
    let mut model = model_of(case, mesh, options.interrupt.clone())?;
    let mut state = model.reference_state();
    // `[mesh] track_contact_edge`: the tube the tracker refits, and the edges it is fitted to
    let tracking = case.mesh.track_contact_edge;
    let tube = crate::edge_track::TubeSpec::of(case);
    let tracked_edges: crate::edge_track::Edges = Default::default();
    let v0 = model.multiplicity() * model.mesh().volume();
    let node = nearest_node(model.mesh(), [1.0, 0.0, 0.0]);
    let report = slot.insert(initial_report(case, label, &model, contact_edge_fit));
    if let Some(ck) = &options.resume {
        restore(
            ck,
            case,
            label,
            tube,
            &mut model,
            &mut state,
            report,
            &tracked_edges,
        )?;
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
    let setup = SetupInput {
        stages,
        law: closed_form_law.as_ref(),
        limits: gps_limits.as_ref(),
        node,
        v0,
    };
    for plan in case.plan() {
        let i = plan.index;
        let resume_here = options.resume.as_ref().filter(|c| c.context.stage == i);
        if options.resume.as_ref().is_some_and(|c| i < c.context.stage) {
            continue; // finished before the restart: in the restored report
        }
        for o in observers.iter_mut() {
            o.stage_started(plan, stages);
        }
        let kind = crate::stage::kind_of(plan, &case.stages[i - 1].plane);
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
                let ctx = setup_stage(kind.as_ref(), plan, &setup, &mut model, &mut state, report)?;
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
        let parts = LoadParts {
            node,
            pv,
            penalty,
            enforcement,
            points,
        };
        let load = kind.load(&parts);
        let stage = Stage {
            index: i,
            from: context.from,
            to: context.to,
            settings,
        };
        let mut steps: Vec<StepRecord> = restored;
        let every_profile = case.output.profiles == crate::case::ProfileFrames::Every;
        let finished: &RunReport = report;
        // critical points located by an arc-length stage, reported to the observers with the
        // step that follows them on the path
        let pending: std::cell::RefCell<Vec<PendingCritical>> = Default::default();
        // a squeeze or confine stage compares with a closed form that starts from a uniform
        // tube: not applicable after a stage that ended with a tube that was not uniform
        let closed_gas = kind.closed_gas();
        let started_uniform: Option<usize> = if closed_gas {
            report.stages.last().and_then(|s| match &s.outcome {
                StageOutcome::Finished(f) if !f.gps_applicable => Some(f.index),
                _ => None,
            })
        } else {
            None
        };
        // a resumed arc-length stage goes on in the direction its last two steps went (in ϖ,
        // or in the planes' parameter with the gas closed)
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
        let record_input = RecordInput {
            kind: kind.as_ref(),
            plan,
            law: closed_form_law.as_ref(),
            start_lambda_s,
            half_length: half,
            every_profile,
            started_uniform,
            tracked_edges: (tracking && closed_gas).then_some(&tracked_edges),
        };
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
                let record = step_record(&record_input, m, st, info, critical_here)?;
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
            let monitor = kind.arc_monitor(&model, node);
            let loading = kind.arc_loading(&parts);
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
                    pressing: match kind.planes() {
                        Some(planes) => crate::edge_track::Pressing::Walls(planes.to_vec()),
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
            let error = stage_error(
                e,
                &FailureInput {
                    kind: kind.as_ref(),
                    plan,
                    stages,
                    law: closed_form_law.as_ref(),
                    steps: &steps,
                    previous: report.stages.last(),
                },
                &mut model,
                &state,
            );
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
        let finished = stage_report(
            &record_input,
            gps_limits.as_ref(),
            &model,
            &state,
            steps,
            criticals,
        )?;
        report.stages.push(finished);
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

/// The report of a run before its first stage: the case, the mesh, the law and the geometry.
fn initial_report(
    case: &Case,
    label: &str,
    model: &Model,
    contact_edge_fit: Option<ContactEdgeFit>,
) -> RunReport {
    let g = &case.geometry;
    RunReport {
        case: label.to_string(),
        mesh: MeshInfo {
            nodes: model.mesh().nodes.len(),
            elements: model.mesh().quads.len(),
            equations: model.n_eq(),
            symmetry: format!("{:?}", model.mesh().symmetry).to_lowercase(),
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
    }
}

/// Continue from the checkpoint `ck`: its report, its state and, for a tracked mesh, the node
/// lines where its step had them. A checkpoint of another case or mesh is refused.
#[allow(clippy::too_many_arguments)]
fn restore(
    ck: &Checkpoint,
    case: &Case,
    label: &str,
    tube: Option<crate::edge_track::TubeSpec>,
    model: &mut Model,
    state: &mut State,
    report: &mut RunReport,
    tracked_edges: &crate::edge_track::Edges,
) -> Result<()> {
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
    Ok(())
}
