//! # tubemem-mesh — quadrilateral membrane surfaces
//!
//! * [`tube::capped_tube`]: a cylinder of radius R and length L closed by two hemispherical caps,
//!   quadrilaterals only. Each cap is the upper half of an equiangular cube-sphere (no pole, no
//!   degenerate element), and its equator conforms node for node with the cylinder's end ring.
//!   Symmetry reductions (half, quarter, eighth) keep the elements on one side of the planes
//!   z = 0, x = 0, y = 0, which are mesh lines by construction.
//! * [`tube::sphere`]: the full cube-sphere, for tests.
//! * [`Mesh::check`]: degenerate, inverted (inconsistently oriented), non-manifold and open
//!   meshes are rejected with an error that names the element or edge.
//! * [`vtu`]: VTK XML unstructured-grid output (ParaView, meshio) and `.pvd` time series.
//!
//! Node numbering of a quad (counter-clockwise seen from outside, so that g1 × g2 points out):
//!
//! ```text
//!  3 ───── 2        η
//!  │       │        ↑
//!  │       │        └─→ ξ
//!  0 ───── 1
//! ```

// `!(a > b)` is deliberate throughout: unlike `a <= b` it is also true when a is NaN, so
// a non-finite coordinate is reported instead of slipping through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod file;
pub mod hoop;
pub mod io;
pub mod refine;
pub mod shape;
pub mod sheet;
pub mod tube;
pub mod volume;
pub mod vtu;

pub use shape::{shape, ElementKind, GAUSS2};
pub use volume::quad_volume;

use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use thiserror::Error;

pub use tubemem_material::Num;

/// A mesh error, naming the element, edge or parameter concerned.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    #[error("invalid mesh parameter `{name}` = {}: {requirement}", Num(*value))]
    InvalidParameter {
        name: &'static str,
        value: f64,
        requirement: &'static str,
    },
    #[error("element {element} refers to node {node}, but the mesh has {nodes} nodes")]
    NodeOutOfRange {
        element: usize,
        node: usize,
        nodes: usize,
    },
    #[error("element {element} is degenerate: {reason}")]
    Degenerate { element: usize, reason: String },
    #[error("element {element} is inverted: its orientation disagrees with its neighbour {neighbour} across edge ({a}, {b})")]
    Inverted {
        element: usize,
        neighbour: usize,
        a: usize,
        b: usize,
    },
    #[error("edge ({a}, {b}) is shared by {count} elements (non-manifold surface)")]
    NonManifold { a: usize, b: usize, count: usize },
    #[error(
        "the surface is open at edge ({a}, {b}) (element {element}) but must be closed{where_}"
    )]
    Open {
        a: usize,
        b: usize,
        element: usize,
        where_: String,
    },
    #[error(
        "the enclosed volume is {volume} ≤ 0: the element normals point inward (inverted mesh)"
    )]
    InwardNormals { volume: f64 },
    #[error("plug {plug}: {reason}")]
    InvalidPlug { plug: usize, reason: String },
    /// the file system refused a read or a write
    #[error("{path}")]
    Io {
        path: String,
        #[source]
        source: Shared<std::io::Error>,
    },
    /// a mesh file that is not JSON of the mesh format
    #[error("{path}: not a tubemem mesh file")]
    Json {
        path: String,
        #[source]
        source: Shared<serde_json::Error>,
    },
    /// a file whose content the reader or writer cannot take (named in `reason`)
    #[error("{path}: {reason}")]
    File { path: String, reason: String },
    #[error("the mesh is not the case's tube: {reason}")]
    NotTheTube { reason: String },
}

/// Another crate's error, shared so that [`MeshError`] stays `Clone` and comparable (two are
/// equal when their messages are). It displays as the error itself and passes its source on;
/// [`Shared::get`] gives the error back.
#[derive(Debug)]
pub struct Shared<E>(pub std::sync::Arc<E>);

impl<E> Shared<E> {
    pub fn new(e: E) -> Self {
        Self(std::sync::Arc::new(e))
    }
    /// The error itself.
    pub fn get(&self) -> &E {
        &self.0
    }
}

impl<E> Clone for Shared<E> {
    fn clone(&self) -> Self {
        Self(self.0.clone())
    }
}

impl<E: std::fmt::Display> PartialEq for Shared<E> {
    fn eq(&self, other: &Self) -> bool {
        self.0.to_string() == other.0.to_string()
    }
}

impl<E: std::fmt::Display> std::fmt::Display for Shared<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl<E: std::error::Error> std::error::Error for Shared<E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

/// How far (in R) a user mesh's node may lie off the case's tube ([`Mesh::check_tube`]): 1e-2.
/// A node of a surface mesh lies on the surface it discretizes (the generator places its nodes on
/// the exact circle);
/// what a mesh of the wrong tube gets wrong is of order R (an axis along x, an ellipse, a
/// radius 2 under `radius = 1`). One per cent leaves room for meshes written with few digits.
pub const TUBE_TOLERANCE: f64 = 1e-2;

/// Which symmetry planes bound the mesh (open edges are allowed only on these planes, and the
/// matching displacement component is fixed there).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Symmetry {
    /// the whole surface
    #[default]
    None,
    /// z ≥ 0 (plane z = 0)
    Half,
    /// z ≥ 0, y ≥ 0 (planes z = 0, y = 0)
    Quarter,
    /// z ≥ 0, y ≥ 0, x ≥ 0 (planes z = 0, y = 0, x = 0)
    Eighth,
}

impl Symmetry {
    /// The coordinate axes (0 = x, 1 = y, 2 = z) whose zero planes are symmetry planes.
    pub fn planes(self) -> &'static [usize] {
        match self {
            Symmetry::None => &[],
            Symmetry::Half => &[2],
            Symmetry::Quarter => &[2, 1],
            Symmetry::Eighth => &[2, 1, 0],
        }
    }
    /// Whether a ring of nodes around the axis goes all the way round (no symmetry plane through
    /// the axis cuts it). The one test of ring topology, for perimeters, contact widths and plug
    /// faces.
    pub fn rings_closed(self) -> bool {
        self.planes().iter().all(|&ax| ax == 2)
    }
    /// How many copies of the model make the whole tube.
    pub fn multiplicity(self) -> f64 {
        match self {
            Symmetry::None => 1.0,
            Symmetry::Half => 2.0,
            Symmetry::Quarter => 4.0,
            Symmetry::Eighth => 8.0,
        }
    }
}

/// A surface mesh of bilinear quadrilaterals.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub nodes: Vec<[f64; 3]>,
    pub quads: Vec<[usize; 4]>,
    pub symmetry: Symmetry,
    /// Rigid end plugs: each is a ring of nodes (sorted by angle) tied to a rigid disc that may
    /// translate axially. The surface may be open along a plug ring; the disc face closes it.
    pub plugs: Vec<Vec<usize>>,
    /// For a biquadratic (9-node) mesh, the mid-side nodes of edges 0–1, 1–2, 2–3, 3–0 and the
    /// centre node of each quad (see the module [`mod@crate::shape`]); empty for a bilinear mesh. The
    /// corners stay in `quads`, so every topological check reads the corners alone.
    pub mid: Vec<[usize; 5]>,
    /// A sheet with free edges (a flat membrane, an annulus): [`Mesh::check`] does not require
    /// it closed, and it encloses no volume (only a zero pressure loads it). False for every
    /// tube.
    pub open: bool,
}

/// Distance below which a node counts as lying on a symmetry plane, relative to the mesh size.
const PLANE_TOL: f64 = 1e-9;

impl Mesh {
    /// A characteristic size: the largest absolute coordinate.
    pub fn scale(&self) -> f64 {
        self.nodes
            .iter()
            .flat_map(|p| p.iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()))
            .max(1e-300)
    }

    /// The rings of nodes at the largest distance from the z axis (a tube's cylinder with the
    /// caps' equators or the plug rings), by reference Z ascending, each ring in the order of
    /// its nodes' angle about the axis (coordinates equal within 1e-9 of the mesh's scale).
    pub fn rings(&self) -> Vec<Vec<usize>> {
        let radius = self
            .nodes
            .iter()
            .map(|p| p[0].hypot(p[1]))
            .fold(0.0, f64::max);
        let tol = PLANE_TOL * self.scale();
        let mut nodes: Vec<usize> = (0..self.nodes.len())
            .filter(|&i| (self.nodes[i][0].hypot(self.nodes[i][1]) - radius).abs() <= tol)
            .collect();
        let angle = |i: usize| self.nodes[i][1].atan2(self.nodes[i][0]);
        nodes.sort_by(|&a, &b| {
            self.nodes[a][2]
                .total_cmp(&self.nodes[b][2])
                .then(angle(a).total_cmp(&angle(b)))
        });
        let mut rings: Vec<Vec<usize>> = vec![];
        for i in nodes {
            match rings.last_mut() {
                Some(r) if (self.nodes[r[0]][2] - self.nodes[i][2]).abs() <= tol => r.push(i),
                _ => rings.push(vec![i]),
            }
        }
        rings
    }

    /// Nodes lying on the symmetry plane `axis` = 0.
    pub fn on_plane(&self, axis: usize) -> Vec<bool> {
        let tol = PLANE_TOL * self.scale();
        self.nodes.iter().map(|p| p[axis].abs() <= tol).collect()
    }

    /// The enclosed volume, V = (1/3) Σ ∫ x·(g1 × g2) dξdη (exact for bilinear quads with 2×2
    /// Gauss). For a symmetry-reduced mesh this is the volume of the reduced part: the missing
    /// closing faces lie on planes through the origin, where x·n = 0.
    pub fn volume(&self) -> f64 {
        self.volume_at(&self.nodes)
    }

    /// The enclosed volume with the nodes at `x` (same connectivity), plug faces included.
    pub fn volume_at(&self, x: &[[f64; 3]]) -> f64 {
        self.membrane_volume_at(x)
            + self
                .plugs
                .iter()
                .map(|r| {
                    plug_face(
                        x,
                        r,
                        self.symmetry.rings_closed(),
                        self.element() == ElementKind::Quad9,
                    )
                    .volume()
                })
                .sum::<f64>()
    }

    /// (1/3) Σ ∫ x·(g1 × g2) over the membrane elements only.
    pub fn membrane_volume_at(&self, x: &[[f64; 3]]) -> f64 {
        match self.element() {
            ElementKind::Quad4 => self
                .quads
                .iter()
                .map(|q| quad_volume(&[x[q[0]], x[q[1]], x[q[2]], x[q[3]]]))
                .sum(),
            ElementKind::Quad9 => (0..self.quads.len())
                .map(|e| volume::quad9_volume(&self.nodes9(e).map(|i| x[i])))
                .sum(),
        }
    }

    /// The kind of element: 9-node when the mid-side and centre nodes are given.
    pub fn element(&self) -> ElementKind {
        if self.mid.is_empty() {
            ElementKind::Quad4
        } else {
            ElementKind::Quad9
        }
    }

    /// The nine nodes of element `e` of a biquadratic mesh (corners, mid-sides, centre).
    pub fn nodes9(&self, e: usize) -> [usize; 9] {
        let (q, m) = (self.quads[e], self.mid[e]);
        [q[0], q[1], q[2], q[3], m[0], m[1], m[2], m[3], m[4]]
    }

    /// Every element's nodes (4 or 9 each), for output.
    pub fn cells(&self) -> Vec<Vec<usize>> {
        (0..self.quads.len())
            .map(|e| self.element_nodes(e))
            .collect()
    }

    /// Every node of element `e` (4 or 9).
    pub fn element_nodes(&self, e: usize) -> Vec<usize> {
        match self.element() {
            ElementKind::Quad4 => self.quads[e].to_vec(),
            ElementKind::Quad9 => self.nodes9(e).to_vec(),
        }
    }

    /// Check connectivity, shape and orientation. A symmetry-reduced mesh may be open only along
    /// its symmetry planes.
    ///
    /// Its length: a sequence of independent checks (indices, counts, degenerate and inverted
    /// elements, edge manifoldness, open edges only on symmetry planes, 9-node placement), each
    /// with its own error naming the element or node.
    pub fn check(&self) -> Result<(), MeshError> {
        let n = self.nodes.len();
        if n == 0 || self.quads.is_empty() {
            return Err(MeshError::InvalidParameter {
                name: "mesh",
                value: n as f64,
                requirement: "a mesh needs nodes and quads",
            });
        }
        if !self.mid.is_empty() && self.mid.len() != self.quads.len() {
            return Err(MeshError::InvalidParameter {
                name: "mid",
                value: self.mid.len() as f64,
                requirement: "a 9-node mesh gives the mid-side and centre nodes of every quad (as many entries as quads)",
            });
        }
        let mut in_plug = vec![usize::MAX; n];
        for (k, ring) in self.plugs.iter().enumerate() {
            let bad = |reason: String| MeshError::InvalidPlug { plug: k, reason };
            if ring.len() < 2 {
                return Err(bad(format!(
                    "a plug ring needs at least 2 nodes, it has {}",
                    ring.len()
                )));
            }
            for &i in ring {
                if i >= n {
                    return Err(bad(format!(
                        "node {i} is out of range (the mesh has {n} nodes)"
                    )));
                }
                if in_plug[i] != usize::MAX {
                    return Err(bad(format!(
                        "node {i} appears twice (also in plug {})",
                        in_plug[i]
                    )));
                }
                in_plug[i] = k;
            }
        }
        for (e, q) in self.quads.iter().enumerate() {
            let all = self.element_nodes(e);
            for &i in &all {
                if i >= n {
                    return Err(MeshError::NodeOutOfRange {
                        element: e,
                        node: i,
                        nodes: n,
                    });
                }
            }
            for a in 0..all.len() {
                for b in a + 1..all.len() {
                    if all[a] == all[b] {
                        return Err(MeshError::Degenerate {
                            element: e,
                            reason: format!("node {} appears twice", all[a]),
                        });
                    }
                }
            }
            let x = q.map(|i| self.nodes[i]);
            let area = quad_area(&x);
            let diag = dist(&x[0], &x[2]).max(dist(&x[1], &x[3]));
            if !(area > 1e-12 * diag * diag) {
                return Err(MeshError::Degenerate {
                    element: e,
                    reason: format!("area {area:e} is zero for diagonal {diag:e}"),
                });
            }
            // The Jacobian g1 × g2 must keep the direction of the centre normal at every corner
            // (a collapsed edge gives zero there, a bow-tie a reversed one).
            // For the 9-node element the same test runs at its nine nodes: a mid-side node
            // placed off its edge's middle third folds the element there.
            let tangents = |xi: f64, eta: f64| match self.element() {
                ElementKind::Quad4 => volume::tangents(&x.map(nalgebra::Vector3::from), xi, eta),
                ElementKind::Quad9 => volume::tangents_n::<9>(
                    &self
                        .nodes9(e)
                        .map(|i| nalgebra::Vector3::from(self.nodes[i])),
                    xi,
                    eta,
                ),
            };
            let [_, c1, c2] = tangents(0.0, 0.0);
            let n0 = c1.cross(&c2);
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            let mids = [(0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)];
            let points = corners
                .iter()
                .map(|&c| (c, "corner"))
                .chain(
                    mids.iter()
                        .filter(|_| self.element() == ElementKind::Quad9)
                        .map(|&c| (c, "mid-side node")),
                )
                .enumerate();
            for (k, ((xi, eta), what)) in points {
                let [_, g1, g2] = tangents(xi, eta);
                if !(g1.cross(&g2).dot(&n0) > 1e-8 * n0.dot(&n0)) {
                    let k = if k < 4 { k } else { k - 4 };
                    return Err(MeshError::Degenerate {
                        element: e,
                        reason: format!("the Jacobian vanishes or reverses at {what} {k} (collapsed edge, bow-tie or misplaced mid-side node)"),
                    });
                }
            }
        }
        // Directed edges: in a consistently oriented manifold, every interior edge appears once
        // in each direction.
        let mut edges: HashMap<(usize, usize), Vec<(usize, bool)>> = HashMap::new();
        for (e, q) in self.quads.iter().enumerate() {
            for k in 0..4 {
                let (a, b) = (q[k], q[(k + 1) % 4]);
                let key = (a.min(b), a.max(b));
                edges.entry(key).or_default().push((e, a < b));
            }
        }
        let on: Vec<Vec<bool>> = (0..3).map(|ax| self.on_plane(ax)).collect();
        let mut keys: Vec<_> = edges.keys().copied().collect();
        keys.sort_unstable();
        // orientation conflicts: (element, element, edge)
        let mut conflicts: Vec<(usize, usize, (usize, usize))> = Vec::new();
        for key in keys {
            let users = &edges[&key];
            match users.len() {
                1 => {
                    let on_sym = self
                        .symmetry
                        .planes()
                        .iter()
                        .any(|&ax| on[ax][key.0] && on[ax][key.1]);
                    let on_plug = self
                        .plugs
                        .iter()
                        .any(|r| r.contains(&key.0) && r.contains(&key.1));
                    if !on_sym && !on_plug && !self.open {
                        return Err(MeshError::Open {
                            a: key.0,
                            b: key.1,
                            element: users[0].0,
                            where_: if self.symmetry == Symmetry::None {
                                String::new()
                            } else {
                                format!(
                                    " (it is not on a symmetry plane of the {:?} model)",
                                    self.symmetry
                                )
                            },
                        });
                    }
                }
                2 => {
                    if users[0].1 == users[1].1 {
                        conflicts.push((users[0].0, users[1].0, key));
                    }
                }
                c => {
                    return Err(MeshError::NonManifold {
                        a: key.0,
                        b: key.1,
                        count: c,
                    })
                }
            }
        }
        if !conflicts.is_empty() {
            // An inverted element disagrees with (up to) all its neighbours, each neighbour only
            // with it: name the element with the most conflicts (ties: the lowest index).
            let mut count: HashMap<usize, usize> = HashMap::new();
            for &(a, b, _) in &conflicts {
                *count.entry(a).or_default() += 1;
                *count.entry(b).or_default() += 1;
            }
            let worst = count
                .iter()
                .max_by(|x, y| x.1.cmp(y.1).then(y.0.cmp(x.0)))
                .map(|(&e, _)| e)
                .unwrap_or(conflicts[0].0);
            let &(a, b, edge) = conflicts
                .iter()
                .find(|c| c.0 == worst || c.1 == worst)
                .unwrap_or(&conflicts[0]);
            return Err(MeshError::Inverted {
                element: worst,
                neighbour: if a == worst { b } else { a },
                a: edge.0,
                b: edge.1,
            });
        }
        // a sheet encloses nothing: its normals' side is the user's to choose
        let v = self.volume();
        if !self.open && !(v > 0.0) {
            return Err(MeshError::InwardNormals { volume: v });
        }
        Ok(())
    }
}

/// The flat face of a rigid plug: its height z_d (mean z of the ring), its area (fan of
/// triangles from the axis point (0, 0, z_d), so a ring cut by symmetry planes through the axis
/// gives the matching sector) and its outward normal sign (+1 for the plug at z > 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlugFace {
    pub z: f64,
    pub area: f64,
    pub sign: f64,
}

impl PlugFace {
    /// (1/3) ∫ x·n dA over the face: (1/3) z_d · area · sign.
    pub fn volume(&self) -> f64 {
        self.z * self.area * self.sign / 3.0
    }
}

/// The face of the plug whose ring is `ring` (sorted by angle), at positions `x`; `closed`
/// when the ring goes all the way round ([`Symmetry::rings_closed`]); `quadratic` when the ring
/// runs corner, mid-side, corner, … along the edges of 9-node elements: each such edge is a
/// parabolic arc, whose area beyond the polygon through its three nodes is a third of their
/// triangle (Archimedes: the segment is 4/3 of the triangle on its chord), so the face matches
/// the curved membrane exactly.
pub fn plug_face(x: &[[f64; 3]], ring: &[usize], closed: bool, quadratic: bool) -> PlugFace {
    let z = ring.iter().map(|&i| x[i][2]).sum::<f64>() / ring.len().max(1) as f64;
    let n = ring.len();
    let segs = if closed { n } else { n.saturating_sub(1) };
    let cross = |p: [f64; 3], q: [f64; 3]| p[0] * q[1] - p[1] * q[0];
    let mut area = 0.0;
    for k in 0..segs {
        let (p, q) = (x[ring[k]], x[ring[(k + 1) % n]]);
        area += 0.5 * cross(p, q);
    }
    if quadratic {
        for k in (0..segs.saturating_sub(1)).step_by(2) {
            let (p0, pm, p1) = (x[ring[k]], x[ring[k + 1]], x[ring[(k + 2) % n]]);
            area += 0.5 * (cross(p0, pm) + cross(pm, p1) + cross(p1, p0)) / 3.0;
        }
    }
    PlugFace {
        z,
        area: area.abs(),
        sign: if z >= 0.0 { 1.0 } else { -1.0 },
    }
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// a − b
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// a × b
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
/// a · b
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Area ∫ |g1 × g2| dξdη (2×2 Gauss).
pub fn quad_area(x: &[[f64; 3]; 4]) -> f64 {
    GAUSS2
        .iter()
        .map(|&(xi, eta)| {
            let [_, g1, g2] = volume::tangents(&x.map(nalgebra::Vector3::from), xi, eta);
            g1.cross(&g2).norm()
        })
        .sum()
}

#[cfg(test)]
mod tests;

impl Mesh {
    /// Whether the mesh (scaled to R = 1) is the tube a case describes, a cylinder of
    /// half-length `half` along z closed by hemispheres (`hemispheres`) or plugs: every node in
    /// an element, one connected piece; every node on the side of each declared symmetry plane; every cylinder node
    /// (|z| < `half`) at distance 1 from the z axis and the mesh reaching z = `half` + 1
    /// (hemispheres) or `half` (plugs), all within [`TUBE_TOLERANCE`]. Else the first mismatch,
    /// named with its node.
    pub fn check_tube(&self, half: f64, hemispheres: bool) -> Result<(), MeshError> {
        let bad = |reason: String| Err(MeshError::NotTheTube { reason });
        // connectivity: union-find over the elements' corners
        let mut parent: Vec<usize> = (0..self.nodes.len()).collect();
        fn root(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for (e, q) in self.quads.iter().enumerate() {
            // a 9-node element's mid-side and centre nodes belong to its corners' piece
            let mid = self.mid.get(e).map_or(&[][..], |m| &m[..]);
            for &n in q[1..].iter().chain(mid) {
                let (a, b) = (root(&mut parent, q[0]), root(&mut parent, n));
                parent[a] = b;
            }
        }
        let used: std::collections::HashSet<usize> = self
            .quads
            .iter()
            .flatten()
            .chain(self.mid.iter().flatten())
            .copied()
            .collect();
        if let Some(i) = (0..self.nodes.len()).find(|i| !used.contains(i)) {
            return bad(format!(
                "node {i} belongs to no element: every node must be a corner of a quad"
            ));
        }
        let pieces: std::collections::HashSet<usize> =
            used.iter().map(|&i| root(&mut parent, i)).collect();
        if pieces.len() > 1 {
            return bad(format!(
                "it has {} separate pieces; a tube is one closed surface",
                pieces.len()
            ));
        }
        let axis = ["x", "y", "z"];
        for &k in self.symmetry.planes() {
            if let Some((i, p)) = self
                .nodes
                .iter()
                .enumerate()
                .find(|(_, p)| p[k] < -TUBE_TOLERANCE)
            {
                return bad(format!(
                    "it is declared symmetry \"{}\", which models {} ≥ 0 only, but node {i} has {} = {:.6}",
                    format!("{:?}", self.symmetry).to_lowercase(),
                    axis[k],
                    axis[k],
                    p[k]
                ));
            }
        }
        for (i, p) in self.nodes.iter().enumerate() {
            if p[2].abs() < half - TUBE_TOLERANCE {
                let r = p[0].hypot(p[1]);
                if (r - 1.0).abs() > TUBE_TOLERANCE {
                    return bad(format!(
                        "node {i} ({:.6}, {:.6}, {:.6}) on the cylinder (|z| < L/2 = {half}) is {r:.6} R from the z axis, not 1 (within {TUBE_TOLERANCE}): the tube's axis must be z and its cross-section the circle of `radius`",
                        p[0], p[1], p[2]
                    ));
                }
            }
        }
        let top = self.nodes.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
        let want = if hemispheres { half + 1.0 } else { half };
        if (top - want).abs() > TUBE_TOLERANCE {
            return bad(format!(
                "it reaches |z| = {top:.6} R, the case's tube {want} R (L/2 = {half}{})",
                if hemispheres {
                    " plus the hemispherical cap"
                } else {
                    ", plugged"
                }
            ));
        }
        Ok(())
    }
}
