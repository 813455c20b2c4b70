//! The 9-node element: its kernels against central differences (the tolerances of
//! [`crate::tests`]: step 1e-6, 1e-6 relative + 1e-7 absolute), the patch test, the quadrature
//! rule's justification (one order less is rank-deficient), assembled tangents with every
//! loading, the exactness and convergence of its enclosed volume, and the sphere against
//! Rivlin's closed form through the pressure maximum.

use crate::contact::{Contact, Plane};
use crate::element::point_state;
use crate::geometry::{RefElement, Vec3};
use crate::tests::{check_element_fd, contact_eval, volume_eval};
use nalgebra::{DMatrix, SMatrix, SVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tubemem_material::laws::{AnssariBenamBucchi, MooneyRivlin};
use tubemem_material::MembraneLaw;
use tubemem_mesh::shape::{rule, QUAD9_LATTICE};
use tubemem_mesh::tube::{capped_tube_of, plugged_tube_of, sphere_of};
use tubemem_mesh::{ElementKind, Symmetry};

const Q9: ElementKind = ElementKind::Quad9;

/// A curved 9-node element over about [0, 1]²: the lattice points perturbed (corners by up to
/// 0.15, mid-side and centre nodes by up to 0.05 in plane), with a random out-of-plane bulge.
fn random_quad9(rng: &mut ChaCha8Rng, flat: bool) -> [[f64; 3]; 9] {
    let bulge = if flat {
        0.0
    } else {
        rng.random_range(-0.3..0.3)
    };
    std::array::from_fn(|a| {
        let (i, j) = QUAD9_LATTICE[a];
        let (u, v) = (0.5 * i as f64, 0.5 * j as f64);
        let d = if a < 4 { 0.15 } else { 0.05 };
        let z = if flat {
            0.0
        } else {
            bulge * 4.0 * u * (1.0 - u) + rng.random_range(-0.05..0.05)
        };
        [u + rng.random_range(-d..d), v + rng.random_range(-d..d), z]
    })
}

fn deform9(x: &[[f64; 3]; 9], rng: &mut ChaCha8Rng) -> [Vec3; 9] {
    x.map(|p| {
        Vec3::new(
            1.3 * p[0] + 0.1 * p[1] + rng.random_range(-0.03..0.03),
            0.05 * p[0] + 1.15 * p[1] + rng.random_range(-0.03..0.03),
            0.2 * p[0] - 0.1 * p[1] + p[2] + rng.random_range(-0.03..0.03),
        )
    })
}

fn nodes9() -> [usize; 9] {
    std::array::from_fn(|a| a)
}

#[test]
fn quad9_membrane_tangents_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(91);
    let laws: Vec<Box<dyn MembraneLaw>> = vec![
        Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
        Box::new(MooneyRivlin::new(1.0, 0.2).unwrap()),
    ];
    for law in &laws {
        for _ in 0..10 {
            let x0 = random_quad9(&mut rng, false);
            let re = RefElement::new(0, nodes9(), &x0).unwrap();
            let x = deform9(&x0, &mut rng);
            check_element_fd(&x, 1e-6, &law.name(), |x| {
                let (mut r, mut k) = (SVector::<f64, 27>::zeros(), SMatrix::zeros());
                let e = crate::element::membrane_kernel(law.as_ref(), &re, x, &mut r, Some(&mut k))
                    .unwrap();
                (e, r, k)
            });
        }
    }
}

/// [`crate::tests::membrane_tangents_in_a_viscoelastic_step_match_finite_differences`] on the
/// 9-node element.
#[test]
fn quad9_membrane_tangents_in_a_viscoelastic_step_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(92);
    for _ in 0..10 {
        let x0 = random_quad9(&mut rng, false);
        let re = RefElement::new(0, nodes9(), &x0).unwrap();
        let x = deform9(&x0, &mut rng);
        crate::tests::check_viscoelastic_step::<9, 27>(&re, &x, &mut rng);
    }
}

#[test]
fn quad9_volume_gradient_and_hessian_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(92);
    for _ in 0..20 {
        let x = deform9(&random_quad9(&mut rng, false), &mut rng);
        check_element_fd(&x, 1e-6, "volume", volume_eval::<9, 27>);
    }
}

#[test]
fn quad9_contact_tangent_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(93);
    let n = Vec3::new(0.2, -0.9, 0.3).normalize();
    for _ in 0..10 {
        let x0 = random_quad9(&mut rng, false);
        let re = RefElement::new(0, nodes9(), &x0).unwrap();
        let x = deform9(&x0, &mut rng);
        let contact = Contact {
            planes: vec![Plane {
                normal: [n[0], n[1], n[2]],
                // not through the centre node: the centre Gauss point sits exactly there, and
                // a gap of exactly 0 is the penalty's kink
                offset: n.dot(&x[8]) + 0.013,
            }],
            penalty: 300.0,
            enforcement: crate::contact::Enforcement::Penalty,
            points: Default::default(),
        };
        let eval = |x: &[Vec3; 9]| contact_eval::<9, 27>(&contact, &re, x, &[]);
        assert!(eval(&x).0 > 0.0, "the plane penetrates the element");
        check_element_fd(&x, 1e-7, "contact", eval);
        // the same at the nodes (ContactPoints::Nodal); the offset keeps every node off the
        // kink too (the centre node is 0.013 from the plane, the others at random gaps)
        let nodal = contact
            .clone()
            .with_points(crate::contact::ContactPoints::Nodal);
        let eval = |x: &[Vec3; 9]| contact_eval::<9, 27>(&nodal, &re, x, &[]);
        assert!(
            eval(&x).0 > 0.0,
            "the plane penetrates the element at a node"
        );
        check_element_fd(&x, 1e-7, "nodal contact", eval);
    }
}

/// Patch test: a flat element with curved (in-plane) edges under a uniform stretch and an
/// out-of-plane rotation reproduces the law's resultants at every Gauss point (the biquadratic
/// isoparametric field contains every affine map); and in an assembled 2 × 2 patch of such
/// elements the interior node carries no force (the assembled internal forces of a uniform
/// stress state balance at interior nodes). Tolerance 1e-12 relative: rounding only.
#[test]
fn quad9_patch_test() {
    let mut rng = ChaCha8Rng::seed_from_u64(94);
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    for _ in 0..10 {
        let x0 = random_quad9(&mut rng, true);
        let re = RefElement::new(0, nodes9(), &x0).unwrap();
        let (l1, l2) = (rng.random_range(1.0..2.5), rng.random_range(0.8..1.8));
        let th: f64 = rng.random_range(0.0..3.0);
        let map = affine(l1, l2, th);
        let x = x0.map(&map);
        let [n1, n2] = law.resultants(l1, l2).unwrap();
        assert_eq!(re.gauss.len(), 9);
        for g in 0..9 {
            let ps = point_state(&law, &re, g, &x).unwrap();
            assert!((ps.stretches[0] - l1.max(l2)).abs() < 1e-12);
            assert!((ps.stretches[1] - l1.min(l2)).abs() < 1e-12);
            assert!((ps.principal[0] - n1.max(n2)).abs() < 1e-12 * n1.abs().max(1.0));
            assert!((ps.principal[1] - n1.min(n2)).abs() < 1e-12 * n1.abs().max(1.0));
        }
    }
    // a 2 × 2 patch on a 5 × 5 node lattice, interior lattice lines wavy
    let wav = |i: usize, j: usize| {
        let (u, v) = (0.25 * i as f64, 0.25 * j as f64);
        let s = if (1..4).contains(&i) && (1..4).contains(&j) {
            0.04
        } else {
            0.0
        };
        [u + s * (7.0 * v).sin(), v + s * (5.0 * u).cos(), 0.0]
    };
    let id = |i: usize, j: usize| 5 * j + i;
    let x0: Vec<[f64; 3]> = (0..25).map(|k| wav(k % 5, k / 5)).collect();
    let map = affine(1.7, 1.2, 0.4);
    let x: Vec<[f64; 3]> = x0.iter().map(|&p| map(p).into()).collect();
    let mut f = vec![Vec3::zeros(); 25];
    for (ei, ej) in [(0, 0), (2, 0), (0, 2), (2, 2)] {
        let nodes: [usize; 9] = std::array::from_fn(|a| {
            let (i, j) = QUAD9_LATTICE[a];
            id(ei + i, ej + j)
        });
        let re = RefElement::new(0, nodes, &nodes.map(|k| x0[k])).unwrap();
        let mut r = SVector::<f64, 27>::zeros();
        crate::element::membrane_kernel(&law, &re, &re.gather(&x), &mut r, None).unwrap();
        for a in 0..9 {
            f[nodes[a]] += r.fixed_rows::<3>(3 * a).into_owned();
        }
    }
    let scale = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
    for (i, j) in [
        (1, 1),
        (2, 1),
        (2, 2),
        (1, 2),
        (3, 3),
        (1, 3),
        (3, 1),
        (2, 3),
        (3, 2),
    ] {
        assert!(
            f[id(i, j)].norm() < 1e-12 * scale,
            "interior node ({i}, {j}): force {}",
            f[id(i, j)].norm()
        );
    }
}

/// x = Q diag(l1, l2) Qᵀ X in the plane, then a rigid rotation about x by 0.7 rad.
fn affine(l1: f64, l2: f64, th: f64) -> impl Fn([f64; 3]) -> Vec3 {
    let (c, s) = (th.cos(), th.sin());
    let (cr, sr) = (0.7f64.cos(), 0.7f64.sin());
    move |p: [f64; 3]| {
        let u = c * p[0] + s * p[1];
        let v = -s * p[0] + c * p[1];
        let (u, v) = (l1 * u, l2 * v);
        let (x, y) = (c * u - s * v, s * u + c * v);
        Vec3::new(x, cr * y, sr * y)
    }
}

/// The quadrature rule. 3 × 3 Gauss is the full rule of the biquadratic element: the in-plane
/// stiffness of one flat element at the reference state (18 in-plane dofs) has exactly the 3
/// zero eigenvalues of the in-plane rigid motions. One order less (2 × 2: 4 points × 3 strain
/// components = 12 constraints on 18 dofs) leaves at least 6 zero eigenvalues: 3 spurious
/// zero-energy (hourglass) modes, which a membrane under load would excite. Zero means below
/// 1e-10 of the largest eigenvalue (the rounding of a 27 × 27 symmetric eigensolve is ~1e-14).
#[test]
fn a_reduced_rule_on_the_quad9_element_has_spurious_zero_energy_modes() {
    let mut rng = ChaCha8Rng::seed_from_u64(95);
    let law = tubemem_material::laws::neo_hookean(1.0).unwrap();
    let x0 = random_quad9(&mut rng, true);
    let zeros = |n: usize| {
        let rule = rule(n).unwrap();
        let re = RefElement::with_rule(0, nodes9(), &x0, &rule).unwrap();
        let (mut r, mut k) = (SVector::<f64, 27>::zeros(), SMatrix::<f64, 27, 27>::zeros());
        crate::element::membrane_kernel(&law, &re, &re.gather(&x0), &mut r, Some(&mut k)).unwrap();
        let inplane: Vec<usize> = (0..27).filter(|i| i % 3 != 2).collect();
        let kin = DMatrix::from_fn(18, 18, |i, j| k[(inplane[i], inplane[j])]);
        let ev = kin.symmetric_eigenvalues();
        let top = ev.amax();
        ev.iter().filter(|&&e| e.abs() < 1e-10 * top).count()
    };
    assert_eq!(zeros(3), 3, "full rule: the rigid in-plane motions only");
    assert!(zeros(2) >= 6, "2 × 2: {} zero modes", zeros(2));
    assert_eq!(zeros(4), 3, "a higher rule changes nothing in the kernel");
}

/// Assembled tangents of 9-node models against central differences of the assembled residual
/// along random directions: a quarter capped tube under pressure, closed gas and a squeeze, and
/// a plugged tube (shared plug equations, the parabolic plug face) under pressure and gas.
#[test]
fn quad9_assembled_tangents_match_finite_differences() {
    crate::tests::check_assembled_tangents(
        capped_tube_of(Q9, 1.0, 3.0, 8, 4, Symmetry::Quarter).unwrap(),
        96,
        2,
    );
    crate::tests::check_plugged_tangents(
        plugged_tube_of(Q9, 1.0, 3.0, 8, 4, Symmetry::None).unwrap(),
        97,
    );
}

/// The plug face of a 9-node ring is bounded by parabolic arcs: its area (Archimedes' third of
/// each arc's triangle added to the polygon) against Green's theorem ½∮(x dy − y dx) along the
/// arcs by composite Simpson, which is exact for this polynomial integrand (degree 3 in t per
/// arc): equal to 1e-12 relative.
#[test]
fn the_plug_face_of_a_quad9_ring_is_its_curved_area() {
    let mesh = plugged_tube_of(Q9, 1.0, 3.0, 8, 4, Symmetry::None).unwrap();
    let ring = &mesh.plugs[0];
    // the area enclosed by the chain of parabolic arcs through the ring nodes, by Green's
    // theorem ½∮(x dy − y dx) with Simpson on each arc
    let n = ring.len();
    let mut area = 0.0;
    for k in (0..n).step_by(2) {
        let (a, m, b) = (
            mesh.nodes[ring[k]],
            mesh.nodes[ring[k + 1]],
            mesh.nodes[ring[(k + 2) % n]],
        );
        let pos = |t: f64, c: usize| {
            0.5 * t * (t - 1.0) * a[c] + (1.0 - t * t) * m[c] + 0.5 * t * (t + 1.0) * b[c]
        };
        let der = |t: f64, c: usize| (t - 0.5) * a[c] - 2.0 * t * m[c] + (t + 0.5) * b[c];
        let steps = 20;
        for s in 0..=steps {
            let t = -1.0 + 2.0 * s as f64 / steps as f64;
            let w = if s == 0 || s == steps {
                1.0
            } else if s % 2 == 1 {
                4.0
            } else {
                2.0
            };
            area += w / 3.0
                * (2.0 / steps as f64)
                * 0.5
                * (pos(t, 0) * der(t, 1) - pos(t, 1) * der(t, 0));
        }
    }
    let closed = mesh.symmetry.rings_closed();
    let face = tubemem_mesh::plug_face(&mesh.nodes, ring, closed, true);
    assert!(
        (face.area - area.abs()).abs() < 1e-12 * area.abs(),
        "{} vs {area}",
        face.area
    );
}

/// The enclosed volume of a 9-node surface is exact for that surface: the 3 × 3 rule agrees
/// with a 4 × 4 rule to rounding (1e-14 relative) on a curved, deformed patch; and the 9-node
/// sphere's volume converges to 4π/3 at order 4 (isoparametric quadratic geometry: O(h³)
/// pointwise, the cubic error term integrating to zero over each element): the observed order
/// over m = 2 → 4 → 8 lies in [3.5, 4.5].
#[test]
fn the_quad9_volume_is_exact_for_its_surface_and_converges_at_order_four() {
    let mut rng = ChaCha8Rng::seed_from_u64(97);
    for _ in 0..10 {
        let x = deform9(&random_quad9(&mut rng, false), &mut rng);
        let v3 = volume_eval::<9, 27>(&x).0;
        let v4: f64 = rule(4)
            .unwrap()
            .iter()
            .map(|&(xi, eta, w)| {
                let [p, g1, g2] = tubemem_mesh::volume::tangents_n::<9>(&x, xi, eta);
                w * p.dot(&g1.cross(&g2)) / 3.0
            })
            .sum();
        assert!((v3 - v4).abs() < 1e-14 * v3.abs().max(1.0), "{v3} vs {v4}");
    }
    let exact = 4.0 * std::f64::consts::PI / 3.0;
    let err = |m: usize| (sphere_of(Q9, 1.0, m, Symmetry::None).unwrap().volume() - exact).abs();
    let e: Vec<f64> = [2, 4, 8].iter().map(|&m| err(m)).collect();
    for w in e.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.5..=4.5).contains(&order), "volume errors {e:?}");
    }
    eprintln!("9-node sphere volume errors, m = 2, 4, 8: {e:?}");
}

/// The 9-node sphere through Rivlin's pressure maximum by arc-length continuation (every check
/// of `arc_length_passes_and_locates_the_pressure_maximum_of_a_sphere`, at m = 2, 4, 8). The
/// located maximum converges at order 4, the order of the element's geometry (its volume, above):
/// each observed order lies in [3.5, 4.5]. Measured: errors 6.6e-4, 4.4e-5 at m = 2, 4 (order
/// 3.90), against 3.4e-2 and 8.5e-3 for the 4-node element at m = 4, 8.
#[test]
fn quad9_sphere_passes_and_locates_the_rivlin_maximum() {
    let errors = crate::tests::sphere_limit_errors(Q9, &[2, 4, 8]);
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.5..=4.5).contains(&order), "errors {errors:?}");
    }
}
