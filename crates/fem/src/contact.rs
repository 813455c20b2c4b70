//! Frictionless contact with rigid planes, integrated at the Gauss points of the membrane
//! elements (reference-area weights; any element, N nodes): a penalty, optionally augmented by
//! Lagrange multipliers (Uzawa). [`Contact`] is the one owner of the planes, the penalty and the
//! enforcement: the assembly, the outputs and the closed-form comparison all read them from it.
//!
//! ```text
//! plane {x : n·x = d}, n the unit normal pointing to the allowed side; gap g = n·x − d
//! traction per reference area at a Gauss point with multiplier λ ≥ 0:  t = ⟨λ − κ g⟩
//! E_c = Σ_gp dA0 (t² − λ²)/(2κ)          (λ = 0: the penalty (κ/2)⟨−g⟩²)
//! r_a += dA0 t (−N_a) n                  (the plane pushes along n)
//! K_ab += dA0 κ N_a N_b n⊗n              (where t > 0)
//! Uzawa (between converged Newton solves, [`crate::model::Model::augment`]):  λ ← ⟨λ − κ g⟩
//! ```
//! Frictionless: the force is along n only. The contact pressure per current area is
//! t dA0/da. With the penalty alone (λ = 0) the membrane sits about p J/κ inside a plane that
//! presses it with the pressure p (J = da/dA0), so κ is chosen from the pressure, the area
//! stretch and a stated penetration tolerance ([`penalty_for`]). The augmented Lagrangian keeps
//! that κ as the regularization and removes the offset: at the fixed point of the update
//! λ = t, so every Gauss point either carries λ > 0 at g = 0 or is free with g ≥ 0; the updates
//! stop when the largest |g| where a plane pushes (t > 0) is within the gap tolerance.

use crate::geometry::{GaussPoint, RefElement, Vec3};
use nalgebra::{SMatrix, SVector};
use serde::Serialize;

/// A rigid plane {x : normal·x = offset}; `normal` is a unit vector pointing to the side where
/// the membrane may be.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Plane {
    pub normal: [f64; 3],
    pub offset: f64,
}

impl Plane {
    pub fn gap(&self, x: [f64; 3]) -> f64 {
        self.gap_at(&Vec3::from(x))
    }

    fn gap_at(&self, x: &Vec3) -> f64 {
        Vec3::from(self.normal).dot(x) - self.offset
    }
}

/// How the planes are enforced.
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(tag = "method", rename_all = "kebab-case")]
pub enum Enforcement {
    /// the penalty alone: the membrane sits about p J/κ inside each plane that presses it
    Penalty,
    /// the penalty augmented by Gauss-point multipliers, updated (Uzawa) between converged
    /// Newton solves until the largest |g| where a plane pushes is at most `gap_tolerance`
    /// (in R)
    Augmented {
        gap_tolerance: f64,
        /// updates allowed in one step before it fails
        max_augmentations: usize,
    },
}

/// Where the contact acts: at an element's Gauss points, or at its nodes, each weighted by
/// ∫N_a dA0 (a nodal quadrature: one constraint per node and plane, where the Gauss points of
/// an element, 9 of them on 9 nodes but closer together, give nearly dependent constraints
/// along a contact edge that cuts the element).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum ContactPoints {
    #[default]
    Gauss,
    Nodal,
}

/// The augmentations allowed in one step by default: 50. With the default regularization the
/// shipped contact cases take one or two a step (README "Contact"); with κ from a tolerance of
/// 1e-3 R the 4-node squeeze took 7 to 27. A step that needs more than 50 is not converging.
pub const DEFAULT_MAX_AUGMENTATIONS: usize = 50;

/// The gap tolerance of an augmented contact by default, in R: 1e-9, the gap issue #23 names
/// as negligible, three orders below its 2e-6 target for λs at 64 around.
pub const DEFAULT_GAP_TOLERANCE: f64 = 1e-9;

impl Enforcement {
    /// The augmented Lagrangian with the default gap tolerance and update limit.
    pub fn augmented() -> Self {
        Enforcement::Augmented {
            gap_tolerance: DEFAULT_GAP_TOLERANCE,
            max_augmentations: DEFAULT_MAX_AUGMENTATIONS,
        }
    }
}

/// Values of a Gauss point's contact history per plane: the multiplier λ, the local penalty κ_g
/// and the gap at the last update of the current solve (NaN: none). Only λ carries over from one
/// solve to the next: κ_g and the gap are reset when a solve starts
/// ([`Contact::restart_history`]).
pub const HISTORY: usize = 3;
/// A gap that fell by less than this factor in one multiplier update raises the local penalty.
pub const SLOW_CONTRACTION: f64 = 0.3;
/// The most the local penalty grows in one update.
pub const PENALTY_GROWTH: f64 = 10.0;
/// The largest local penalty, over the stage's κ: 100, a penetration tolerance of 1e-5 R at
/// the default 1e-3 (the README's penalty study converged down to 1e-5 without stalls on the
/// 4-node squeeze).
pub const MAX_PENALTY_RATIO: f64 = 1e2;

/// What one multiplier update found (maxima over the Gauss points and planes it covers).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UpdateSize {
    /// the largest |g| where the plane pushes (t > 0), in R
    pub gap: f64,
    /// the largest |Δλ| (per reference area, in μH/R)
    pub change: f64,
    /// the largest penetration ⟨−g⟩ where the plane pushes, in R
    pub penetration: f64,
}

impl UpdateSize {
    /// The maxima of two.
    pub fn max(self, o: Self) -> Self {
        Self {
            gap: self.gap.max(o.gap),
            change: self.change.max(o.change),
            penetration: self.penetration.max(o.penetration),
        }
    }
}

/// A Gauss point's multiplier and local penalty against one plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussContact {
    pub lambda: f64,
    pub penalty: f64,
}

/// The rigid planes of a step, the penalty and how they are enforced.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Contact {
    pub planes: Vec<Plane>,
    /// κ, per unit μH/R² (see [`penalty_for`])
    pub penalty: f64,
    pub enforcement: Enforcement,
    /// where the planes act on an element
    pub points: ContactPoints,
}

impl Contact {
    /// Two plates y = ±`half_gap` (normals ∓e_y), the squeeze of the paper's Sec. 4.
    pub fn plates(half_gap: f64, penalty: f64) -> Self {
        Self {
            planes: vec![
                Plane {
                    normal: [0.0, -1.0, 0.0],
                    offset: -half_gap,
                },
                Plane {
                    normal: [0.0, 1.0, 0.0],
                    offset: -half_gap,
                },
            ],
            penalty,
            enforcement: Enforcement::Penalty,
            points: ContactPoints::Gauss,
        }
    }

    /// The same planes, acting at `points`.
    pub fn with_points(mut self, points: ContactPoints) -> Self {
        self.points = points;
        self
    }

    /// The points of element `re` where the planes act ([`Contact::points`]): its Gauss points
    /// or its nodes.
    pub fn samples<'a, const N: usize>(&self, re: &'a RefElement<N>) -> &'a [GaussPoint<N>] {
        match self.points {
            ContactPoints::Gauss => &re.gauss,
            ContactPoints::Nodal => &re.nodal,
        }
    }

    /// The same planes and penalty, enforced by `enforcement`.
    pub fn with_enforcement(mut self, enforcement: Enforcement) -> Self {
        self.enforcement = enforcement;
        self
    }

    /// The number of history values per element of `points` contact points ([`Contact::samples`]): for each
    /// Gauss point and plane, [`HISTORY`] values (the multiplier, the local penalty and the
    /// gap at the last update).
    pub fn multipliers_per_element(&self, points: usize) -> usize {
        HISTORY * points * self.planes.len()
    }

    /// Element `e`'s part of a model's contact history `all` (elements of `points`
    /// Gauss points, element major; empty when `all` holds none, e.g. under the penalty alone).
    pub fn element_history<'a>(&self, all: &'a [f64], e: usize, points: usize) -> &'a [f64] {
        let per = self.multipliers_per_element(points);
        all.get(e * per..(e + 1) * per).unwrap_or(&[])
    }

    /// Start a solve from `history`: every point's local penalty back to κ and no last gap,
    /// the multipliers kept (a local penalty raised in the last step's updates would meet this
    /// step's new penetrations as a stiff penalty, which Newton handles badly).
    pub fn restart_history(&self, history: &mut [f64]) {
        for h in history.chunks_exact_mut(HISTORY) {
            h[1] = self.penalty;
            h[2] = f64::NAN;
        }
    }

    /// The top plate's height h for two plates made by [`Contact::plates`].
    pub fn half_gap(&self) -> Option<f64> {
        self.top_plate().map(|k| -self.planes[k].offset)
    }

    /// The index of the top plate y = h (normal −e_y) among the planes.
    pub fn top_plate(&self) -> Option<usize> {
        self.planes
            .iter()
            .position(|p| p.normal == [0.0, -1.0, 0.0])
    }

    /// Contact traction per reference area at a gap with no multiplier (κ⟨−g⟩).
    pub fn traction(&self, gap: f64) -> f64 {
        self.traction_at(
            gap,
            GaussContact {
                lambda: 0.0,
                penalty: self.penalty,
            },
        )
    }

    /// Contact traction per reference area at a gap and a Gauss point's multiplier and local
    /// penalty: ⟨λ − κ_g g⟩.
    pub fn traction_at(&self, gap: f64, at: GaussContact) -> f64 {
        let t = at.lambda - at.penalty * gap;
        if t > 0.0 {
            t
        } else {
            0.0
        }
    }

    /// The multiplier and local penalty of Gauss point `g` against plane `k` in one element's
    /// history `lambda` ([`Contact::multipliers_per_element`] values, Gauss point major;
    /// empty: λ = 0 and the stage's penalty κ).
    pub fn point(&self, lambda: &[f64], g: usize, k: usize) -> GaussContact {
        let i = HISTORY * (g * self.planes.len() + k);
        match lambda.get(i..i + HISTORY) {
            Some(h) => GaussContact {
                lambda: h[0],
                penalty: h[1],
            },
            None => GaussContact {
                lambda: 0.0,
                penalty: self.penalty,
            },
        }
    }

    /// A fresh history for one element of `points` contact points: λ = 0, the stage's κ,
    /// no last gap.
    pub fn fresh_history(&self, points: usize) -> Vec<f64> {
        (0..points * self.planes.len())
            .flat_map(|_| [0.0, self.penalty, f64::NAN])
            .collect()
    }

    /// Add the contact energy, residual and (if asked) stiffness of one element whose
    /// contact history is `lambda` ([`Contact::point`]; empty: the penalty alone).
    pub fn kernel<const N: usize, const D: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        lambda: &[f64],
        r: &mut SVector<f64, D>,
        k: Option<&mut SMatrix<f64, D, D>>,
    ) -> f64 {
        self.kernel_on_branch(re, xe, None, lambda, r, k)
    }

    /// [`Contact::kernel`] on the branch of the element's positions `branch` (where a Newton
    /// step ends): a point is pushed where the plane pushes it at `branch`, with the traction
    /// λ − κ_g g linearized at `xe` (negative where the point is apart at `xe`: the pushed
    /// branch continued), and free where the plane does not push it at `branch` (no force,
    /// no stiffness, even where it pushes at `xe`). The traction t = ⟨λ − κ_g g⟩ is piecewise
    /// linear in x; a Newton step on the branch it ends on is the semi-smooth Newton step
    /// ([`crate::model`]'s `relinearize`). `branch` = `xe` (or none) is [`Contact::kernel`].
    /// The energy returned is the branch's quadratic (t² − λ²)/(2κ_g), for pushed points.
    pub fn kernel_on_branch<const N: usize, const D: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        branch: Option<&[Vec3; N]>,
        lambda: &[f64],
        r: &mut SVector<f64, D>,
        mut k: Option<&mut SMatrix<f64, D, D>>,
    ) -> f64 {
        let mut energy = 0.0;
        for (g, gp) in self.samples(re).iter().enumerate() {
            let n = &gp.n;
            let p = gp.position(xe);
            let at_branch = branch.map(|b| gp.position(b));
            for (kp, plane) in self.planes.iter().enumerate() {
                let gap = plane.gap_at(&p);
                let at = self.point(lambda, g, kp);
                let (l, kappa) = (at.lambda, at.penalty);
                // pushed: the plane's traction t at the status positions is positive; t the
                // pushed branch's value at xe (on its own branch, ⟨λ − κ_g g⟩)
                let (pushed, t) = match &at_branch {
                    None => {
                        let t = self.traction_at(gap, at);
                        (t > 0.0, t)
                    }
                    Some(b) => (self.traction_at(plane.gap_at(b), at) > 0.0, l - kappa * gap),
                };
                if !pushed {
                    // free: E = −λ²/(2κ), a constant of x
                    if l != 0.0 {
                        energy -= gp.w * l * l / (2.0 * kappa);
                    }
                    continue;
                }
                let w = gp.w * kappa;
                // r −= dA0 t u: with λ = 0 (the penalty alone) written as dA0 κ g u, the same
                // arithmetic as before the multipliers existed (penalty runs are bitwise
                // unchanged)
                let coefficient = if l == 0.0 {
                    energy += 0.5 * w * gap * gap;
                    w * gap
                } else {
                    energy += gp.w * (t * t - l * l) / (2.0 * kappa);
                    -gp.w * t
                };
                // u = ∂g/∂x_e: u[3a + i] = N_a n_i, and K += dA0 κ u uᵀ (rank one)
                let u = SVector::<f64, D>::from_fn(|row, _| n[row / 3] * plane.normal[row % 3]);
                r.axpy(coefficient, &u, 1.0);
                if let Some(k) = k.as_deref_mut() {
                    k.ger(w, &u, &u, 1.0);
                }
            }
        }
        energy
    }

    /// The number of points and planes of one element whose contact status (pushed: t > 0, or
    /// free) differs between the positions `xe` and `other`, with the history `lambda`.
    pub fn status_changes<const N: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        other: &[Vec3; N],
        lambda: &[f64],
    ) -> usize {
        let mut changes = 0;
        for (g, gp) in self.samples(re).iter().enumerate() {
            let (p, q) = (gp.position(xe), gp.position(other));
            for (kp, plane) in self.planes.iter().enumerate() {
                let at = self.point(lambda, g, kp);
                let pushed = self.traction_at(plane.gap_at(&p), at) > 0.0;
                changes += usize::from(pushed != (self.traction_at(plane.gap_at(&q), at) > 0.0));
            }
        }
        changes
    }

    /// The Uzawa update of one element's contact history at the positions `xe`, written to
    /// `out`: λ ← ⟨λ − κ_g g⟩ for every Gauss point and plane, and the local penalty κ_g raised
    /// where the gap fell slowly since the last update of the same solve (none when the last
    /// gap is NaN, as after [`Contact::restart_history`]). The multiplier iteration contracts a gap by about K/(K + κ_g), with K the
    /// membrane's local stiffness against the plane: where a gap fell by less than
    /// [`SLOW_CONTRACTION`] (K above about κ_g/2, e.g. where the flat zone meets the caps),
    /// κ_g is raised to 9 K, which contracts by 0.1 (by at most [`PENALTY_GROWTH`] per update
    /// and [`MAX_PENALTY_RATIO`] κ in all). Returns the largest |g| where the plane pushes
    /// (t > 0: the gap left, either sign; where t = 0 the point is free with g ≥ λ/κ_g ≥ 0 and
    /// complementarity holds), the largest |Δλ| and the largest penetration ⟨−g⟩ where the
    /// plane pushes.
    pub fn update_multipliers<const N: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        lambda: &[f64],
        gap_tolerance: f64,
        out: &mut [f64],
    ) -> UpdateSize {
        let mut size = UpdateSize::default();
        for (g, gp) in self.samples(re).iter().enumerate() {
            let p = gp.position(xe);
            for (kp, plane) in self.planes.iter().enumerate() {
                let gap = plane.gap_at(&p);
                let at = self.point(lambda, g, kp);
                let t = self.traction_at(gap, at);
                size.change = size.change.max((t - at.lambda).abs());
                if t > 0.0 {
                    size.gap = size.gap.max(gap.abs());
                    size.penetration = size.penetration.max(-gap);
                }
                let i = HISTORY * (g * self.planes.len() + kp);
                let last = lambda.get(i + 2).copied().unwrap_or(f64::NAN);
                let mut kappa = at.penalty;
                if t > 0.0 && gap.abs() > 10.0 * gap_tolerance && last.is_finite() {
                    let ratio = gap.abs() / last.abs().max(1e-300);
                    if ratio > SLOW_CONTRACTION {
                        let factor = if ratio < 1.0 {
                            (9.0 * ratio / (1.0 - ratio)).min(PENALTY_GROWTH)
                        } else {
                            PENALTY_GROWTH
                        };
                        kappa = (kappa * factor).min(MAX_PENALTY_RATIO * self.penalty);
                    }
                }
                out[i] = t;
                out[i + 1] = kappa;
                out[i + 2] = if t > 0.0 { gap } else { f64::NAN };
            }
        }
        size
    }

    /// Add one element's ∂r/∂λ for planes whose offsets move as d_k(λ) with dd_k/dλ =
    /// `rates[k]`: the gap g = n·x − d_k falls by dd_k, so ∂r_a/∂d_k = −w N_a n where g < 0.
    pub fn rate_kernel<const N: usize, const D: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        lambda: &[f64],
        rates: &[f64],
        q: &mut SVector<f64, D>,
    ) {
        for (g, gp) in self.samples(re).iter().enumerate() {
            let n = &gp.n;
            let p = gp.position(xe);
            for (kp, (plane, rate)) in self.planes.iter().zip(rates).enumerate() {
                let at = self.point(lambda, g, kp);
                let t = self.traction_at(plane.gap_at(&p), at);
                if t <= 0.0 || *rate == 0.0 {
                    continue;
                }
                let w = gp.w * at.penalty;
                let u = SVector::<f64, D>::from_fn(|row, _| n[row / 3] * plane.normal[row % 3]);
                q.axpy(-w * rate, &u, 1.0);
            }
        }
    }

    /// The contact pressure per current area at each of element `re`'s contact points
    /// ([`Contact::samples`]) against plane `k`, with its history `lambda`: at a Gauss point
    /// t/J; at a node the force t w_a over the node's share of the element's current area,
    /// ∫N_a da = Σ_g w_g N_a J_g (t/J at the node itself would carry the O(h²) variation of J
    /// over a curved reference element: +1.5e-3 and −7.7e-4 at the corner and mid-side lines of
    /// the 9-node squeeze's flat zone at 32 around, where the force over the area is ϖ).
    pub fn point_pressures<const N: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        lambda: &[f64],
        k: usize,
    ) -> Vec<f64> {
        let plane = &self.planes[k];
        let points = self.samples(re);
        let nodal_area: Vec<f64> = match self.points {
            ContactPoints::Gauss => vec![],
            ContactPoints::Nodal => {
                let j: Vec<f64> = re.gauss.iter().map(|gp| gp.area_ratio(xe)).collect();
                (0..N)
                    .map(|a| {
                        re.gauss
                            .iter()
                            .zip(&j)
                            .map(|(gp, j)| gp.w * gp.n[a] * j)
                            .sum()
                    })
                    .collect()
            }
        };
        points
            .iter()
            .enumerate()
            .map(|(g, gp)| {
                let t = self.traction_at(plane.gap_at(&gp.position(xe)), self.point(lambda, g, k));
                match self.points {
                    ContactPoints::Gauss => t / gp.area_ratio(xe),
                    ContactPoints::Nodal => t * gp.w / nodal_area[g],
                }
            })
            .collect()
    }

    /// Mean contact pressure per current area of an element with multipliers `lambda` (for
    /// output): the planes' force on it over its current area.
    pub fn element_pressure<const N: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        lambda: &[f64],
    ) -> f64 {
        let mut s = 0.0;
        let points = self.samples(re);
        match self.points {
            ContactPoints::Gauss => {
                // the mean of t/J over the Gauss points
                let share = 1.0 / points.len() as f64;
                for (g, gp) in points.iter().enumerate() {
                    let p = gp.position(xe);
                    let da = gp.area_ratio(xe);
                    for (kp, pl) in self.planes.iter().enumerate() {
                        s +=
                            share * self.traction_at(pl.gap_at(&p), self.point(lambda, g, kp)) / da;
                    }
                }
                s
            }
            ContactPoints::Nodal => {
                let area: f64 = re.gauss.iter().map(|gp| gp.w * gp.area_ratio(xe)).sum();
                for (g, gp) in points.iter().enumerate() {
                    for (kp, pl) in self.planes.iter().enumerate() {
                        s += gp.w
                            * self.traction_at(
                                pl.gap_at(&gp.position(xe)),
                                self.point(lambda, g, kp),
                            );
                    }
                }
                s / area
            }
        }
    }
}

/// Planes moved by one load parameter λ: plane k's offset is d_k(0) + `rates[k]`·λ (the plates
/// of a squeeze with λ the half-gap h, or the planes of a confine stage with λ ∈ [0, 1]). The
/// load parameter of a closed-gas arc-length path.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingPlanes {
    /// the planes at λ = 0
    pub at_zero: Contact,
    /// dd_k/dλ, one per plane
    pub rates: Vec<f64>,
}

impl MovingPlanes {
    /// The two plates y = ±h of [`Contact::plates`], λ = h.
    pub fn plates(penalty: f64) -> Self {
        Self {
            at_zero: Contact::plates(0.0, penalty),
            rates: vec![-1.0, -1.0],
        }
    }

    /// The same planes enforced by `enforcement`.
    pub fn with_enforcement(mut self, enforcement: Enforcement) -> Self {
        self.at_zero.enforcement = enforcement;
        self
    }

    /// The same planes acting at `points`.
    pub fn with_points(mut self, points: ContactPoints) -> Self {
        self.at_zero.points = points;
        self
    }

    /// The planes at λ.
    pub fn at(&self, lambda: f64) -> Contact {
        let mut c = self.at_zero.clone();
        for (p, r) in c.planes.iter_mut().zip(&self.rates) {
            p.offset += r * lambda;
        }
        c
    }
}

/// The penalty κ that gives a penetration of `tolerance` (in R) under the reduced pressure
/// `pressure` where the membrane's area stretch is `area_stretch` (J = λ1λ2): the penalty acts
/// per reference area, so the penetration is p J/κ and κ = ϖ J / tolerance.
pub fn penalty_for(pressure: f64, area_stretch: f64, tolerance: f64) -> f64 {
    pressure * area_stretch / tolerance
}
