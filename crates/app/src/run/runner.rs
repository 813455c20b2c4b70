//! What a run builds before its first stage and carries from stage to stage: the mesh, the
//! model and its state, the closed form's law and limit points, the tracked tube; and where a
//! stage starts (set up afresh, or restored from a checkpoint).

use super::{build_mesh_with_fit, RunOptions};
use crate::case::{Case, StagePlan};
use crate::checkpoint::{checkpoint_edges, Checkpoint, StageContext};
use crate::edge_track::{Edges, TubeSpec};
use crate::model_setup::{check_memory, equations_estimate, model_of};
use crate::report::*;
use crate::stage::setup::{setup_stage, SetupInput};
use crate::stage::StageKind;
use crate::{AppError, Result};
use tubemem_fem::model::{nearest_node, Model, State};
use tubemem_fem::stepping::StepState;
use tubemem_gps::limits::Limits;
use tubemem_gps::Hypothesis;
use tubemem_material::MembraneLaw;

/// The run's model and everything fixed for the run.
pub(super) struct Runner<'a> {
    pub case: &'a Case,
    /// the law of the closed form (without the tension-field relaxation)
    pub law: Box<dyn MembraneLaw>,
    /// the closed form's limit points, for the warnings, the critical points' references and
    /// the stage-end notes (one scan per run)
    pub limits: Option<Limits>,
    pub model: Model,
    pub state: State,
    /// `[mesh] track_contact_edge`: the tube the tracker refits, and the edges it is fitted to
    pub tube: Option<TubeSpec>,
    pub tracked_edges: Edges,
    /// the node whose hoop stretch a stretch control holds
    pub node: usize,
    /// the reference volume of the whole tube
    pub v0: f64,
    /// `[solver] mesh_sequencing`: the coarse run whose steps guide this one's
    pub coarse: Option<crate::sequencing::Coarse>,
}

/// Where a stage starts: its context and, for a restored stage, the stepping's progress and
/// the steps and critical points it had before the restart.
pub(super) struct StageStart {
    pub context: StageContext,
    pub progress: Option<(StepState, Option<State>)>,
    pub steps: Vec<StepRecord>,
    pub criticals: Vec<CriticalRecord>,
}

/// The GPS limit points of the case's law, computed once per law in a process: they depend on
/// the law alone, and a sweep or an atlas runs many cases of one law (on `small_abb30_ls1.2` the
/// scan is about a quarter of a run's time). Keyed by the law's table as the case gives it.
fn gps_limits(
    spec: &tubemem_material::MaterialSpec,
    law: &dyn tubemem_material::MembraneLaw,
    interrupt: Option<&std::sync::Arc<std::sync::atomic::AtomicBool>>,
) -> Option<Limits> {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static MEMO: OnceLock<Mutex<HashMap<String, Option<Limits>>>> = OnceLock::new();
    let memo = MEMO.get_or_init(Default::default);
    let key = serde_json::to_string(spec).ok()?;
    if let Some(l) = memo.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return *l;
    }
    let stop = || interrupt.is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed));
    let limits = match tubemem_gps::limits::limit_points_until(law, Hypothesis::Gps, &stop) {
        // not memoized: the next run of this law scans again; this one stops at its first
        // Newton iteration
        Err(tubemem_gps::GpsError::Interrupted) => return None,
        r => r.ok(),
    };
    memo.lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, limits);
    limits
}

impl<'a> Runner<'a> {
    /// The memory guard, the mesh (fitted to the contact edge if the case asks), the law and
    /// the model in its reference state; with where the mesh was fitted.
    pub fn build(
        case: &'a Case,
        options: &RunOptions,
        observers: &mut [&mut dyn crate::observer::Observer],
    ) -> Result<(Self, Option<ContactEdgeFit>)> {
        // the memory guard, before anything large is built
        if let Some(n) = equations_estimate(case) {
            check_memory(n, options.force)?;
        }
        // the coarse run of mesh sequencing first, so that its model is gone before this
        // one is built; a resumed run runs it again (it is deterministic), so that its steps
        // repeat the uninterrupted run's
        let quiet = RunOptions {
            interrupt: options.interrupt.clone(),
            force: options.force,
            resume: None,
        };
        let coarse = crate::sequencing::Coarse::run(case, observers, &mut |coarse, collector| {
            super::run_with(
                coarse,
                "mesh-sequencing coarse run",
                &quiet,
                &mut [collector],
            )
        })?;
        let (mesh, contact_edge_fit) = build_mesh_with_fit(case, options.interrupt.as_ref())?;
        if case.mesh.file.is_some() {
            check_memory(3 * mesh.nodes.len(), options.force)?;
        }
        let law = case.material.build()?;
        let limits = gps_limits(&case.material, law.as_ref(), options.interrupt.as_ref());
        let model = model_of(case, mesh, options.interrupt.clone())?;
        let state = model.reference_state();
        let v0 = model.multiplicity() * model.mesh().volume();
        let node = nearest_node(model.mesh(), [1.0, 0.0, 0.0]);
        let runner = Runner {
            case,
            law,
            limits,
            model,
            state,
            tube: TubeSpec::of(case),
            tracked_edges: Default::default(),
            node,
            v0,
            coarse,
        };
        Ok((runner, contact_edge_fit))
    }

    /// The report of the run before its first stage: the case, the mesh, the law and the
    /// geometry.
    pub fn initial_report(&self, label: &str, fit: Option<ContactEdgeFit>) -> RunReport {
        let (case, model) = (self.case, &self.model);
        let g = &case.geometry;
        RunReport {
            mesh: MeshInfo {
                nodes: model.mesh().nodes.len(),
                elements: model.mesh().quads.len(),
                equations: model.n_eq(),
                symmetry: format!("{:?}", model.mesh().symmetry).to_lowercase(),
                element: model.mesh().element().name().into(),
                factor_nnz: model.factor_nnz(),
                factor_flops: model.factor_flops(),
                ordering: serde_json::to_value(model.factor_ordering())
                    .ok()
                    .and_then(|v| v.as_str().map(String::from))
                    .unwrap_or_default(),
                split_separator: model.factor_split_separator(),
                reuses_factor: model.reuses_factor(),
                contact_edge_fit: fit,
            },
            material: model.law().name(),
            geometry: GeometryInfo {
                radius: g.radius,
                length: g.length,
                thickness: g.thickness,
                caps: format!("{:?}", g.caps).to_lowercase(),
            },
            ..RunReport::empty(case, label)
        }
    }

    /// Continue from the checkpoint `ck`: its report, its state and, for a tracked mesh, the
    /// node lines where its step had them. A checkpoint of another case or mesh is refused.
    pub fn restore(&mut self, ck: &Checkpoint, label: &str, report: &mut RunReport) -> Result<()> {
        if let Some(message) = ck.mismatch(self.case.hash(), Some(self.state.x.len())) {
            return Err(AppError::Folder {
                path: std::path::PathBuf::from(label),
                message,
            });
        }
        *report = ck.report.clone();
        self.state.x.clone_from(&ck.x);
        self.state.p = ck.p;
        self.state.multipliers.clone_from(&ck.multipliers);
        // a tracked mesh: fitted where the checkpoint's step had it
        if let (Some(tube), Some(edges)) = (self.tube, checkpoint_edges(ck)) {
            let nodes = tube.nodes(&edges).map_err(AppError::Mesh)?;
            let n = nodes.len();
            self.model
                .move_reference(
                    nodes,
                    &tubemem_mesh::hoop::Transfer::identity(n),
                    None,
                    &mut [],
                )
                .map_err(AppError::Model)?;
            *self.tracked_edges.borrow_mut() = edges;
        }
        Ok(())
    }

    /// Where stage `plan` starts: restored from `resume` (a checkpoint taken in this stage),
    /// or set up afresh (a precondition that fails is recorded in the report).
    pub fn stage_start(
        &mut self,
        kind: &dyn StageKind,
        plan: &StagePlan,
        stages: usize,
        report: &mut RunReport,
        resume: Option<&Checkpoint>,
    ) -> Result<StageStart> {
        if let Some(ck) = resume {
            let previous = ck.previous.as_ref().map(|(x, p)| State {
                x: x.clone(),
                p: *p,
                planes: 0.0,
                multipliers: Vec::new(),
            });
            return Ok(StageStart {
                context: ck.context,
                progress: Some((ck.progress, previous)),
                steps: ck.steps.clone(),
                criticals: ck.critical_points.clone(),
            });
        }
        let setup = SetupInput {
            stages,
            law: self.law.as_ref(),
            limits: self.limits.as_ref(),
            node: self.node,
            v0: self.v0,
            guided: self.coarse.as_ref().is_some_and(|c| c.guides(plan.index)),
            units: self.case.units(),
        };
        let context = setup_stage(kind, plan, &setup, &mut self.model, &mut self.state, report)?;
        Ok(StageStart {
            context,
            progress: None,
            steps: vec![],
            criticals: vec![],
        })
    }
}
