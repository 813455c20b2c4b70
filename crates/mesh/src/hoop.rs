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
    ///
    /// The map is one of angles: built with `around` = g, it fits any tube whose elements
    /// around are a multiple of g, moving lines of the g-element tube. The meshes of n, 2n,
    /// 4n … around fitted with the same g are then uniform refinements of one another (each
    /// element between two anchors stretched by the same factor on all of them), where the
    /// nearest line (g = n) stretches them by factors that differ from mesh to mesh and the
    /// observed order between two meshes is not the element's.
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
        let mut sorted = edges.to_vec();
        for &t in &sorted {
            if !(t.is_finite() && (0.0..2.0 * PI).contains(&t)) {
                return Err(MeshError::InvalidParameter {
                    name: "contact edge angle",
                    value: t,
                    requirement: "must be an angle in [0, 2π) from the x axis",
                });
            }
        }
        sorted.sort_by(f64::total_cmp);
        // the node lines taken by the edges so far, in order
        let mut lines: Vec<(usize, f64)> = Vec::with_capacity(sorted.len());
        for &t in &sorted {
            let mut k = (t / h).round() as usize;
            if k.is_multiple_of(quarter) {
                // on x = 0 or y = 0: its neighbour towards the edge
                k = if t >= k as f64 * h { k + 1 } else { k - 1 };
            }
            // a contact zone narrower than an element: its second edge takes the next line (the
            // element between the two lines spans the zone), or, where the next is a symmetry
            // line, its first edge the line before
            if let Some(&(l, _)) = lines.last().filter(|&&(l, _)| k <= l) {
                k = l + 1;
                if k.is_multiple_of(quarter) {
                    let before = lines.len().checked_sub(2).map(|i| lines[i].0);
                    let free = l >= 1
                        && !(l - 1).is_multiple_of(quarter)
                        && before.is_none_or(|b| b < l - 1);
                    if !free {
                        return Err(MeshError::InvalidParameter {
                            name: "contact edge angle",
                            value: t,
                            requirement: "two contact edges are nearest the same node line between two symmetry lines: refine `around`",
                        });
                    }
                    if let Some(last) = lines.last_mut() {
                        last.0 = l - 1;
                    }
                    k = l;
                }
            }
            lines.push((k, t));
        }
        anchors.extend(lines.iter().map(|&(k, t)| (k as f64 * h, t)));
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

/// The interpolation of nodal fields from a mesh onto the same mesh with some nodes moved along
/// their hoops (a refitted [`HoopMap`]): for each node, the old nodes and weights whose
/// combination gives the field at its new place.
///
/// ```text
/// a node that did not move:  f'(n) = f(n)
/// a moved node at (θ', z):   f'(n) = Σ_b w_b f(b), over the old element row that holds θ'
///   on the ring of old nodes at the same z: linear in θ through its 2 nodes (4-node
///   elements) or quadratic through its 3 (9-node), so that a field linear (quadratic) in θ
///   along the ring is carried exactly
/// ```
/// A hyperelastic membrane has no history: its state is the map from the reference surface to
/// the current one, so moving the reference nodes and evaluating that map at their new places
/// (this transfer) gives a state of the new mesh, exact up to the interpolation's error, from
/// which Newton finds the new mesh's equilibrium.
#[derive(Clone, Debug, PartialEq)]
pub struct Transfer {
    weights: Vec<Vec<(usize, f64)>>,
}

impl Transfer {
    /// The transfer from `old` to the same mesh with the nodes `moved` (same count; a node
    /// whose coordinates differ, by more than 1e-13 R, must keep its z and move along the ring
    /// of old nodes at that z).
    pub fn between(old: &crate::Mesh, moved: &[[f64; 3]]) -> Result<Self, MeshError> {
        if moved.len() != old.nodes.len() {
            return Err(MeshError::InvalidParameter {
                name: "moved nodes",
                value: moved.len() as f64,
                requirement: "a refitted mesh must have the old mesh's node count",
            });
        }
        let order = match old.element() {
            crate::ElementKind::Quad4 => 1,
            crate::ElementKind::Quad9 => 2,
        };
        let angle = |p: &[f64; 3]| p[1].atan2(p[0]).rem_euclid(2.0 * PI);
        // the rings (old nodes at one z, by angle) that hold a moved node
        let mut rings: std::collections::HashMap<u64, Vec<(f64, usize)>> = Default::default();
        // a node moved by rounding only (the map's arithmetic at a line it keeps) did not move
        let still = |a: &[f64; 3], b: &[f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-13);
        for (n, (a, b)) in old.nodes.iter().zip(moved).enumerate() {
            if !still(a, b) {
                if a[2] != b[2] {
                    return Err(MeshError::InvalidParameter {
                        name: "moved node",
                        value: n as f64,
                        requirement: "a refitted node keeps its z (it moves along its hoop)",
                    });
                }
                rings.entry(a[2].to_bits()).or_default();
            }
        }
        for (n, p) in old.nodes.iter().enumerate() {
            if let Some(r) = rings.get_mut(&p[2].to_bits()) {
                r.push((angle(p), n));
            }
        }
        for r in rings.values_mut() {
            r.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let full = old.symmetry.rings_closed();
        let mut weights = Vec::with_capacity(moved.len());
        for (n, (a, b)) in old.nodes.iter().zip(moved).enumerate() {
            if still(a, b) {
                weights.push(vec![(n, 1.0)]);
                continue;
            }
            let ring = &rings[&a[2].to_bits()];
            weights.push(ring_weights(ring, angle(b), order, full).ok_or(
                MeshError::InvalidParameter {
                    name: "moved node",
                    value: n as f64,
                    requirement: "a refitted node must stay within its ring's elements",
                },
            )?);
        }
        Ok(Self { weights })
    }

    /// The identity on `nodes` nodes.
    pub fn identity(nodes: usize) -> Self {
        Self {
            weights: (0..nodes).map(|n| vec![(n, 1.0)]).collect(),
        }
    }

    /// Node `n`'s old nodes and weights.
    pub fn weights(&self, n: usize) -> &[(usize, f64)] {
        &self.weights[n]
    }

    /// The field `f` (one value per old node) at the new nodes.
    pub fn apply<T: Copy + Default + std::ops::Add<Output = T> + std::ops::Mul<f64, Output = T>>(
        &self,
        f: &[T],
    ) -> Vec<T> {
        self.weights
            .iter()
            .map(|w| w.iter().fold(T::default(), |s, &(b, c)| s + f[b] * c))
            .collect()
    }
}

/// The weights at angle `t` on `ring` (old (θ, node) sorted by θ, its first node on the
/// element corner line θ = 0), element rows of `order` + 1 nodes; `full`: the ring closes
/// (its last row runs from its last corner to the first at 2π).
fn ring_weights(
    ring: &[(f64, usize)],
    t: f64,
    order: usize,
    full: bool,
) -> Option<Vec<(usize, f64)>> {
    let len = ring.len();
    let first = ring.first()?;
    if first.0 > 1e-12 {
        return None;
    }
    // the row's nodes as (θ, node), its first at a corner (index multiple of `order`)
    let at = |i: usize| -> (f64, usize) {
        if i < len {
            ring[i]
        } else {
            (ring[i - len].0 + 2.0 * PI, ring[i - len].1)
        }
    };
    let rows = if full { len / order } else { (len - 1) / order };
    let row = (0..rows).find(|&r| {
        let (a, b) = (at(r * order).0, at((r + 1) * order).0);
        a <= t && t <= b
    })?;
    let pts: Vec<(f64, usize)> = (0..=order).map(|k| at(row * order + k)).collect();
    // Lagrange weights through the row's nodes
    Some(
        pts.iter()
            .enumerate()
            .map(|(i, &(ti, node))| {
                let w = pts
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != i)
                    .map(|(_, &(tj, _))| (t - tj) / (ti - tj))
                    .product::<f64>();
                (node, w)
            })
            .collect(),
    )
}
