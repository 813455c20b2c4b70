//! The FE run of a case: plan → mesh → model → stepping → [`RunReport`], with observers called
//! at every converged step (writers, progress displays, interrupt checks).

use crate::case::Case;
use crate::checkpoint::{checkpoint_edges, Checkpoint};
use crate::model_setup::{check_memory, equations_estimate, sideways_planes};
use crate::observer::{BoxError, Observer, StepView};
use crate::report::*;
use crate::stage::critical::{
    critical_record, pressure_maximum_below, PendingCritical, BRANCH_SWITCH_FRACTION,
};
use crate::stage::profile::{boundary_layer, wrinkle_report};
use crate::stage::setup::{setup_stage, SetupInput};
use crate::stage::{LoadParts, MAX_PENETRATION_FRACTION};
use crate::{AppError, Result};
use tubemem_fem::contact::{Contact, Enforcement};
use tubemem_fem::continuation::{run_arc_stage, ArcLoading, Critical, CriticalKind};
use tubemem_fem::model::{nearest_node, Model, State};
use tubemem_fem::post::{midspan, ring_profile};
use tubemem_fem::stepping::{run_stage_refitted, Stage, StageError, StepInfo, StepSettings};
use tubemem_fem::NewtonSettings;
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
                let contact = kind.step_contact(m, st, info, start_lambda_s);

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
                let (closed_form, walls) = kind.step_closed_form(
                    m,
                    st,
                    info,
                    closed_form_law.as_ref(),
                    &ms,
                    contact.as_ref(),
                    start_lambda_s,
                    i,
                )?;
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
                    match kind.target_pressure().filter(|_| !plan.arc_length) {
                        // a pressure target the path cannot reach: say where its maximum is
                        Some(target) if state.p < target => {
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
        let (ms, contact, its, neg) = match steps.last() {
            Some(l) => (l.midspan, l.contact, l.newton_iterations, l.negative_pivots),
            None => (
                midspan(&model, &state).map_err(|source| AppError::Post { stage: i, source })?,
                None,
                0,
                0,
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
        let unstable_note = kind.unstable_note(&ms, gps_limits.as_ref());
        let wrinkling = wrinkle_report(&model, &state, i)?;
        let comparison = kind.stage_comparison(
            closed_form_law.as_ref(),
            &ms,
            contact.as_ref(),
            steps.last(),
            start_lambda_s,
        )?;
        let summary = StageSummary {
            index: i,
            kind: kind.name().into(),
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
            gps: comparison.gps,
            ps: comparison.ps,
            relative_error_vs_gps: comparison.gps_errors,
            relative_error_vs_ps: comparison.ps_errors,
            gps_at_fe_pressure: comparison.local_section,
            relative_error_vs_gps_at_fe_pressure: comparison.local_errors,
            walls: comparison.walls,
            planes: kind.planes().map(<[_]>::to_vec).unwrap_or_default(),
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
