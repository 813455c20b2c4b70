//! Frictionless penalty contact with rigid planes, integrated at the Gauss points of the
//! membrane elements (reference-area weights; any element, N nodes). [`Contact`] is the one owner of the planes and
//! the penalty: the assembly, the outputs and the closed-form comparison all read them from it.
//!
//! ```text
//! plane {x : n·x = d}, n the unit normal pointing to the allowed side; gap g = n·x − d
//! E_c = Σ_gp dA0 (κ/2) ⟨−g⟩²           (⟨·⟩ the positive part: only penetration costs)
//! r_a += dA0 κ ⟨−g⟩ (−N_a) n            (the plane pushes along n)
//! K_ab += dA0 κ N_a N_b n⊗n             (where g < 0)
//! ```
//! Frictionless: the force is along n only. The contact pressure per current area is
//! κ⟨−g⟩ dA0/da; the penetration at a contact pressure p is about p J/κ (J = da/dA0), so κ is
//! chosen from the pressure, the area stretch and a stated penetration tolerance
//! ([`penalty_for`]).

use crate::geometry::{RefElement, Vec3};
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

/// The rigid planes of a step and the penalty that enforces them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Contact {
    pub planes: Vec<Plane>,
    /// κ, per unit μH/R² (see [`penalty_for`])
    pub penalty: f64,
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
        }
    }

    /// The top plate's height h for two plates made by [`Contact::plates`].
    pub fn half_gap(&self) -> Option<f64> {
        self.planes
            .iter()
            .find(|p| p.normal == [0.0, -1.0, 0.0])
            .map(|p| -p.offset)
    }

    /// Contact traction per reference area at a gap (κ⟨−g⟩).
    pub fn traction(&self, gap: f64) -> f64 {
        if gap < 0.0 {
            -self.penalty * gap
        } else {
            0.0
        }
    }

    /// Add the contact energy, residual and (if asked) stiffness of one element.
    pub fn kernel<const N: usize, const D: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        r: &mut SVector<f64, D>,
        mut k: Option<&mut SMatrix<f64, D, D>>,
    ) -> f64 {
        let mut energy = 0.0;
        for (g, gp) in re.gauss.iter().enumerate() {
            let n = &gp.n;
            let p = re.position(g, xe);
            for plane in &self.planes {
                let gap = plane.gap_at(&p);
                if gap >= 0.0 {
                    continue;
                }
                let w = gp.w * self.penalty;
                energy += 0.5 * w * gap * gap;
                // u = ∂g/∂x_e: u[3a + i] = N_a n_i, so r += w g u and K += w u uᵀ (rank one)
                let u = SVector::<f64, D>::from_fn(|row, _| n[row / 3] * plane.normal[row % 3]);
                r.axpy(w * gap, &u, 1.0);
                if let Some(k) = k.as_deref_mut() {
                    k.ger(w, &u, &u, 1.0);
                }
            }
        }
        energy
    }

    /// Add one element's ∂r/∂λ for planes whose offsets move as d_k(λ) with dd_k/dλ =
    /// `rates[k]`: the gap g = n·x − d_k falls by dd_k, so ∂r_a/∂d_k = −w N_a n where g < 0.
    pub fn rate_kernel<const N: usize, const D: usize>(
        &self,
        re: &RefElement<N>,
        xe: &[Vec3; N],
        rates: &[f64],
        q: &mut SVector<f64, D>,
    ) {
        for (g, gp) in re.gauss.iter().enumerate() {
            let n = &gp.n;
            let p = re.position(g, xe);
            for (plane, rate) in self.planes.iter().zip(rates) {
                if plane.gap_at(&p) >= 0.0 || *rate == 0.0 {
                    continue;
                }
                let w = gp.w * self.penalty;
                let u = SVector::<f64, D>::from_fn(|row, _| n[row / 3] * plane.normal[row % 3]);
                q.axpy(-w * rate, &u, 1.0);
            }
        }
    }

    /// Mean contact pressure per current area of an element (for output).
    pub fn element_pressure<const N: usize>(&self, re: &RefElement<N>, xe: &[Vec3; N]) -> f64 {
        let mut s = 0.0;
        let share = 1.0 / re.gauss.len() as f64;
        for g in 0..re.gauss.len() {
            let p = re.position(g, xe);
            let da = re.area_ratio(g, xe);
            for pl in &self.planes {
                s += share * self.traction(pl.gap_at(&p)) / da;
            }
        }
        s
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
