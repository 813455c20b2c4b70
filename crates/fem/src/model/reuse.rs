//! Factorizing less often: within a load step the tangent changes little, so the last LDLᵀ
//! factor of K, taken at an earlier linearization, preconditions GMRES ([`crate::krylov`]) on
//! the current tangent, and the model refactorizes only when that stops paying.
//!
//! The rules ([`Refactorization::OnDemand`]):
//!
//! - **What is solved.** The same Newton correction as with a fresh factor — the same
//!   residual R, the same bordered (volume or node control) and closed-gas systems — to the
//!   relative tolerance η of an inexact Newton method (Eisenstat & Walker 1996):
//!   η = min([`MAX_FORCING`], max(r, 0.1 rtol / r)) with r the scaled residual. η = O(r) keeps
//!   Newton's quadratic convergence (Dembo, Eisenstat & Steihaug 1982: an inexact Newton with
//!   η_k = O(‖R_k‖) converges quadratically); the 0.1 rtol / r floor asks no more than what
//!   takes the next residual under a tenth of the tolerance. The closed gas's rank-one term is
//!   in the operator GMRES applies, so the factor of K alone preconditions K + c g gᵀ.
//! - **How convergence is judged.** Unchanged: on the true residual R of a fresh assembly at
//!   every iterate, against the Newton tolerance rtol. The factor only shapes the corrections.
//! - **When to reuse.** A solve's first linearization factorizes (so that what a solve
//!   computes does not depend on the solves before it: a restarted run repeats the
//!   uninterrupted one bit for bit). Later ones reuse the last factor where the residual fell
//!   to [`CONTRACTION`] of the previous linearization's or less (Newton is converging, and the
//!   tangent changes little from one iterate to the next), at the first linearization of an
//!   augmentation's re-solve (the multipliers moved, the tangent barely) and at a semi-smooth
//!   re-linearization (the same state on other contact branches). A GMRES solve that does
//!   not reach η within [`MAX_KRYLOV`] iterations gives up, and the linearization
//!   factorizes and solves directly. So that it seldom has to, a linearization where more
//!   than [`MAX_STATUS_CHANGES`] contact points changed status (pushed or free) since the
//!   factor's tangent factorizes at once. A factorization that needed a diagonal shift (a singular
//!   K) is not reused.
//! - **The inertia.** A linearization that reuses the factor has no inertia of its own; the
//!   solve that converges on one refactorizes once at its converged state
//!   ([`Model::refresh_inertia`]), so every reported negative-pivot count is that of the
//!   converged state's own tangent, as with a fresh factor at every iteration.
//! - **Where.** Plain Newton solves under pressure, volume, node or closed-gas control (with
//!   or without contact and its augmentations). Arc-length correctors, held modes and moving
//!   planes factorize at every iteration: they use the factor for inverse iterations and
//!   deflation, where a stale factor would change what they compute.
//!
//! [`Refactorization::Auto`] does this only where a factorization costs many substitutions:
//! its flops at least [`AUTO_FLOP_RATIO`] times those of a forward and back substitution
//! (4 nnz(L)). Measured side by side (`refactorize = "always"` against `"on-demand"`, release,
//! one thread, this 2-core machine, `scripts/bench-million.sh` and the shipped cases):
//!
//! | model | equations | flop ratio | factorizations | wall |
//! |---|---|---|---|---|
//! | million benchmark at a sixteenth (112 × 140) | 61,152 | 78 | 72 → 42 | 16.3 → 14.4 s |
//! | million benchmark at a quarter (224 × 280) | 244,608 | 111 | 90 → 59 | 116.8 → 97.7 s |
//! | `squeeze_abb30_ls1.3` | 4,520 | 15.5 | | 0.87 → 0.74 s |
//! | `squeeze_abb30_ls1.3_lr80` | 16,280 | 15.7 | | 3.3 → 2.7–3.0 s |
//! | `vgroove_abb30_ls1.3` | 8,945 | 20.9 | 94 → 46 | 3.3 → 3.7 s |
//!
//! The V-groove is slower on demand: its inexact corrections take 126 linearizations against
//! 94, and a factorization there costs about four GMRES iterations. Every shipped case is
//! below the threshold, so `Auto` keeps the exact Newton method on them, bit for bit; the
//! squeezes gain by asking for `"on-demand"`.

use super::*;
use crate::krylov::{self, KrylovReport};

/// When the Newton linearizations factorize their tangent (`[solver] refactorize`).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum Refactorization {
    /// every linearization factorizes (the exact Newton method)
    Always,
    /// on demand where a factorization costs at least [`AUTO_FLOP_RATIO`] substitutions in
    /// flops, at every linearization otherwise
    #[default]
    Auto,
    /// on demand whatever the size
    OnDemand,
}

/// The largest GMRES iteration count of one solve with a reused factor: 8. Past it the solve
/// refactorizes. One iteration costs about one substitution with the factor (plus a product
/// with K and the orthogonalization); on the million-unknown tube a factorization costs about
/// 13 substitutions in time (5.0 against 0.38 s, `scripts/bench-million.sh`), so a solve that
/// gives up after 8 has lost less than a factorization.
pub const MAX_KRYLOV: usize = 8;

/// The contact points whose status (pushed or free) may differ between the factor's tangent
/// and the current one for the factor to be reused: 4, half of [`MAX_KRYLOV`] (each change is
/// a rank-one term GMRES needs about one iteration for).
pub const MAX_STATUS_CHANGES: usize = 4;

/// The largest forcing term η of an inexact Newton correction: 1e-2.
pub const MAX_FORCING: f64 = 1e-2;

/// The residual reduction since the previous linearization from which a linearization reuses
/// the factor: 0.5 (the last correction at least halved the residual).
pub const CONTRACTION: f64 = 0.5;

/// [`Refactorization::Auto`]: the ratio of a factorization's flops to a substitution's
/// (4 nnz(L)) from which the factor is reused: 50. The substitution is memory-bound and the
/// factorization is not, so in time the ratio is smaller (the million-unknown tube: 194 in
/// flops, 13 in time).
pub const AUTO_FLOP_RATIO: f64 = 50.0;

/// A Newton correction (Δx on the free dofs, Δϖ).
pub(super) type Correction = (Vec<f64>, f64);

/// The factor's state across linearizations.
#[derive(Default)]
pub(super) struct FactorReuse {
    pub(super) policy: Refactorization,
    /// the last factorization's negative pivots and shift
    last: (usize, f64),
    /// the next linearization factorizes
    refactor: bool,
    /// Krylov iterations since the model was built (all solves)
    pub(super) krylov_iterations: usize,
    /// the positions whose contact branches the factor's tangent took (None: unknown, a
    /// factorization outside the membrane problem)
    at: Option<Vec<[f64; 3]>>,
}

impl Model {
    /// When the Newton linearizations factorize their tangent ([`Refactorization`]).
    pub fn set_refactorization(&mut self, policy: Refactorization) {
        self.reuse.policy = policy;
    }

    /// The policy set with [`Model::set_refactorization`].
    pub fn refactorization(&self) -> Refactorization {
        self.reuse.policy
    }

    /// Whether the policy reuses the factor on this model ([`Refactorization::Auto`] resolved
    /// by the flop ratio).
    pub fn reuses_factor(&self) -> bool {
        match self.reuse.policy {
            Refactorization::Always => false,
            Refactorization::OnDemand => true,
            Refactorization::Auto => {
                self.ldlt.factor_flops() >= AUTO_FLOP_RATIO * 4.0 * self.ldlt.factor_nnz() as f64
            }
        }
    }

    /// The GMRES iterations of all reused-factor solves so far.
    pub fn krylov_iterations(&self) -> usize {
        self.reuse.krylov_iterations
    }

    /// Whether the next linearization may solve with the factor it has.
    pub(super) fn may_reuse(&self) -> bool {
        self.reuses_factor()
            && self.ldlt.is_factorized()
            && !self.reuse.refactor
            && self.reuse.last.1 == 0.0
    }

    /// Make the next linearization factorize.
    pub(super) fn require_factorization(&mut self) {
        self.reuse.refactor = true;
    }

    /// The factorization's inertia and shift, remembered for the linearizations that reuse it.
    pub(super) fn factorized(&mut self, neg: usize, shift: f64) {
        self.reuse.last = (neg, shift);
        self.reuse.refactor = false;
        self.reuse.at = None;
    }

    /// The positions whose contact branches the last factorization's tangent took.
    pub(super) fn factorized_at(&mut self, x: &[[f64; 3]]) {
        self.reuse.at = Some(x.to_vec());
    }

    /// Whether the contact points pushed at `x` are those the factor's tangent had pushed,
    /// up to [`MAX_STATUS_CHANGES`] of them: each point that changed adds a rank-one penalty
    /// term κ n nᵀ to the difference between the tangent and the factor's, and GMRES needs
    /// about one iteration per such term. A factor of unknown positions is tried.
    pub(super) fn contact_branches_kept(
        &self,
        x: &[[f64; 3]],
        contact: Option<&Contact>,
        multipliers: &[f64],
    ) -> bool {
        match (&self.reuse.at, contact) {
            (Some(at), Some(contact)) => {
                self.contact_status_changes(at, x, contact, multipliers) <= MAX_STATUS_CHANGES
            }
            _ => true,
        }
    }

    /// The negative pivots of the last factorization (the reused factor's).
    pub(super) fn last_negative_pivots(&self) -> usize {
        self.reuse.last.0
    }

    /// The Newton correction (Δx, Δp) with the reused factor preconditioning GMRES on the
    /// current tangent K = K_int − ϖH (+ (ϖ/V) g gᵀ for closed gas) of the assembly `a`, whose
    /// values (one per pattern entry) are `k`: `minus_r` is −R, `border`
    /// the constraint's (h, c, ∂c/∂ϖ) of a bordered control. None where a solve did not reach
    /// `eta` within [`MAX_KRYLOV`] iterations (the caller refactorizes); Err where K cannot be
    /// built. Also returns the GMRES iterations it took.
    pub(super) fn reused_correction(
        &mut self,
        (a, k): (&Assembled, &[f64]),
        p: f64,
        gas: bool,
        mut minus_r: Vec<f64>,
        border: Option<(&[f64], f64, f64)>,
        eta: f64,
    ) -> Result<(Option<Correction>, usize), FemError> {
        let k = self.ldlt.matrix(k)?;
        let cc = if gas { p / a.volume } else { 0.0 };
        let ldlt = &self.ldlt;
        let mut iterations = 0;
        let mut solve = |v: &mut Vec<f64>| -> bool {
            let report: KrylovReport = krylov::gmres(
                v,
                eta,
                MAX_KRYLOV,
                |x, out| {
                    k.apply(x, out);
                    if cc != 0.0 {
                        let gx = dot(&a.g, x);
                        for (o, g) in out.iter_mut().zip(&a.g) {
                            *o += cc * g * gx;
                        }
                    }
                },
                |x| ldlt.solve(x),
            );
            iterations += report.iterations;
            report.converged
        };
        let mut ok = solve(&mut minus_r);
        let mut dp = 0.0;
        if ok {
            if let Some((h, c, cp)) = border {
                let mut b = a.g.clone();
                ok = solve(&mut b);
                let hb = dot(h, &b) + cp;
                dp = (-c - dot(h, &minus_r)) / hb;
                for (d, bb) in minus_r.iter_mut().zip(&b) {
                    *d += dp * bb;
                }
            }
        }
        self.reuse.krylov_iterations += iterations;
        Ok((ok.then_some((minus_r, dp)), iterations))
    }
}

/// The forcing term of an inexact Newton correction at the scaled residual `r` with the
/// tolerance `rtol` (see the module's rules).
pub(super) fn forcing(r: f64, rtol: f64) -> f64 {
    MAX_FORCING.min(r.max(0.1 * rtol / r.max(1e-300)))
}
