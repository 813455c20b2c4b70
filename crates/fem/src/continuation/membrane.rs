//! The membrane model as an arc-length [`Path`]: its load parameter ([`ArcLoading`]: the
//! pressure, or the planes' parameter with the gas closed), its bordered solves, and the
//! arc-length stage that the application runs ([`run_arc_stage`]).

use super::*;

/// Inverse iterations for the critical mode of a bifurcation: K is singular at the located
/// point to its bracket, so the iteration converges by the ratio of the two smallest
/// eigenvalues, which is tiny; 8 solves leave the mode converged to rounding.
pub const MODE_ITERATIONS: usize = 8;

/// Inverse iterations for the diagnosis of a stalled path ([`crate::model::Model::mode_report`]):
/// away from a located point the two smallest eigenvalues need not be far apart, and 30 solves
/// converge the mode of a neutral translation (eigenvalue 1e-12 of the stiffness and below) to
/// a few digits.
pub const NEUTRAL_ITERATIONS: usize = 30;

/// What a membrane arc-length path varies as its load parameter λ.
#[derive(Clone, Debug, PartialEq)]
pub enum ArcLoading {
    /// λ = ϖ, the reduced pressure, under fixed planes (if any)
    Pressure(Option<crate::contact::Contact>),
    /// λ = the planes' parameter (`State::planes`), the gas closed in with Boyle's constant
    /// `pv`: a squeeze or confine stage continued by arc length
    ClosedGas {
        pv: f64,
        planes: crate::contact::MovingPlanes,
    },
}

/// The membrane model as a [`Path`]: u the free dofs, λ the reduced pressure ϖ or the planes'
/// parameter ([`ArcLoading`]). The weight of the displacements is 1/n_eq, so that ‖Δu‖ is their
/// root mean square (in R), of the same order as Δϖ and as a plate's travel.
pub struct MembranePath<'a> {
    pub model: &'a mut crate::model::Model,
    pub loading: ArcLoading,
    /// the report of the last successful corrector
    pub last: Option<crate::newton::NewtonReport>,
    /// a neutral mode held out of the tangent and the corrector's load column
    /// ([`Path::hold_neutral`])
    pub neutral: Option<Vec<f64>>,
}

impl ArcLoading {
    /// The load at the state `s` of the path (the planes where λ puts them).
    pub fn load_at(&self, s: &crate::model::State) -> crate::model::Load {
        use crate::model::{Load, Loading};
        match self {
            ArcLoading::Pressure(contact) => Load {
                loading: Loading::Pressure(s.p),
                contact: contact.clone(),
            },
            ArcLoading::ClosedGas { pv, planes } => {
                Load::with_contact(Loading::Gas { pv: *pv }, planes.at(s.planes))
            }
        }
    }
}

impl<'a> MembranePath<'a> {
    /// The path of `model` under `loading`.
    pub fn new(model: &'a mut crate::model::Model, loading: ArcLoading) -> Self {
        Self {
            model,
            loading,
            last: None,
            neutral: None,
        }
    }

    /// The load at the state `s` of the path.
    pub fn load_at(&self, s: &crate::model::State) -> crate::model::Load {
        self.loading.load_at(s)
    }
}

fn problem_error(source: crate::FemError) -> crate::newton::NewtonError<crate::FemError> {
    crate::newton::NewtonError::Problem {
        iteration: 0,
        source,
    }
}

impl Path for MembranePath<'_> {
    type State = crate::model::State;
    type Error = crate::newton::NewtonError<crate::FemError>;
    fn load(&self, s: &Self::State) -> f64 {
        match self.loading {
            ArcLoading::Pressure(_) => s.p,
            ArcLoading::ClosedGas { .. } => s.planes,
        }
    }
    fn weight(&self) -> f64 {
        1.0 / self.model.n_eq().max(1) as f64
    }
    fn difference(&self, a: &Self::State, b: &Self::State) -> Vec<f64> {
        self.model.free_difference(&a.x, &b.x)
    }
    fn predict(&self, base: &Self::State, tu: &[f64], tl: f64, ds: f64) -> Self::State {
        let mut s = base.clone();
        self.model.free_update(&mut s.x, tu, ds);
        match self.loading {
            ArcLoading::Pressure(_) => s.p += ds * tl,
            ArcLoading::ClosedGas { .. } => s.planes += ds * tl,
        }
        s
    }
    fn tangent(&mut self, s: &Self::State) -> Result<Tangent, Self::Error> {
        let (b, g, negative) = match &self.loading {
            ArcLoading::Pressure(_) => {
                let load = self.load_at(s);
                match &self.neutral {
                    Some(phi0) => self.model.pressure_tangent_deflated(s, &load, phi0).map(
                        |(b, g, n, phi)| {
                            // released once the mode is no longer neutral
                            self.neutral = phi;
                            (b, g, n)
                        },
                    ),
                    None => self.model.pressure_tangent(s, &load),
                }
            }
            ArcLoading::ClosedGas { pv, planes } => self.model.plane_tangent(s, *pv, planes),
        }
        .map_err(problem_error)?;
        Ok(Tangent::new(b, &g, negative))
    }
    fn critical_mode(&mut self, s: &Self::State) -> Result<Option<Vec<f64>>, Self::Error> {
        let load = self.load_at(s);
        self.model
            .smallest_mode(s, &load, MODE_ITERATIONS)
            .map(|(v, _)| Some(v))
            .map_err(problem_error)
    }
    fn correct(
        &mut self,
        s: &mut Self::State,
        arc: &Arc<'_, Self::State>,
    ) -> Result<usize, Self::Error> {
        let c = crate::model::ArcConstraint {
            x0: &arc.base.x,
            p0: self.load(arc.base),
            tx: arc.tu,
            tp: arc.tl,
            w: arc.w,
            ds: arc.ds,
            neutral: self.neutral.as_deref(),
        };
        let r = match &self.loading {
            ArcLoading::Pressure(contact) => {
                let load = crate::model::Load {
                    loading: crate::model::Loading::Pressure(s.p),
                    contact: contact.clone(),
                };
                self.model.solve_arc(s, &load, &c)?
            }
            ArcLoading::ClosedGas { pv, planes } => self.model.solve_arc_gas(s, *pv, planes, &c)?,
        };
        // the step length follows the load step's own difficulty, not the augmentations'
        let it = r.load_iterations();
        self.last = Some(r);
        Ok(it)
    }
    fn is_final(&self, e: &Self::Error) -> bool {
        matches!(e.cause(), Some(crate::FemError::Interrupted))
    }
    fn hold_neutral(&mut self, s: &Self::State) -> Result<bool, Self::Error> {
        // under pressure only (a closed gas's stiffness has no such family here), once
        if self.neutral.is_some() || !matches!(self.loading, ArcLoading::Pressure(_)) {
            return Ok(false);
        }
        let load = self.load_at(s);
        let (report, smallest) = self
            .model
            .mode_report(s, &load, NEUTRAL_ITERATIONS)
            .map_err(problem_error)?;
        if !report.is_neutral() {
            return Ok(false);
        }
        // the smallest mode, made free of the load where a second nearly neutral mode (the
        // fronts' advance on a plateau) mixes with it; held only if what remains is neutral
        let Some(phi) = self
            .model
            .pressure_tangent_deflated(s, &load, &smallest)
            .map_err(problem_error)?
            .3
        else {
            return Ok(false);
        };
        self.neutral = Some(phi);
        Ok(true)
    }
}

/// One arc-length stage of the membrane: from the equilibrium `state`, follow the path in
/// (x, ϖ) until `monitor` reaches `stage.to` (`stage.from` is its value at the start, for the
/// progress fraction). Every converged step goes to `on_step` as a [`StepInfo`] (its `value` the
/// monitored quantity, its Newton report's inertia the negative pivots of the pressure-control
/// stiffness K), every located critical point to `on_critical`; `state` is the last converged
/// step whatever happens. [`StepState::lambda`] carries the arc length and `dl` the next Δs.
///
/// Its length: the membrane's path is set up (loading, monitor, target, resume), followed by
/// [`super::follow`], and its events turned into the stage's steps and critical points, with
/// the target's overshoot located back, in one place so that a resumed stage repeats it.
#[allow(clippy::too_many_arguments)]
pub fn run_arc_stage<E>(
    model: &mut crate::model::Model,
    state: &mut crate::model::State,
    stage: &Stage,
    resume: Option<StepState>,
    loading: ArcLoading,
    monitor: &dyn Fn(&crate::model::State) -> f64,
    first_direction: f64,
    switch_fraction: Option<f64>,
    mut on_step: impl FnMut(&crate::model::Model, &crate::model::State, &StepInfo) -> Result<(), E>,
    mut on_critical: impl FnMut(
        &mut crate::model::Model,
        &Critical<crate::model::State>,
    ) -> Result<(), E>,
) -> Result<Vec<Critical<crate::model::State>>, StageError<E>> {
    use crate::FemError;
    let settings = ArcSettings {
        initial_steps: stage.settings.initial_steps,
        max_cuts: stage.settings.max_cuts,
        max_steps: stage.settings.max_steps,
        first_direction,
        orient_to_target: resume.is_none(),
        switch_fraction,
        ..ArcSettings::default()
    };
    let mut path = MembranePath::new(model, loading);
    if resume.is_some() {
        // a run resumed past a neutral point holds its mode again at once, as the run before
        // the checkpoint did (it was reported then); a mode that is not neutral here is not held
        // (an error here only means no hold: the path finds the mode itself if it needs to)
        let _ = path.hold_neutral(state);
    }
    let target = Target {
        name: "target",
        monitor,
        value: stage.to,
    };
    let span = stage.to - stage.from;
    let index = stage.index;
    // a resumed stage numbers its steps and measures its arc length on from the checkpoint
    let (step0, s0) = resume.map_or((0, 0.0), |r| (r.step, r.lambda));
    let result = follow(
        &mut path,
        state.clone(),
        &target,
        &settings,
        |path, event| {
            match event {
                ArcEvent::Step(s) => {
                    let mut newton = path.last.clone().unwrap_or(crate::newton::NewtonReport {
                        iterations: s.iterations,
                        residual: 0.0,
                        history: vec![],
                        inertia: Default::default(),
                        augmentation: Default::default(),
                    });
                    newton.inertia.negative_pivots = s.negative_pivots;
                    let info = StepInfo {
                        progress: StepState {
                            lambda: s0 + s.s,
                            dl: s.ds,
                            step: step0 + s.step,
                            cuts: s.cuts,
                            previous_lambda: None,
                            unguided: false,
                        },
                        step: step0 + s.step,
                        value: s.monitor,
                        // exactly 1 at the located target (the stage end), below 1 before it
                        fraction: if s.at_target || span == 0.0 {
                            1.0
                        } else {
                            ((s.monitor - stage.from) / span).min(1.0 - 1e-12)
                        },
                        load: &path.load_at(s.state),
                        newton: &newton,
                        dw_ds: s.tl,
                        negative_conjugate: Some(s.negative_pivots_conjugate),
                        previous: None,
                        refits: 0,
                    };
                    *state = s.state.clone();
                    on_step(path.model, s.state, &info)
                }
                ArcEvent::Critical(c) => {
                    let mut c = c.clone();
                    c.step += step0;
                    c.s += s0;
                    on_critical(path.model, &c)
                }
            }
        },
    );
    // a path that stalls or turns where the stiffness has a neutral mode: say so (the
    // equilibria there form a family, and no tangent picks one member)
    let neutral = match &result {
        Err(ArcError::Turn { .. } | ArcError::Stalled { .. }) => {
            let load = path.load_at(state);
            path.model
                .mode_report(state, &load, NEUTRAL_ITERATIONS)
                .ok()
                .map(|(m, _)| m)
                .filter(|m| m.is_neutral())
        }
        _ => None,
    };
    let why = |what: String| {
        match neutral {
        Some(m) => format!(
            "{what}. At the last converged step the stiffness has a neutral mode (eigenvalue {:.1e} of its largest diagonal entry; {:.0} % axial; volume change gᵀφ/‖g‖ = {:.1e}): the equilibria there form a family — a bulge that can sit anywhere along the tube — and no path tangent picks one. Model half the tube (symmetry = \"half\" or finer) to hold the bulge at mid-span",
            m.relative_eigenvalue,
            100.0 * m.axial_share,
            m.volume_change
        ),
        None => what,
    }
    };
    result.map_err(|e| match e {
        ArcError::Observer { step, source } => StageError::Observer {
            stage: index,
            step: step0 + step,
            source,
        },
        ArcError::Final { .. } => StageError::Solve(FemError::Interrupted),
        ArcError::StepLimit { steps, monitor, .. } => StageError::Solve(FemError::StepLimit {
            stage: index,
            steps,
            fraction: if span != 0.0 {
                (monitor - stage.from) / span
            } else {
                0.0
            },
        }),
        ArcError::Stalled {
            step,
            ds,
            cuts,
            load: _,
            source,
        } => StageError::Solve(FemError::Arc {
            stage: index,
            step: step0 + step,
            // the pressure of the last converged state (the path's load parameter may be a
            // plate position)
            p: state.p,
            what: why(format!(
                "no convergence after {cuts} halvings of the arc length (last Δs = {ds:.3e})"
            )),
            source: Some(Box::new(source)),
        }),
        ArcError::Turn { step, ds, load: _ } => StageError::Solve(FemError::Arc {
            stage: index,
            step: step0 + step,
            p: state.p,
            what: why(format!(
                "the path turns by more than {:.0}° even within Δs = {ds:.3e}",
                ArcSettings::default().min_turn_cos.acos().to_degrees()
            )),
            source: None,
        }),
        ArcError::Tangent { step, source } => StageError::Solve(FemError::Arc {
            stage: index,
            step: step0 + step,
            p: state.p,
            what: "the path tangent could not be computed".into(),
            source: Some(Box::new(source)),
        }),
    })
}
