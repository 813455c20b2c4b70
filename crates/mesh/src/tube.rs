//! Capped-tube and sphere generators.
//!
//! The caps are halves of an *equiangular cube-sphere*: the cube [−1, 1]³ carries an m × m grid
//! on each face, with lattice coordinate T(k) = tan(π/4 · (2k/m − 1)) (exactly −1, 0, 1 at
//! k = 0, m/2, m), and each lattice point c is projected to the sphere as R c/|c|. The equator of
//! a half cube-sphere has 4m nodes at uniform angles 2π/(4m), which are the nodes of the
//! cylinder's end rings: the mesh conforms at the cap–cylinder junction by construction, and
//! nodes are shared through their integer lattice keys (no tolerance-based merging).
//!
//! Elements: `around` = 4m around the cylinder (a multiple of 8, so that x = 0 and y = 0 are
//! mesh lines), `along` along it (even, so that z = 0 is a mesh line), 3m² per cap.

use crate::{dot, ElementKind, Mesh, MeshError, Symmetry};
use std::collections::HashMap;
use std::f64::consts::FRAC_PI_4;

fn lattice(k: usize, m: usize) -> f64 {
    if k == 0 {
        -1.0
    } else if k == m {
        1.0
    } else if 2 * k == m {
        0.0
    } else {
        (FRAC_PI_4 * (2.0 * k as f64 / m as f64 - 1.0)).tan()
    }
}

fn unit(c: [f64; 3]) -> [f64; 3] {
    let n = dot(c, c).sqrt();
    [c[0] / n, c[1] / n, c[2] / n]
}

/// A cell of the lattice: its origin and its two edge directions (one lattice step each). The
/// corners are o, o + s u, o + s u + s v, o + s v with s = `order` lattice steps; a 9-node cell
/// (order 2) adds the mid-sides o + u, o + 2u + v, o + u + 2v, o + v and the centre o + u + v.
type Cell = ([usize; 3], [usize; 3], [usize; 3]);

/// The lattice points of a cell, 4 (order 1) or 9 (order 2), in element node order.
fn cell_points(c: &Cell, order: usize) -> Vec<[usize; 3]> {
    let (o, u, v) = c;
    let at = |a: usize, b: usize| {
        [
            o[0] + a * u[0] + b * v[0],
            o[1] + a * u[1] + b * v[1],
            o[2] + a * u[2] + b * v[2],
        ]
    };
    let s = order;
    let mut pts = vec![at(0, 0), at(s, 0), at(s, s), at(0, s)];
    if order == 2 {
        pts.extend([at(1, 0), at(2, 1), at(1, 2), at(0, 1), at(1, 1)]);
    }
    pts
}

/// The lattice points and cells of the surface of the box [0, m]² × [0, rows]: its side faces
/// and its top face k = `rows`, and with `closed` its bottom face k = 0 too. The lattice has
/// `m` steps a face edge and `rows` up the sides; the cells have `order` steps a side.
fn box_surface(m: usize, rows: usize, order: usize, closed: bool) -> (Vec<[usize; 3]>, Vec<Cell>) {
    let mut points = vec![];
    for i in 0..=m {
        for j in 0..=m {
            for k in 0..=rows {
                if k == rows || (closed && k == 0) || i == 0 || i == m || j == 0 || j == m {
                    points.push([i, j, k]);
                }
            }
        }
    }
    let (ex, ey, ez) = ([1, 0, 0], [0, 1, 0], [0, 0, 1]);
    let mut cells = vec![];
    let faces: &[usize] = if closed { &[0, rows] } else { &[rows] };
    for &k in faces {
        for i in (0..m).step_by(order) {
            for j in (0..m).step_by(order) {
                cells.push(([i, j, k], ex, ey));
            }
        }
    }
    for i in [0, m] {
        for j in (0..m).step_by(order) {
            for k in (0..rows).step_by(order) {
                cells.push(([i, j, k], ey, ez));
            }
        }
    }
    for j in [0, m] {
        for i in (0..m).step_by(order) {
            for k in (0..rows).step_by(order) {
                cells.push(([i, j, k], ex, ez));
            }
        }
    }
    (points, cells)
}

/// The lattice points and cells of the whole cube surface (for the sphere); the lattice has
/// `m` steps a face edge, the cells `order` steps a side.
fn cube_surface(m: usize, order: usize) -> (Vec<[usize; 3]>, Vec<Cell>) {
    box_surface(m, m, order, true)
}

/// Cube coordinate of row `k` of `rows` on a side face of the half cube: 0 at the equator,
/// exactly 1 at the top face, equiangular in between.
fn latitude(k: usize, rows: usize) -> f64 {
    if k == 0 {
        0.0
    } else if k == rows {
        1.0
    } else {
        (FRAC_PI_4 * k as f64 / rows as f64).tan()
    }
}

/// The upper half of the cube surface for a cap: lattice points (i, j, k) with k the row on the
/// side faces (0 = equator, `rows` = the top face), and its cells (`order` steps a side).
fn half_cube(m: usize, rows: usize, order: usize) -> (Vec<[usize; 3]>, Vec<Cell>) {
    box_surface(m, rows, order, false)
}

/// Split element node lists (4 or 9 each) into corner quads and mid/centre nodes.
fn split_cells(cells: Vec<Vec<usize>>) -> (Vec<[usize; 4]>, Vec<[usize; 5]>) {
    let mut quads = Vec::with_capacity(cells.len());
    let mut mid = Vec::new();
    for c in cells {
        quads.push([c[0], c[1], c[2], c[3]]);
        if c.len() == 9 {
            mid.push([c[4], c[5], c[6], c[7], c[8]]);
        }
    }
    (quads, mid)
}

/// Orient every element so that g1 × g2 at its centre points away from `center(centroid)`;
/// a flipped 9-node element keeps its mid-side nodes on the matching edges.
fn orient(
    nodes: &[[f64; 3]],
    quads: &mut [[usize; 4]],
    mid: &mut [[usize; 5]],
    center: impl Fn([f64; 3]) -> [f64; 3],
) {
    for (e, q) in quads.iter_mut().enumerate() {
        let x = q.map(|i| nalgebra::Vector3::from(nodes[i]));
        let [p, g1, g2] = crate::volume::tangents(&x, 0.0, 0.0);
        let c = nalgebra::Vector3::from(center(p.into()));
        if g1.cross(&g2).dot(&(p - c)) < 0.0 {
            *q = [q[0], q[3], q[2], q[1]];
            if let Some(m) = mid.get_mut(e) {
                *m = [m[3], m[2], m[1], m[0], m[4]];
            }
        }
    }
}

/// The perimeter of the square cross-section of the cube at mid-height, counter-clockwise from
/// (i, j) = (m, m/2), i.e. from angle 0: 4m lattice (i, j) pairs at increasing angle.
fn perimeter(m: usize) -> Vec<(usize, usize)> {
    let (mut i, mut j) = (m, m / 2);
    let mut out = Vec::with_capacity(4 * m);
    let mut step = |di: i64, dj: i64, count: usize, i: &mut usize, j: &mut usize| {
        for _ in 0..count {
            out.push((*i, *j));
            *i = (*i as i64 + di) as usize;
            *j = (*j as i64 + dj) as usize;
        }
    };
    step(0, 1, m / 2, &mut i, &mut j);
    step(-1, 0, m, &mut i, &mut j);
    step(0, -1, m, &mut i, &mut j);
    step(1, 0, m, &mut i, &mut j);
    step(0, 1, m / 2, &mut i, &mut j);
    out
}

fn check_positive(name: &'static str, v: f64) -> Result<(), MeshError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(MeshError::InvalidParameter {
            name,
            value: v,
            requirement: "must be finite and > 0",
        })
    }
}

/// A capped tube: cylinder radius `radius`, cylinder length `length` (along z, centred at the
/// origin), hemispherical caps, `around` elements around (multiple of 8, ≥ 8) and `along`
/// elements along the cylinder (even, ≥ 2), reduced by `symmetry`. The caps have the default
/// `around/8` rows of elements between the equator and the top face (see
/// [`capped_tube_with_cap_rows`]).
pub fn capped_tube(
    radius: f64,
    length: f64,
    around: usize,
    along: usize,
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    capped_tube_with_cap_rows(radius, length, around, along, around / 8, symmetry)
}

/// As [`capped_tube`], with `cap_rows` rows of elements (≥ 1) on the side faces of each half
/// cube-sphere, between the equator and the edge of the top face (latitudes 0 to 45°); the top
/// face keeps (around/4)² elements, as conformity with the side faces requires. The rows are
/// equiangular in latitude: z = tan(π/4 · k/cap_rows) on the cube.
pub fn capped_tube_with_cap_rows(
    radius: f64,
    length: f64,
    around: usize,
    along: usize,
    cap_rows: usize,
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    capped_tube_with_cap_rows_of(
        ElementKind::Quad4,
        radius,
        length,
        around,
        along,
        cap_rows,
        symmetry,
    )
}

/// [`capped_tube`] with elements of `kind`: for the 9-node element the generator works on the
/// lattice of twice the resolution (every lattice point is on the exact cylinder or sphere:
/// equiangular around, uniform along, equiangular on the cube-sphere), and each element takes a
/// 3 × 3 block of it, so the mid-side and centre nodes lie on the exact surface.
pub fn capped_tube_of(
    kind: ElementKind,
    radius: f64,
    length: f64,
    around: usize,
    along: usize,
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    capped_tube_with_cap_rows_of(kind, radius, length, around, along, around / 8, symmetry)
}

/// [`capped_tube_with_cap_rows`] with elements of `kind` (see [`capped_tube_of`]).
pub fn capped_tube_with_cap_rows_of(
    kind: ElementKind,
    radius: f64,
    length: f64,
    around: usize,
    along: usize,
    cap_rows: usize,
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    capped_tube_fitted_of(
        kind, radius, length, around, along, cap_rows, symmetry, None,
    )
}

/// The element counts a generated tube admits (checked before anything is built, also by the
/// case validation): `around` a multiple of 8 (≥ 8), `along` even (≥ 2), `cap_rows` ≥ 1.
pub fn check_counts(around: usize, along: usize, cap_rows: usize) -> Result<(), MeshError> {
    if cap_rows == 0 {
        return Err(MeshError::InvalidParameter {
            name: "cap_rows",
            value: 0.0,
            requirement:
                "a cap needs at least one row of elements between its equator and its top face",
        });
    }
    if around < 8 || !around.is_multiple_of(8) {
        return Err(MeshError::InvalidParameter {
            name: "around",
            value: around as f64,
            requirement: "elements around must be a multiple of 8 (≥ 8), so that the caps are half cube-spheres and x = 0, y = 0 are mesh lines",
        });
    }
    if along < 2 || !along.is_multiple_of(2) {
        return Err(MeshError::InvalidParameter {
            name: "along",
            value: along as f64,
            requirement:
                "elements along must be even (≥ 2), so that the mid-span z = 0 is a mesh line",
        });
    }
    Ok(())
}

/// [`capped_tube_with_cap_rows_of`] with the cylinder's hoop spacing fitted by `fit` (see
/// [`crate::hoop`]): its corner node lines moved by the map, the mid-side lines of a 9-node
/// element at the mid-angle of its corners, blended back to uniform spacing towards the caps
/// ([`crate::hoop::blend`]). `None`: uniform.
#[allow(clippy::too_many_arguments)]
pub fn capped_tube_fitted_of(
    kind: ElementKind,
    radius: f64,
    length: f64,
    around: usize,
    along: usize,
    cap_rows: usize,
    symmetry: Symmetry,
    fit: Option<&crate::hoop::HoopMap>,
) -> Result<Mesh, MeshError> {
    check_positive("radius", radius)?;
    check_positive("length", length)?;
    check_counts(around, along, cap_rows)?;
    // the node lattice: `order` lattice steps per element side
    let order = kind.gauss_per_direction() - 1;
    let (m, lattice_along, rows) = (order * around / 4, order * along, order * cap_rows);
    let per = perimeter(m);
    let ring_dir: Vec<[f64; 3]> = per
        .iter()
        .map(|&(i, j)| unit([lattice(i, m), lattice(j, m), 0.0]))
        .collect();
    let np = per.len();
    // the uniform angles of the ring's lattice points (θ_p = 2πp/np from the x axis) and, with
    // a fit, their fitted angles: corner lines mapped, mid-side lines at their corners' mean
    let fitted: Option<Vec<(f64, f64)>> = fit.map(|f| {
        let theta = |p: usize| 2.0 * std::f64::consts::PI * p as f64 / np as f64;
        (0..np)
            .map(|p| {
                let phi = if p % (np / 4) == 0 {
                    // the lines x = 0 and y = 0 stay where the lattice has them
                    theta(p)
                } else if p % order == 0 {
                    f.map(theta(p))
                } else {
                    let (a, b) = (theta(p - 1), theta(p + 1));
                    let (fa, fb) = (f.map(a), f.map(b));
                    // the map reduces angles to [0, 2π): keep the pair together across 0
                    let fb = if fb < fa {
                        fb + 2.0 * std::f64::consts::PI
                    } else {
                        fb
                    };
                    0.5 * (fa + fb)
                };
                (theta(p), phi)
            })
            .collect()
    });
    let mut nodes = Vec::new();
    for l in 0..=lattice_along {
        let z = -0.5 * length + length * l as f64 / lattice_along as f64;
        let z = if 2 * l == lattice_along { 0.0 } else { z };
        let b = fitted
            .as_ref()
            .map_or(0.0, |_| crate::hoop::blend(z, 0.5 * length, radius));
        for (p, d) in ring_dir.iter().enumerate() {
            match fitted.as_ref().map(|f| f[p]) {
                // moved: on the circle at the blended angle (lines that do not move, the
                // symmetry lines among them, and rings where b = 0 keep the lattice's values)
                Some((theta, phi)) if b > 0.0 && phi != theta => {
                    let a = theta + b * (phi - theta);
                    nodes.push([radius * a.cos(), radius * a.sin(), z]);
                }
                _ => nodes.push([radius * d[0], radius * d[1], z]),
            }
        }
    }
    let mut cells: Vec<Vec<usize>> = Vec::new();
    for l in (0..lattice_along).step_by(order) {
        for p in (0..np).step_by(order) {
            // (l, p) lattice cell of `order` steps: the same (origin, u, v) rule as the caps
            let id = |a: usize, b: usize| (l + b) * np + (p + a) % np;
            cells.push(
                cell_points(&([0, 0, 0], [1, 0, 0], [0, 1, 0]), order)
                    .iter()
                    .map(|pt| id(pt[0], pt[1]))
                    .collect(),
            );
        }
    }
    let ring_of: HashMap<(usize, usize), usize> =
        per.iter().enumerate().map(|(p, &ij)| (ij, p)).collect();
    let (points, caps) = half_cube(m, rows, order);
    for (sign, ring) in [(1.0, lattice_along), (-1.0, 0)] {
        let mut id: HashMap<[usize; 3], usize> = HashMap::new();
        for pt in &points {
            if pt[2] == 0 {
                id.insert(*pt, ring * np + ring_of[&(pt[0], pt[1])]);
            } else {
                let d = unit([lattice(pt[0], m), lattice(pt[1], m), latitude(pt[2], rows)]);
                id.insert(*pt, nodes.len());
                nodes.push([
                    radius * d[0],
                    radius * d[1],
                    sign * (0.5 * length + radius * d[2]),
                ]);
            }
        }
        for c in &caps {
            cells.push(cell_points(c, order).iter().map(|pt| id[pt]).collect());
        }
    }
    let half = 0.5 * length;
    closed_mesh(
        nodes,
        cells,
        |p| [0.0, 0.0, p[2].clamp(-half, half)],
        symmetry,
    )
}

/// The closed surface of `nodes` and `cells` (4 or 9 nodes each), each element oriented
/// outwards from its `center` point, reduced to `symmetry` and checked.
fn closed_mesh(
    nodes: Vec<[f64; 3]>,
    cells: Vec<Vec<usize>>,
    center: impl Fn([f64; 3]) -> [f64; 3],
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    let (mut quads, mut mid) = split_cells(cells);
    orient(&nodes, &mut quads, &mut mid, center);
    let mesh = reduce(
        Mesh {
            nodes,
            quads,
            symmetry: Symmetry::None,
            plugs: vec![],
            mid,
            open: false,
        },
        symmetry,
    );
    mesh.check()?;
    Ok(mesh)
}

/// An open cylinder of radius `radius` and length `length` whose end rings are tied to rigid
/// discs (plugs) that may translate axially: the variant of the capped tube that matches how
/// many actuators are built. Same `around`/`along` rules as [`capped_tube`].
pub fn plugged_tube(
    radius: f64,
    length: f64,
    around: usize,
    along: usize,
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    plugged_tube_of(ElementKind::Quad4, radius, length, around, along, symmetry)
}

/// [`plugged_tube`] with elements of `kind` (the plug rings then hold the hoop mid-side nodes
/// of the end rings too).
pub fn plugged_tube_of(
    kind: ElementKind,
    radius: f64,
    length: f64,
    around: usize,
    along: usize,
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    let capped = capped_tube_of(kind, radius, length, around, along, Symmetry::None)?;
    let half = 0.5 * length;
    let tol = 1e-12 * (radius + length);
    // keep the cylinder elements: every node within the cylinder's z range
    let keep: Vec<usize> = (0..capped.quads.len())
        .filter(|&e| {
            capped.quads[e]
                .iter()
                .all(|&i| capped.nodes[i][2].abs() <= half + tol)
        })
        .collect();
    let mesh = renumber(keep_elements(capped, &keep));
    let ring = |sign: f64| {
        let mut r: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&i| (mesh.nodes[i][2] - sign * half).abs() <= tol)
            .collect();
        r.sort_by(|&a, &b| {
            mesh.nodes[a][1]
                .atan2(mesh.nodes[a][0])
                .total_cmp(&mesh.nodes[b][1].atan2(mesh.nodes[b][0]))
        });
        r
    };
    let plugs = vec![ring(1.0), ring(-1.0)];
    let mut mesh = reduce(Mesh { plugs, ..mesh }, symmetry);
    mesh.plugs.retain(|r| !r.is_empty());
    mesh.check()?;
    Ok(mesh)
}

/// Drop unused nodes and renumber (in the original order, so numbering is deterministic);
/// plug rings keep their used nodes.
fn renumber(mesh: Mesh) -> Mesh {
    let mut used = vec![false; mesh.nodes.len()];
    for &i in mesh.quads.iter().flatten().chain(mesh.mid.iter().flatten()) {
        used[i] = true;
    }
    let mut new_id = vec![usize::MAX; mesh.nodes.len()];
    let mut nodes = vec![];
    for (i, p) in mesh.nodes.iter().enumerate() {
        if used[i] {
            new_id[i] = nodes.len();
            nodes.push(*p);
        }
    }
    Mesh {
        nodes,
        quads: mesh.quads.iter().map(|q| q.map(|i| new_id[i])).collect(),
        mid: mesh.mid.iter().map(|q| q.map(|i| new_id[i])).collect(),
        symmetry: mesh.symmetry,
        open: mesh.open,
        plugs: mesh
            .plugs
            .iter()
            .map(|r| r.iter().filter(|&&i| used[i]).map(|&i| new_id[i]).collect())
            .collect(),
    }
}

/// A sphere of radius `radius` centred at the origin: the equiangular cube-sphere with
/// `m` × `m` elements per cube face (m even, ≥ 2), 6m² elements in all.
pub fn sphere(radius: f64, m: usize, symmetry: Symmetry) -> Result<Mesh, MeshError> {
    sphere_of(ElementKind::Quad4, radius, m, symmetry)
}

/// [`sphere`] with elements of `kind` (9-node: every node on the exact sphere).
pub fn sphere_of(
    kind: ElementKind,
    radius: f64,
    m: usize,
    symmetry: Symmetry,
) -> Result<Mesh, MeshError> {
    check_positive("radius", radius)?;
    if m < 2 || !m.is_multiple_of(2) {
        return Err(MeshError::InvalidParameter {
            name: "m",
            value: m as f64,
            requirement: "elements per cube-face edge must be even (≥ 2)",
        });
    }
    let order = kind.gauss_per_direction() - 1;
    let lm = order * m;
    let (points, cells) = cube_surface(lm, order);
    let mut id = HashMap::new();
    let mut nodes = vec![];
    for pt in &points {
        let d = unit([lattice(pt[0], lm), lattice(pt[1], lm), lattice(pt[2], lm)]);
        id.insert(*pt, nodes.len());
        nodes.push([radius * d[0], radius * d[1], radius * d[2]]);
    }
    let cells = cells
        .iter()
        .map(|c| cell_points(c, order).iter().map(|pt| id[pt]).collect())
        .collect();
    closed_mesh(nodes, cells, |_| [0.0; 3], symmetry)
}

/// Keep the elements whose centroid (of corners) lies on the positive side of each symmetry
/// plane and renumber the nodes (in their original order, so numbering is deterministic).
pub fn reduce(mesh: Mesh, symmetry: Symmetry) -> Mesh {
    if symmetry == Symmetry::None {
        return mesh;
    }
    let keep: Vec<usize> = (0..mesh.quads.len())
        .filter(|&e| {
            let c = mesh.quads[e].iter().fold([0.0; 3], |s, &i| {
                let p = mesh.nodes[i];
                [s[0] + p[0], s[1] + p[1], s[2] + p[2]]
            });
            symmetry.planes().iter().all(|&ax| c[ax] > 0.0)
        })
        .collect();
    renumber(Mesh {
        symmetry,
        ..keep_elements(mesh, &keep)
    })
}

/// `mesh` with the elements `keep` only (corners and, for 9-node meshes, the other nodes);
/// the nodes are not renumbered.
fn keep_elements(mesh: Mesh, keep: &[usize]) -> Mesh {
    let quads = keep.iter().map(|&e| mesh.quads[e]).collect();
    let mid = if mesh.mid.is_empty() {
        vec![]
    } else {
        keep.iter().map(|&e| mesh.mid[e]).collect()
    };
    Mesh { quads, mid, ..mesh }
}
