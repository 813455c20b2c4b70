//! Mid-span extraction at the cross-section Z = 0 (reference) of a capped tube, profiles along
//! it, contact values and per-element output values.
//!
//! ```text
//! λs   = (current length of the mid-span ring) / (its reference length): the polygon through
//!        the ring nodes for the 4-node element, the chain of parabolic arcs (corner, mid-side,
//!        corner) of the element edges for the 9-node element (the discrete analogue of
//!        L_γ/L_Γ, eq. 57: no chordal bias for a uniform state)
//! λz   = mean over the ring of the stretch of the meridian edges that leave the ring (both
//!        sides where both exist): |x_j − x_i| / |X_j − X_i| for the 4-node element (the axial
//!        stretch at ±ΔZ/2), |x'(a)|/|X'(a)| at the ring end a of the parabolic edge a, m, b
//!        for the 9-node element (x'(a) ∝ −3x_a + 4x_m − x_b: the axial stretch at the ring)
//! N_s, N_z, N_sz = tᵀNt, aᵀNa, tᵀNa averaged over the Gauss points of the elements that touch
//!        the ring, with t the current hoop tangent (image of the reference hoop direction,
//!        made horizontal) and a the axial direction in the tangent plane
//! ϖ    = the reduced pressure,  volume = total enclosed volume (all symmetry copies)
//! ```
use crate::contact::{Contact, ContactPoints};
use crate::element::{point_state_in_step, PointState};
use crate::geometry::{RefElement, Vec3};
use crate::model::{Elements, Model, State};
use crate::with_elements;
use crate::FemError;
use serde::{Deserialize, Serialize};
pub use tubemem_material::relaxed::Regime;

/// Mid-span values, dimensionless (resultants per μH).
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MidSpan {
    pub w: f64,
    pub lambda_s: f64,
    pub lambda_z: f64,
    pub n_s: f64,
    pub n_z: f64,
    pub n_sz: f64,
    pub volume: f64,
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (Vec3::from(a) - Vec3::from(b)).norm()
}

/// One Gauss point of an element, for output: its reference area weight and frame, reference
/// and current position, and the in-plane gradient columns f_1, f_2.
#[derive(Clone, Copy, Debug)]
pub struct GaussSample {
    pub w: f64,
    pub frame: [Vec3; 2],
    pub x_ref: Vec3,
    pub x: Vec3,
    pub f: [Vec3; 2],
}

impl GaussSample {
    /// The image F v of a vector v of the reference tangent plane.
    pub fn push_forward(&self, v: &Vec3) -> Vec3 {
        self.f[0] * self.frame[0].dot(v) + self.f[1] * self.frame[1].dot(v)
    }
    /// The area ratio J = |f_1 × f_2|.
    pub fn area_ratio(&self) -> f64 {
        self.f[0].cross(&self.f[1]).norm()
    }
}

fn samples_of<const N: usize>(
    points: &[crate::geometry::GaussPoint<N>],
    el: &RefElement<N>,
    x0: &[[f64; 3]],
    x: &[[f64; 3]],
) -> Vec<GaussSample> {
    let (xe, xr) = (el.gather(x), el.gather(x0));
    points
        .iter()
        .map(|gp| GaussSample {
            w: gp.w,
            frame: gp.frame,
            x_ref: gp.position(&xr),
            x: gp.position(&xe),
            f: gp.gradient(&xe),
        })
        .collect()
}

/// The Gauss points of element `e` at the nodal positions `x`.
pub fn gauss_samples(model: &Model, e: usize, x: &[[f64; 3]]) -> Vec<GaussSample> {
    with_elements!(model.elements(), els => samples_of(&els[e].gauss, &els[e], &model.mesh().nodes, x))
}

/// The points of element `e` where `contact` acts ([`Contact::samples`]: its Gauss points or
/// its nodes) at the nodal positions `x`.
pub fn contact_samples(
    model: &Model,
    e: usize,
    x: &[[f64; 3]],
    contact: &Contact,
) -> Vec<GaussSample> {
    with_elements!(model.elements(), els => {
        let el = &els[e];
        samples_of(contact.samples(el), el, &model.mesh().nodes, x)
    })
}

/// The length of a chain of parabolic arcs through the points `p` (corner, mid-side, corner,
/// mid-side, …; an odd count), each arc x(t) = Σ L_i(t) p_i on t ∈ [−1, 1], by 4-point Gauss
/// per arc (the arcs of a uniformly scaled ring are scaled copies, so ratios of such lengths are
/// exact whatever the rule).
fn parabolic_length(p: &[[f64; 3]]) -> f64 {
    let rule = tubemem_mesh::shape::gauss_1d(4).unwrap_or_default();
    let mut len = 0.0;
    for k in (0..p.len().saturating_sub(2)).step_by(2) {
        let (a, m, b) = (Vec3::from(p[k]), Vec3::from(p[k + 1]), Vec3::from(p[k + 2]));
        for &(t, w) in &rule {
            // x'(t) = (t − ½) a − 2t m + (t + ½) b
            len += w * (a * (t - 0.5) - m * (2.0 * t) + b * (t + 0.5)).norm();
        }
    }
    len
}

/// A ring of nodes around the axis at one reference height: the one owner of ring topology.
#[derive(Clone, Debug, PartialEq)]
pub struct Ring {
    /// the nodes, sorted by angle
    pub nodes: Vec<usize>,
    /// whether the ring goes all the way round (no symmetry plane through the axis cuts it)
    pub closed: bool,
    /// whether the ring runs along 9-node element edges (corner, mid-side, corner, …)
    pub quadratic: bool,
}

impl Ring {
    /// The nodes of the reference ring at height `z` (on the cylinder), sorted by angle.
    pub fn at(model: &Model, z: f64) -> Self {
        let mesh = model.mesh();
        let tol = 1e-9 * mesh.scale();
        let mut nodes: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&i| (mesh.nodes[i][2] - z).abs() <= tol)
            .collect();
        nodes.sort_by(|&a, &b| {
            let ang = |i: usize| mesh.nodes[i][1].atan2(mesh.nodes[i][0]);
            ang(a).total_cmp(&ang(b))
        });
        Self::of(model, nodes)
    }

    /// The ring of `nodes` (sorted by angle) of `model`'s mesh: closed or not by its symmetry,
    /// quadratic for 9-node elements.
    fn of(model: &Model, nodes: Vec<usize>) -> Self {
        Self {
            nodes,
            closed: model.mesh().symmetry.rings_closed(),
            quadratic: model.elements().kind() == tubemem_mesh::ElementKind::Quad9,
        }
    }

    /// The reference ring at Z = 0.
    pub fn midspan(model: &Model) -> Self {
        Self::at(model, 0.0)
    }

    /// The ring's segments (pairs of consecutive nodes; the closing one if closed).
    pub fn segments(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let n = self.nodes.len();
        let segs = if self.closed { n } else { n.saturating_sub(1) };
        (0..segs).map(move |k| (self.nodes[k], self.nodes[(k + 1) % n]))
    }

    /// The ring's length at the nodal positions `x`: the polygon through its nodes, or for a
    /// quadratic ring the chain of parabolic arcs of its element edges.
    pub fn length(&self, x: &[[f64; 3]]) -> f64 {
        if self.quadratic {
            let mut p: Vec<[f64; 3]> = self.nodes.iter().map(|&i| x[i]).collect();
            if self.closed {
                if let Some(&first) = p.first() {
                    p.push(first);
                }
            }
            parabolic_length(&p)
        } else {
            self.segments().map(|(a, b)| dist(x[a], x[b])).sum()
        }
    }

    /// The elements with a node on the ring, in ascending order.
    pub fn touching(&self, model: &Model) -> Vec<usize> {
        let on_ring = self.contains_set();
        (0..model.elements().len())
            .filter(|&e| {
                model
                    .elements()
                    .nodes(e)
                    .iter()
                    .any(|i| on_ring.contains(i))
            })
            .collect()
    }

    fn contains_set(&self) -> std::collections::HashSet<usize> {
        self.nodes.iter().copied().collect()
    }
}

/// The state of Gauss point `g` of element `e` with gradient columns `f`: the law's, or a
/// viscoelastic law's at its committed history ([`crate::memory::Memory::committed_at`]).
fn point_state_committed(
    model: &Model,
    e: usize,
    g: usize,
    f: &[Vec3; 2],
) -> Result<PointState, tubemem_material::MaterialError> {
    let committed = model.memory().map(|m| (m.committed_at(e), g));
    point_state_in_step(model.law(), committed, f)
}

/// Mid-span values: [`ring_state`] at Z = 0.
pub fn midspan(model: &Model, state: &State) -> Result<MidSpan, FemError> {
    ring_state(model, state, &Ring::midspan(model))
}

/// The values of the module header at one ring of nodes: perimeter ratio, meridian stretch of
/// the edges leaving the ring, and resultants averaged over the Gauss points of the elements
/// that touch it. `volume` is the total enclosed volume.
pub fn ring_state(model: &Model, state: &State, ring: &Ring) -> Result<MidSpan, FemError> {
    let touching = ring.touching(model);
    let projected = touching
        .iter()
        .map(|&e| projected_resultants(model, e, &gauss_samples(model, e, &state.x)))
        .collect::<Result<Vec<_>, _>>()?;
    let pr = &projected;
    ring_state_of(
        model,
        state,
        ring,
        &touching,
        move |k, _| pr[k].as_slice(),
        model.total_volume(&state.x),
    )
}

/// (t·Nt, a·Na, t·Na) at the Gauss points of element `e`: the resultants projected on the
/// current hoop tangent t (image of the reference hoop direction, made horizontal) and the axial
/// direction a in the tangent plane. They do not depend on the ring, so a profile computes them
/// once per element (from its Gauss points `samples`).
fn projected_resultants(
    model: &Model,
    e: usize,
    samples: &[GaussSample],
) -> Result<Vec<[f64; 3]>, FemError> {
    let mut out = vec![[0.0; 3]; samples.len()];
    for (g, (o, sp)) in out.iter_mut().zip(samples).enumerate() {
        let f = sp.f;
        let ps = point_state_committed(model, e, g, &f).map_err(|source| FemError::Material {
            element: e,
            gauss_point: g,
            source,
        })?;
        // reference hoop direction at the Gauss point and its image F T
        let xr = sp.x_ref;
        let t_ref = Vec3::new(-xr[1], xr[0], 0.0).normalize();
        let ft = sp.push_forward(&t_ref);
        let t = Vec3::new(ft[0], ft[1], 0.0).normalize();
        let normal = f[0].cross(&f[1]).normalize();
        let ez = Vec3::z();
        let a = (ez - normal * ez.dot(&normal)).normalize();
        *o = [
            t.dot(&(ps.cauchy * t)),
            a.dot(&(ps.cauchy * a)),
            t.dot(&(ps.cauchy * a)),
        ];
    }
    Ok(out)
}

/// [`ring_state`] given the elements that touch the ring (in ascending order), their projected
/// resultants (`projected(k, e)` for the k-th of them, element e) and the enclosed volume.
fn ring_state_of<'p>(
    model: &Model,
    state: &State,
    ring: &Ring,
    touching: &[usize],
    projected: impl Fn(usize, usize) -> &'p [[f64; 3]],
    volume: f64,
) -> Result<MidSpan, FemError> {
    let mesh = model.mesh();
    let cur = ring.length(&state.x);
    let reference = ring.length(&mesh.nodes);
    let on_ring = ring.contains_set();
    let mut lz_sum = 0.0;
    let mut lz_n = 0usize;
    let (mut ns, mut nz, mut nsz, mut ng) = (0.0, 0.0, 0.0, 0usize);
    let els = model.elements();
    for (k, &e) in touching.iter().enumerate() {
        let q = els.nodes(e);
        for j in 0..4 {
            let (a, b) = (q[j], q[(j + 1) % 4]);
            if on_ring.contains(&a) == on_ring.contains(&b) {
                continue;
            }
            // meridian edge: each is shared by two elements, so each is counted twice
            lz_sum += if let Elements::Quad9(_) = els {
                // the parabolic edge from the ring end `a` through the mid-side node `m`
                let (a, b) = if on_ring.contains(&a) { (a, b) } else { (b, a) };
                let m = q[4 + j];
                let d = |x: &[[f64; 3]]| {
                    (Vec3::from(x[a]) * -3.0 + Vec3::from(x[m]) * 4.0 - Vec3::from(x[b])).norm()
                };
                d(&state.x) / d(&mesh.nodes)
            } else {
                dist(state.x[a], state.x[b]) / dist(mesh.nodes[a], mesh.nodes[b])
            };
            lz_n += 1;
        }
        // summed Gauss point by Gauss point, in element order (as before the split)
        for &[s, z, sz] in projected(k, e) {
            ns += s;
            nz += z;
            nsz += sz;
            ng += 1;
        }
    }
    let ng = ng.max(1) as f64;
    Ok(MidSpan {
        w: state.p,
        lambda_s: cur / reference.max(1e-300),
        lambda_z: lz_sum / lz_n.max(1) as f64,
        n_s: ns / ng,
        n_z: nz / ng,
        n_sz: nsz / ng,
        volume,
    })
}

/// Per-element output values (averaged over the Gauss points).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellValues {
    /// stretch along the reference hoop direction (horizontal tangent)
    pub hoop_stretch: f64,
    /// stretch along the reference meridian (tangent ⟂ hoop)
    pub axial_stretch: f64,
    /// principal Cauchy resultants per μH (N1 ≥ N2)
    pub n1: f64,
    pub n2: f64,
}

impl CellValues {
    /// Taut (both principal resultants positive), wrinkled (N1 > 0 ≥ N2: tension in one
    /// direction only; with the relaxed law N2 is then exactly 0), slack (N1 ≤ 0: no tension).
    /// A tolerance of 1e-10 (|N1| + |N2|) separates "zero" from positive.
    pub fn regime(&self) -> Regime {
        let tol = 1e-10 * (self.n1.abs() + self.n2.abs()) + 1e-14;
        if self.n1 <= tol {
            Regime::Slack
        } else if self.n2 <= tol {
            Regime::Wrinkled
        } else {
            Regime::Taut
        }
    }
}

/// The VTU code of a regime: 0 taut, 1 wrinkled, 2 slack.
pub fn regime_code(r: Regime) -> f64 {
    match r {
        Regime::Taut => 0.0,
        Regime::Wrinkled => 1.0,
        Regime::Slack => 2.0,
    }
}

/// Element values for output (VTU cell data).
pub fn cell_values(model: &Model, state: &State) -> Result<Vec<CellValues>, FemError> {
    (0..model.elements().len())
        .map(|e| {
            let samples = gauss_samples(model, e, &state.x);
            let share = 1.0 / samples.len() as f64;
            let mut c = CellValues::default();
            for (g, sp) in samples.iter().enumerate() {
                let ps = point_state_committed(model, e, g, &sp.f).map_err(|source| {
                    FemError::Material {
                        element: e,
                        gauss_point: g,
                        source,
                    }
                })?;
                let xr = sp.x_ref;
                let [e1, e2] = sp.frame;
                let normal = e1.cross(&e2);
                let horizontal = Vec3::new(-xr[1], xr[0], 0.0);
                let t = if horizontal.dot(&horizontal) > 1e-20 {
                    horizontal.normalize()
                } else {
                    e1
                };
                // project onto the reference tangent plane
                let t = (t - normal * t.dot(&normal)).normalize();
                let m = normal.cross(&t);
                c.hoop_stretch += share * sp.push_forward(&t).norm();
                c.axial_stretch += share * sp.push_forward(&m).norm();
                c.n1 += share * ps.principal[0];
                c.n2 += share * ps.principal[1];
            }
            Ok(c)
        })
        .collect()
}

/// One ring of the cylinder at reference height Z: the [`ring_state`] values there.
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RingValues {
    /// reference height Z (in R)
    pub z_ref: f64,
    /// current mean height
    pub z: f64,
    /// mean distance from the axis
    pub radius: f64,
    pub values: MidSpan,
    /// the ring's geometric contact width against the plate y = h, as at mid-span
    /// ([`ContactValues::chi_geometric`], c/(πR) over all symmetry copies); 0 without plates
    #[serde(default)]
    pub contact_width: f64,
    /// the plate force per unit current length at the ring over πμH, as at mid-span
    /// ([`ContactValues::force`]); 0 without plates
    #[serde(default)]
    pub contact_force: f64,
}

/// Profiles along the cylinder: one entry per ring of nodes at the reference radius (the
/// cylinder and the cap equators), from the lowest Z to the highest, with each ring's contact
/// width against the plates of `contact`. One pass over the nodes and elements (each element is
/// visited for the rings it touches), so it costs about one residual assembly.
pub fn ring_profile(
    model: &Model,
    state: &State,
    contact: Option<&Contact>,
) -> Result<Vec<RingValues>, FemError> {
    let mesh = model.mesh();
    let tol = 1e-9 * mesh.scale();
    let radius = mesh
        .nodes
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, f64::max);
    // rings at element boundaries: the heights of corner nodes (every node of a 4-node mesh;
    // the interior rows of 9-node elements are not rings of element edges)
    let mut corner = vec![false; mesh.nodes.len()];
    for q in &mesh.quads {
        for &i in q {
            corner[i] = true;
        }
    }
    let mut heights: Vec<f64> = mesh
        .nodes
        .iter()
        .zip(&corner)
        .filter(|(p, &c)| c && (p[0].hypot(p[1]) - radius).abs() <= 1e-9 * radius)
        .map(|(p, _)| p[2])
        .collect();
    heights.sort_by(f64::total_cmp);
    heights.dedup_by(|a, b| (*a - *b).abs() <= tol);
    // each node's ring (the nodes within `tol` of a height, as `Ring::at` takes them)
    let ring_of = |z: f64| -> Option<usize> {
        let k = heights.partition_point(|&h| h < z - tol);
        (k < heights.len() && (heights[k] - z).abs() <= tol).then_some(k)
    };
    let mut nodes: Vec<Vec<usize>> = vec![vec![]; heights.len()];
    let mut node_ring = vec![None; mesh.nodes.len()];
    for (i, p) in mesh.nodes.iter().enumerate() {
        if let Some(k) = ring_of(p[2]) {
            nodes[k].push(i);
            node_ring[i] = Some(k);
        }
    }
    let mut touching: Vec<Vec<usize>> = vec![vec![]; heights.len()];
    for e in 0..model.elements().len() {
        let mut rings: Vec<usize> = model
            .elements()
            .nodes(e)
            .iter()
            .filter_map(|&i| node_ring[i])
            .collect();
        rings.sort_unstable();
        rings.dedup();
        for k in rings {
            touching[k].push(e);
        }
    }
    let half_gap = contact.and_then(Contact::half_gap);
    let top = contact.and_then(Contact::top_plate);
    let offsets = match (contact, top) {
        (Some(c), Some(k)) => nodal_offsets(model, state, c, k),
        _ => vec![],
    };
    // every element's projected resultants once (in parallel; collected in element order, so
    // the result does not depend on the thread count), and the volume once
    // each element's Gauss points once: its projected resultants and, against plates, its
    // contact force
    let per_element = {
        use rayon::prelude::*;
        (0..model.elements().len())
            .into_par_iter()
            .map(|e| {
                let samples = gauss_samples(model, e, &state.x);
                let force = match (contact, top) {
                    (Some(c), Some(top)) => {
                        // the Gauss points already at hand, or the nodes
                        let nodal;
                        let points = match c.points {
                            ContactPoints::Gauss => &samples,
                            ContactPoints::Nodal => {
                                nodal = contact_samples(model, e, &state.x, c);
                                &nodal
                            }
                        };
                        element_contact_force(
                            points,
                            c,
                            top,
                            c.element_history(&state.multipliers, e, points.len()),
                        )
                    }
                    _ => 0.0,
                };
                Ok((projected_resultants(model, e, &samples)?, force))
            })
            .collect::<Result<Vec<_>, FemError>>()?
    };
    let (projected, forces): (Vec<Vec<[f64; 3]>>, Vec<f64>) = per_element.into_iter().unzip();
    let forces = if half_gap.is_some() && contact.is_some() {
        forces
    } else {
        vec![]
    };
    let volume = model.total_volume(&state.x);
    heights
        .iter()
        .zip(nodes)
        .zip(&touching)
        .map(|((&z, mut ring_nodes), touching)| {
            ring_nodes.sort_by(|&a, &b| {
                let ang = |i: usize| mesh.nodes[i][1].atan2(mesh.nodes[i][0]);
                ang(a).total_cmp(&ang(b))
            });
            let ring = Ring::of(model, ring_nodes);
            let n = ring.nodes.len() as f64;
            Ok(RingValues {
                z_ref: z,
                z: ring.nodes.iter().map(|&i| state.x[i][2]).sum::<f64>() / n,
                radius: ring
                    .nodes
                    .iter()
                    .map(|&i| state.x[i][0].hypot(state.x[i][1]))
                    .sum::<f64>()
                    / n,
                values: ring_state_of(
                    model,
                    state,
                    &ring,
                    touching,
                    |_, e| projected[e].as_slice(),
                    volume,
                )?,
                contact_width: half_gap
                    .map_or(0.0, |h| contact_width(model, state, &ring, h, &offsets)),
                contact_force: if forces.is_empty() {
                    0.0
                } else {
                    ring_force(model, state, &ring, touching.iter().copied(), |e| forces[e])
                },
            })
        })
        .collect()
}

/// The geometric contact width of `ring` against the plate y = `h` (plane `top` of `contact`):
/// the length of the ring polygon in contact (zero crossings of the nodes' contact indicator,
/// [`nodal_offsets`], interpolated linearly, O(h) accurate), over π, for all copies across the
/// x = 0 symmetry plane.
fn contact_width(model: &Model, state: &State, ring: &Ring, h: f64, offsets: &[f64]) -> f64 {
    let c = penetrated_length(state, ring, |i, p| {
        h - p[1] - offsets.get(i).copied().unwrap_or(0.0)
    });
    let x_copies = if model.mesh().symmetry.planes().contains(&0) {
        2.0
    } else {
        1.0
    };
    x_copies * c / std::f64::consts::PI
}

/// The nodes' contact-indicator offsets against plane `k` of `contact`: λ/κ_g at each node
/// where the contact acts at the nodes with multipliers (the augmented Lagrangian pushes where
/// g − λ/κ_g < 0, so a node in contact sits at g ≈ 0 and its gap's sign says nothing), 0
/// elsewhere (the penalty alone, or Gauss points: there the gap's sign is the indicator).
pub fn nodal_offsets(model: &Model, state: &State, contact: &Contact, k: usize) -> Vec<f64> {
    let mut out = vec![0.0; model.mesh().nodes.len()];
    if contact.points != ContactPoints::Nodal || state.multipliers.is_empty() {
        return out;
    }
    with_elements!(model.elements(), els => {
        for (e, el) in els.iter().enumerate() {
            let h = contact.element_history(&state.multipliers, e, el.nodal.len());
            for (a, &node) in el.nodes.iter().enumerate() {
                let at = contact.point(h, a, k);
                if at.lambda > 0.0 {
                    out[node] = out[node].max(at.lambda / at.penalty);
                }
            }
        }
    });
    out
}

/// The length of the ring polygon where `gap` (of the node index and position) < 0 (zero
/// crossings interpolated linearly).
fn penetrated_length(state: &State, ring: &Ring, gap: impl Fn(usize, [f64; 3]) -> f64) -> f64 {
    let mut c = 0.0;
    for (ia, ib) in ring.segments() {
        let (a, b) = (state.x[ia], state.x[ib]);
        let (ga, gb) = (gap(ia, a), gap(ib, b));
        let len = dist(a, b);
        c += match (ga < 0.0, gb < 0.0) {
            (true, true) => len,
            (true, false) => len * ga / (ga - gb),
            (false, true) => len * gb / (gb - ga),
            _ => 0.0,
        };
    }
    c
}

/// The reflections of the modelled part across the symmetry planes through the axis, as sign
/// pairs on (x, y): the identity first.
pub fn reflections(model: &Model) -> Vec<[f64; 2]> {
    let planes = model.mesh().symmetry.planes();
    let mut signs = vec![[1.0, 1.0]];
    if planes.contains(&0) {
        signs.push([-1.0, 1.0]);
    }
    if planes.contains(&1) {
        let n = signs.len();
        for k in 0..n {
            signs.push([signs[k][0], -1.0]);
        }
    }
    signs
}

/// The plate force per unit current length at `ring` over πμH (all copies across x = 0), from
/// the contact forces `fe(e)` of the elements that touch it (ascending): each side's row force
/// over the row's mean axial extent (the meridian edges with one end on the ring), averaged over
/// the sides that have one.
fn ring_force(
    model: &Model,
    state: &State,
    ring: &Ring,
    touching: impl Iterator<Item = usize>,
    fe: impl Fn(usize) -> f64,
) -> f64 {
    let x_copies = if model.mesh().symmetry.planes().contains(&0) {
        2.0
    } else {
        1.0
    };
    x_copies * ring_force_per_length(model, state, ring, touching, fe) / std::f64::consts::PI
}

/// The force per unit current length at `ring` of the modelled part (no copies, not over π).
fn ring_force_per_length(
    model: &Model,
    state: &State,
    ring: &Ring,
    touching: impl Iterator<Item = usize>,
    fe: impl Fn(usize) -> f64,
) -> f64 {
    let mesh = model.mesh();
    let on_ring = ring.contains_set();
    let z_ring = ring.nodes.first().map_or(0.0, |&i| mesh.nodes[i][2]);
    let mut side_force = [0.0; 2];
    let mut side_extent = [(0.0, 0usize); 2];
    for e in touching {
        let q = model.elements().corners(e);
        let zc = q.iter().map(|&i| mesh.nodes[i][2]).sum::<f64>() / 4.0;
        let side = usize::from(zc < z_ring);
        side_force[side] += fe(e);
        // axial extent: mean |Δz| of the element's meridian edges (one corner on the ring)
        let mut ext = 0.0;
        let mut m = 0;
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            if on_ring.contains(&a) != on_ring.contains(&b) {
                ext += (state.x[a][2] - state.x[b][2]).abs();
                m += 1;
            }
        }
        if m > 0 {
            side_extent[side].0 += ext / m as f64;
            side_extent[side].1 += 1;
        }
    }
    // per unit length: the row's force over its axial extent (the mean extent of its elements)
    let mut f_per_len = 0.0;
    let mut sides = 0.0;
    for s in 0..2 {
        if side_extent[s].1 > 0 && side_extent[s].0 > 0.0 {
            f_per_len += side_force[s] / (side_extent[s].0 / side_extent[s].1 as f64);
            sides += 1.0;
        }
    }
    if sides > 0.0 {
        f_per_len / sides
    } else {
        0.0
    }
}

/// Mid-span contact of one wall of the whole tube.
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallValues {
    /// flat contact length on the wall (zero crossings of the nodal gap, O(h)), per R
    pub contact_length: f64,
    /// force per unit current length on the wall over πμH (as the closed form's ϖc/π)
    pub force: f64,
    /// largest penetration of the wall anywhere
    pub penetration: f64,
}

/// Mid-span contact values of each plane of `contact`, for the whole tube: each wall's values
/// are summed over the symmetry copies of the modelled part (the copy mirrored across x = 0
/// and/or y = 0 meets the mirror image of the wall, which the plane set must contain; a wall
/// without its mirror gets only the modelled part's share).
pub fn midspan_walls(model: &Model, state: &State, contact: &Contact) -> Vec<WallValues> {
    let ring = Ring::midspan(model);
    let touching = ring.touching(model);
    // the modelled part's values against each plane
    let own: Vec<(f64, f64, f64)> = contact
        .planes
        .iter()
        .enumerate()
        .map(|(kp, plane)| {
            let offsets = nodal_offsets(model, state, contact, kp);
            let c = penetrated_length(state, &ring, |i, p| plane.gap(p) - offsets[i]);
            let mut penetration = 0.0f64;
            let forces: Vec<f64> = (0..model.elements().len())
                .map(|e| {
                    let mut fe = 0.0;
                    let samples = contact_samples(model, e, &state.x, contact);
                    let lambda = contact.element_history(&state.multipliers, e, samples.len());
                    for (g, sp) in samples.iter().enumerate() {
                        let gap = plane.gap(sp.x.into());
                        fe += sp.w * contact.traction_at(gap, contact.point(lambda, g, kp));
                        if gap < 0.0 {
                            penetration = penetration.max(-gap);
                        }
                    }
                    fe
                })
                .collect();
            let f =
                ring_force_per_length(model, state, &ring, touching.iter().copied(), |e| forces[e]);
            (c, f, penetration)
        })
        .collect();
    let signs = reflections(model);
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + a.abs());
    contact
        .planes
        .iter()
        .map(|p| {
            let mut v = WallValues {
                contact_length: 0.0,
                force: 0.0,
                penetration: 0.0,
            };
            for sg in &signs {
                // the copy mirrored by `sg` meets wall p where the model meets p's mirror
                let m = [sg[0] * p.normal[0], sg[1] * p.normal[1], p.normal[2]];
                if let Some(k) = contact.planes.iter().position(|q| {
                    same(q.normal[0], m[0]) && same(q.normal[1], m[1]) && same(q.offset, p.offset)
                }) {
                    v.contact_length += own[k].0;
                    v.force += own[k].1 / std::f64::consts::PI;
                    v.penetration = v.penetration.max(own[k].2);
                }
            }
            v
        })
        .collect()
}

/// The contact force of one element (its Gauss points `samples`, its contact history `lambda`)
/// against the top plate y = h (plane `top` of `contact`): Σ_g w_g t(gap_g, λ_g) over its
/// Gauss points in contact.
fn element_contact_force(
    samples: &[GaussSample],
    contact: &Contact,
    top: usize,
    lambda: &[f64],
) -> f64 {
    let h = -contact.planes[top].offset;
    let mut fe = 0.0;
    for (g, sp) in samples.iter().enumerate() {
        let gp_gap = h - sp.x[1];
        fe += sp.w * contact.traction_at(gp_gap, contact.point(lambda, g, top));
    }
    fe
}

/// Mid-span contact values of a squeeze, dimensionless.
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactValues {
    /// ρ = h/R
    pub rho: f64,
    /// χ = c/(πR) with c = ∫ p_c ds / ϖ, the contact width that the contact-pressure distribution
    /// around the mid-span ring implies (in GPS p_c = ϖ on the flat zone, so this is its width)
    pub chi: f64,
    /// the geometric width of the penetrated part of the mid-span ring (zero crossings of the
    /// nodal gap, linearly interpolated; O(h) accurate)
    pub chi_geometric: f64,
    /// plate force per unit current length at mid-span over πμH (the FE counterpart of ϖχ,
    /// eq. 80)
    pub force: f64,
    /// mean contact pressure per current area at the contact points in contact of the elements
    /// next to Z = 0 (`Contact::point_pressures`; GPS: equal to ϖ in the flat zone)
    pub contact_pressure: f64,
    /// the largest |p_c/ϖ − 1| over the flat zone's interior next to Z = 0: the contact points
    /// of the elements there that are wholly in contact, at nodal points without the flat
    /// zone's last nodes, which carry the edge's share (`None`: no element wholly in contact)
    #[serde(default)]
    pub flat_pressure_deviation: Option<f64>,
    /// largest penetration anywhere
    pub penetration: f64,
    /// total force on one plate (all symmetry copies), over μH R
    pub total_force: f64,
}

/// Contact at mid-span against the top plate y = h of two plates made by
/// [`Contact::plates`]; `None` if `contact` has no such plate.
pub fn midspan_contact(model: &Model, state: &State, contact: &Contact) -> Option<ContactValues> {
    let h = contact.half_gap()?;
    let top = contact.top_plate()?;
    let mesh = model.mesh();
    let planes = mesh.symmetry.planes();
    let x_copies = if planes.contains(&0) { 2.0 } else { 1.0 };
    let z_copies = if planes.contains(&2) { 2.0 } else { 1.0 };
    let gap = |p: [f64; 3]| h - p[1];
    let ring = Ring::midspan(model);
    let chi_geometric = contact_width(
        model,
        state,
        &ring,
        h,
        &nodal_offsets(model, state, contact, top),
    );
    let on_ring = ring.contains_set();
    let (mut total, mut penetration) = (0.0, 0.0_f64);
    let mut forces = vec![0.0; model.elements().len()];
    let mut touching = vec![];
    // the elements next to the ring: their contact points' pressures per current area, and
    // whether every point of the element is in contact
    let mut points: Vec<(usize, Vec<f64>, bool)> = vec![];
    for e in 0..model.elements().len() {
        let touches = model
            .elements()
            .nodes(e)
            .iter()
            .any(|i| on_ring.contains(i));
        let mut fe = 0.0;
        let samples = contact_samples(model, e, &state.x, contact);
        let lambda = contact.element_history(&state.multipliers, e, samples.len());
        for (g, sp) in samples.iter().enumerate() {
            let gp_gap = gap(sp.x.into());
            let t = contact.traction_at(gp_gap, contact.point(lambda, g, top));
            if gp_gap < 0.0 {
                penetration = penetration.max(-gp_gap);
            }
            if t > 0.0 {
                fe += sp.w * t;
            }
        }
        let pressures = if touches {
            with_elements!(model.elements(), els => {
                let el = &els[e];
                contact.point_pressures(el, &el.gather(&state.x), lambda, top)
            })
        } else {
            vec![]
        };
        total += fe;
        forces[e] = fe;
        if touches {
            touching.push(e);
            let full = pressures.iter().all(|&p| p > 0.0);
            points.push((e, pressures, full));
        }
    }
    // the flat zone's interior: the points of elements wholly in contact, and at nodal points
    // only nodes whose every element next to the ring is wholly in contact (the last node of
    // the flat zone carries the edge's share, not a pressure); pressures per current area as
    // `Contact::point_pressures` (at a node: its force over its share of the current area)
    let nodal = contact.points == ContactPoints::Nodal;
    let mut edge_nodes = std::collections::HashSet::new();
    if nodal {
        for (e, _, full) in &points {
            if !full {
                edge_nodes.extend(model.elements().nodes(*e).iter().copied());
            }
        }
    }
    let (mut pc_sum, mut pc_n) = (0.0, 0usize);
    let (mut deviation, mut flat_points) = (0.0f64, 0usize);
    for (e, pressures, full) in &points {
        let nodes = model.elements().nodes(*e);
        for (g, &pc) in pressures.iter().enumerate() {
            if pc > 0.0 {
                pc_sum += pc;
                pc_n += 1;
            }
            if !full || (nodal && edge_nodes.contains(&nodes[g])) {
                continue;
            }
            flat_points += 1;
            if state.p > 0.0 {
                deviation = deviation.max((pc / state.p - 1.0).abs());
            }
        }
    }
    // force per unit length from the element rows next to the ring, side by side
    let force = ring_force(model, state, &ring, touching.into_iter(), |e| forces[e]);
    Some(ContactValues {
        rho: h,
        chi: if state.p > 0.0 { force / state.p } else { 0.0 },
        chi_geometric,
        force,
        contact_pressure: if pc_n > 0 { pc_sum / pc_n as f64 } else { 0.0 },
        flat_pressure_deviation: if flat_points > 0 {
            Some(deviation)
        } else {
            None
        },
        penetration,
        total_force: x_copies * z_copies * total,
    })
}

/// Mean contact pressure per current area of each element (VTU cell data).
pub fn cell_contact_pressure(model: &Model, state: &State, contact: Option<&Contact>) -> Vec<f64> {
    with_elements!(model.elements(), els => els
        .iter()
        .enumerate()
        .map(|(e, el)| match contact {
            Some(c) => c.element_pressure(
                el,
                &el.gather(&state.x),
                c.element_history(&state.multipliers, e, c.samples(el).len()),
            ),
            None => 0.0,
        })
        .collect())
}
