//! What a run tells its observers as it goes: the [`Observer`] trait (writers, progress
//! displays, interrupt checks, Python callbacks) and the [`StepView`] of a converged step.

use crate::case::StagePlan;
use crate::checkpoint::StageContext;
use crate::report::{CriticalRecord, RunReport, StepRecord};
use crate::AppError;
use tubemem_fem::model::{Load, Model, State};

/// An observer's error: it stops the run (which then reports it with stage and step).
pub type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// What an observer sees at a converged step.
pub struct StepView<'a> {
    /// the run so far: the finished stages
    pub report: &'a RunReport,
    /// the current stage's steps so far, this one last
    pub stage_steps: &'a [StepRecord],
    /// the critical points the current stage has located so far (arc-length stages)
    pub stage_critical_points: &'a [CriticalRecord],
    /// how the current stage was set up, and where its stepping stands (for checkpoints)
    pub context: &'a StageContext,
    pub progress: tubemem_fem::stepping::StepState,
    pub model: &'a Model,
    pub state: &'a State,
    pub load: &'a Load,
    pub plan: &'a StagePlan,
    pub stages: usize,
    pub record: &'a StepRecord,
    /// the fraction of the stage done
    pub fraction: f64,
    /// the converged state before this one in the stage (the stepping's secant predictor
    /// continues from both after a restart)
    pub previous: Option<&'a State>,
}

/// Called by [`crate::run::run`] as it goes. Every method has a no-op default.
pub trait Observer {
    /// The model is built and `state` is the reference configuration.
    fn started(
        &mut self,
        _report: &RunReport,
        _model: &Model,
        _state: &State,
    ) -> Result<(), BoxError> {
        Ok(())
    }
    /// `[solver] mesh_sequencing`: the case runs first on the tube of `around` × `along`
    /// elements, before this run's model is built ([`crate::sequencing`]).
    fn coarse_started(&mut self, _around: usize, _along: usize) {}
    /// The coarse run of `[solver] mesh_sequencing` ended: it finished `stages` of the case's
    /// stages with `steps` converged steps in `seconds` (its failure, if any, comes as the
    /// run's warning).
    fn coarse_finished(&mut self, _stages: usize, _steps: usize, _seconds: f64) {}
    /// A converged step of the coarse run of `[solver] mesh_sequencing`, between
    /// [`Observer::coarse_started`] and [`Observer::coarse_finished`] (its own coarse run's
    /// steps, at two levels and more, are not passed on).
    fn coarse_step(&mut self, _view: &StepView) {}
    fn stage_started(&mut self, _plan: &StagePlan, _stages: usize) {}
    /// A converged step; an error stops the run.
    fn step(&mut self, _view: &StepView) -> Result<(), BoxError> {
        Ok(())
    }
    /// A stage finished; its report is the last of `report.stages`.
    fn stage_finished(&mut self, _report: &RunReport) -> Result<(), BoxError> {
        Ok(())
    }
    fn finished(&mut self, _report: &RunReport) -> Result<(), BoxError> {
        Ok(())
    }
    /// The run failed; `report` holds every converged step, and the failed stage's error.
    fn failed(&mut self, _report: &RunReport, _error: &AppError) {}
    /// An arc-length stage located a critical point (`state` there; `mode` the critical mode
    /// of a bifurcation as nodal vectors), reported before the step that follows it.
    fn critical(
        &mut self,
        _record: &CriticalRecord,
        _model: &Model,
        _state: &State,
        _mode: Option<&[[f64; 3]]>,
    ) -> Result<(), BoxError> {
        Ok(())
    }
}
