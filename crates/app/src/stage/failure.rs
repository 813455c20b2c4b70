//! What a stage's failure is reported as: an interruption, a Newton failure (with the
//! inertia of the last converged state, and for a pressure target the path cannot reach the
//! pressure maximum on the way), or an observer's error.

use super::critical::pressure_maximum_below;
use super::StageKind;
use crate::case::StagePlan;
use crate::observer::BoxError;
use crate::report::{StageReport, StepRecord};
use crate::AppError;
use tubemem_fem::model::{Model, State};
use tubemem_fem::stepping::StageError;
use tubemem_material::MembraneLaw;

/// What a stage's failure is judged with.
pub struct FailureInput<'a> {
    pub kind: &'a dyn StageKind,
    pub plan: &'a StagePlan,
    /// the number of stages of the run
    pub stages: usize,
    /// the law of the closed form
    pub law: &'a dyn MembraneLaw,
    /// the stage's converged steps
    pub steps: &'a [StepRecord],
    /// the stage before it
    pub previous: Option<&'a StageReport>,
}

/// The run's error for the stage's failure `e`, from the last converged `state` (the model is
/// used for the probe of a pressure maximum, and left as it was).
pub(crate) fn stage_error(
    e: StageError<BoxError>,
    f: &FailureInput,
    model: &mut Model,
    state: &State,
) -> AppError {
    let i = f.plan.index;
    match e {
        StageError::Solve(tubemem_fem::FemError::Interrupted) => AppError::Interrupted {
            stage: i,
            steps: f.steps.len(),
        },
        StageError::Solve(source) => {
            // the last converged state of the stage, or of the run before it
            let last_negative = f.steps.last().map(|r| r.negative_pivots).or_else(|| {
                f.previous
                    .filter(|s| !s.plan.arc_length)
                    .and_then(|s| s.steps.last())
                    .map(|r| r.negative_pivots)
            });
            let unstable = last_negative.filter(|&n| n > 0 && !f.plan.arc_length);
            match f.kind.target_pressure().filter(|_| !f.plan.arc_length) {
                // a pressure target the path cannot reach: say where its maximum is
                Some(target) if state.p < target => {
                    match pressure_maximum_below(model, state, target, f.law) {
                        Some((w_max, lambda_s)) => AppError::BeyondLimit {
                            stage: i,
                            stages: f.stages,
                            target,
                            w_max,
                            lambda_s,
                            source: Box::new(source),
                        },
                        None => AppError::Stage {
                            stage: i,
                            stages: f.stages,
                            unstable,
                            source,
                        },
                    }
                }
                _ => AppError::Stage {
                    stage: i,
                    stages: f.stages,
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
    }
}
