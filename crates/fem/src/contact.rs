//! Frictionless penalty contact with rigid planes, integrated at the Gauss points of the
//! membrane elements (reference-area weights).
//!
//! ```text
//! plane {x : n·x = d}, n the unit normal pointing to the allowed side; gap g = n·x − d
//! E_c = Σ_gp dA0 (κ/2) ⟨−g⟩²           (⟨·⟩ the positive part: only penetration costs)
//! r_a += dA0 κ ⟨−g⟩ (−N_a) n            (the plane pushes along n)
//! K_ab += dA0 κ N_a N_b n⊗n             (where g < 0)
//! ```
//! Frictionless: the force is along n only. The contact pressure per current area is
//! κ⟨−g⟩ dA0/da; the penetration at a contact pressure p is about p J/κ (J = da/dA0), so κ is
//! chosen from the pressure, the area stretch and a stated penetration tolerance (`penalty_for`).

use crate::element::RefElement;
use tubemem_mesh::dot;

/// A rigid plane {x : normal·x = offset}; `normal` is a unit vector pointing to the side where
/// the membrane may be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub normal: [f64; 3],
    pub offset: f64,
}

impl Plane {
    pub fn gap(&self, x: [f64; 3]) -> f64 {
        dot(self.normal, x) - self.offset
    }
}

/// The penalty κ that gives a penetration of `tolerance` (in R) under the reduced pressure
/// `pressure` where the membrane's area stretch is `area_stretch` (J = λ1λ2): the penalty acts
/// per reference area, so the penetration is p J/κ and κ = ϖ J / tolerance.
pub fn penalty_for(pressure: f64, area_stretch: f64, tolerance: f64) -> f64 {
    pressure * area_stretch / tolerance
}

/// Add the contact energy, residual and (if asked) stiffness of one element.
pub fn contact_kernel(
    re: &RefElement,
    x: &[[f64; 3]; 4],
    planes: &[Plane],
    kappa: f64,
    r: &mut [f64; 12],
    mut k: Option<&mut [f64; 144]>,
) -> f64 {
    let mut energy = 0.0;
    for g in 0..4 {
        let n = &re.n[g];
        let p = [0, 1, 2].map(|c| (0..4).map(|a| n[a] * x[a][c]).sum::<f64>());
        for plane in planes {
            let gap = plane.gap(p);
            if gap >= 0.0 {
                continue;
            }
            let w = re.w[g] * kappa;
            energy += 0.5 * w * gap * gap;
            for a in 0..4 {
                for c in 0..3 {
                    r[3 * a + c] += w * gap * n[a] * plane.normal[c];
                }
            }
            if let Some(k) = k.as_deref_mut() {
                for a in 0..4 {
                    for b in 0..4 {
                        for i in 0..3 {
                            for j in 0..3 {
                                k[(3 * a + i) * 12 + 3 * b + j] +=
                                    w * n[a] * n[b] * plane.normal[i] * plane.normal[j];
                            }
                        }
                    }
                }
            }
        }
    }
    energy
}

/// Contact traction at one Gauss point: (force per reference area, per current area).
pub fn traction(gap: f64, kappa: f64) -> f64 {
    if gap < 0.0 {
        -kappa * gap
    } else {
        0.0
    }
}
