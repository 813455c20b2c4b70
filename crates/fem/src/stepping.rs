//! Load stepping: a stage moves a scalar load parameter from `from` to `to` through
//! [`Model::solve`], with step cut-back on failure and growth after easy steps.
//!
//! ```text
//! Δλ₀ = 1/initial_steps;  on success: λ ← λ + Δλ, and Δλ ← min(growth·Δλ, max_fraction) when
//! the step took ≤ easy_iterations; on failure: Δλ ← Δλ/2 (at most max_cuts times per stage).
//! predictor (from the stage's second step on): the secant through the last two converged
//! states, x⁰ₙ₊₁ = xₙ + r (xₙ − xₙ₋₁), ϖ⁰ₙ₊₁ = ϖₙ + r (ϖₙ − ϖₙ₋₁), r = Δλₙ₊₁/Δλₙ
//! ```
//! The secant predictor places the nodes that a moving plate pushes, and the whole tube of an
//! inflation, close to where the step ends: a squeeze step from the last state starts with the
//! plate's whole advance as penetration (residual ≈ 1) and the penalty's active set moving
//! under Newton; from the prediction the contact zone is already where the step ends.

use crate::model::{Load, Loading, Model, State};
use crate::newton::NewtonReport;
use crate::FemError;

/// The stepping settings. Every number the stepping uses is here, named.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSettings {
    /// initial number of steps over the stage
    pub initial_steps: usize,
    /// cut-backs allowed in a stage before it fails
    pub max_cuts: usize,
    /// step growth factor after an easy step
    pub growth: f64,
    /// a step is easy when Newton took at most this many iterations
    pub easy_iterations: usize,
    /// the largest step as a fraction of the stage
    pub max_fraction: f64,
    /// converged steps allowed in one stage (each writes a row and a VTU frame): 2,000, forty
    /// times what the shipped cases need (at most 50)
    pub max_steps: usize,
    /// the pre-stress pressure ϖ taken out of a stress-free state before a bordered or
    /// gas-controlled stage (a hoop strain of about 0.25 % at ϖ = 0.01), halved on failure…
    pub prestress: f64,
    /// … down to this value
    pub min_prestress: f64,
}

impl Default for StepSettings {
    fn default() -> Self {
        Self {
            initial_steps: 8,
            max_cuts: 12,
            growth: 1.5,
            easy_iterations: 5,
            max_fraction: 0.25,
            max_steps: 2000,
            prestress: 0.01,
            min_prestress: 1e-6,
        }
    }
}

/// One stage of a run: its number (for messages), the load parameter at its start and end.
pub struct Stage {
    pub index: usize,
    pub from: f64,
    pub to: f64,
    pub settings: StepSettings,
}

/// Where the stepping of a stage stands: enough to continue it exactly (a restart from a
/// checkpoint continues bit for bit).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepState {
    /// the fraction of the stage done
    pub lambda: f64,
    /// the next step's fraction
    pub dl: f64,
    /// converged steps so far
    pub step: usize,
    /// cut-backs so far
    pub cuts: usize,
    /// the fraction of the stage at the converged step before the last (for the secant
    /// predictor; `None` before the stage's second step)
    #[serde(default)]
    pub previous_lambda: Option<f64>,
    /// the stage's [`Guide`] was dropped (a step from its state failed): the rest of the stage,
    /// a resumed one too, is stepped without it
    #[serde(default)]
    pub unguided: bool,
}

/// A converged step as the stepping reports it to its caller.
pub struct StepInfo<'a> {
    /// the stepping state after this step (what a restart continues from)
    pub progress: StepState,
    pub step: usize,
    /// the load parameter
    pub value: f64,
    /// the fraction of the stage done
    pub fraction: f64,
    pub load: &'a Load,
    pub newton: &'a NewtonReport,
    /// an arc-length step: dϖ/ds of the path's unit tangent (NaN for load stepping)
    pub dw_ds: f64,
    /// an arc-length step: the negative pivots under volume control (the closed tube's
    /// stability), beside the pressure-control count of `newton.inertia`
    pub negative_conjugate: Option<usize>,
    /// the converged state before this one in the stage (the secant predictor's other point,
    /// at `progress.previous_lambda`), for checkpoints
    pub previous: Option<&'a State>,
    /// the times the reference mesh moved after this step's first solve, each followed by a
    /// re-solve ([`Refit`]; 0 without one)
    pub refits: usize,
}

/// A reference mesh that follows the solution through a stage ([`run_stage_refitted`]): the
/// tube's hoop node lines kept on the contact edges as they move. Before each step's solve
/// (on the secant prediction) and after it converges, the stepping asks for the nodes the
/// model should have; when they differ it moves the model there
/// ([`Model::move_reference`]), carries the states over and, after a converged solve, solves
/// again, up to [`MAX_REFITS`] times a step. Where a solve on a moved mesh fails, the step goes
/// back to the mesh it came from: a failed first solve is tried again there (then cut back as
/// any other), a failed re-solve keeps the step's converged state on its own mesh.
pub trait Refit {
    /// The reference nodes the model should have at load value `value` with `state`, or
    /// `None` when the current ones do.
    fn nodes(
        &mut self,
        model: &Model,
        state: &State,
        value: f64,
    ) -> Result<Option<Vec<[f64; 3]>>, FemError>;
    /// What the refit needs to go back to the mesh it has now (its fitted edges).
    fn snapshot(&self) -> Vec<f64>;
    /// Go back to a [`Refit::snapshot`] (the stepping has put the model's mesh back).
    fn restore(&mut self, snapshot: &[f64]);
}

/// The states a move of the mesh carries over: the trial, the last converged state and the one
/// before it (the secant predictor's).
fn carried<'a>(
    trial: &'a mut State,
    state: &'a mut State,
    previous: &'a mut Option<State>,
) -> Vec<&'a mut State> {
    let mut v = vec![trial, state];
    v.extend(previous.as_mut());
    v
}

/// The converged states of the same stage on a coarser mesh of the same surface (mesh
/// sequencing, nested iteration; [`run_stage_refitted`]): the stage is stepped to the fractions
/// where they are, each step's Newton solve starting from the state there carried to the model
/// ([`Model::prolong`]) instead of the secant predictor. A step that fails from a guide's state
/// is cut back as any other, and the rest of the stage is stepped without the guide.
pub trait Guide {
    /// The fractions of the stage (ascending, in (0, 1], the last 1) where the guide has states.
    fn fractions(&self) -> &[f64];
    /// The state at `fractions()[k]`, carried to `model` under the step's `load`.
    fn state(&self, model: &Model, k: usize, load: &Load) -> Result<State, FemError>;
}

/// A reference mesh and the states on it, kept to go back to ([`run_stage_refitted`]).
struct Fixed {
    nodes: Vec<[f64; 3]>,
    refit: Vec<f64>,
    state: State,
    previous: Option<State>,
}

impl Fixed {
    fn take(model: &Model, refit: &dyn Refit, state: &State, previous: &Option<State>) -> Self {
        Self {
            nodes: model.mesh().nodes.clone(),
            refit: refit.snapshot(),
            state: state.clone(),
            previous: previous.clone(),
        }
    }

    /// Whether the model's mesh is no longer this one.
    fn moved(&self, model: &Model) -> bool {
        model.mesh().nodes != self.nodes
    }

    /// Put the model, the refit and the states back.
    fn restore(
        &self,
        model: &mut Model,
        refit: &mut dyn Refit,
        state: &mut State,
        previous: &mut Option<State>,
    ) -> Result<(), FemError> {
        if self.moved(model) {
            let identity = tubemem_mesh::hoop::Transfer::identity(self.nodes.len());
            model.move_reference(self.nodes.clone(), &identity, None, &mut [])?;
        }
        refit.restore(&self.refit);
        state.clone_from(&self.state);
        previous.clone_from(&self.previous);
        Ok(())
    }
}

/// The re-solves after moving the mesh allowed in one step: 3. Each move follows the
/// converged pressure, which the re-solve changes far less than the step did, so the shipped
/// cases need at most one (README "Contact").
pub const MAX_REFITS: usize = 3;

/// Move `model` to the nodes `refit` asks for at `value` with `at` (if it asks), carrying
/// `states` over; whether it moved.
fn follow(
    model: &mut Model,
    refit: &mut dyn Refit,
    value: f64,
    at: &State,
    load: &Load,
    states: &mut [&mut State],
) -> Result<bool, FemError> {
    let Some(nodes) = refit.nodes(model, at, value)? else {
        return Ok(false);
    };
    let transfer = tubemem_mesh::hoop::Transfer::between(model.mesh(), &nodes)?;
    model.move_reference(nodes, &transfer, load.contact.as_ref(), states)?;
    Ok(true)
}

/// Run one stage: the load parameter moves linearly from `stage.from` to `stage.to` (the load
/// built by `load(value)`). `on_step(model, state, info)` is called for every converged step, so
/// results can be written as the run goes; an error of the callback stops the stage.
///
/// A stress-free membrane has no stiffness against inextensional modes, and a bordered or gas
/// control amplifies them: from an unloaded state, first take a small pressure-controlled step
/// ([`StepSettings::prestress`]), which converges from the reference and gives the membrane its
/// geometric stiffness.
pub fn run_stage<E>(
    model: &mut Model,
    state: &mut State,
    stage: &Stage,
    load: impl Fn(f64) -> Load,
    on_step: impl FnMut(&Model, &State, &StepInfo) -> Result<(), E>,
) -> Result<(), StageError<E>> {
    run_stage_from(model, state, stage, None, load, on_step)
}

/// `state` moved along the secant from `previous` (at fraction `l0`) through it (at `l1`) to
/// fraction `l2`: x + r (x − x_prev), ϖ + r (ϖ − ϖ_prev), r = (l2 − l1)/(l1 − l0).
fn secant(state: &State, previous: &State, l0: f64, l1: f64, l2: f64) -> State {
    let r = (l2 - l1) / (l1 - l0);
    let mut out = state.clone();
    for (x, x0) in out.x.iter_mut().zip(&previous.x) {
        for k in 0..3 {
            x[k] += r * (x[k] - x0[k]);
        }
    }
    out.p += r * (state.p - previous.p);
    out
}

/// [`run_stage`], continued from `resume` (a [`StepInfo::progress`] of an earlier run, with
/// `state` the state of that step, and its [`StepInfo::previous`]) when given.
pub fn run_stage_from<E>(
    model: &mut Model,
    state: &mut State,
    stage: &Stage,
    resume: Option<(StepState, Option<State>)>,
    load: impl Fn(f64) -> Load,
    on_step: impl FnMut(&Model, &State, &StepInfo) -> Result<(), E>,
) -> Result<(), StageError<E>> {
    run_stage_refitted(model, state, stage, resume, load, on_step, None, None)
}

/// [`run_stage_from`] with the reference mesh following the solution by `refit` (see
/// [`Refit`]). A step whose re-solve on the moved mesh fails is cut back like any other, from
/// the last converged state carried to the moved mesh.
///
/// With a `guide`, the steps go to the guide's fractions and start from its states
/// ([`Guide`]); a resumed stage takes the same guide from where it stopped, so that it repeats
/// the uninterrupted one.
///
/// Its length is the adaptive load-stepping loop in one place: step size, the mesh refit, the
/// Newton solve, the cut-back of a failed step from the last converged state, and the growth
/// of the next; each branch updates the same step state.
#[allow(clippy::too_many_arguments)]
pub fn run_stage_refitted<E>(
    model: &mut Model,
    state: &mut State,
    stage: &Stage,
    resume: Option<(StepState, Option<State>)>,
    load: impl Fn(f64) -> Load,
    mut on_step: impl FnMut(&Model, &State, &StepInfo) -> Result<(), E>,
    mut refit: Option<&mut dyn Refit>,
    guide: Option<&dyn Guide>,
) -> Result<(), StageError<E>> {
    let (from, to) = (stage.from, stage.to);
    let set = &stage.settings;
    // the guide, while its states lead the steps
    let mut guide = guide.filter(|g| g.fractions().last() == Some(&1.0));
    if resume.is_none() {
        // nothing to do: the stage ends where it starts (a target equal to the current state)
        if (to - from).abs() <= 1e-14 * from.abs().max(to.abs()).max(1.0) {
            return Ok(());
        }
        // (a guided stage starts from the guide's loaded state instead)
        if state.p == 0.0 && guide.is_none() && !matches!(load(from).loading, Loading::Pressure(_))
        {
            prestress(model, state, stage)?;
        }
    }
    let (progress, mut previous) = resume.unwrap_or((
        StepState {
            lambda: 0.0,
            dl: 1.0 / set.initial_steps.max(1) as f64,
            step: 0,
            cuts: 0,
            previous_lambda: None,
            unguided: false,
        },
        None,
    ));
    let StepState {
        mut lambda,
        mut dl,
        mut step,
        mut cuts,
        mut previous_lambda,
        mut unguided,
    } = progress;
    if unguided {
        guide = None;
    }
    if previous_lambda.is_none() {
        previous = None;
    }
    // the last material error that rejected an attempt at the current step
    let mut material: Option<FemError> = None;
    while lambda < 1.0 {
        if step >= set.max_steps {
            return Err(StageError::Solve(FemError::StepLimit {
                stage: stage.index,
                steps: step,
                fraction: lambda,
            }));
        }
        // the guide's next state, where it leads: its first fraction past this one
        let guided = guide.and_then(|g| {
            g.fractions()
                .iter()
                .position(|&f| f > lambda + 1e-12)
                .map(|k| (g, k, g.fractions()[k]))
        });
        // snap to the end when within rounding of it (no zero-length last step)
        let next = match guided {
            Some((_, _, f)) => f,
            None if lambda + dl >= 1.0 - 1e-9 => 1.0,
            None => lambda + dl,
        };
        let value = from + (to - from) * next;
        let predict = |state: &State, previous: &Option<State>| match (previous, previous_lambda) {
            (Some(prev), Some(l0)) if lambda > l0 => secant(state, prev, l0, lambda, next),
            _ => state.clone(),
        };
        let l = load(value);
        let mut trial = match guided {
            Some((g, k, _)) => g.state(model, k, &l).map_err(StageError::Solve)?,
            None => predict(state, &previous),
        };
        let mut refits = 0;
        let moved = |source: FemError| crate::newton::NewtonError::Problem {
            iteration: 0,
            source,
        };
        // the step's difficulty for the step-size control: its first solve's iterations
        let mut difficulty = 0;
        let solved: Result<NewtonReport, crate::newton::NewtonError<FemError>> = (|| {
            // the mesh before the step's first move, to go back to where a solve on a moved
            // mesh fails: the step is then solved (or cut back) on the mesh it came from
            let before = refit
                .as_deref()
                .map(|r| Fixed::take(model, r, state, &previous));
            if let Some(r) = refit.as_deref_mut() {
                let at = trial.clone();
                let mut carried = carried(&mut trial, state, &mut previous);
                follow(model, r, value, &at, &l, &mut carried).map_err(moved)?;
            }
            let mut report = match model.solve(&mut trial, &l) {
                Ok(r) => r,
                Err(e) => {
                    let (Some(b), Some(r)) = (&before, refit.as_deref_mut()) else {
                        return Err(e);
                    };
                    if !b.moved(model) || matches!(e.cause(), Some(FemError::Interrupted)) {
                        return Err(e);
                    }
                    b.restore(model, r, state, &mut previous).map_err(moved)?;
                    trial = predict(state, &previous);
                    model.solve(&mut trial, &l)?
                }
            };
            difficulty = report.load_iterations();
            while let Some(r) = refit.as_deref_mut() {
                if refits == MAX_REFITS {
                    break;
                }
                let converged = Fixed::take(model, r, state, &previous);
                let kept = trial.clone();
                let at = trial.clone();
                let mut carried = carried(&mut trial, state, &mut previous);
                if !follow(model, r, value, &at, &l, &mut carried).map_err(moved)? {
                    break;
                }
                let again = match model.solve(&mut trial, &l) {
                    Ok(again) => again,
                    Err(e) if matches!(e.cause(), Some(FemError::Interrupted)) => return Err(e),
                    Err(_) => {
                        // the re-solve on the moved mesh failed: keep the step's converged
                        // state on the mesh it converged on
                        converged
                            .restore(model, r, state, &mut previous)
                            .map_err(moved)?;
                        trial = kept;
                        break;
                    }
                };
                refits += 1;
                // the step's iterations and updates are all its solves'; the state's own
                // measures (residual, inertia, gap) the last one's
                let (iterations, updates, augmenting) = (
                    report.iterations + again.iterations,
                    report.augmentation.updates + again.augmentation.updates,
                    report.augmentation.iterations + again.augmentation.iterations,
                );
                report = again;
                report.iterations = iterations;
                report.augmentation.updates = updates;
                report.augmentation.iterations = augmenting;
            }
            Ok(report)
        })();
        match solved {
            Ok(report) => {
                material = None;
                step += 1;
                previous_lambda = Some(lambda);
                lambda = next;
                previous = Some(std::mem::replace(state, trial));
                if guided.is_some() {
                    // the step the guide took: the length to go on from without it
                    dl = (lambda - previous_lambda.unwrap_or(0.0)).min(set.max_fraction);
                } else if difficulty <= set.easy_iterations {
                    dl = (dl * set.growth).min(set.max_fraction);
                }
                let info = StepInfo {
                    progress: StepState {
                        lambda,
                        dl,
                        step,
                        cuts,
                        previous_lambda,
                        unguided,
                    },
                    step,
                    value,
                    fraction: next,
                    load: &l,
                    newton: &report,
                    dw_ds: f64::NAN,
                    negative_conjugate: None,
                    previous: previous.as_ref(),
                    refits,
                };
                on_step(model, state, &info).map_err(|source| StageError::Observer {
                    stage: stage.index,
                    step,
                    source,
                })?;
            }
            Err(e) => {
                if matches!(e.cause(), Some(FemError::Interrupted)) {
                    return Err(StageError::Solve(FemError::Interrupted));
                }
                if let Some(m) = e.cause().filter(|c| c.material_cause().is_some()) {
                    material = Some(m.clone());
                }
                if guided.is_some() {
                    // cut back the guide's step, and go on without it (from the pre-stress a
                    // stress-free start takes without a guide)
                    guide = None;
                    unguided = true;
                    dl = next - lambda;
                    if state.p == 0.0 && !matches!(l.loading, Loading::Pressure(_)) {
                        prestress(model, state, stage)?;
                    }
                }
                cuts += 1;
                dl *= 0.5;
                if cuts > set.max_cuts {
                    let own = e.cause().is_some_and(|c| c.material_cause().is_some());
                    let near_locking = model
                        .locking_proximity(&state.x)
                        .filter(|l| l.fraction() >= crate::model::NEAR_LOCKING);
                    return Err(StageError::Solve(FemError::Stage {
                        stage: stage.index,
                        step: step + 1,
                        value,
                        cuts: cuts - 1,
                        material: if own { None } else { material.map(Box::new) },
                        near_locking,
                        source: Box::new(e),
                    }));
                }
            }
        }
    }
    Ok(())
}

/// Take the stress-free `state` to the small pressure [`StepSettings::prestress`] (halved on
/// failure down to [`StepSettings::min_prestress`]), which converges from the reference and
/// gives the membrane its geometric stiffness.
pub fn prestress<E>(
    model: &mut Model,
    state: &mut State,
    stage: &Stage,
) -> Result<(), StageError<E>> {
    let set = &stage.settings;
    let mut p0 = set.prestress;
    loop {
        // From the stress-free state Newton has no out-of-plane stiffness to work with (it
        // creeps, its corrections capped, for some twenty iterations); from a uniform dilation
        // about the origin (the tube's centre, on every symmetry plane) every element is in
        // equibiaxial tension and it converges at once. The dilation is the small-strain
        // cylinder's hoop strain under ϖ: N_s = ϖR and N ≈ 12 μH ε for equibiaxial stretch of
        // an incompressible membrane give ε = ϖ/12 (the caps, as spheres, want half of it);
        // constrained components (symmetry planes, pins, plug rings) stay where they are.
        let mut trial = dilated(model, state, p0 / 12.0);
        let first = model.solve(&mut trial, &Load::pressure(p0));
        let outcome = match first {
            Ok(r) => Ok(r),
            Err(e) if matches!(e.cause(), Some(FemError::Interrupted)) => Err(e),
            Err(_) => {
                // the dilation did not help: from the stress-free state, as before
                trial = state.clone();
                model.solve(&mut trial, &Load::pressure(p0))
            }
        };
        match outcome {
            Ok(_) => {
                *state = trial;
                return Ok(());
            }
            Err(e) if matches!(e.cause(), Some(FemError::Interrupted)) => {
                return Err(StageError::Solve(FemError::Interrupted));
            }
            Err(e) => {
                p0 *= 0.5;
                if p0 < set.min_prestress {
                    return Err(StageError::Solve(FemError::Stage {
                        stage: stage.index,
                        step: 0,
                        value: p0,
                        cuts: 0,
                        material: None,
                        near_locking: None,
                        source: Box::new(e),
                    }));
                }
            }
        }
    }
}

/// `state` dilated by 1 + `eps` about the origin, on the free components only.
fn dilated(model: &Model, state: &State, eps: f64) -> State {
    let mut out = state.clone();
    for (i, x) in out.x.iter_mut().enumerate() {
        for (k, c) in x.iter_mut().enumerate() {
            if model.dofs().eq(i, k).is_some() {
                *c *= 1.0 + eps;
            }
        }
    }
    out
}

/// Why a stage stopped.
#[derive(Debug)]
pub enum StageError<E> {
    /// the solve failed (a [`FemError::Stage`] naming stage, step and load)
    Solve(FemError),
    /// the step callback failed (e.g. writing the results)
    Observer {
        stage: usize,
        step: usize,
        source: E,
    },
}

impl<E> std::fmt::Display for StageError<E> {
    /// What stopped, naming where; the cause is the [`std::error::Error::source`].
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Solve(_) => write!(f, "the stage's solve failed"),
            Self::Observer { stage, step, .. } => {
                write!(f, "stage {stage} step {step}: the step's observer failed")
            }
        }
    }
}

impl<E: std::error::Error + 'static> std::error::Error for StageError<E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Solve(e) => Some(e),
            Self::Observer { source, .. } => Some(source),
        }
    }
}

#[cfg(test)]
mod error_tests {
    use super::StageError;
    use std::error::Error;

    /// A stage's error is a `std::error::Error` whose source is its cause (issue #22: it was
    /// neither `Display` nor `Error`, so front ends could not walk its chain).
    #[test]
    fn a_stage_error_keeps_its_cause_as_source() {
        let e: StageError<std::io::Error> = StageError::Observer {
            stage: 2,
            step: 5,
            source: std::io::Error::other("disk full"),
        };
        assert_eq!(e.to_string(), "stage 2 step 5: the step's observer failed");
        assert_eq!(e.source().unwrap().to_string(), "disk full");
    }
}
