//! The linear algebra of one Newton iteration on the model: the shifted LDLᵀ factorization, the
//! bordered (volume, node, arc-length) and closed-gas (Sherman–Morrison) solves, and the solve
//! drivers (one load; the augmented-Lagrangian contact loop; a held mode; arc-length steps).

use super::problem::MembraneProblem;
use super::*;

/// How many times the augmented solve halves a multiplier update whose solve failed: 3
/// (to 1/8 of the update; the channel's first contact steps at 32 and 64 around converge at
/// the first halving).
pub const MAX_UPDATE_HALVINGS: i32 = 3;

/// A held equilibrium's mode ([`Model::solve_held`]).
#[derive(Clone, Debug)]
pub struct Held {
    /// the refreshed unit mode (free dofs)
    pub mode: Vec<f64>,
    /// its eigenvalue over K's largest diagonal entry
    pub relative_eigenvalue: f64,
    /// the reaction φ0ᵀR of the hold (R = f_int − ϖ g on the free dofs, φ0 the held direction)
    pub force: f64,
    /// the membrane energy (over μH, whole model)
    pub energy: f64,
}

/// The values of K = K_int − p H, one per pattern entry.
pub(super) fn tangent_values(a: &Assembled, p: f64) -> Vec<f64> {
    a.k_int
        .iter()
        .zip(&a.k_vol)
        .map(|(k, h)| k - p * h)
        .collect()
}

impl Model {
    /// Factorize K = K_int − p H; if K is singular, retry with diagonal shifts of 1e-10 …
    /// 1e-4 of its largest diagonal entry. Returns (#neg, shift).
    pub(super) fn factorize(&mut self, a: &Assembled, p: f64) -> Result<(usize, f64), FemError> {
        self.factorize_values(tangent_values(a, p))
    }

    /// [`Model::factorize`] of the tangent whose values (one per pattern entry) are `vals`,
    /// taken: the factorization drops them when it can ([`SparseLdlt::factorize_shifted`]).
    pub(super) fn factorize_values(&mut self, vals: Vec<f64>) -> Result<(usize, f64), FemError> {
        let scale = self.largest_diagonal_in(&vals);
        self.factorize_scaled(vals, scale)
    }

    /// [`Model::factorize_values`] with the largest |diagonal entry| of `vals` already known
    /// (`scale`, [`Model::largest_diagonal_in`]), which sets the shifts.
    pub(super) fn factorize_scaled(
        &mut self,
        vals: Vec<f64>,
        scale: f64,
    ) -> Result<(usize, f64), FemError> {
        const SHIFTS: [f64; 4] = [1e-10, 1e-8, 1e-6, 1e-4];
        // the tangent's values and the factorization's transients are freed by the end of
        // it: on a large model their pages go back to the system ([`crate::heap`])
        let large = vals.len() >= crate::heap::LARGE_VALUES;
        let result = self.ldlt.factorize_shifted(
            vals,
            self.pattern.diagonal(),
            &SHIFTS.map(|rel| rel * scale),
        );
        if large {
            crate::heap::release_free();
        }
        if let Ok((neg, shift)) = result {
            self.factorized(neg, shift);
        }
        result
    }

    /// Newton iterations under `load`; `state` is the initial guess and, on success, the
    /// converged state.
    pub fn solve(
        &mut self,
        state: &mut State,
        load: &Load,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        if let Loading::Pressure(p) = load.loading {
            state.p = p;
        }
        self.solve_load(state, load, None)
    }

    /// Newton under `load` (with the arc-length constraint `arc`, if any) inside the
    /// augmentation loop of the load's contact ([`Model::augmented`]).
    pub(super) fn solve_load(
        &mut self,
        state: &mut State,
        load: &Load,
        arc: Option<&ArcConstraint<'_>>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        // an open sheet encloses no volume: no pressure, volume or gas acts on it
        if self.mesh.open && load.loading != Loading::Pressure(0.0) {
            return Err(NewtonError::Problem {
                iteration: 0,
                source: FemError::Setup {
                    reason: format!(
                        "the mesh is an open sheet, which encloses no volume: only a zero pressure loads it, not {:?}",
                        load.loading
                    ),
                },
            });
        }
        let settings = self.settings;
        let contact = load.contact.clone();
        // every solve starts from a factorization at its first iterate, so that what it
        // computes does not depend on the solves before it (a restarted run repeats the
        // uninterrupted one bit for bit)
        self.require_factorization();
        let mut report = self.augmented(
            state,
            |_| contact.clone(),
            |model, state| {
                newton::solve(
                    &mut MembraneProblem::new(model, load, arc),
                    state,
                    &settings,
                )
            },
        )?;
        if report.inertia.stale {
            report.inertia =
                self.refresh_inertia(state, load, arc)
                    .map_err(|source| NewtonError::Problem {
                        iteration: report.iterations,
                        source,
                    })?;
        }
        Ok(report)
    }

    /// The inertia of the tangent at the converged `state` of a solve whose last linearization
    /// reused an earlier factor ([`super::reuse`]): one more linearization there, which
    /// factorizes.
    fn refresh_inertia(
        &mut self,
        state: &mut State,
        load: &Load,
        arc: Option<&ArcConstraint<'_>>,
    ) -> Result<Inertia, FemError> {
        self.require_factorization();
        let lin = newton::Problem::linearize(&mut MembraneProblem::new(self, load, arc), state)?;
        Ok(lin.inertia)
    }

    /// The Uzawa update of `state`'s contact history under `contact`
    /// ([`Contact::update_multipliers`] for every element). Returns the updated history and
    /// the update's maxima. Elements run in parallel; the maxima do not depend on the number of
    /// threads.
    pub(super) fn augment(
        &self,
        state: &State,
        contact: &Contact,
        gap_tolerance: f64,
    ) -> (Vec<f64>, UpdateSize) {
        crate::with_elements!(&self.elements, els => {
            let per = contact.multipliers_per_element(els.first().map_or(0, |e| contact.samples(e).len()));
            let mut out = vec![0.0; per * els.len()];
            let size = out
                .par_chunks_mut(per.max(1))
                .zip(els.par_iter())
                .enumerate()
                .map(|(e, (o, el))| {
                    let lambda = contact.element_history(&state.multipliers, e, contact.samples(el).len());
                    contact.update_multipliers(el, &el.gather(&state.x), lambda, gap_tolerance, o)
                })
                .reduce(UpdateSize::default, UpdateSize::max);
            (out, size)
        })
    }

    /// The contact points and planes whose status (pushed or free) differs between the
    /// positions `x` and `other`, with the multipliers `multipliers`.
    pub(super) fn contact_status_changes(
        &self,
        x: &[[f64; 3]],
        other: &[[f64; 3]],
        contact: &Contact,
        multipliers: &[f64],
    ) -> usize {
        crate::with_elements!(&self.elements, els => els
            .par_iter()
            .enumerate()
            .map(|(e, el)| {
                let lambda = contact.element_history(multipliers, e, contact.samples(el).len());
                contact.status_changes(el, &el.gather(x), &el.gather(other), lambda)
            })
            .sum())
    }

    /// Run `once` (one Newton solve of `state`) and, when the contact at the state
    /// (`contact_at`) is augmented ([`Enforcement::Augmented`]), the Uzawa loop around it:
    /// update the multipliers ([`Model::augment`]) and solve again until the largest gap where
    /// a plane pushes is within the gap tolerance. The state keeps the multipliers it is in
    /// equilibrium with (the last update, which found the gap within the tolerance, is not
    /// applied). A penalty contact (or none) drops the state's multipliers and solves once.
    pub(super) fn augmented(
        &mut self,
        state: &mut State,
        contact_at: impl Fn(&State) -> Option<Contact>,
        mut once: impl FnMut(
            &mut Self,
            &mut State,
        ) -> Result<newton::NewtonReport, NewtonError<FemError>>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        let start = contact_at(state);
        let (Some(contact), Some((gap_tolerance, max_augmentations))) = (
            start.as_ref(),
            start.as_ref().and_then(|c| match c.enforcement {
                Enforcement::Augmented {
                    gap_tolerance,
                    max_augmentations,
                } => Some((gap_tolerance, max_augmentations)),
                Enforcement::Penalty => None,
            }),
        ) else {
            state.multipliers.clear();
            return once(self, state);
        };
        // a stage whose planes changed (or the first with multipliers) starts afresh; every
        // solve restarts the local penalties and keeps the multipliers
        let points = crate::with_elements!(&self.elements, els => els.first().map_or(0, |e| contact.samples(e).len()));
        let per = contact.multipliers_per_element(points);
        if state.multipliers.len() == per * self.elements.len() {
            contact.restart_history(&mut state.multipliers);
        } else {
            state.multipliers = contact.fresh_history(points).repeat(self.elements.len());
        }
        let mut report = once(self, state)?;
        let mut aug = Augmentation::default();
        // the planes at the state (closed gas pressed by moving planes: at its parameter)
        while let Some(contact) = contact_at(state) {
            let (lambda, size) = self.augment(state, &contact, gap_tolerance);
            aug.gap = size.gap;
            aug.penetration = size.penetration;
            if !(size.gap.is_finite() && size.change.is_finite()) {
                return Err(NewtonError::Problem {
                    iteration: report.iterations,
                    source: FemError::NonFiniteResidual {
                        what: "contact multipliers",
                    },
                });
            }
            if size.gap <= gap_tolerance {
                break;
            }
            if aug.updates >= max_augmentations {
                return Err(NewtonError::Problem {
                    iteration: report.iterations,
                    source: FemError::Augmentation {
                        updates: aug.updates,
                        gap: size.gap,
                        penetration: size.penetration,
                        change: size.change,
                        tolerance: gap_tolerance,
                        penalty: contact.penalty,
                    },
                });
            }
            aug.updates += 1;
            aug.change = size.change;
            let again = self.solve_updated(state, lambda, &mut once)?;
            aug.iterations += again.iterations;
            report.iterations += again.iterations;
            report.history.extend(again.history);
            report.residual = again.residual;
            report.inertia = again.inertia;
        }
        report.augmentation = aug;
        Ok(report)
    }

    /// Solve `state` again after its multipliers' Uzawa update to `lambda` (from
    /// [`Model::augment`]). Where Newton finds no descent at its first iteration from the
    /// updated multipliers (a point at the contact edge whose gap and multiplier are both about
    /// zero can make the first direction one that no step length follows), the update is
    /// halved, up to [`MAX_UPDATE_HALVINGS`] times, from the state in equilibrium before it:
    /// the multipliers move part of the way, the local penalties stay. A solve that converges
    /// at once is unchanged.
    pub(super) fn solve_updated(
        &mut self,
        state: &mut State,
        lambda: Vec<f64>,
        once: &mut impl FnMut(
            &mut Self,
            &mut State,
        ) -> Result<newton::NewtonReport, NewtonError<FemError>>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        let before = state.clone();
        state.multipliers = lambda.clone();
        let mut halvings = 0;
        loop {
            match once(self, state) {
                Ok(r) => return Ok(r),
                // the kink: no descent at the first iteration (cheap to detect); a solve that
                // fails later is not retried (each retry would cost up to a whole solve)
                Err(NewtonError::NoDescent { iteration: 0, .. })
                    if halvings < MAX_UPDATE_HALVINGS =>
                {
                    halvings += 1;
                    let w = 0.5f64.powi(halvings);
                    *state = before.clone();
                    // the history is [λ, κ, last gap] per point: λ part of the way, κ as it
                    // was, the gap of the update
                    let h = crate::contact::HISTORY;
                    for (m, full) in state
                        .multipliers
                        .chunks_exact_mut(h)
                        .zip(lambda.chunks_exact(h))
                    {
                        m[0] += w * (full[0] - m[0]);
                        m[2] = full[2];
                    }
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// Newton iterations at the prescribed total volume `volume` with the direction `phi0`
    /// (normalized here) held (a bulge held where it sits, `phi0` its translation): the correction and the volume
    /// column are projected off the mode φ = K⁻¹φ0/‖K⁻¹φ0‖ at every linearization (one inverse
    /// iteration, so Kφ lies along φ0); at the fixed point the residual R = f_int − ϖg lies along `phi0`,
    /// and convergence is on the residual off it. `state` is the initial guess and, on success,
    /// the converged state. Returns the Newton report and the [`Held`] values there: the
    /// refreshed mode, its eigenvalue and the reaction f = φ0ᵀR (f > 0: the energy at fixed
    /// volume grows along +φ0, so the state, let go, would move along −φ0).
    pub fn solve_held(
        &mut self,
        state: &mut State,
        volume: f64,
        phi0: &[f64],
    ) -> Result<(newton::NewtonReport, Held), NewtonError<FemError>> {
        let settings = self.settings;
        let load = Load::new(Loading::Volume(volume));
        // the hold's projections assume a unit direction
        let n = norm(phi0).max(1e-300);
        let phi0: Vec<f64> = phi0.iter().map(|v| v / n).collect();
        let mut problem = MembraneProblem::new(self, &load, None);
        problem.hold = Some(&phi0);
        let report = newton::solve(&mut problem, state, &settings)?;
        // set by the converged linearization (Newton returns only from one)
        let held = problem.held.take().ok_or(NewtonError::Problem {
            iteration: report.iterations,
            source: FemError::NonFiniteResidual {
                what: "the held mode (no converged linearization)",
            },
        })?;
        Ok((report, held))
    }

    /// Newton iterations on equilibrium under the pressure `state.p` (a free unknown) together
    /// with the arc-length constraint `arc` (see [`ArcConstraint`]); `state` is the predictor
    /// and, on success, the converged point. `load.loading` must be a pressure (its value is
    /// ignored: the pressure is the continuation parameter).
    pub fn solve_arc(
        &mut self,
        state: &mut State,
        load: &Load,
        arc: &ArcConstraint<'_>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        // the pressure is the continuation parameter: whatever the stage's own control, the
        // corrector solves equilibrium under ϖ (an unknown) with the stage's planes
        let load = &Load {
            loading: Loading::Pressure(state.p),
            contact: load.contact.clone(),
        };
        self.solve_load(state, load, Some(arc))
    }

    /// Newton iterations on equilibrium of the closed gas (Boyle's constant `pv`) pressed by
    /// `planes` at the parameter `state.planes` (a free unknown), together with the arc-length
    /// constraint `arc` in (x, λ); `state` is the predictor and, on success, the converged point
    /// (its `p` the gas pressure there).
    pub fn solve_arc_gas(
        &mut self,
        state: &mut State,
        pv: f64,
        planes: &MovingPlanes,
        arc: &ArcConstraint<'_>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        let settings = self.settings;
        let load = &Load::new(Loading::Gas { pv });
        self.augmented(
            state,
            |s| Some(planes.at(s.planes)),
            |model, state| {
                let mut problem = MembraneProblem::new(model, load, Some(arc));
                problem.planes = Some(planes);
                newton::solve(&mut problem, state, &settings)
            },
        )
    }

    /// Solve K_gas y = v in place with the factor of K = K_int − ϖH (+ K_c) by Sherman–Morrison
    /// for the closed gas's rank-one term (ϖ/V_part) g gᵀ; returns 1 when that term takes one
    /// negative pivot away from K's count (1 + (ϖ/V) gᵀK⁻¹g < 0), else 0.
    pub(super) fn solve_gas(&self, a: &Assembled, p: f64, v: &mut [f64]) -> usize {
        let cc = p / a.volume;
        let mut b = a.g.clone();
        self.ldlt.solve(&mut b);
        self.ldlt.solve(v);
        let denom = 1.0 + cc * dot(&a.g, &b);
        let gv = dot(&a.g, v);
        for (y, bb) in v.iter_mut().zip(&b) {
            *y -= cc * bb * gv / denom;
        }
        usize::from(denom < 0.0)
    }
}
