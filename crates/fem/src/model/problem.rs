//! The membrane equilibrium under one load as a [`newton::Problem`] ([`MembraneProblem`]), its
//! convergence scale and potential, and the arc-length constraint ([`ArcConstraint`]).

use super::assembly::{Pressure, TangentForm};
use super::reuse::{self, CONTRACTION};
use super::*;

/// The pressure below which forces count as zero in the convergence test: ϖ = 1e-6 (six
/// orders below the pressures of the paper's examples). Near the stress-free state the internal
/// force vanishes, and a residual measured against it alone would never converge.
pub const PRESSURE_FLOOR: f64 = 1e-6;

/// The force scale the residual is measured against: the internal force, the pressure load,
/// the load of [`PRESSURE_FLOOR`], or the added terms' load ([`Model::set_load_scale`]),
/// whichever is largest.
pub(super) fn force_scale(a: &Assembled, p: f64, load_scale: f64) -> f64 {
    let g = norm(&a.g);
    norm(&a.f_int)
        .max(p.abs() * g)
        .max(1e-12)
        .max(PRESSURE_FLOOR * g)
        .max(load_scale)
}

/// The total potential of the modelled part: Π = W_int + E_contact − p V_part (pressure) or
/// − (pv/m) ln V_part (closed gas; by Boyle's law pv/m = p V_part at every state).
pub(super) fn potential(loading: Loading, energy: f64, v_part: f64, p: f64) -> f64 {
    match loading {
        Loading::Gas { .. } => energy - p * v_part * v_part.ln(),
        _ => energy - p * v_part,
    }
}

/// The arc-length (pseudo-arclength) constraint of one continuation step from the converged
/// point (x₀, ϖ₀) along the unit tangent (t_x, t_ϖ):
///
/// ```text
/// c(x, ϖ) = w t_xᵀ(x − x₀) + t_ϖ (ϖ − ϖ₀) − Δs = 0
/// ```
///
/// with x − x₀ on the free dofs and `w` the weight of the displacements in the arc-length norm
/// ‖(Δx, Δϖ)‖² = w ΔxᵀΔx + Δϖ².
#[derive(Clone, Copy, Debug)]
pub struct ArcConstraint<'a> {
    pub x0: &'a [[f64; 3]],
    pub p0: f64,
    pub tx: &'a [f64],
    pub tp: f64,
    pub w: f64,
    pub ds: f64,
    /// a neutral mode of K held out of the corrector (unit, free dofs; refreshed by one inverse
    /// iteration at every linearization): see [`Model::deflate`]
    pub neutral: Option<&'a [f64]>,
}

/// A line-search trial's positions, its assembly (with the tangent) and the seconds it took.
pub(super) type TrialAssembly = (State, Assembled, f64);

/// The membrane equilibrium under one load, as a [`newton::Problem`]: the state is (x, p), the
/// step (Δx on the free dofs, Δp). With `arc`, the pressure is an unknown and the arc-length
/// constraint closes the system.
pub(super) struct MembraneProblem<'a> {
    pub(super) model: &'a mut Model,
    pub(super) load: &'a Load,
    pub(super) arc: Option<&'a ArcConstraint<'a>>,
    /// closed gas pressed by planes that move with `State::planes`, the arc's load parameter
    /// (then `load.contact` is unused)
    pub(super) planes: Option<&'a MovingPlanes>,
    /// a direction φ0 held in a volume-control Newton (unit, free dofs): the correction is
    /// projected off φ = K⁻¹φ0/‖K⁻¹φ0‖ (one inverse iteration: the neutral mode near φ0), so the
    /// state keeps its coordinate along the mode, and the residual along φ0 — the generalized
    /// force that would move the state along the mode — is left as the hold's reaction (see
    /// [`Model::solve_held`])
    pub(super) hold: Option<&'a [f64]>,
    /// with `hold`: the held mode, its eigenvalue, the reaction and the energy at the converged
    /// linearization
    pub(super) held: Option<Held>,
    /// the assembly (with the tangent) of the last trial state the line search evaluated:
    /// when that trial is accepted, the next linearization is at the same state and takes it
    /// instead of assembling again
    pub(super) trial: std::cell::RefCell<Option<TrialAssembly>>,
    /// seconds spent assembling line-search trials that were not taken since the last
    /// linearization
    pub(super) rejected_seconds: std::cell::Cell<f64>,
    /// positions whose contact status the next linearization's contact takes
    /// ([`Contact::kernel_on_branch`]; set only by `relinearize`)
    pub(super) branch: Option<Vec<[f64; 3]>>,
    /// the residual R = f_int − ϖg of the last linearization on its own branch
    pub(super) residual: Vec<f64>,
    /// the scaled residual of the last linearization on its own branch, and whether it reused
    /// the factor ([`super::reuse::CONTRACTION`])
    pub(super) previous: Option<(f64, bool)>,
}

impl MembraneProblem<'_> {
    pub(super) fn new<'a>(
        model: &'a mut Model,
        load: &'a Load,
        arc: Option<&'a ArcConstraint<'a>>,
    ) -> MembraneProblem<'a> {
        MembraneProblem {
            model,
            load,
            arc,
            planes: None,
            hold: None,
            held: None,
            trial: std::cell::RefCell::new(None),
            rejected_seconds: std::cell::Cell::new(0.0),
            branch: None,
            residual: Vec::new(),
            previous: None,
        }
    }

    /// The planes at `state`: the load's, or the moving planes at the state's parameter.
    pub(super) fn contact(&self, state: &State) -> Option<std::borrow::Cow<'_, Contact>> {
        match self.planes {
            Some(m) => Some(std::borrow::Cow::Owned(m.at(state.planes))),
            None => self.load.contact.as_ref().map(std::borrow::Cow::Borrowed),
        }
    }

    /// The assembly with the tangent at `state` and the seconds it took: the cached trial's if
    /// it was made at exactly these positions and planes (bitwise), a fresh one otherwise.
    pub(super) fn assemble_at(&self, state: &State) -> Result<(Assembled, f64), FemError> {
        let x = &state.x;
        if let Some(branch) = &self.branch {
            let t = std::time::Instant::now();
            let contact = self.contact(state);
            let a = self.model.assemble_terms(
                x,
                TangentForm::At(self.pressure_of(state)),
                contact.as_deref(),
                &state.multipliers,
                Some(branch),
            )?;
            return Ok((a, t.elapsed().as_secs_f64()));
        }
        if let Some((xt, a, secs)) = self.trial.borrow_mut().take() {
            let same = xt.x.len() == x.len()
                && xt.planes.to_bits() == state.planes.to_bits()
                && self.pressure_of(&xt).same_as(self.pressure_of(state))
                && xt
                    .x
                    .iter()
                    .zip(x)
                    .all(|(p, q)| (0..3).all(|k| p[k].to_bits() == q[k].to_bits()));
            if same {
                return Ok((a, secs));
            }
            self.rejected_seconds
                .set(self.rejected_seconds.get() + secs);
        }
        let t = std::time::Instant::now();
        let a = self.assemble_tangent(state)?;
        Ok((a, t.elapsed().as_secs_f64()))
    }

    /// The assembly at `state` with K = K_int − ϖH at the state's pressure
    /// ([`MembraneProblem::pressure_of`]).
    fn assemble_tangent(&self, state: &State) -> Result<Assembled, FemError> {
        self.model.assemble_terms(
            &state.x,
            TangentForm::At(self.pressure_of(state)),
            self.contact(state).as_deref(),
            &state.multipliers,
            None,
        )
    }

    /// The pressure at `state`: the state's own, or closed gas's pv/(m V_part).
    pub(super) fn pressure_of(&self, state: &State) -> Pressure {
        Pressure::under(self.load, self.model.multiplicity(), state.p)
    }

    /// Refuse states the loading cannot have: closed gas needs a positive volume, and the
    /// residual must be finite (so that no NaN reaches the convergence test or a message).
    pub(super) fn admissible(&self, a: &Assembled, p: f64, res: f64) -> Result<(), FemError> {
        if self.load.gas().is_some() && !(a.volume > 0.0) {
            return Err(FemError::GasVolume { volume: a.volume });
        }
        if !p.is_finite() {
            return Err(FemError::NonFiniteResidual {
                what: "gas pressure",
            });
        }
        if !res.is_finite() {
            return Err(FemError::NonFiniteResidual {
                what: "internal or contact forces",
            });
        }
        Ok(())
    }
}

impl newton::Problem for MembraneProblem<'_> {
    type State = State;
    type Step = (Vec<f64>, f64);
    type Error = FemError;

    /// Its length: the residual and the bordered tangent of every loading (pressure, volume,
    /// stretch, closed gas, moving planes, with or without augmented multipliers) are assembled
    /// and factorized here once per Newton iteration, one arm per loading.
    fn linearize(&mut self, state: &mut State) -> Result<Linearization<Self::Step>, FemError> {
        if self.model.interrupted() {
            return Err(FemError::Interrupted);
        }
        let m = self.model.multiplicity();
        let (mut a, assembly_seconds) = self.assemble_at(state)?;
        // the pressure the assembly formed K = K_int − ϖH at
        state.p = self.pressure_of(state).at(a.volume);
        let p = state.p;
        let k = std::mem::take(&mut a.k);
        let r: Vec<f64> = a.f_int.iter().zip(&a.g).map(|(f, g)| f - p * g).collect();
        // the constraint c, its gradient h in x and its derivative cp in ϖ
        let mut cp = 0.0;
        let (c, h): (f64, Option<Vec<f64>>) = match (self.arc, self.load.loading) {
            (Some(arc), _) => {
                let d = self.model.dofs.difference(&state.x, arc.x0);
                cp = arc.tp;
                let lambda = if self.planes.is_some() {
                    state.planes
                } else {
                    p
                };
                (
                    arc.w * dot(arc.tx, &d) + arc.tp * (lambda - arc.p0) - arc.ds,
                    Some(arc.tx.iter().map(|t| arc.w * t).collect()),
                )
            }
            (None, Loading::Volume(v)) => {
                (m * a.volume - v, Some(a.g.iter().map(|g| m * g).collect()))
            }
            (
                None,
                Loading::Node {
                    node,
                    component,
                    target,
                },
            ) => {
                let k = self
                    .model
                    .dofs
                    .eq(node, component)
                    .ok_or(FemError::FixedControlDof { node, component })?;
                let mut e = vec![0.0; self.model.n_eq()];
                e[k] = 1.0;
                (state.x[node][component] - target, Some(e))
            }
            _ => (0.0, None),
        };
        let reference = force_scale(&a, p, self.model.load_scale);
        let res = norm(&r) / reference;
        self.admissible(&a, p, res)?;
        let cscale = match (self.arc, self.load.loading) {
            // the constraint is an arc length (RMS displacement and ϖ, O(1) quantities): held to
            // 1e-12 of the step, but not below 1e-15 absolute — a locating step of σ ~ 1e-8
            // would otherwise ask for 1e-20, under the rounding of its own terms
            (Some(arc), _) => arc.ds.abs().max(1e-3),
            (None, Loading::Volume(v)) => v.abs().max(1e-300),
            _ => 1.0,
        };
        let merit = res + c.abs() / cscale;
        let mut converged = res <= self.model.settings.rtol && c.abs() <= 1e-12 * cscale;
        let gas_newton = self.load.gas().is_some() && self.arc.is_none();
        // the last factor reused ([`super::reuse`]): plain solves only, where the last
        // correction contracted the residual well, at the first linearization of a re-solve
        // (after a multiplier update) and at a semi-smooth re-linearization (the same state)
        let eligible = self.arc.is_none() && self.hold.is_none() && self.planes.is_none();
        let contracted = match (&self.branch, self.previous) {
            (None, Some((r0, _))) => res <= CONTRACTION * r0,
            _ => true,
        };
        let mut failed = (0, 0.0);
        let mut reused = None;
        let positions = self.branch.as_deref().unwrap_or(&state.x);
        if eligible
            && contracted
            && self.model.may_reuse()
            && self.model.contact_branches_kept(
                positions,
                self.contact(state).as_deref(),
                &state.multipliers,
            )
        {
            let t_solve = std::time::Instant::now();
            let (correction, krylov) = if converged {
                // no correction is needed; the converged state's inertia comes from one
                // factorization there at the end of the solve (`Model::refresh_inertia`)
                (Some((vec![0.0; r.len()], 0.0)), 0)
            } else {
                let eta = reuse::forcing(res, self.model.settings.rtol);
                let minus_r: Vec<f64> = r.iter().map(|v| -v).collect();
                self.model.reused_correction(
                    (&a, &k),
                    p,
                    gas_newton,
                    minus_r,
                    h.as_deref().map(|h| (h, c, cp)),
                    eta,
                )?
            };
            match correction {
                Some((dx, dp)) => reused = Some((dx, dp, krylov, t_solve.elapsed().as_secs_f64())),
                // GMRES did not reach its tolerance: factorize here and solve directly (the
                // record keeps the iterations and seconds it spent)
                None => failed = (krylov, t_solve.elapsed().as_secs_f64()),
            }
        }
        // (correction, negative pivots, shift, factorization seconds, solve seconds, GMRES
        // iterations, whether this linearization factorized)
        let (dx, dp, negative, shift, factorization_seconds, solve_seconds, krylov, fresh) =
            if let Some((dx, dp, krylov, seconds)) = reused {
                let negative = self.model.last_negative_pivots();
                (dx, dp, negative, 0.0, 0.0, seconds, krylov, false)
            } else {
                let t_factor = std::time::Instant::now();
                // the stiffness scale of a held mode's eigenvalue (and of the factorization's
                // shifts), before the factorization takes (and may shift) the values
                let stiffness = self.model.largest_diagonal_in(&k);
                let (neg, shift) = self.model.factorize_scaled(k, stiffness)?;
                if eligible && self.model.reuses_factor() {
                    let positions = self.branch.as_deref().unwrap_or(&state.x).to_vec();
                    self.model.factorized_at(&positions);
                }
                let factorization_seconds = t_factor.elapsed().as_secs_f64();
                let t_solve = std::time::Instant::now();
                // the Newton correction
                let ldlt = &self.model.ldlt;
                let mut dx: Vec<f64> = r.iter().map(|v| -v).collect();
                let moving = self.planes.zip(self.arc);
                // closed gas: K_gas = K + (ϖ/V) g gᵀ, applied by Sherman–Morrison (`solve_gas`)
                if moving.is_none() && !gas_newton {
                    ldlt.solve(&mut dx);
                }
                let mut dp = 0.0;
                let mut negative = neg;
                if let Some((planes, arc)) = moving {
                    // closed gas with moving planes: K_gas [dx; dλ] bordered by ∂R/∂λ and the arc
                    // constraint, K_gas⁻¹ by Sherman–Morrison on the factor of K
                    negative = negative.saturating_sub(self.model.solve_gas(&a, p, &mut dx));
                    let mut bq: Vec<f64> = self
                        .model
                        .plane_rate(state, planes, state.planes)
                        .into_iter()
                        .map(|v| -v)
                        .collect();
                    self.model.solve_gas(&a, p, &mut bq);
                    let h: Vec<f64> = arc.tx.iter().map(|t| arc.w * t).collect();
                    let hb = dot(&h, &bq) + cp;
                    dp = (-c - dot(&h, &dx)) / hb;
                    for (d, bb) in dx.iter_mut().zip(&bq) {
                        *d += dp * bb;
                    }
                } else if gas_newton {
                    negative = negative.saturating_sub(self.model.solve_gas(&a, p, &mut dx));
                } else if let Some(h) = &h {
                    let mut b = a.g.clone();
                    ldlt.solve(&mut b);
                    if let Some(phi0) = self.hold {
                        // the held mode out of the load column and the correction, and its force out of
                        // the convergence test (it is the reaction of the hold)
                        let (phi, mu) = self.model.inverse_iteration(phi0);
                        project_out(&mut b, &phi);
                        project_out(&mut dx, &phi);
                        negative -= usize::from(mu < 0.0 && negative > 0);
                        // deflating from φ0 makes Kφ lie along φ0 (one inverse iteration), so at the
                        // fixed point R is along φ0: the reaction
                        let mut r_off = r.clone();
                        project_out(&mut r_off, phi0);
                        converged = norm(&r_off) / reference <= self.model.settings.rtol
                            && c.abs() <= 1e-12 * cscale;
                        if converged {
                            self.held = Some(Held {
                                force: dot(phi0, &r),
                                relative_eigenvalue: mu / stiffness,
                                energy: a.energy,
                                mode: phi,
                            });
                        }
                    } else if let Some(phi0) = self.arc.and_then(|arc| arc.neutral) {
                        // the neutral mode out of the load column (not out of the correction: the
                        // residual along it must still go); its pivot out of the count (its sign is
                        // round-off)
                        let (phi, mu) = self.model.deflate(phi0, &a.g, &b);
                        project_out(&mut b, &phi);
                        negative -= usize::from(mu < 0.0 && negative > 0);
                    }
                    let hb = dot(h, &b) + cp;
                    let ha = dot(h, &dx);
                    // the bordered operator's inertia (volume or stretch control); an arc-length step
                    // reports the pressure-control stiffness K itself
                    if hb < 0.0 && self.arc.is_none() {
                        negative = negative.saturating_sub(1);
                    }
                    dp = (-c - ha) / hb;
                    for (d, bb) in dx.iter_mut().zip(&b) {
                        *d += dp * bb;
                    }
                }
                (
                    dx,
                    dp,
                    negative,
                    shift,
                    factorization_seconds,
                    t_solve.elapsed().as_secs_f64() + failed.1,
                    failed.0,
                    true,
                )
            };
        let slope = dot(&r, &dx);
        if self.branch.is_none() {
            self.residual = r;
            self.previous = Some((res, !fresh));
        }
        self.model.log_iteration(IterationRecord {
            assembly: assembly_seconds,
            line_search: self.rejected_seconds.replace(0.0),
            factorization: factorization_seconds,
            factorized: fresh,
            krylov,
            solve: solve_seconds,
            residual: res,
            negative_pivots: negative,
        });
        Ok(Linearization {
            residual: res,
            merit,
            converged,
            potential: potential(self.load.loading, a.energy, a.volume, p),
            slope,
            step: (dx, dp),
            bordered: h.is_some(),
            inertia: Inertia {
                negative_pivots: negative,
                shift,
                stale: !fresh,
            },
        })
    }

    /// Where the full step from `state` ends at `trial` with contact points on the other side
    /// of their kink (pushed at one end, free at the other), the semi-smooth Newton step: the
    /// linearization with each point's contact on the branch it has at `trial`
    /// ([`Contact::kernel_on_branch`]), its residual and potential (for the line search) the
    /// state's own. None where no point changes.
    fn relinearize(
        &mut self,
        state: &mut State,
        lin: &Linearization<Self::Step>,
        trial: &State,
    ) -> Result<Option<Linearization<Self::Step>>, FemError> {
        let Some(contact) = self.contact(state) else {
            return Ok(None);
        };
        let changes =
            self.model
                .contact_status_changes(&state.x, &trial.x, &contact, &state.multipliers);
        drop(contact);
        if changes == 0 {
            return Ok(None);
        }
        let own = std::mem::take(&mut self.residual);
        self.branch = Some(trial.x.clone());
        let branched = self.linearize(state);
        self.branch = None;
        let mut branched = branched?;
        branched.slope = dot(&own, &branched.step.0);
        self.residual = own;
        branched.residual = lin.residual;
        branched.merit = lin.merit;
        branched.potential = lin.potential;
        branched.converged = lin.converged;
        Ok(Some(branched))
    }

    fn evaluate(&self, state: &State) -> Result<Evaluation, FemError> {
        // with the tangent: an accepted trial is where the next iteration linearizes, and it
        // takes this assembly (`assemble_at`) instead of assembling the same state again
        let t = std::time::Instant::now();
        if let Some((_, _, secs)) = self.trial.borrow_mut().take() {
            // an earlier trial of this line search, not taken
            self.rejected_seconds
                .set(self.rejected_seconds.get() + secs);
        }
        let trial = self.assemble_tangent(state)?;
        let pt = self.pressure_of(state).at(trial.volume);
        let rt: Vec<f64> = trial
            .f_int
            .iter()
            .zip(&trial.g)
            .map(|(f, g)| f - pt * g)
            .collect();
        let reft = force_scale(&trial, pt, self.model.load_scale);
        let residual = norm(&rt) / reft;
        self.admissible(&trial, pt, residual)?;
        let out = Evaluation {
            residual,
            potential: potential(self.load.loading, trial.energy, trial.volume, pt),
        };
        *self.trial.borrow_mut() = Some((state.clone(), trial, t.elapsed().as_secs_f64()));
        Ok(out)
    }

    fn update(&self, base: &State, step: &Self::Step, t: f64, state: &mut State) {
        state.x.clone_from(&base.x);
        self.model.dofs.apply(&mut state.x, &step.0, t);
        if self.planes.is_some() {
            // the planes move; the gas pressure follows the volume (set at evaluation)
            state.planes = base.planes + t * step.1;
            state.p = base.p;
        } else {
            state.p = base.p + t * step.1;
        }
    }

    fn step_size(&self, step: &Self::Step) -> f64 {
        self.model.dofs.max_nodal_norm(&step.0)
    }

    fn step_is_finite(&self, step: &Self::Step) -> bool {
        step.0.iter().all(|v| v.is_finite()) && step.1.is_finite()
    }
}
