//! `[solver] mesh_sequencing = L`: nested iteration over meshes. The case is first run on the
//! generated tube with half the elements in each direction (itself sequenced with L − 1
//! levels), and each load step on the case's own mesh then starts from that run's converged
//! state at the same point of its stage, carried over ([`tubemem_fem::model::Model::prolong`]),
//! instead of from the secant predictor ([`tubemem_fem::stepping::Guide`]).
//!
//! Why: a squeeze step's Newton iterations are mostly the contact zone's release, about one
//! element row at each zone edge per iteration, so their number grows as 1/h. From the coarse
//! state the zone is right to within a coarse element, and the fine solve releases a row or two.
//! The answer is the fine mesh's own: every step is converged on it to the same tolerances.
//! The coarse run writes nothing; its Newton iterations are not in the run's iteration log.

use crate::case::Case;
use crate::observer::{BoxError, Observer, StepView};
use crate::report::{RunOutcome, RunReport, StageOutcome};
use crate::{AppError, Result};
use tubemem_fem::contact::Enforcement;
use tubemem_fem::model::{Load, Model, Prolongation, State};
use tubemem_fem::FemError;
use tubemem_mesh::Mesh;

/// The coarse run's Newton tolerance (at least the case's): its state differs from the fine
/// mesh's by the coarse discretization error, about 1e-4 relative in ϖ at 224 around (0.651487
/// against 0.651439 at 448, `scripts/bench-million.sh`), so converging it below 1e-6 buys the
/// fine start nothing. Measured on the benchmark (`THREADS=2 bash scripts/bench-million.sh`,
/// one run each): 1:45.2 and 1:48.8 wall with this and [`COARSE_GAP_TOLERANCE`], 1:49.5 with
/// this alone, against 1:52–1:56 with the case's 1e-9, and the same printed fine results.
pub const COARSE_RTOL: f64 = 1e-6;

/// The coarse run's multiplier-update gap tolerance (at least the case's), in R: far below the
/// coarse discretization's own displacement error, as [`COARSE_RTOL`].
pub const COARSE_GAP_TOLERANCE: f64 = 1e-6;

/// The case one level coarser: half the elements around, along and in the caps, one level
/// fewer, nothing written, with the predictor's tolerances ([`COARSE_RTOL`],
/// [`COARSE_GAP_TOLERANCE`]).
pub fn coarse_case(case: &Case) -> Case {
    let mut coarse = case.clone();
    coarse.mesh.around = case.mesh.around.map(|v| v / 2);
    coarse.mesh.along = case.mesh.along.map(|v| v / 2);
    coarse.mesh.cap_rows = case.mesh.cap_rows.map(|v| v / 2);
    coarse.solver.mesh_sequencing = case.solver.mesh_sequencing.saturating_sub(1);
    coarse.solver.checkpoint_every = 0;
    // a predictor needs no more precision than its discretization has
    coarse.solver.rtol = case.solver.rtol.max(COARSE_RTOL);
    for p in coarse.plan_mut() {
        if let Some(Enforcement::Augmented { gap_tolerance, .. }) = &mut p.enforcement {
            *gap_tolerance = gap_tolerance.max(COARSE_GAP_TOLERANCE);
        }
    }
    coarse
}

/// The converged steps of a coarse run: its mesh and, per stage, the fraction of the stage and
/// the state at each converged step.
struct Collector<'o, 'p> {
    mesh: Option<Mesh>,
    stages: Vec<Vec<(f64, State)>>,
    /// the run's observers, told of each converged coarse step
    observers: &'o mut [&'p mut dyn Observer],
}

impl Observer for Collector<'_, '_> {
    fn started(
        &mut self,
        _report: &RunReport,
        model: &Model,
        _state: &State,
    ) -> std::result::Result<(), BoxError> {
        self.mesh = Some(model.mesh().clone());
        Ok(())
    }

    fn step(&mut self, view: &StepView) -> std::result::Result<(), BoxError> {
        let i = view.plan.index - 1;
        if self.stages.len() <= i {
            self.stages.resize_with(i + 1, Vec::new);
        }
        self.stages[i].push((view.fraction, view.state.clone()));
        for o in self.observers.iter_mut() {
            o.coarse_step(view);
        }
        Ok(())
    }
}

/// The coarse run of a sequenced case: its mesh, the converged steps of each stage it finished,
/// and why it stopped early, if it did.
pub struct Coarse {
    mesh: Mesh,
    stages: Vec<Vec<(f64, State)>>,
    /// where the run's nodes lie on the coarse mesh: located at the first guided stage, for
    /// all (the run's mesh does not move: sequencing refuses the moving ones)
    prolongation: std::cell::OnceCell<Prolongation>,
    /// the coarse run's failure: stages from its failed one on are stepped without a guide
    pub warning: Option<String>,
}

impl Coarse {
    /// Run `case` one level coarser ([`coarse_case`]) by `solve` (the run, with the run's
    /// interrupt, given the observer that collects its converged steps; the `observers` are
    /// told it starts); `None` when the case is not sequenced. An interrupt stops it as it
    /// stops the run.
    pub fn run(
        case: &Case,
        observers: &mut [&mut dyn Observer],
        solve: &mut dyn FnMut(&Case, &mut dyn Observer) -> RunOutcome,
    ) -> Result<Option<Coarse>> {
        if case.solver.mesh_sequencing == 0 {
            return Ok(None);
        }
        let coarse = coarse_case(case);
        let around = coarse.mesh.around.unwrap_or(0);
        for o in observers.iter_mut() {
            o.coarse_started(around, coarse.mesh.along.unwrap_or(0));
        }
        let started = std::time::Instant::now();
        let mut collector = Collector {
            mesh: None,
            stages: Vec::new(),
            observers: &mut *observers,
        };
        let outcome = solve(&coarse, &mut collector);
        let (mesh, stages) = (collector.mesh, collector.stages);
        let seconds = started.elapsed().as_secs_f64();
        if let Some(e @ AppError::Interrupted { .. }) = outcome.error {
            return Err(e);
        }
        let Some(mesh) = mesh else {
            return Err(AppError::Sequencing {
                around,
                source: Box::new(outcome.error.unwrap_or(AppError::Case(
                    crate::case::CaseError::Invalid("the coarse run built no model".into()),
                ))),
            });
        };
        // only the stages the coarse run finished guide the fine one
        let finished = outcome
            .report
            .stages
            .iter()
            .take_while(|s| matches!(s.outcome, StageOutcome::Finished(_)))
            .count();
        let mut stages = stages;
        stages.truncate(finished);
        let steps = stages.iter().map(Vec::len).sum();
        for o in observers.iter_mut() {
            o.coarse_finished(finished, steps, seconds);
        }
        let warning = outcome.error.map(|e| {
            format!(
                "[solver] mesh_sequencing: the coarse run ({around} around) stopped after {finished} finished stage(s) ({}); the stages after them were stepped without it",
                e.chain()
            )
        });
        Ok(Some(Coarse {
            mesh,
            stages,
            prolongation: std::cell::OnceCell::new(),
            warning,
        }))
    }

    /// Whether the coarse run guides stage `index` (from 1): it finished it.
    pub fn guides(&self, index: usize) -> bool {
        self.stages.get(index - 1).is_some_and(|s| !s.is_empty())
    }

    /// Drop the states of stage `index` (from 1), once it is driven.
    pub fn release(&mut self, index: usize) {
        if let Some(s) = self.stages.get_mut(index - 1) {
            *s = Vec::new();
        }
    }

    /// The guide of stage `index` (from 1) on `model`: the coarse run's converged steps of
    /// that stage, carried over on demand; `None` where the coarse run did not finish the
    /// stage.
    pub fn guide(
        &self,
        index: usize,
        model: &Model,
    ) -> std::result::Result<Option<StageGuide<'_>>, FemError> {
        let Some(steps) = self.stages.get(index - 1).filter(|s| !s.is_empty()) else {
            return Ok(None);
        };
        if self.prolongation.get().is_none() {
            // set once: it was empty just above, and nothing else sets it
            let _ = self.prolongation.set(model.prolongation_from(&self.mesh)?);
        }
        let Some(prolongation) = self.prolongation.get() else {
            return Ok(None);
        };
        Ok(Some(StageGuide {
            fractions: steps.iter().map(|s| s.0).collect(),
            steps,
            prolongation,
        }))
    }
}

/// One stage's coarse steps, carried to the fine model when asked.
pub struct StageGuide<'a> {
    fractions: Vec<f64>,
    steps: &'a [(f64, State)],
    prolongation: &'a Prolongation,
}

impl tubemem_fem::stepping::Guide for StageGuide<'_> {
    fn fractions(&self) -> &[f64] {
        &self.fractions
    }

    fn state(&self, model: &Model, k: usize, load: &Load) -> std::result::Result<State, FemError> {
        model.prolong(self.prolongation, &self.steps[k].1, load.contact.as_ref())
    }
}
