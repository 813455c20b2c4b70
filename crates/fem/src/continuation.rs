//! Arc-length continuation through limit points and snap-backs, with the critical points of
//! the path located and classified. The driver knows nothing of membranes: a [`Path`] gives the
//! equilibrium R(u, λ) = 0 of its own problem through a tangent and a corrector.
//!
//! # The method: pseudo-arclength (Keller) in (u, λ) with a scaled norm
//!
//! ```text
//! ‖(Δu, Δλ)‖² = w ΔuᵀΔu + Δλ²                     (w: the Path's displacement weight)
//! tangent:    b = K⁻¹ g  (g = −∂R/∂λ),  t = ±(b, 1)/‖(b, 1)‖
//! predictor:  z = z_k + Δs t
//! corrector:  R(u, λ) = 0  and  w t_uᵀ(u − u_k) + t_λ (λ − λ_k) = Δs    (bordered Newton)
//! ```
//!
//! Why this one rather than Crisfield's spherical constraint: the linear constraint gives one
//! bordered solve per iteration with no quadratic to choose a root from (Crisfield's root choice
//! is exactly where its implementations reverse on snap-backs), and the hyperplane through the
//! predictor cuts the path once for any Δs below the path's radius of curvature.
//!
//! The predictor's sign: t is oriented so that it points along the last converged secant,
//! tᵀ(z_k − z_{k−1}) > 0 in the scaled norm. At a limit point t_λ changes sign while t_u does
//! not, and in a snap-back the displacement-like quantities reverse while the path's secant does
//! not: the rule follows the curve where a rule on sign(Δλ) or on det K would turn back. (A
//! simple bifurcation also flips det K; the secant rule is blind to it, and the path goes on
//! along the branch it was on.)
//!
//! Adaptive length: Δs ← Δs · clamp(√(N_d / N), ½, 2) after a step of N Newton iterations (N_d
//! desired, Crisfield's rule), at most `max_ds`; a failed corrector halves Δs and tries again
//! from the same converged point, so no converged step is ever lost.
//!
//! # Critical points
//!
//! Between two converged points k−1 and k:
//! * t_λ changed sign: a **limit point** (λ has an extremum along the path). Located by the
//!   Illinois variant of regula falsi on t_λ(σ), σ the arc length from k−1.
//! * the negative-pivot count of K changed and t_λ did not: a **bifurcation** (an eigenvalue of
//!   K crosses zero with its mode orthogonal to g). Located by bisection on the count.
//!
//! Both stop when the bracket on σ is at most `locate_tol` (1e-8 by default) long.
//! A target (a monitored quantity of the state, e.g. the volume) reached between k−1 and k is
//! located the same way, by Illinois on q(σ) − q*, and becomes the stage's last point.

use crate::stepping::{Stage, StageError, StepInfo, StepState};
use std::fmt;

/// The path's tangent data at an equilibrium.
pub struct Tangent {
    /// K⁻¹g: du/dλ under load control
    pub b: Vec<f64>,
    /// negative pivots of K (stability under load control)
    pub negative: usize,
    /// negative pivots of the bordered operator of the conjugate control (the load's work
    /// conjugate, e.g. the volume, held fixed): `negative` less one when gᵀK⁻¹g < 0
    pub negative_conjugate: usize,
}

impl Tangent {
    /// From K⁻¹g, g and the negative pivots of K.
    pub fn new(b: Vec<f64>, g: &[f64], negative: usize) -> Self {
        let gb: f64 = g.iter().zip(&b).map(|(a, c)| a * c).sum();
        Self {
            b,
            negative,
            negative_conjugate: if gb < 0.0 {
                negative.saturating_sub(1)
            } else {
                negative
            },
        }
    }
}

/// An equilibrium path R(u, λ) = 0 the driver can follow.
pub trait Path {
    type State: Clone;
    type Error: fmt::Display;
    /// The load parameter λ of a state.
    fn load(&self, s: &Self::State) -> f64;
    /// The weight w of the displacements in the arc-length norm.
    fn weight(&self) -> f64;
    /// u(a) − u(b) on the free unknowns.
    fn difference(&self, a: &Self::State, b: &Self::State) -> Vec<f64>;
    /// base + ds (t_u, t_λ).
    fn predict(&self, base: &Self::State, tu: &[f64], tl: f64, ds: f64) -> Self::State;
    /// At an equilibrium: K⁻¹g (du/dλ under load control) and the negative pivots.
    fn tangent(&mut self, s: &Self::State) -> Result<Tangent, Self::Error>;
    /// The critical mode at a bifurcation (the eigenvector of K of smallest |eigenvalue|, on
    /// the free unknowns), for branch switching; `None` when the problem has none to give.
    fn critical_mode(&mut self, _s: &Self::State) -> Result<Option<Vec<f64>>, Self::Error> {
        Ok(None)
    }
    /// Correct the predictor `s` onto the path under `arc`; the Newton iterations taken.
    fn correct(
        &mut self,
        s: &mut Self::State,
        arc: &Arc<'_, Self::State>,
    ) -> Result<usize, Self::Error>;
    /// Whether an error ends the stage at once (an interrupt) instead of cutting the step.
    fn is_final(&self, _e: &Self::Error) -> bool {
        false
    }
    /// When even the shortest step turns too far at `s`: if the stiffness there has a neutral
    /// mode that the load does not drive (an eigenvalue at round-off, orthogonal to g — the
    /// equilibria form a family along it), hold it out of the path tangent (and out of the
    /// corrector's load column) until it stiffens, and say so (`true`); the driver then retries
    /// the step.
    fn hold_neutral(&mut self, _s: &Self::State) -> Result<bool, Self::Error> {
        Ok(false)
    }
}

/// The arc-length constraint of one corrector: w t_uᵀ(u − u_base) + t_λ(λ − λ_base) = ds.
pub struct Arc<'a, S> {
    pub base: &'a S,
    pub tu: &'a [f64],
    pub tl: f64,
    pub w: f64,
    pub ds: f64,
}

/// Every number the continuation uses, named.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArcSettings {
    /// the first step goes 1/`initial_steps` of the way to the target (measured along the
    /// tangent)
    pub initial_steps: usize,
    /// Newton iterations a step should take (Crisfield's rule)
    pub desired_iterations: usize,
    /// the longest step, as a multiple of the first
    pub max_ds_factor: f64,
    /// consecutive halvings of one step before the stage fails
    pub max_cuts: usize,
    /// the smallest cosine of the angle between the unit tangents at the two ends of a step
    /// (scaled norm); a step that turns more is halved. 0.8 (37°): the paths here turn through
    /// 90° at a limit point within a few steps, and a reversed corrector turns by 180°
    pub min_turn_cos: f64,
    /// the same for a step that would read as crossing a bifurcation (the negative-pivot count
    /// of K changes, dλ/ds keeps its sign): 0.98 (11°)
    pub min_turn_cos_critical: f64,
    /// a step shorter than this multiple of the first fails the stage (a path that can only be
    /// crept along, e.g. towards a state the corrector can never pass)
    pub min_ds_factor: f64,
    /// converged steps allowed in one stage
    pub max_steps: usize,
    /// the bracket on σ to which critical points and the target are located
    pub locate_tol: f64,
    /// iterations of the locating loops
    pub locate_iterations: usize,
    /// the relative accuracy of a located target, |q − q*| ≤ target_rtol·max(|q*|, 1e-300)
    pub target_rtol: f64,
    /// the sign of dλ/ds at the start (+1: the load increases first)…
    pub first_direction: f64,
    /// … unless the monitored quantity would then move away from the target: a fresh stage
    /// sets out towards it (off for a resumed stage, which keeps `first_direction`)
    pub orient_to_target: bool,
    /// branch switching: at the first bifurcation where K gains a negative pivot, leave the
    /// path along the critical mode by this fraction of the step's arc length (`None`: stay on
    /// the path)
    pub switch_fraction: Option<f64>,
}

impl Default for ArcSettings {
    fn default() -> Self {
        Self {
            initial_steps: 8,
            desired_iterations: 5,
            max_ds_factor: 4.0,
            max_cuts: 12,
            min_ds_factor: 1e-6,
            min_turn_cos: 0.8,
            min_turn_cos_critical: 0.98,
            max_steps: 2000,
            locate_tol: 1e-8,
            locate_iterations: 80,
            target_rtol: 1e-10,
            first_direction: 1.0,
            orient_to_target: true,
            switch_fraction: None,
        }
    }
}

/// What stops the stage: a monitored quantity reaching its value.
pub struct Target<'a, S> {
    pub name: &'a str,
    pub monitor: &'a dyn Fn(&S) -> f64,
    pub value: f64,
}

/// The kind of a critical point.
#[derive(
    schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum CriticalKind {
    /// a maximum of the load along the path
    LimitMax,
    /// a minimum of the load along the path
    LimitMin,
    /// an eigenvalue of K crossed zero with no turn of the load
    Bifurcation,
    /// an eigenvalue of K at round-off whose mode the load does not drive: the equilibria form
    /// a family along it (a bulge that can slide along a whole tube); from here on the mode is
    /// held out of the path ([`Path::hold_neutral`]). Found where the negative-pivot count
    /// first changes by such a mode (its sign is round-off: no branch leaves there), or where
    /// the path would otherwise turn within any step; not located on the arc length
    Neutral,
}

impl fmt::Display for CriticalKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::LimitMax => "limit point (load maximum)",
            Self::LimitMin => "limit point (load minimum)",
            Self::Bifurcation => "bifurcation point",
            Self::Neutral => "neutral mode (a family of equilibria, held out of the path)",
        })
    }
}

/// A located critical point.
#[derive(Clone, Debug)]
pub struct Critical<S> {
    pub kind: CriticalKind,
    /// it lies between converged steps `step − 1` and `step`
    pub step: usize,
    /// the arc length from the path's start
    pub s: f64,
    /// the final bracket on σ (the whole step when a corrector inside it failed: the point
    /// is then only bracketed by the step, and `state` is the step's end)
    pub bracket: f64,
    pub state: S,
    pub load: f64,
    /// negative pivots of K before and after
    pub negative_before: usize,
    pub negative_after: usize,
    /// a bifurcation the path left by branch switching: the arc length of the switching step
    /// along the critical mode
    pub switched: Option<f64>,
}

/// A converged step.
pub struct ArcStep<'a, S> {
    pub step: usize,
    pub state: &'a S,
    pub load: f64,
    /// the arc length from the path's start
    pub s: f64,
    pub ds: f64,
    pub iterations: usize,
    /// dλ/ds of the unit tangent there
    pub tl: f64,
    /// negative pivots of K (stability under load control) and of the conjugate control's
    /// bordered operator (e.g. under volume control: the stability of a closed tube)
    pub negative_pivots: usize,
    pub negative_pivots_conjugate: usize,
    /// the monitored quantity
    pub monitor: f64,
    /// the step ends exactly at the target
    pub at_target: bool,
    pub cuts: usize,
}

/// What the driver reports as it goes.
pub enum ArcEvent<'a, S> {
    Step(ArcStep<'a, S>),
    Critical(&'a Critical<S>),
}

/// Why a continuation stopped.
#[derive(Debug)]
pub enum ArcError<E, O> {
    /// the tangent could not be computed at a converged point
    Tangent { step: usize, source: E },
    /// `cuts` halvings of step `step` did not converge
    Stalled {
        step: usize,
        ds: f64,
        cuts: usize,
        load: f64,
        source: E,
    },
    /// the step limit was reached before the target
    StepLimit {
        steps: usize,
        load: f64,
        monitor: f64,
    },
    /// even the shortest step turned the path by more than the settings allow
    Turn { step: usize, ds: f64, load: f64 },
    /// the observer failed
    Observer { step: usize, source: O },
    /// the problem asked to stop (an interrupt)
    Final { step: usize, source: E },
}

impl<E: fmt::Display, O: fmt::Display> fmt::Display for ArcError<E, O> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Tangent { step, .. } => {
                write!(f, "the path tangent at step {step} failed")
            }
            Self::Stalled {
                step,
                ds,
                cuts,
                load,
                ..
            } => write!(
                f,
                "arc-length step {step} from load {load:.9} did not converge after {cuts} halvings (Δs = {ds:.3e})"
            ),
            Self::StepLimit {
                steps,
                load,
                monitor,
            } => write!(
                f,
                "{steps} arc-length steps without reaching the target (load {load:.9}, monitored value {monitor:.9})"
            ),
            Self::Turn { step, ds, load } => write!(
                f,
                "arc-length step {step} from load {load:.9}: the path turns by more than the allowed angle even within Δs = {ds:.3e}"
            ),
            Self::Observer { step, .. } => write!(f, "the observer failed at step {step}"),
            Self::Final { step, .. } => write!(f, "stopped at step {step}"),
        }
    }
}

/// The cause of a failed path, as `source()`: the problem's error, or the observer's. Each
/// variant's own message does not repeat it.
impl<E, O> std::error::Error for ArcError<E, O>
where
    E: std::error::Error + 'static,
    O: std::error::Error + 'static,
{
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Tangent { source, .. }
            | Self::Stalled { source, .. }
            | Self::Final { source, .. } => Some(source),
            Self::Observer { source, .. } => Some(source),
            Self::StepLimit { .. } | Self::Turn { .. } => None,
        }
    }
}

/// The unit tangent at an equilibrium from b = K⁻¹g, oriented along `reference` (a secant, or
/// `None` for the first step, then by `first_direction` on t_λ).
fn unit_tangent(
    b: Vec<f64>,
    w: f64,
    reference: Option<(&[f64], f64)>,
    dir: f64,
) -> (Vec<f64>, f64) {
    let n = (w * b.iter().map(|v| v * v).sum::<f64>() + 1.0).sqrt();
    let mut tu: Vec<f64> = b.into_iter().map(|v| v / n).collect();
    let mut tl = 1.0 / n;
    let sign = match reference {
        Some((du, dl)) => w * tu.iter().zip(du).map(|(a, b)| a * b).sum::<f64>() + tl * dl,
        None => tl * dir,
    };
    if sign < 0.0 {
        tu.iter_mut().for_each(|v| *v = -*v);
        tl = -tl;
    }
    (tu, tl)
}

/// A converged point of the path with its oriented tangent.
struct Point<S> {
    state: S,
    tu: Vec<f64>,
    tl: f64,
    negative: usize,
    s: f64,
}

/// The located critical points of a followed path, or why it stopped.
pub type FollowResult<P, O> =
    Result<Vec<Critical<<P as Path>::State>>, ArcError<<P as Path>::Error, O>>;

/// Follow the path of `path` from the equilibrium `start` until `target` is reached (located to
/// `target_rtol`). `on_event` gets every converged step and every located critical point, in
/// path order. Returns the located critical points.
///
/// Its length (the longest function of the crate) is one pass of the arc-length algorithm
/// kept in one place: predictor, corrector, step control, the sign changes of the tangent
/// stiffness and of the load's derivative, the bisection that locates a critical point, the
/// branch switch, and the stop at the target; each branch reads and updates the same path
/// state, and splitting it would pass that state through a dozen functions.
pub fn follow<P: Path, O>(
    path: &mut P,
    start: P::State,
    target: &Target<'_, P::State>,
    settings: &ArcSettings,
    mut on_event: impl FnMut(&mut P, ArcEvent<'_, P::State>) -> Result<(), O>,
) -> FollowResult<P, O> {
    let w = path.weight();
    let t = path
        .tangent(&start)
        .map_err(|source| ArcError::Tangent { step: 0, source })?;
    let (tu, tl) = unit_tangent(t.b, w, None, settings.first_direction);
    let mut point = Point {
        state: start,
        tu,
        tl,
        negative: t.negative,
        s: 0.0,
    };
    let q0 = (target.monitor)(&point.state);
    // the first step: 1/initial_steps of the distance to the target along the tangent (dq/ds by
    // a difference along the predictor: q is a function of the state alone)
    let h = 1e-6;
    let probe = path.predict(&point.state, &point.tu, point.tl, h);
    let mut dqds = ((target.monitor)(&probe) - q0) / h;
    // a fresh stage sets out towards its target (a deflation, a stage that starts past a
    // maximum); a resumed one keeps the direction it had (`first_direction`)
    if settings.orient_to_target && dqds * (target.value - q0) < 0.0 {
        point.tu.iter_mut().for_each(|v| *v = -*v);
        point.tl = -point.tl;
        dqds = -dqds;
    }
    let mut ds = if dqds.is_finite() && dqds.abs() > 0.0 {
        ((target.value - q0) / dqds).abs() / settings.initial_steps.max(1) as f64
    } else {
        1e-2
    };
    if !(ds > 0.0 && ds.is_finite()) {
        ds = 1e-2;
    }
    let max_ds = settings.max_ds_factor * ds;
    let min_ds = settings.min_ds_factor * ds;
    let mut criticals = Vec::new();
    let mut step = 0usize;
    // branches are switched once: on the new branch the critical mode (e.g. a bulge's
    // translation, neutral in a long tube) keeps crossing zero as the discretization ripples
    let mut switched_once = false;
    let qtol = settings.target_rtol * target.value.abs().max(1e-300);
    loop {
        if step >= settings.max_steps {
            return Err(ArcError::StepLimit {
                steps: step,
                load: path.load(&point.state),
                monitor: (target.monitor)(&point.state),
            });
        }
        // one converged step of length ds, halved when the corrector fails or when the path
        // turns by more than the settings allow within it (a corrector that lands on a part of
        // the path folded back across the hyperplane would otherwise reverse the continuation)
        let mut cuts = 0;
        let ds_start = ds;
        let (next, iterations, t, tu, tl) = loop {
            let attempt = corrector(path, &point, w, ds).and_then(|(st, it)| {
                let t = path.tangent(&st)?;
                Ok((st, it, t))
            });
            let failure = match attempt {
                Ok((st, it, t)) => {
                    let secant = (
                        path.difference(&st, &point.state),
                        path.load(&st) - path.load(&point.state),
                    );
                    let (tu, tl) = unit_tangent(t.b.clone(), w, Some((&secant.0, secant.1)), 1.0);
                    // the turn of the tangent, and of the secant against the old tangent (its
                    // projection on it is ds by the constraint, so a corrector that travelled
                    // far from the predictor — across a sharp corner of the path — shows as a
                    // long secant)
                    let along = w * tu.iter().zip(&point.tu).map(|(a, b)| a * b).sum::<f64>()
                        + tl * point.tl;
                    let chord = (w * secant.0.iter().map(|v| v * v).sum::<f64>()
                        + secant.1 * secant.1)
                        .sqrt();
                    let cos = along.min(ds / chord.max(1e-300));
                    // a step that would be read as crossing a bifurcation (K's inertia changed,
                    // dλ/ds did not) must be resolved finely: in a long tube the path turns
                    // through most of 180° at the pressure maximum (uniform inflation → a
                    // localized bulge with the rest deflating), and a coarse step across it lands
                    // on the far leg, where the secant orients the tangent backwards, dλ/ds keeps
                    // its sign and the limit point looks like a bifurcation. A real bifurcation
                    // passes the test once the step is short (the path is smooth through it)
                    let needed = if t.negative != point.negative && tl * point.tl > 0.0 {
                        settings.min_turn_cos_critical
                    } else {
                        settings.min_turn_cos
                    };
                    // a tangent with no displacement part (the load does not act on the state
                    // yet: plates that only touch the tube) says nothing about where the path
                    // turns once it does; the corner there is the path's, not a fold
                    let blind = point.tu.iter().all(|v| *v == 0.0);
                    if cos >= needed || (blind && tl * point.tl > 0.0) {
                        break (st, it, t, tu, tl);
                    }
                    None
                }
                Err(e) => {
                    if path.is_final(&e) {
                        return Err(ArcError::Final {
                            step: step + 1,
                            source: e,
                        });
                    }
                    Some(e)
                }
            };
            cuts += 1;
            if cuts > settings.max_cuts || ds * 0.5 < min_ds {
                // a path that turns within any step where the stiffness has a neutral mode:
                // hold the mode out and take the step again, once
                if failure.is_none() {
                    if let Some((t, cp)) =
                        neutral_point(path, &point.state, point.s, point.negative, step + 1)?
                    {
                        on_event(path, ArcEvent::Critical(&cp)).map_err(|source| {
                            ArcError::Observer {
                                step: step + 1,
                                source,
                            }
                        })?;
                        criticals.push(cp);
                        (point.tu, point.tl) =
                            unit_tangent(t.b, w, Some((&point.tu, point.tl)), 1.0);
                        point.negative = t.negative;
                        ds = ds_start;
                        cuts = 0;
                        continue;
                    }
                }
                return Err(match failure {
                    Some(e) => ArcError::Stalled {
                        step: step + 1,
                        ds,
                        cuts: cuts - 1,
                        load: path.load(&point.state),
                        source: e,
                    },
                    None => ArcError::Turn {
                        step: step + 1,
                        ds,
                        load: path.load(&point.state),
                    },
                });
            }
            ds *= 0.5;
        };
        let mut next = next;
        let mut iterations = iterations;
        let (mut negative, mut negative_conjugate) = (t.negative, t.negative_conjugate);
        let (mut tu, mut tl) = (tu, tl);
        let mut s_next = point.s + ds;
        let q_prev = (target.monitor)(&point.state);
        // the target inside the step: located first, so that a critical point beyond it (in the
        // same step) is not reported, and no branch is switched in the stage's last step
        let q_step = (target.monitor)(&next);
        let target_end =
            if (q_prev - target.value) * (q_step - target.value) <= 0.0 && q_prev != target.value {
                Some(if (q_step - target.value).abs() <= qtol {
                    (ds, next.clone())
                } else {
                    let monitor = target.monitor;
                    let goal = target.value;
                    let (sigma, _, st) = locate_root(
                        path,
                        &point,
                        w,
                        (0.0, q_prev - goal),
                        (ds, q_step - goal),
                        // the target to its own accuracy, not to the critical points' bracket on s
                        &ArcSettings {
                            locate_tol: 1e-15 * ds,
                            ..*settings
                        },
                        qtol,
                        |_, s| Ok(monitor(s) - goal),
                    )
                    .map_err(|source| ArcError::Stalled {
                        step: step + 1,
                        ds,
                        cuts: 0,
                        load: path.load(&point.state),
                        source,
                    })?;
                    (sigma, st)
                })
            } else {
                None
            };
        let sigma_target = target_end.as_ref().map_or(f64::INFINITY, |t| t.0);
        // critical points inside the step (before the target), in path order; a count change
        // by a neutral mode is held, not located
        let neutral = if tl * point.tl >= 0.0 && negative != point.negative {
            neutral_point(path, &next, s_next, point.negative, step + 1)?
        } else {
            None
        };
        if tl * point.tl < 0.0 {
            let (tu0, tl0) = (point.tu.clone(), point.tl);
            let c = locate(path, &point, w, ds, settings, |path, s| {
                let t = path.tangent(s)?;
                Ok(unit_tangent(t.b, w, Some((&tu0, tl0)), 1.0).1)
            });
            let c = located_or_step(path, c, step + 1, ds, &next)?;
            let kind = if point.tl > 0.0 {
                CriticalKind::LimitMax
            } else {
                CriticalKind::LimitMin
            };
            if c.0 <= sigma_target {
                let load = path.load(&c.2);
                let cp = Critical::at(kind, step + 1, &point, c, load, negative);
                on_event(path, ArcEvent::Critical(&cp)).map_err(|source| ArcError::Observer {
                    step: step + 1,
                    source,
                })?;
                criticals.push(cp);
            }
        } else if let Some((t, cp)) = neutral {
            // the count changed by a mode that is neutral at the step's end (eigenvalue at
            // round-off, free of the load: a bulge's translation in a long tube, which flips
            // sign with the rounding): not a bifurcation — no branch leaves here, and every
            // perturbation along it is another member of the same family. Held from here on,
            // and reported once as the neutral point
            negative = t.negative;
            negative_conjugate = t.negative_conjugate;
            (tu, tl) = unit_tangent(t.b, w, Some((&tu, tl)), 1.0);
            if target_end.is_none() {
                on_event(path, ArcEvent::Critical(&cp)).map_err(|source| ArcError::Observer {
                    step: step + 1,
                    source,
                })?;
                criticals.push(cp);
            }
        } else if negative != point.negative {
            let before = point.negative as f64;
            let c = locate_count(path, &point, w, ds, settings, before);
            let c = located_or_step(path, c, step + 1, ds, &next)?;
            let beyond_target = c.0 > sigma_target;
            let load = path.load(&c.2);
            let mut cp = Critical::at(
                CriticalKind::Bifurcation,
                step + 1,
                &point,
                c,
                load,
                negative,
            );
            // branch switching where an instability enters: leave the path along the critical
            // mode, by an arc of `switch_fraction` of the step that crossed the bifurcation
            if let (Some(fraction), true, false, None) = (
                settings.switch_fraction,
                negative > point.negative,
                switched_once,
                &target_end,
            ) {
                let mode = path
                    .critical_mode(&cp.state)
                    .map_err(|source| ArcError::Tangent {
                        step: step + 1,
                        source,
                    })?;
                if let Some(mode) = mode {
                    let n = (w * mode.iter().map(|v| v * v).sum::<f64>()).sqrt();
                    let base = Point {
                        state: cp.state.clone(),
                        tu: mode.iter().map(|v| v / n).collect(),
                        tl: 0.0,
                        negative: cp.negative_after,
                        s: cp.s,
                    };
                    let mut dsw = fraction * ds;
                    let mut tries = 0;
                    let (st, it) = loop {
                        match corrector(path, &base, w, dsw) {
                            Ok(r) => break r,
                            Err(e) => {
                                tries += 1;
                                if path.is_final(&e) || tries > settings.max_cuts {
                                    return Err(ArcError::Stalled {
                                        step: step + 1,
                                        ds: dsw,
                                        cuts: tries - 1,
                                        load: cp.load,
                                        source: e,
                                    });
                                }
                                dsw *= 0.5;
                            }
                        }
                    };
                    let sec = (
                        path.difference(&st, &cp.state),
                        path.load(&st) - path.load(&cp.state),
                    );
                    let t = path.tangent(&st).map_err(|source| ArcError::Tangent {
                        step: step + 1,
                        source,
                    })?;
                    negative = t.negative;
                    negative_conjugate = t.negative_conjugate;
                    (tu, tl) = unit_tangent(t.b, w, Some((&sec.0, sec.1)), 1.0);
                    s_next = cp.s + dsw;
                    next = st;
                    iterations = it;
                    switched_once = true;
                    cp.switched = Some(dsw);
                }
            }
            if !beyond_target {
                on_event(path, ArcEvent::Critical(&cp)).map_err(|source| ArcError::Observer {
                    step: step + 1,
                    source,
                })?;
                criticals.push(cp);
            }
        }
        step += 1;
        let q_next = (target.monitor)(&next);
        if let Some((sigma, end)) = target_end {
            let t_end = path
                .tangent(&end)
                .map_err(|source| ArcError::Tangent { step, source })?;
            let info = ArcStep {
                step,
                load: path.load(&end),
                state: &end,
                s: point.s + sigma,
                ds: sigma,
                iterations,
                tl: point.tl,
                negative_pivots: t_end.negative,
                negative_pivots_conjugate: t_end.negative_conjugate,
                monitor: (target.monitor)(&end),
                at_target: true,
                cuts,
            };
            on_event(path, ArcEvent::Step(info))
                .map_err(|source| ArcError::Observer { step, source })?;
            return Ok(criticals);
        }
        let info = ArcStep {
            step,
            load: path.load(&next),
            state: &next,
            s: s_next,
            ds: s_next - point.s,
            iterations,
            tl,
            negative_pivots: negative,
            negative_pivots_conjugate: negative_conjugate,
            monitor: q_next,
            at_target: false,
            cuts,
        };
        on_event(path, ArcEvent::Step(info))
            .map_err(|source| ArcError::Observer { step, source })?;
        point = Point {
            state: next,
            tu,
            tl,
            negative,
            s: s_next,
        };
        // Crisfield's rule for the next length
        let f = (settings.desired_iterations.max(1) as f64 / iterations.max(1) as f64).sqrt();
        ds = (ds * f.clamp(0.5, 2.0)).min(max_ds);
    }
}

/// The neutral point at `state` (arc length `s`, reached with `negative_before` negative
/// pivots, in step `step`): when [`Path::hold_neutral`] finds a neutral mode there and holds it,
/// the path tangent with the mode held out and the point as a critical point of kind
/// [`CriticalKind::Neutral`]; `None` otherwise.
#[allow(clippy::type_complexity)]
fn neutral_point<P: Path, O>(
    path: &mut P,
    state: &P::State,
    s: f64,
    negative_before: usize,
    step: usize,
) -> Result<Option<(Tangent, Critical<P::State>)>, ArcError<P::Error, O>> {
    if !path
        .hold_neutral(state)
        .map_err(|source| ArcError::Tangent { step, source })?
    {
        return Ok(None);
    }
    let t = path
        .tangent(state)
        .map_err(|source| ArcError::Tangent { step, source })?;
    let cp = Critical {
        kind: CriticalKind::Neutral,
        step,
        s,
        bracket: 0.0,
        state: state.clone(),
        load: path.load(state),
        negative_before,
        negative_after: t.negative,
        switched: None,
    };
    Ok(Some((t, cp)))
}

impl<S> Critical<S> {
    /// The critical point located at `c` in the step `step` from `point`, with `negative`
    /// pivots after it.
    fn at(
        kind: CriticalKind,
        step: usize,
        point: &Point<S>,
        (sigma, bracket, state): Located<S>,
        load: f64,
        negative: usize,
    ) -> Self {
        Self {
            kind,
            step,
            s: point.s + sigma,
            bracket,
            load,
            state,
            negative_before: point.negative,
            negative_after: negative,
            switched: None,
        }
    }
}

/// A located point: its arc length σ from the step's start, its final bracket and its state.
type Located<S> = (f64, f64, S);

/// A located critical point, or — when a corrector inside the bracket failed — the step's end
/// with the whole step as its bracket (reported, not fatal: the path goes on); an interrupt
/// ends the stage.
fn located_or_step<P: Path, O>(
    path: &P,
    located: Result<Located<P::State>, P::Error>,
    step: usize,
    ds: f64,
    end: &P::State,
) -> Result<Located<P::State>, ArcError<P::Error, O>> {
    match located {
        Ok(c) => Ok(c),
        Err(e) if path.is_final(&e) => Err(ArcError::Final { step, source: e }),
        Err(_) => Ok((ds, ds, end.clone())),
    }
}

/// One corrector from `point` with arc length `ds`: the converged state and its iterations.
fn corrector<P: Path>(
    path: &mut P,
    point: &Point<P::State>,
    w: f64,
    ds: f64,
) -> Result<(P::State, usize), P::Error> {
    let mut s = path.predict(&point.state, &point.tu, point.tl, ds);
    let arc = Arc {
        base: &point.state,
        tu: &point.tu,
        tl: point.tl,
        w,
        ds,
    };
    let it = path.correct(&mut s, &arc)?;
    Ok((s, it))
}

/// Illinois regula falsi on f(σ) over the bracket (a, fa), (b, fb) with fa·fb < 0: stops when the
/// bracket is at most `locate_tol` long or |f| ≤ `ftol`. Returns (σ, final bracket, state).
#[allow(clippy::too_many_arguments)]
fn locate_root<P: Path>(
    path: &mut P,
    point: &Point<P::State>,
    w: f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    settings: &ArcSettings,
    ftol: f64,
    mut f: impl FnMut(&mut P, &P::State) -> Result<f64, P::Error>,
) -> Result<(f64, f64, P::State), P::Error> {
    let mut best: Option<(f64, f64, P::State)> = None;
    // a bisection whenever two Illinois steps did not halve the bracket: the secant steps may
    // converge from one side only, leaving the bracket long; this bounds it by 2·log₂(ds/tol)
    // iterations
    let mut widths = vec![(b - a).abs()];
    for _ in 0..settings.locate_iterations {
        let bisect = widths.len() >= 3 && widths[widths.len() - 1] > 0.5 * widths[widths.len() - 3];
        let mut c = (a * fb - b * fa) / (fb - fa);
        if bisect || !(c > a.min(b) && c < a.max(b)) {
            c = 0.5 * (a + b);
        }
        let (s, _) = corrector(path, point, w, c)?;
        let fc = f(path, &s)?;
        if best.as_ref().is_none_or(|bb| fc.abs() < bb.1) {
            best = Some((c, fc.abs(), s.clone()));
        }
        if fc == 0.0 || fc.abs() <= ftol {
            // exactly at the root (or the target to its tolerance): no bracket left
            return Ok((c, if fc == 0.0 { 0.0 } else { (b - a).abs() }, s));
        }
        if fc * fb < 0.0 {
            a = b;
            fa = fb;
        } else if !bisect {
            // the same end stays: halve its value (Illinois)
            fa *= 0.5;
        }
        b = c;
        fb = fc;
        widths.push((b - a).abs());
        if (b - a).abs() <= settings.locate_tol {
            return Ok((c, (b - a).abs(), s));
        }
    }
    match best {
        Some((c, _, s)) => Ok((c, (b - a).abs(), s)),
        // no iteration allowed: the bracket's far end
        None => {
            let (s, _) = corrector(path, point, w, b)?;
            Ok((b, (b - a).abs(), s))
        }
    }
}

/// Locate a limit point: the zero of the oriented t_λ(σ) in (0, ds].
fn locate<P: Path>(
    path: &mut P,
    point: &Point<P::State>,
    w: f64,
    ds: f64,
    settings: &ArcSettings,
    tl_at: impl FnMut(&mut P, &P::State) -> Result<f64, P::Error>,
) -> Result<(f64, f64, P::State), P::Error> {
    let mut tl_at = tl_at;
    let (s_end, _) = corrector(path, point, w, ds)?;
    let f_end = tl_at(path, &s_end)?;
    locate_root(
        path,
        point,
        w,
        (0.0, point.tl),
        (ds, f_end),
        settings,
        0.0,
        tl_at,
    )
}

/// Locate a bifurcation: bisection on σ ∈ (0, ds] for the change of the negative-pivot count
/// from `before`. Returns the first point past the change.
fn locate_count<P: Path>(
    path: &mut P,
    point: &Point<P::State>,
    w: f64,
    ds: f64,
    settings: &ArcSettings,
    before: f64,
) -> Result<(f64, f64, P::State), P::Error> {
    let (mut a, mut b) = (0.0, ds);
    let (mut state_b, _) = corrector(path, point, w, ds)?;
    for _ in 0..settings.locate_iterations {
        if b - a <= settings.locate_tol {
            break;
        }
        let c = 0.5 * (a + b);
        let (s, _) = corrector(path, point, w, c)?;
        let neg = path.tangent(&s)?.negative;
        if neg as f64 == before {
            a = c;
        } else {
            b = c;
            state_b = s;
        }
    }
    Ok((b, b - a, state_b))
}

#[cfg(test)]
mod tests;

mod membrane;
pub use membrane::{run_arc_stage, ArcLoading, MembranePath, MODE_ITERATIONS, NEUTRAL_ITERATIONS};
