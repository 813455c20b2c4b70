//! Carrying a converged state from a coarser mesh of the same surface to this model: the
//! prolongation of mesh sequencing (nested iteration), where each load step on the fine mesh
//! starts from the coarse mesh's converged state at the same point of its stage.
//!
//! ```text
//! locate:   every fine node X on the coarse reference surface: the coarse element e and parent
//!           point ξ* = argmin |Σ_a N_a(ξ) X_a^e − X|, ξ ∈ [−1, 1]² (Gauss–Newton on the
//!           element's map, among the elements at the four nearest coarse nodes), within a
//!           quarter of a coarse element's size
//! carry:    x = X + Σ_a N_a(ξ*) (x_a − X_a)     (the coarse displacement interpolated)
//!           inside a plane: back to the chord, gap g = Σ_a N_a(ξ*) g(x_a)
//!           ϖ and the planes' parameter: the coarse state's; no contact multipliers
//! ```
//! A uniform translation and the identity carry over exactly; the interpolation's error is the
//! coarse element's O(h²) (4-node) or O(h³) (9-node), which the fine Newton solve removes.
//! Components a constraint fixes keep their reference values, as every state has them.
//!
//! The multipliers start afresh (the solve's augmented Lagrangian takes them from the
//! penalty): carried from the nearest coarse Gauss point, they were wrong by a coarse element
//! at the zone's edges, and the benchmark's squeeze at 224 around took two multiplier updates
//! and 14 factorizations with them against one update and 12 without (`scripts/bench-million.sh`,
//! `AROUND=224 ALONG=280 SEQUENCING=1`).

use super::*;
use crate::contact::Contact;
use tubemem_mesh::shape::shape_n;

/// Where every node of a fine model lies on a coarse mesh, to carry states
/// from it ([`Model::prolong`]).
#[derive(Clone, Debug)]
pub struct Prolongation {
    /// the coarse mesh's reference nodes
    coarse_nodes: Vec<[f64; 3]>,
    /// per fine node: the coarse nodes and their shape values at the located point
    nodes: Vec<Vec<(usize, f64)>>,
}

/// The largest distance from a fine node to the coarse surface, over the coarse element's size.
pub const MAX_OFF_SURFACE: f64 = 0.25;

/// Gauss–Newton iterations of the closest-point search in one element.
const CLOSEST_ITERATIONS: usize = 30;

/// The closest point to `p` of the element with nodes `xs` (parent coordinates clamped to the
/// square) and its squared distance.
fn closest<const N: usize>(xs: &[[f64; 3]], p: [f64; 3]) -> ([f64; 2], f64) {
    let mut xi = [0.0, 0.0];
    let at = |xi: [f64; 2]| {
        let (n, d) = shape_n::<N>(xi[0], xi[1]);
        let mut x = [0.0; 3];
        let mut g = [[0.0; 3]; 2];
        for a in 0..N {
            for k in 0..3 {
                x[k] += n[a] * xs[a][k];
                g[0][k] += d[a][0] * xs[a][k];
                g[1][k] += d[a][1] * xs[a][k];
            }
        }
        (x, g)
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for _ in 0..CLOSEST_ITERATIONS {
        let (x, g) = at(xi);
        let r = [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
        let (a11, a12, a22) = (dot(g[0], g[0]), dot(g[0], g[1]), dot(g[1], g[1]));
        let (b1, b2) = (dot(g[0], r), dot(g[1], r));
        let det = a11 * a22 - a12 * a12;
        if det <= 0.0 {
            break;
        }
        let d = [(a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det];
        let next = [
            (xi[0] + d[0]).clamp(-1.0, 1.0),
            (xi[1] + d[1]).clamp(-1.0, 1.0),
        ];
        let step = (next[0] - xi[0]).abs().max((next[1] - xi[1]).abs());
        xi = next;
        if step < 1e-14 {
            break;
        }
    }
    let (x, _) = at(xi);
    let r = [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
    (xi, dot(r, r))
}

/// The coarse mesh prepared for point location: its elements' nodes, the elements at each
/// node, and a bucket grid of its nodes.
struct Locator<'a> {
    mesh: &'a Mesh,
    elements: Vec<Vec<usize>>,
    at_node: Vec<Vec<usize>>,
    cell: f64,
    grid: std::collections::HashMap<[i64; 3], Vec<usize>>,
}

impl<'a> Locator<'a> {
    fn new(mesh: &'a Mesh) -> Self {
        let elements: Vec<Vec<usize>> = (0..mesh.quads.len())
            .map(|e| mesh.element_nodes(e))
            .collect();
        let mut at_node = vec![Vec::new(); mesh.nodes.len()];
        for (e, ns) in elements.iter().enumerate() {
            for &n in ns {
                at_node[n].push(e);
            }
        }
        // the cell: the mean corner-to-corner diagonal of the coarse elements
        let diag = |q: &[usize; 4]| {
            let (a, c) = (mesh.nodes[q[0]], mesh.nodes[q[2]]);
            ((a[0] - c[0]).powi(2) + (a[1] - c[1]).powi(2) + (a[2] - c[2]).powi(2)).sqrt()
        };
        let cell = mesh.quads.iter().map(diag).sum::<f64>() / mesh.quads.len().max(1) as f64;
        let cell = if cell > 0.0 { cell } else { 1.0 };
        let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
        for (n, p) in mesh.nodes.iter().enumerate() {
            grid.entry(Self::key(p, cell)).or_default().push(n);
        }
        Self {
            mesh,
            elements,
            at_node,
            cell,
            grid,
        }
    }

    fn key(p: &[f64; 3], cell: f64) -> [i64; 3] {
        p.map(|v| (v / cell).floor() as i64)
    }

    /// The coarse element and parent point closest to `p`, with the distance over the cell
    /// size; `None` when no coarse node is within two cells.
    fn locate(&self, p: [f64; 3]) -> Option<(usize, [f64; 2], f64)> {
        let k = Self::key(&p, self.cell);
        let mut near: Vec<(f64, usize)> = Vec::new();
        for i in -1..=1 {
            for j in -1..=1 {
                for l in -1..=1 {
                    if let Some(ns) = self.grid.get(&[k[0] + i, k[1] + j, k[2] + l]) {
                        for &n in ns {
                            let q = self.mesh.nodes[n];
                            let d = (q[0] - p[0]).powi(2)
                                + (q[1] - p[1]).powi(2)
                                + (q[2] - p[2]).powi(2);
                            near.push((d, n));
                        }
                    }
                }
            }
        }
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut candidates: Vec<usize> = near
            .iter()
            .take(4)
            .flat_map(|&(_, n)| self.at_node[n].iter().copied())
            .collect();
        candidates.sort_unstable();
        candidates.dedup();
        let mut best: Option<(usize, [f64; 2], f64)> = None;
        for e in candidates {
            let xs: Vec<[f64; 3]> = self.elements[e]
                .iter()
                .map(|&n| self.mesh.nodes[n])
                .collect();
            let (xi, d2) = match xs.len() {
                4 => closest::<4>(&xs, p),
                _ => closest::<9>(&xs, p),
            };
            if best.is_none_or(|b| d2 < b.2) {
                best = Some((e, xi, d2));
            }
        }
        best.map(|(e, xi, d2)| (e, xi, d2.sqrt() / self.cell))
    }

    /// The coarse nodes of element `e` with their shape values at `xi`.
    fn weights(&self, e: usize, xi: [f64; 2]) -> Vec<(usize, f64)> {
        let ns = &self.elements[e];
        let n: Vec<f64> = match ns.len() {
            4 => shape_n::<4>(xi[0], xi[1]).0.to_vec(),
            _ => shape_n::<9>(xi[0], xi[1]).0.to_vec(),
        };
        ns.iter().copied().zip(n).collect()
    }
}

impl Model {
    /// Locate this model's nodes on the coarser mesh `coarse` of the same surface (same
    /// element kind and symmetry, no plugs). An error names the first node that is not on the
    /// coarse surface (farther than [`MAX_OFF_SURFACE`] of a coarse element's size).
    pub fn prolongation_from(&self, coarse: &Mesh) -> Result<Prolongation, FemError> {
        let fail = |reason: String| FemError::Prolong { reason };
        if coarse.element() != self.mesh.element() {
            return Err(fail(format!(
                "the coarse mesh has {} elements, this one {}",
                coarse.element().name(),
                self.mesh.element().name()
            )));
        }
        if !coarse.plugs.is_empty() || !self.mesh.plugs.is_empty() {
            return Err(fail("meshes with rigid plugs are not carried over".into()));
        }
        if coarse.symmetry != self.mesh.symmetry {
            return Err(fail("the coarse mesh has another symmetry".into()));
        }
        let locator = Locator::new(coarse);
        let nodes: Vec<Vec<(usize, f64)>> = self
            .mesh
            .nodes
            .par_iter()
            .enumerate()
            .map(|(n, &p)| match locator.locate(p) {
                Some((e, xi, d)) if d <= MAX_OFF_SURFACE => Ok(locator.weights(e, xi)),
                found => {
                    let d = found.map_or(f64::INFINITY, |f| f.2);
                    Err(fail(format!(
                        "node {n} of this mesh is {d:.3} coarse element sizes from the coarse surface (at most {MAX_OFF_SURFACE})"
                    )))
                }
            })
            .collect::<Result<_, _>>()?;
        Ok(Prolongation {
            coarse_nodes: coarse.nodes.clone(),
            nodes,
        })
    }

    /// The coarse mesh's state `coarse` carried to this model by `prolongation` (from
    /// [`Model::prolongation_from`]) under the step's `contact`: the displacements
    /// interpolated, a node inside a plane put back on the chord of its coarse nodes, the
    /// pressure and the planes' parameter kept, no multipliers.
    pub fn prolong(
        &self,
        prolongation: &Prolongation,
        coarse: &State,
        contact: Option<&Contact>,
    ) -> Result<State, FemError> {
        let pr = prolongation;
        let fail = |reason: String| FemError::Prolong { reason };
        if coarse.x.len() != pr.coarse_nodes.len() || pr.nodes.len() != self.mesh.nodes.len() {
            return Err(fail(format!(
                "the prolongation maps {} coarse nodes to {}, the state has {} and this mesh {}",
                pr.coarse_nodes.len(),
                pr.nodes.len(),
                coarse.x.len(),
                self.mesh.nodes.len()
            )));
        }
        let x: Vec<[f64; 3]> = (0..self.mesh.nodes.len())
            .map(|n| {
                let mut p = self.mesh.nodes[n];
                let mut u = [0.0; 3];
                for &(b, w) in &pr.nodes[n] {
                    for k in 0..3 {
                        u[k] += w * (coarse.x[b][k] - pr.coarse_nodes[b][k]);
                    }
                }
                for (k, uk) in u.iter().enumerate() {
                    // a fixed component keeps its reference value
                    if self.dofs.eq(n, k).is_some() {
                        p[k] += uk;
                    }
                }
                p
            })
            .collect();
        // a fine node that the interpolation puts inside a plane goes back to the chord of its
        // coarse nodes (their interpolated gap, ≥ 0 where they are all outside or on it): the
        // displacement's interpolation carries the reference sagitta between them (h²/8R,
        // 1e-4 R at 224 around), which the contact zone's flat no longer has; inside the plane
        // it would be a traction a hundred times the pressure under the regularizing penalty
        // (from a 1e-6 R tolerance), and would press a row beyond the zone's edge
        let x = match contact {
            Some(c) => {
                let mut x = x;
                for (n, xn) in x.iter_mut().enumerate() {
                    for plane in &c.planes {
                        let now = plane.gap(*xn);
                        let chord: f64 = pr.nodes[n]
                            .iter()
                            .map(|&(b, w)| w * plane.gap(coarse.x[b]))
                            .sum();
                        if now < 0.0 && now < chord {
                            for k in 0..3 {
                                if self.dofs.eq(n, k).is_some() {
                                    xn[k] -= (now - chord) * plane.normal[k];
                                }
                            }
                        }
                    }
                }
                x
            }
            None => x,
        };
        Ok(State {
            x,
            p: coarse.p,
            planes: coarse.planes,
            multipliers: Vec::new(),
        })
    }
}
