//! Hoop spacing of a generated tube fitted to contact edges: the element node line nearest each
//! given reference angle is moved onto it, so that an element boundary lies where the contact
//! zone ends and the curvature jumps from 0 to 1/r (inside an element the solution is only C¹
//! there, which limits the order of any element).
//!
//! ```text
//! first quadrant θ ∈ [0, π/2]: φ piecewise linear through (0, 0), (θ_k, t_k), …, (π/2, π/2)
//!   t_k a target angle, θ_k = the interior corner line nearest it (uniform spacing 2π/around)
//! other quadrants by the reflections x → −x, y → −y:  φ(π − θ) = π − φ(θ), φ(−θ) = −φ(θ)
//! along the tube:  θ ↦ θ + b(z) (φ(θ) − θ),  b = 1 for |z| ≤ z1, 0 for |z| ≥ z2 (C¹ between)
//! ```
//! Each element between two anchors is stretched by the same factor, at least 1 − 1/(2k) with
//! k ≥ 1 the elements between the anchors, so no element shrinks below half its uniform width.
//! The lines x = 0 and y = 0 stay put (they are symmetry planes), and so do the cylinder's end
//! rings (b = 0 there), which the caps' equators share.

use crate::MeshError;
use std::f64::consts::FRAC_PI_2;

/// The hoop map of one quadrant: the anchors (θ, φ), sorted, from (0, 0) to (π/2, π/2).
#[derive(Clone, Debug, PartialEq)]
pub struct HoopMap {
    anchors: Vec<(f64, f64)>,
}

impl HoopMap {
    /// The map that moves, for each angle of `edges` (in (0, π/2), the first quadrant's
    /// contact edges, mirrored to the other three), the nearest corner line of a tube with
    /// `around` elements around onto it. Two edges that would move the same line, or an edge
    /// not strictly inside the quadrant, are an error.
    pub fn fitted(around: usize, edges: &[f64]) -> Result<Self, MeshError> {
        let per_quadrant = around / 4;
        if per_quadrant < 2 {
            return Err(MeshError::InvalidParameter {
                name: "around",
                value: around as f64,
                requirement: "fitting a contact edge needs at least 8 elements around (a node line inside each quadrant)",
            });
        }
        let h = FRAC_PI_2 / per_quadrant as f64;
        let mut anchors = vec![(0.0, 0.0), (FRAC_PI_2, FRAC_PI_2)];
        for &t in edges {
            if !(t > 0.0 && t < FRAC_PI_2) {
                return Err(MeshError::InvalidParameter {
                    name: "contact edge angle",
                    value: t,
                    requirement: "must lie strictly between the symmetry lines, in (0, π/2)",
                });
            }
            let k = ((t / h).round() as usize).clamp(1, per_quadrant - 1);
            let theta = k as f64 * h;
            if anchors.iter().any(|a| a.0 == theta) {
                return Err(MeshError::InvalidParameter {
                    name: "contact edge angle",
                    value: t,
                    requirement:
                        "two contact edges are nearest the same node line: refine `around`",
                });
            }
            anchors.push((theta, t));
        }
        anchors.sort_by(|a, b| a.0.total_cmp(&b.0));
        if anchors.windows(2).any(|w| !(w[1].1 > w[0].1)) {
            return Err(MeshError::InvalidParameter {
                name: "contact edge angle",
                value: f64::NAN,
                requirement: "the fitted node lines must stay in their order around the tube",
            });
        }
        Ok(Self { anchors })
    }

    /// φ(θ) in the first quadrant.
    fn quadrant(&self, theta: f64) -> f64 {
        let i = self
            .anchors
            .partition_point(|a| a.0 <= theta)
            .clamp(1, self.anchors.len() - 1);
        let (a, b) = (self.anchors[i - 1], self.anchors[i]);
        a.1 + (b.1 - a.1) * (theta - a.0) / (b.0 - a.0)
    }

    /// φ(θ) for any θ (mirrored across x = 0 and y = 0).
    pub fn map(&self, theta: f64) -> f64 {
        use std::f64::consts::PI;
        let t = theta.rem_euclid(2.0 * PI);
        if t <= FRAC_PI_2 {
            self.quadrant(t)
        } else if t <= PI {
            PI - self.quadrant(PI - t)
        } else if t <= 1.5 * PI {
            PI + self.quadrant(t - PI)
        } else {
            2.0 * PI - self.quadrant(2.0 * PI - t)
        }
    }
}

/// The weight b(z) of the fit at height z of a cylinder of half-length `half` and radius
/// `radius`: 1 up to z1 = z2 − w, 0 from z2 = half − w on (w = min(R, half/2)), a C¹ cubic
/// between.
pub fn blend(z: f64, half: f64, radius: f64) -> f64 {
    let w = radius.min(0.5 * half);
    let (z1, z2) = (half - 2.0 * w, half - w);
    let a = z.abs();
    if a <= z1 {
        1.0
    } else if a >= z2 {
        0.0
    } else {
        let s = (a - z1) / (z2 - z1);
        1.0 - s * s * (3.0 - 2.0 * s)
    }
}
