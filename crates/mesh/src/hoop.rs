//! Hoop spacing of a generated tube fitted to contact edges: the element node line nearest each
//! given reference angle is moved onto it, so that an element boundary lies where the contact
//! zone ends and the curvature jumps from 0 to 1/r (inside an element the solution is only C¹
//! there, which limits the order of any element).
//!
//! ```text
//! φ piecewise linear through (0, 0), (θ_k, t_k), …, (π/2, π/2), …, (2π, 2π)
//!   t_k a target angle, θ_k = 2πk/around the corner line nearest it (not on x = 0 or y = 0)
//! along the tube:  θ ↦ θ + b(z) (φ(θ) − θ),  b = 1 for |z| ≤ z1, 0 for |z| ≥ z2 (C¹ between)
//! ```
//! Each element between two anchors is stretched by the same factor, at least 1 − 1/(2k) with
//! k ≥ 1 the elements between the anchors, so no element shrinks below half its uniform width.
//! The lines x = 0 and y = 0 stay put (they may be symmetry planes), and so do the cylinder's
//! end rings (b = 0 there), which the caps' equators share. Targets symmetric under the
//! model's reflections give a map with the same symmetry.

use crate::MeshError;
use std::f64::consts::{FRAC_PI_2, PI};

/// The hoop map: the anchors (θ, φ), sorted, from (0, 0) to (2π, 2π).
#[derive(Clone, Debug, PartialEq)]
pub struct HoopMap {
    anchors: Vec<(f64, f64)>,
}

impl HoopMap {
    /// The map that moves, for each angle of `edges` (in [0, 2π), from the x axis), the
    /// nearest corner line of a tube with `around` elements around onto it (the lines x = 0
    /// and y = 0 excepted: an edge nearest one of those moves its neighbour). Two edges that
    /// would move the same line are an error.
    pub fn fitted(around: usize, edges: &[f64]) -> Result<Self, MeshError> {
        let quarter = around / 4;
        if quarter < 2 {
            return Err(MeshError::InvalidParameter {
                name: "around",
                value: around as f64,
                requirement: "fitting a contact edge needs at least 8 elements around (a node line inside each quadrant)",
            });
        }
        let h = 2.0 * PI / around as f64;
        let mut anchors: Vec<(f64, f64)> = (0..=4)
            .map(|q| (q as f64 * FRAC_PI_2, q as f64 * FRAC_PI_2))
            .collect();
        for &t in edges {
            if !(t.is_finite() && (0.0..2.0 * PI).contains(&t)) {
                return Err(MeshError::InvalidParameter {
                    name: "contact edge angle",
                    value: t,
                    requirement: "must be an angle in [0, 2π) from the x axis",
                });
            }
            let mut k = (t / h).round() as usize;
            if k.is_multiple_of(quarter) {
                // on x = 0 or y = 0: its neighbour towards the edge
                k = if t >= k as f64 * h { k + 1 } else { k - 1 };
            }
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
                requirement:
                    "the fitted node lines must keep their order around the tube (refine `around`)",
            });
        }
        Ok(Self { anchors })
    }

    /// φ(θ).
    pub fn map(&self, theta: f64) -> f64 {
        let t = theta.rem_euclid(2.0 * PI);
        let i = self
            .anchors
            .partition_point(|a| a.0 <= t)
            .clamp(1, self.anchors.len() - 1);
        let (a, b) = (self.anchors[i - 1], self.anchors[i]);
        a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
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
