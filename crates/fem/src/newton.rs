//! A damped Newton driver that knows nothing of membranes.
//!
//! A [`Problem`] linearizes itself at a state (residual measure, convergence test, Newton
//! correction) and evaluates trial states; the driver caps the step length, backtracks, and
//! returns a typed report with the residual history, or a typed error.
//!
//! ```text
//! for it = 0, 1, …, max_iterations:
//!     lin = problem.linearize(x)               (assembly, factorization, correction dx)
//!     if lin.converged: return
//!     t = min(1, max_step / |dx|_node)          (step cap)
//!     repeat up to `backtracks` times:          (line search on x + t dx)
//!         accept if the problem is bordered (full steps), or the residual fell, or the
//!         potential fell by Armijo's rule Π(x + t dx) ≤ Π(x) + c t Rᵀdx, or t < min_fraction
//!         t ← t/2
//! ```

use std::fmt;

/// The driver's settings. Every number the iteration uses is here, named.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// converged when the problem's scaled residual is at most `rtol`
    pub rtol: f64,
    pub max_iterations: usize,
    /// the largest nodal displacement per iteration (in R); longer corrections are scaled down
    pub max_step: f64,
    /// halvings of the step in one line search before the iteration gives up
    pub backtracks: usize,
    /// Armijo's sufficient-decrease constant c
    pub armijo: f64,
    /// a step fraction below which the trial is taken whatever it gives
    pub min_fraction: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            rtol: 1e-9,
            max_iterations: 30,
            max_step: 0.25,
            backtracks: 8,
            armijo: 1e-4,
            min_fraction: 1e-3,
        }
    }
}

/// What the problem reports at the linearization point.
pub struct Linearization<S> {
    /// the scaled residual tested against `rtol`
    pub residual: f64,
    /// the residual plus the scaled constraint violation (reported on failure)
    pub merit: f64,
    pub converged: bool,
    /// the Newton correction
    pub step: S,
    /// the total potential Π at the point (for the Armijo test)
    pub potential: f64,
    /// Rᵀ·step, the potential's slope along the correction
    pub slope: f64,
    /// bordered (constrained) problems accept full steps: the merit mixes R and c
    pub bordered: bool,
    /// the problem-specific inertia data of the operator solved
    pub inertia: Inertia,
}

/// The stability data of the factorized operator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inertia {
    /// negative eigenvalues of the operator actually solved
    pub negative_pivots: usize,
    /// the diagonal shift that had to be added to factorize (0 in regular states)
    pub shift: f64,
    /// the count is an earlier linearization's (the factor was reused, not made here)
    pub stale: bool,
}

/// A trial state's residual and potential.
pub struct Evaluation {
    pub residual: f64,
    pub potential: f64,
}

/// A nonlinear problem the driver can solve.
pub trait Problem {
    type State: Clone;
    type Step;
    type Error;
    /// Linearize at `state` (which the problem may update, e.g. a pressure that follows from it).
    fn linearize(
        &mut self,
        state: &mut Self::State,
    ) -> Result<Linearization<Self::Step>, Self::Error>;
    /// Evaluate a trial state without the tangent.
    fn evaluate(&self, state: &Self::State) -> Result<Evaluation, Self::Error>;
    /// `state` ← `base` + t·`step`.
    fn update(&self, base: &Self::State, step: &Self::Step, t: f64, state: &mut Self::State);
    /// The step's largest nodal displacement (for the step cap).
    fn step_size(&self, step: &Self::Step) -> f64;
    /// Whether every entry of the step is finite.
    fn step_is_finite(&self, step: &Self::Step) -> bool;
    /// For a residual that is only piecewise smooth (e.g. contact, whose traction has a kink
    /// where a point touches): where the step of `lin` from `state` ends at `trial` on other
    /// pieces than `state`'s, the linearization at `state` on `trial`'s pieces (a semi-smooth
    /// Newton step), with `lin`'s residual, merit and potential. None (the default): the
    /// residual is smooth, or `trial` is on the same pieces.
    fn relinearize(
        &mut self,
        state: &mut Self::State,
        lin: &Linearization<Self::Step>,
        trial: &Self::State,
    ) -> Result<Option<Linearization<Self::Step>>, Self::Error> {
        let _ = (state, lin, trial);
        Ok(None)
    }
}

/// The semi-smooth re-linearizations ([`Problem::relinearize`]) one Newton iteration may take
/// when its full step is rejected: 2 (a second where the first step also ends across a kink,
/// e.g. a point the first one took into contact that the new step frees).
pub const MAX_RELINEARIZATIONS: usize = 2;

/// A converged solve.
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonReport {
    /// all Newton iterations, those of the augmentations' re-solves included
    pub iterations: usize,
    pub residual: f64,
    /// the scaled residual (merit) at every linearization
    pub history: Vec<f64>,
    pub inertia: Inertia,
    /// the contact multipliers' updates of an augmented-Lagrangian solve (zero otherwise)
    pub augmentation: Augmentation,
}

impl NewtonReport {
    /// The iterations of the first solve, before any augmentation: the measure of how hard
    /// the load step itself was (for step-size control).
    pub fn load_iterations(&self) -> usize {
        self.iterations - self.augmentation.iterations
    }
}

/// The Uzawa updates of the contact multipliers in one solve
/// ([`crate::contact::Enforcement::Augmented`]).
#[derive(
    schemars::JsonSchema,
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    serde::Serialize,
    serde::Deserialize,
)]
pub struct Augmentation {
    /// multiplier updates, each followed by a Newton re-solve
    pub updates: usize,
    /// the Newton iterations of those re-solves
    pub iterations: usize,
    /// the largest |g| where a plane pushes at the returned state (in R): within the gap
    /// tolerance
    pub gap: f64,
    /// the largest multiplier change |Δλ| of the last update applied (per reference area, in
    /// μH/R; 0 when none was needed)
    pub change: f64,
    /// the largest penetration of a plane where it pushes, at the returned state (in R)
    pub penetration: f64,
}

/// Why a solve failed.
#[derive(Clone, Debug, PartialEq)]
pub enum NewtonError<E> {
    /// the problem could not be linearized or evaluated (assembly, factorization)
    Problem { iteration: usize, source: E },
    /// the correction has non-finite entries
    NonFinite { iteration: usize, history: Vec<f64> },
    /// no step length along the correction reduced the residual or the potential;
    /// `rejected` is why the last trial state that could not even be evaluated failed (e.g. a
    /// stretch beyond the law's locking limit)
    NoDescent {
        iteration: usize,
        history: Vec<f64>,
        rejected: Option<Box<E>>,
    },
    /// the iteration limit was reached; `rejected` as for `NoDescent`, from any line search
    NoConvergence {
        iterations: usize,
        tolerance: f64,
        history: Vec<f64>,
        rejected: Option<Box<E>>,
    },
}

impl<E> NewtonError<E> {
    /// The residual history up to the failure.
    pub fn history(&self) -> &[f64] {
        match self {
            NewtonError::Problem { .. } => &[],
            NewtonError::NonFinite { history, .. }
            | NewtonError::NoDescent { history, .. }
            | NewtonError::NoConvergence { history, .. } => history,
        }
    }

    /// The last residual, if any was computed.
    pub fn last_residual(&self) -> Option<f64> {
        self.history().last().copied()
    }

    /// The problem's own error behind this one: the failed linearization, or the last trial
    /// state that could not be evaluated.
    pub fn cause(&self) -> Option<&E> {
        match self {
            NewtonError::Problem { source, .. } => Some(source),
            NewtonError::NoDescent { rejected, .. }
            | NewtonError::NoConvergence { rejected, .. } => rejected.as_deref(),
            NewtonError::NonFinite { .. } => None,
        }
    }
}

/// The residual history, the first three and the last five when it is longer than ten.
fn fmt_history(h: &[f64]) -> String {
    let f = |r: &f64| format!("{r:.2e}");
    if h.len() <= 10 {
        h.iter().map(f).collect::<Vec<_>>().join(", ")
    } else {
        let head: Vec<String> = h[..3].iter().map(f).collect();
        let tail: Vec<String> = h[h.len() - 5..].iter().map(f).collect();
        format!("{}, …, {}", head.join(", "), tail.join(", "))
    }
}

impl<E: fmt::Display> fmt::Display for NewtonError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NewtonError::Problem { iteration, .. } => {
                write!(f, "Newton iteration {iteration}")
            }
            NewtonError::NonFinite { iteration, .. } => write!(
                f,
                "Newton iteration {iteration}: the correction is not finite (singular tangent)"
            ),
            NewtonError::NoDescent {
                iteration,
                history,
                rejected,
            } => write!(
                f,
                "Newton iteration {iteration}: no step length reduces the residual or the potential (residuals {}){}",
                fmt_history(history),
                if rejected.is_some() { "; a trial state was rejected" } else { "" }
            ),
            NewtonError::NoConvergence {
                iterations,
                tolerance,
                history,
                rejected,
            } => write!(
                f,
                "Newton did not converge in {iterations} iterations (residual {:.3e}, tolerance {tolerance:.1e}; residuals {}){}",
                history.last().copied().unwrap_or(f64::NAN),
                fmt_history(history),
                if rejected.is_some() { "; a trial state was rejected" } else { "" }
            ),
        }
    }
}

impl<E: std::error::Error + 'static> std::error::Error for NewtonError<E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.cause()
            .map(|e| e as &(dyn std::error::Error + 'static))
    }
}

/// Solve `problem` from `state`; on success `state` is the converged state, on failure it is
/// the last accepted iterate.
pub fn solve<P: Problem>(
    problem: &mut P,
    state: &mut P::State,
    settings: &NewtonSettings,
) -> Result<NewtonReport, NewtonError<P::Error>> {
    let mut history = Vec::new();
    let mut rejected = None;
    for it in 0..=settings.max_iterations {
        let lin = problem
            .linearize(state)
            .map_err(|source| NewtonError::Problem {
                iteration: it,
                source,
            })?;
        history.push(lin.merit);
        if lin.converged {
            return Ok(NewtonReport {
                iterations: it,
                residual: lin.residual,
                history,
                inertia: lin.inertia,
                augmentation: Augmentation::default(),
            });
        }
        if it == settings.max_iterations {
            break;
        }
        let mut lin = lin;
        let mut base = state.clone();
        let mut relinearized = 0;
        let mut accepted = false;
        'direction: loop {
            let size = problem.step_size(&lin.step);
            let mut t = if size > settings.max_step {
                settings.max_step / size
            } else {
                1.0
            };
            if !problem.step_is_finite(&lin.step) {
                return Err(NewtonError::NonFinite {
                    iteration: it,
                    history,
                });
            }
            let armijo = |t: f64| lin.potential + settings.armijo * t * lin.slope;
            for trial_index in 0..settings.backtracks {
                problem.update(&base, &lin.step, t, state);
                match problem.evaluate(state) {
                    Ok(trial) => {
                        if lin.bordered
                            || trial.residual < lin.residual
                            || trial.potential < armijo(t)
                            || t < settings.min_fraction
                        {
                            accepted = true;
                            break 'direction;
                        }
                    }
                    Err(e) => rejected = Some(Box::new(e)),
                }
                // the first (longest) trial rejected: where it ends across a kink of the
                // residual, step again on the pieces it ends on
                if trial_index == 0 && relinearized < MAX_RELINEARIZATIONS {
                    let branched =
                        problem
                            .relinearize(&mut base, &lin, state)
                            .map_err(|source| NewtonError::Problem {
                                iteration: it,
                                source,
                            })?;
                    if let Some(branched) = branched {
                        relinearized += 1;
                        lin = branched;
                        continue 'direction;
                    }
                }
                t *= 0.5;
            }
            break;
        }
        if !accepted {
            *state = base;
            return Err(NewtonError::NoDescent {
                iteration: it,
                history,
                rejected,
            });
        }
    }
    Err(NewtonError::NoConvergence {
        iterations: settings.max_iterations,
        tolerance: settings.rtol,
        history,
        rejected,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x) = x³ − 2 (root 2^(1/3)), Π = x⁴/4 − 2x: the driver converges quadratically and
    /// records its history; a problem whose linearization fails reports the failure with its
    /// iteration, and a problem with too few iterations reports no convergence.
    struct Cubic {
        fail_at: Option<f64>,
    }
    impl Problem for Cubic {
        type State = f64;
        type Step = f64;
        type Error = String;
        fn linearize(&mut self, x: &mut f64) -> Result<Linearization<f64>, String> {
            if let Some(limit) = self.fail_at {
                if *x > limit {
                    return Err(format!("x = {x} beyond {limit}"));
                }
            }
            let r = *x * *x * *x - 2.0;
            let step = -r / (3.0 * *x * *x);
            Ok(Linearization {
                residual: r.abs() / 2.0,
                merit: r.abs() / 2.0,
                converged: r.abs() / 2.0 <= 1e-14,
                step,
                potential: x.powi(4) / 4.0 - 2.0 * *x,
                slope: r * step,
                bordered: false,
                inertia: Inertia::default(),
            })
        }
        fn evaluate(&self, x: &f64) -> Result<Evaluation, String> {
            Ok(Evaluation {
                residual: (x.powi(3) - 2.0).abs() / 2.0,
                potential: x.powi(4) / 4.0 - 2.0 * x,
            })
        }
        fn update(&self, base: &f64, step: &f64, t: f64, x: &mut f64) {
            *x = base + t * step;
        }
        fn step_size(&self, step: &f64) -> f64 {
            step.abs()
        }
        fn step_is_finite(&self, step: &f64) -> bool {
            step.is_finite()
        }
    }

    #[test]
    fn newton_driver_converges_and_reports_failures() {
        let settings = NewtonSettings {
            max_step: 10.0,
            ..Default::default()
        };
        let mut x = 1.0;
        let rep = solve(&mut Cubic { fail_at: None }, &mut x, &settings).unwrap();
        assert!((x - 2f64.cbrt()).abs() < 1e-14);
        assert_eq!(rep.history.len(), rep.iterations + 1);
        // quadratic convergence: each residual at most ~ the square of the previous one (×10)
        let h = &rep.history;
        assert!(h[h.len() - 2] <= 10.0 * h[h.len() - 3].powi(2));

        let mut x = 1.0;
        let err = solve(&mut Cubic { fail_at: Some(1.1) }, &mut x, &settings).unwrap_err();
        assert!(
            matches!(err, NewtonError::Problem { iteration: 1, .. }),
            "{err:?}"
        );

        let few = NewtonSettings {
            max_iterations: 2,
            ..settings
        };
        let mut x = 1.0;
        let err = solve(&mut Cubic { fail_at: None }, &mut x, &few).unwrap_err();
        match err {
            NewtonError::NoConvergence { history, .. } => assert_eq!(history.len(), 3),
            e => panic!("{e:?}"),
        }
    }

    /// A soft spring a pulled by f against a stiff penalty κ beyond the gap c:
    /// Π(x) = a x²/2 − f x + κ⟨x − c⟩²/2, exact x* = (f + κc)/(a + κ) (pushed, since f > ac).
    /// From x = 0 (free), Newton's step f/a goes far past the kink, and every halving of it
    /// still ends deep in the penalty: the plain driver finds no descent. With the step
    /// re-linearized on the piece it ends on, the step lands on x* (the residual is linear
    /// there) and the driver converges at the next linearization.
    struct Touch {
        a: f64,
        f: f64,
        c: f64,
        kappa: f64,
        semi_smooth: bool,
    }
    impl Touch {
        fn residual(&self, x: f64) -> f64 {
            self.a * x - self.f + self.kappa * (x - self.c).max(0.0)
        }
        fn potential(&self, x: f64) -> f64 {
            let pen = (x - self.c).max(0.0);
            0.5 * self.a * x * x - self.f * x + 0.5 * self.kappa * pen * pen
        }
        /// the linearization at x on the piece of `piece` (pushed where piece > c)
        fn on_piece(&self, x: f64, piece: f64) -> Linearization<f64> {
            let pushed = piece > self.c;
            let r = self.a * x - self.f
                + if pushed {
                    self.kappa * (x - self.c)
                } else {
                    0.0
                };
            let k = self.a + if pushed { self.kappa } else { 0.0 };
            let step = -r / k;
            let own = self.residual(x);
            Linearization {
                residual: own.abs(),
                merit: own.abs(),
                converged: own.abs() <= 1e-12,
                step,
                potential: self.potential(x),
                slope: own * step,
                bordered: false,
                inertia: Inertia::default(),
            }
        }
    }
    impl Problem for Touch {
        type State = f64;
        type Step = f64;
        type Error = String;
        fn linearize(&mut self, x: &mut f64) -> Result<Linearization<f64>, String> {
            Ok(self.on_piece(*x, *x))
        }
        fn evaluate(&self, x: &f64) -> Result<Evaluation, String> {
            Ok(Evaluation {
                residual: self.residual(*x).abs(),
                potential: self.potential(*x),
            })
        }
        fn update(&self, base: &f64, step: &f64, t: f64, x: &mut f64) {
            *x = base + t * step;
        }
        fn step_size(&self, step: &f64) -> f64 {
            step.abs()
        }
        fn step_is_finite(&self, step: &f64) -> bool {
            step.is_finite()
        }
        fn relinearize(
            &mut self,
            x: &mut f64,
            _lin: &Linearization<f64>,
            trial: &f64,
        ) -> Result<Option<Linearization<f64>>, String> {
            let changed = (*x > self.c) != (*trial > self.c);
            Ok((self.semi_smooth && changed).then(|| self.on_piece(*x, *trial)))
        }
    }

    #[test]
    fn a_step_across_a_kink_is_taken_on_the_piece_it_ends_on() {
        let settings = NewtonSettings {
            max_step: 10.0,
            ..Default::default()
        };
        let touch = |semi_smooth| Touch {
            a: 1.0,
            f: 1.0,
            c: 1e-4,
            kappa: 1e8,
            semi_smooth,
        };
        let exact = (1.0 + 1e8 * 1e-4) / (1.0 + 1e8);
        let mut x = 0.0;
        let err = solve(&mut touch(false), &mut x, &settings).unwrap_err();
        assert!(
            matches!(err, NewtonError::NoDescent { iteration: 0, .. }),
            "{err:?}"
        );
        assert_eq!(x, 0.0, "a failed solve leaves the state where it was");
        let mut x = 0.0;
        let rep = solve(&mut touch(true), &mut x, &settings).unwrap();
        assert_eq!(rep.iterations, 1, "{rep:?}");
        // one step on the linear piece is exact up to rounding: x* ≈ 1e-4 to a few ulps
        // (1.4e-20 each); 1e-15 is far above that and far below the error of the free
        // piece's step (x = f/a = 1)
        assert!((x - exact).abs() <= 1e-15, "{x} against {exact}");
    }
}
