//! Solving a manufactured problem on a mesh and measuring the error, and the observed order of
//! a mesh family.

use super::body::{BodyForce, Manufactured};
use super::field::Field;
use super::surface::CappedTube;
use crate::contact::{Contact, ContactPoints, Enforcement};
use crate::model::{Load, Loading, Model, State};
use crate::{with_elements, FemError};
use std::sync::Arc;
use tubemem_material::dual::HyperDual2;
use tubemem_material::MembraneLaw;

/// How the manufactured state is loaded besides the body force.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MmsLoading {
    /// the body force alone (p* = 0)
    None,
    /// a prescribed pressure p*
    Pressure,
    /// the enclosed volume prescribed (V* of x*'s surface), the pressure its multiplier
    Volume,
    /// the gas closed in: p V = p* V*
    Gas,
}

impl MmsLoading {
    pub const ALL: [MmsLoading; 4] = [
        MmsLoading::None,
        MmsLoading::Pressure,
        MmsLoading::Volume,
        MmsLoading::Gas,
    ];
    pub fn label(self) -> &'static str {
        match self {
            MmsLoading::None => "none",
            MmsLoading::Pressure => "pressure",
            MmsLoading::Volume => "volume",
            MmsLoading::Gas => "gas",
        }
    }
}

/// The errors of one mesh, against the manufactured field.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct MmsErrors {
    /// elements around the whole tube (for the mesh size h ∝ 1/around)
    pub around: usize,
    pub equations: usize,
    /// √(∫ |x_h − x*|² dA0 / ∫ dA0) over the Gauss points (x* at their projections)
    pub l2_position: f64,
    /// the largest |x_h − x*| at a Gauss point
    pub max_position: f64,
    /// the largest |x_h − x*| at a node
    pub max_nodal: f64,
    /// the reference position of that node
    pub max_nodal_at: [f64; 3],
    /// √(∫ |N_h − N*|² dA0 / ∫ dA0), the principal Cauchy resultants
    pub l2_resultants: f64,
    /// the FE pressure's relative error (p_h − p*)/p* (volume and gas loadings; 0 otherwise)
    pub pressure: f64,
    /// √(∫ (t_h − q*)² dA0 / ∫ dA0) / max q*, the planes' traction per reference area at the
    /// Gauss points against the manufactured contact pressure (0 without planes)
    pub l2_contact: f64,
    /// the FE's largest penetration of a plane at a Gauss point (0 without planes)
    pub penetration: f64,
}

/// The penalty of the manufactured contact, per μH/R² (the regularization of the augmented
/// Lagrangian: the penalty alone would leave the membrane q/κ ≈ 2.2e-4 R inside the plane of
/// [`super::field::Pressed::standard`])
pub const MMS_PENALTY: f64 = 1e4;
/// The gap tolerance of the manufactured contact, in R: four orders below the finest meshes'
/// position errors (9-node, 256 around: 2.8e-6 R in L2).
pub const MMS_GAP_TOLERANCE: f64 = 1e-10;

/// The contact of a field pressed against planes: the augmented Lagrangian at `points`.
fn contact_of<F: Field>(field: &F, points: ContactPoints) -> Option<Contact> {
    let planes = field.planes();
    (!planes.is_empty()).then_some(Contact {
        planes,
        penalty: MMS_PENALTY,
        enforcement: Enforcement::Augmented {
            gap_tolerance: MMS_GAP_TOLERANCE,
            max_augmentations: crate::contact::DEFAULT_MAX_AUGMENTATIONS,
        },
        points,
    })
}

/// The reference position of every Gauss point of every element of `model`.
fn gauss_points(model: &Model) -> Vec<Vec<[f64; 3]>> {
    let nodes = &model.mesh().nodes;
    with_elements!(model.elements(), els => els
        .iter()
        .map(|e| {
            let x0 = e.gather(nodes);
            e.gauss.iter().map(|g| {
                let p = g.position(&x0);
                [p[0], p[1], p[2]]
            }).collect()
        })
        .collect())
}

/// The volume enclosed by x*(S) (the whole tube), by the divergence theorem V = ⅓ ∮ x·n da on
/// the exact surface: the cylinder in (θ, z), each cap in spherical angles (φ, θ); θ by the
/// trapezoidal rule (spectral for a periodic integrand), z and φ by 48-point Gauss–Legendre.
pub fn enclosed_volume<F: Field>(field: &F, s: &CappedTube) -> f64 {
    let (r, h) = (s.radius, s.half_length);
    let (gl_x, gl_w) = gauss_legendre(48);
    let nt = 256;
    let dtheta = 2.0 * std::f64::consts::PI / nt as f64;
    let flux = |x: [HyperDual2; 3]| {
        let y = field.map(x);
        let (p, a, b) = (y.map(|c| c.re), y.map(|c| c.g[0]), y.map(|c| c.g[1]));
        let n = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / 3.0
    };
    let mut v = 0.0;
    for k in 0..nt {
        let th0 = k as f64 * dtheta;
        for (xg, wg) in gl_x.iter().zip(&gl_w) {
            // the cylinder: u = θ, v = z
            let z0 = h * xg;
            let th = HyperDual2::variable(th0, 0);
            let z = HyperDual2::variable(z0, 1);
            use tubemem_material::dual::Real;
            let x = [th.cos() * r, th.sin() * r, z];
            v += flux(x) * dtheta * wg * h;
            // the caps: u = φ, v = θ, outward for φ ∈ (0, π/2) above and (π/2, π) below
            for (c, phi0) in [
                (h, 0.25 * std::f64::consts::PI * (1.0 + xg)),
                (-h, 0.25 * std::f64::consts::PI * (3.0 + xg)),
            ] {
                let phi = HyperDual2::variable(phi0, 0);
                let th = HyperDual2::variable(th0, 1);
                let x = [
                    phi.sin() * th.cos() * r,
                    phi.sin() * th.sin() * r,
                    phi.cos() * r + c,
                ];
                v += flux(x) * dtheta * wg * 0.25 * std::f64::consts::PI;
            }
        }
    }
    v
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the Legendre polynomial from
/// Tricomi's initial guesses; the standard construction, exact to round-off).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    // P_n(t) by the three-term recurrence, and its derivative
    let legendre = |t: f64| {
        let (mut p0, mut p1) = (1.0, t);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * t * p1 - (k - 1) as f64 * p0) / k as f64;
            p0 = p1;
            p1 = p2;
        }
        (p1, n as f64 * (t * p1 - p0) / (t * t - 1.0))
    };
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut t = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(t);
            let dt = p / dp;
            t -= dt;
            if dt.abs() < 1e-16 {
                let dq = legendre(t).1;
                w[i] = 2.0 / ((1.0 - t * t) * dq * dq);
                break;
            }
        }
        x[i] = t;
    }
    (x, w)
}

/// The principal Cauchy resultants at a Gauss point of the current state.
fn gauss_resultants<const N: usize>(
    law: &dyn MembraneLaw,
    g: &crate::geometry::GaussPoint<N>,
    x: &[crate::geometry::Vec3; N],
) -> Result<[f64; 2], tubemem_material::MaterialError> {
    let f = g.gradient(x);
    let c = [f[0].dot(&f[0]), f[1].dot(&f[1]), f[0].dot(&f[1])];
    let a = c[0] + c[1];
    let b = c[0] * c[1] - c[2] * c[2];
    let d = (0.25 * a * a - b).max(0.0).sqrt();
    let (l1, l2) = ((0.5 * a + d).sqrt(), (0.5 * a - d).max(0.0).sqrt());
    let r = law.resultants(l1, l2)?;
    Ok([r[0].max(r[1]), r[0].min(r[1])])
}

/// Solve the manufactured problem on `model` (its mesh a generated capped tube on `surface`)
/// and measure the error. Newton starts from the nodal interpolant of x* (and p*): the
/// discrete solution is the one near the manufactured state whatever the path, and a
/// stress-free membrane has no stiffness to start a load path from (a run's pre-stress step
/// exists for that). `steps` > 1 ramps the loads from the interpolant's own residual instead
/// (a homotopy: the body force and the loading at t/steps of their values plus the
/// interpolant's unbalanced force at 1 − t/steps), for a law whose Newton needs it.
pub fn solve<F: Field>(
    mut model: Model,
    problem: &Manufactured<'_, F>,
    loading: MmsLoading,
    around: usize,
    points_of_contact: ContactPoints,
) -> Result<MmsErrors, FemError> {
    if loading == MmsLoading::None && problem.pressure != 0.0 {
        return Err(FemError::Setup {
            reason: format!(
                "a manufactured problem without pressure needs its body force made with p = 0, not {}",
                problem.pressure
            ),
        });
    }
    let points = gauss_points(&model);
    let body = Arc::new(
        BodyForce::new(problem, &points).map_err(|source| FemError::Material {
            element: 0,
            gauss_point: 0,
            source,
        })?,
    );
    model.add_term(Box::new(body.clone()));
    body.set_scale(1.0);
    model.set_load_scale(body.load_norm(&model));
    let mut state: State = model.reference_state();
    for (x, x0) in state.x.iter_mut().zip(&model.mesh().nodes) {
        *x = problem.field.map(problem.surface.project(*x0));
    }
    let p = problem.pressure;
    state.p = p;
    let loading_now = match loading {
        MmsLoading::None => Loading::Pressure(0.0),
        MmsLoading::Pressure => Loading::Pressure(p),
        MmsLoading::Volume => Loading::Volume(enclosed_volume(problem.field, &problem.surface)),
        MmsLoading::Gas => Loading::Gas {
            pv: p * enclosed_volume(problem.field, &problem.surface),
        },
    };
    let contact = contact_of(problem.field, points_of_contact);
    let load = match &contact {
        Some(c) => Load::with_contact(loading_now, c.clone()),
        None => Load::new(loading_now),
    };
    model
        .solve(&mut state, &load)
        .map_err(|e| FemError::Stage {
            stage: 1,
            step: 1,
            value: 1.0,
            cuts: 0,
            material: None,
            near_locking: None,
            source: Box::new(e),
        })?;
    let mut e = errors(&model, &state, problem, &points, loading, around)?;
    if let Some(c) = &contact {
        (e.l2_contact, e.penetration) = contact_errors(&model, &state, problem, c);
    }
    Ok(e)
}

/// The planes' traction at the contact points against the manufactured contact pressure (L2
/// with the points' weights, relative to its largest value), and the largest penetration.
fn contact_errors<F: Field>(
    model: &Model,
    state: &State,
    problem: &Manufactured<'_, F>,
    contact: &Contact,
) -> (f64, f64) {
    let (mut e2, mut area, mut qmax, mut pen) = (0.0, 0.0, 0.0f64, 0.0f64);
    let nodes = &model.mesh().nodes;
    with_elements!(model.elements(), els => {
        for (e, el) in els.iter().enumerate() {
            let (x, x0) = (el.gather(&state.x), el.gather(nodes));
            let history = contact.element_history(&state.multipliers, e, contact.samples(el).len());
            for (g, gp) in contact.samples(el).iter().enumerate() {
                let (xh, at) = (gp.position(&x), gp.position(&x0));
                let exact = problem.field.contact_pressures(problem.surface.project([at[0], at[1], at[2]]));
                let mut d2 = 0.0;
                for (k, plane) in contact.planes.iter().enumerate() {
                    let gap = plane.gap([xh[0], xh[1], xh[2]]);
                    pen = pen.max(-gap);
                    let t = contact.traction_at(gap, contact.point(history, g, k));
                    let q = exact[k];
                    qmax = qmax.max(q);
                    d2 += (t - q) * (t - q);
                }
                e2 += gp.w * d2;
                area += gp.w;
            }
        }
    });
    (
        (e2 / area).sqrt() / qmax.max(f64::MIN_POSITIVE),
        pen.max(0.0),
    )
}

fn errors<F: Field>(
    model: &Model,
    state: &State,
    problem: &Manufactured<'_, F>,
    points: &[Vec<[f64; 3]>],
    loading: MmsLoading,
    around: usize,
) -> Result<MmsErrors, FemError> {
    let material = |source| FemError::Material {
        element: 0,
        gauss_point: 0,
        source,
    };
    let (mut e2, mut n2, mut area, mut emax) = (0.0, 0.0, 0.0, 0.0f64);
    with_elements!(model.elements(), els => {
        for (e, el) in els.iter().enumerate() {
            let x = el.gather(&state.x);
            for (g, gp) in el.gauss.iter().enumerate() {
                let exact = problem.exact(problem.surface.project(points[e][g])).map_err(material)?;
                let xh = gp.position(&x);
                let d = [xh[0] - exact.x[0], xh[1] - exact.x[1], xh[2] - exact.x[2]];
                let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                e2 += gp.w * dd;
                emax = emax.max(dd.sqrt());
                let nh = gauss_resultants(problem.law, gp, &x).map_err(material)?;
                let dn = [nh[0] - exact.resultants[0], nh[1] - exact.resultants[1]];
                n2 += gp.w * (dn[0] * dn[0] + dn[1] * dn[1]);
                area += gp.w;
            }
        }
    });
    let (mut nodal, mut nodal_at) = (0.0, [0.0; 3]);
    for (x, x0) in state.x.iter().zip(&model.mesh().nodes) {
        let xs = problem.field.map(problem.surface.project(*x0));
        let d = [x[0] - xs[0], x[1] - xs[1], x[2] - xs[2]];
        let d = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if d > nodal {
            (nodal, nodal_at) = (d, *x0);
        }
    }
    let pressure = match loading {
        MmsLoading::Volume | MmsLoading::Gas => state.p / problem.pressure - 1.0,
        _ => 0.0,
    };
    Ok(MmsErrors {
        around,
        equations: model.n_eq(),
        l2_position: (e2 / area).sqrt(),
        max_position: emax,
        max_nodal: nodal,
        max_nodal_at: nodal_at,
        l2_resultants: (n2 / area).sqrt(),
        pressure,
        l2_contact: 0.0,
        penetration: 0.0,
    })
}

/// The observed order between two meshes of sizes ∝ 1/around.
pub fn order(coarse: f64, fine: f64, around_coarse: usize, around_fine: usize) -> f64 {
    (coarse / fine).ln() / (around_fine as f64 / around_coarse as f64).ln()
}

#[cfg(test)]
mod tests {
    use super::gauss_legendre;

    /// n points integrate t^k exactly for k ≤ 2n − 1 (∫ t^k = 2/(k + 1) for even k, 0 for odd)
    /// and not t^(2n) (checked for small n: the rule's error there, (n!)⁴ 2^(2n+1) /
    /// ((2n + 1) ((2n)!)³) times (2n)!, falls below round-off by n = 48).
    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in [1, 2, 5, 48] {
            let (x, w) = gauss_legendre(n);
            let integral = |k: i32| x.iter().zip(&w).map(|(t, w)| w * t.powi(k)).sum::<f64>();
            for k in 0..2 * n as i32 {
                let exact = if k % 2 == 0 {
                    2.0 / (k + 1) as f64
                } else {
                    0.0
                };
                assert!((integral(k) - exact).abs() < 1e-13, "n = {n}, t^{k}");
            }
            let k = 2 * n as i32;
            if n > 5 {
                continue;
            }
            assert!(
                (integral(k) - 2.0 / (k + 1) as f64).abs() > 1e-6,
                "n = {n}: t^{k} exact?"
            );
        }
    }
}
