//! Kernel and model unit tests. Every tangent is checked against central finite differences
//! (step 1e-6; truncation ≈ 1e-12 and rounding ≈ 1e-10 relative to the entries, so 1e-6
//! relative + 1e-7 absolute), the patch test against the law's resultants, and the model's
//! loadings, constraints and error paths on small meshes. The FE-versus-closed-form
//! verification of whole tubes lives in the top-level `tests/` folder.

use crate::contact::{Contact, Enforcement, Plane};
use crate::element::{membrane_kernel, point_state, Matrix12, Vector12};
use crate::geometry::{RefElement, Vec3};
use crate::model::{Load, Loading, Model};
use crate::newton::NewtonError;
use crate::post::{CellValues, Regime};
use crate::stepping::{run_stage, Stage, StepSettings};
use crate::FemError;
use nalgebra::{SMatrix, SVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tubemem_material::laws::{AnssariBenamBucchi, MooneyRivlin};
use tubemem_material::{MaterialError, MembraneLaw};
use tubemem_mesh::tube::{capped_tube, plugged_tube, sphere};
use tubemem_mesh::volume::volume_kernel_n;
use tubemem_mesh::Symmetry;

fn random_quad(rng: &mut ChaCha8Rng) -> [[f64; 3]; 4] {
    let base = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    base.map(|p| {
        [
            p[0] + rng.random_range(-0.15..0.15),
            p[1] + rng.random_range(-0.15..0.15),
            p[2] + rng.random_range(-0.2..0.2),
        ]
    })
}

fn deform(x: &[[f64; 3]; 4], rng: &mut ChaCha8Rng) -> [Vec3; 4] {
    // a stretch with some shear and out-of-plane motion
    x.map(|p| {
        Vec3::new(
            1.3 * p[0] + 0.1 * p[1] + rng.random_range(-0.05..0.05),
            0.05 * p[0] + 1.15 * p[1] + rng.random_range(-0.05..0.05),
            0.2 * p[0] - 0.1 * p[1] + p[2] + rng.random_range(-0.05..0.05),
        )
    })
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + 1e-7 * scale
}

/// Membrane energy, residual and tangent of one element (residual and tangent zeroed first).
fn membrane<const N: usize, const D: usize>(
    law: &dyn MembraneLaw,
    re: &RefElement<N>,
    x: &[Vec3; N],
) -> (f64, SVector<f64, D>, SMatrix<f64, D, D>) {
    let (mut r, mut k) = (SVector::zeros(), SMatrix::zeros());
    let e = membrane_kernel(law, re, x, &mut r, Some(&mut k)).unwrap();
    (e, r, k)
}

/// Check an element's residual r and tangent K, as functions of its D nodal coordinates,
/// against central differences (step `h`) of its energy and residual (`eval` gives all three),
/// and K for symmetry.
pub(crate) fn check_element_fd<const N: usize, const D: usize>(
    x: &[Vec3; N],
    h: f64,
    what: &str,
    eval: impl Fn(&[Vec3; N]) -> (f64, SVector<f64, D>, SMatrix<f64, D, D>),
) {
    let (_, r, k) = eval(x);
    let scale = k.amax();
    for j in 0..D {
        let (mut xp, mut xm) = (*x, *x);
        xp[j / 3][j % 3] += h;
        xm[j / 3][j % 3] -= h;
        let ((ep, rp, _), (em, rm, _)) = (eval(&xp), eval(&xm));
        assert!(close(r[j], (ep - em) / (2.0 * h), scale), "{what} r[{j}]");
        for i in 0..D {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            assert!(
                close(k[(i, j)], fd, scale),
                "{what} K[{i}][{j}] = {} vs {fd}",
                k[(i, j)]
            );
        }
    }
    assert!(
        (k - k.transpose()).amax() <= 1e-12 * scale.max(1.0),
        "{what}: K not symmetric"
    );
}

#[test]
fn membrane_tangents_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let laws: Vec<Box<dyn MembraneLaw>> = vec![
        Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
        Box::new(MooneyRivlin::new(1.0, 0.2).unwrap()),
    ];
    for law in &laws {
        for _ in 0..20 {
            let x0 = random_quad(&mut rng);
            let re = RefElement::new(0, [0, 1, 2, 3], &x0).unwrap();
            let x = deform(&x0, &mut rng);
            check_element_fd(&x, 1e-6, &law.name(), |x| {
                membrane::<4, 12>(law.as_ref(), &re, x)
            });
        }
    }
}

/// Within a viscoelastic time step each Gauss point's energy is α W(C) + ½ B:(C − I)
/// ([`crate::element::Hereditary`]): the kernel's residual is its gradient and its tangent the
/// Hessian, for random α in (0.1, 1) and random offsets B per point (central differences,
/// [`check_element_fd`]'s bounds).
#[test]
fn membrane_tangents_in_a_viscoelastic_step_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    for _ in 0..20 {
        let x0 = random_quad(&mut rng);
        let re = RefElement::new(0, [0, 1, 2, 3], &x0).unwrap();
        let x = deform(&x0, &mut rng);
        check_viscoelastic_step::<4, 12>(&re, &x, &mut rng);
    }
}

/// [`check_element_fd`] on the membrane kernel within a viscoelastic step of random α in
/// (0.1, 1) and random offsets B in (−0.5, 0.5) per point (ABB 30).
pub(crate) fn check_viscoelastic_step<const N: usize, const D: usize>(
    re: &RefElement<N>,
    x: &[Vec3; N],
    rng: &mut ChaCha8Rng,
) {
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let offsets: Vec<[f64; 3]> = (0..re.gauss.len())
        .map(|_| std::array::from_fn(|_| rng.random_range(-0.5..0.5)))
        .collect();
    let step = crate::element::Hereditary {
        alpha: rng.random_range(0.1..1.0),
        offsets: &offsets,
    };
    check_element_fd(x, 1e-6, "viscoelastic step", |x| {
        let (mut r, mut k) = (SVector::<f64, D>::zeros(), SMatrix::zeros());
        let e =
            crate::element::membrane_kernel_in_step(&law, Some(step), re, x, &mut r, Some(&mut k))
                .unwrap();
        (e, r, k)
    });
}

/// The volume as an "energy" for [`check_element_fd`]: (V, ∂V/∂x, ∂²V/∂x²).
pub(crate) fn volume_eval<const N: usize, const D: usize>(
    x: &[Vec3; N],
) -> (f64, SVector<f64, D>, SMatrix<f64, D, D>) {
    let (mut g, mut hs) = (SVector::zeros(), SMatrix::zeros());
    let v = volume_kernel_n(x, Some(&mut g), Some(&mut hs));
    (v, g, hs)
}

#[test]
fn volume_gradient_and_hessian_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..50 {
        let x = deform(&random_quad(&mut rng), &mut rng);
        check_element_fd(&x, 1e-6, "volume", volume_eval::<4, 12>);
        let (_, _, hs) = volume_eval::<4, 12>(&x);
        assert!((hs - hs.transpose()).amax() < 1e-14);
    }
}

/// A random distorted element, deformed, and a tilted plane through its centroid with the
/// penalty κ = 300 (so that some Gauss points penetrate it), for the contact FD checks.
fn element_on_tilted_plane(rng: &mut ChaCha8Rng) -> (RefElement<4>, [Vec3; 4], Contact) {
    let n = Vec3::new(0.2, -0.9, 0.3).normalize();
    let x0 = random_quad(rng);
    let re = RefElement::new(0, [0, 1, 2, 3], &x0).unwrap();
    let x = deform(&x0, rng);
    let mid = (x[0] + x[1] + x[2] + x[3]) / 4.0;
    let contact = Contact {
        planes: vec![Plane {
            normal: [n[0], n[1], n[2]],
            offset: n.dot(&mid),
        }],
        penalty: 300.0,
        enforcement: Enforcement::Penalty,
        points: Default::default(),
    };
    (re, x, contact)
}

/// The contact kernel's residual and tangent against central differences of its energy and
/// residual, with a tilted plane that some Gauss points penetrate.
#[test]
fn contact_tangent_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let h = 1e-7;
    for _ in 0..20 {
        let (re, x, contact) = element_on_tilted_plane(&mut rng);
        let eval = |x: &[Vec3; 4]| contact_eval::<4, 12>(&contact, &re, x, &[]);
        assert!(eval(&x).0 > 0.0, "the plane penetrates the element");
        // the penalty is C¹: where a Gauss point crosses the plane within ±h the difference
        // quotient sees the kink; none does at these random states
        check_element_fd(&x, h, "contact", eval);
    }
}

/// The contact kernel as an energy for [`check_element_fd`].
pub(crate) fn contact_eval<const N: usize, const D: usize>(
    contact: &Contact,
    re: &RefElement<N>,
    x: &[Vec3; N],
    history: &[f64],
) -> (f64, SVector<f64, D>, SMatrix<f64, D, D>) {
    let (mut r, mut k) = (SVector::zeros(), SMatrix::zeros());
    let e = contact.kernel(re, x, history, &mut r, Some(&mut k));
    (e, r, k)
}

/// The augmented-Lagrangian contact kernel, t = ⟨λ − κ_g g⟩ with random multipliers and local
/// penalties at each Gauss point (so that some points are pushed where they do not penetrate,
/// g > 0 with λ > κ_g g, and some penetrate with λ = 0): residual and tangent against central
/// differences of its energy and residual.
#[test]
fn augmented_contact_tangent_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let h = 1e-7;
    let mut pushed_outside = 0;
    for _ in 0..20 {
        let (re, x, contact) = element_on_tilted_plane(&mut rng);
        let contact = contact.with_enforcement(Enforcement::augmented());
        let gaps: Vec<f64> = (0..4)
            .map(|g| contact.planes[0].gap(re.position(g, &x).into()))
            .collect();
        // λ = κ_g (g + s): a point outside the plane (g > 0) with s > 0 is pushed from a
        // distance, a penetrating one (g < 0) with g + s < 0 carries no multiplier
        let history: Vec<f64> = gaps
            .iter()
            .flat_map(|gap| {
                let kappa = 300.0 * rng.random_range(1.0..20.0);
                let s = rng.random_range(-0.05..0.3);
                [(kappa * (gap + s)).max(0.0), kappa, f64::NAN]
            })
            .collect();
        pushed_outside += gaps
            .iter()
            .enumerate()
            .filter(|&(g, &gap)| {
                gap > 0.0 && contact.traction_at(gap, contact.point(&history, g, 0)) > 0.0
            })
            .count();
        let eval = |x: &[Vec3; 4]| contact_eval::<4, 12>(&contact, &re, x, &history);
        check_element_fd(&x, h, "augmented contact", eval);
    }
    assert!(
        pushed_outside > 0,
        "no Gauss point pushed outside the plane"
    );
}

/// The contact kernel on a branch ([`Contact::kernel_on_branch`]) with the status positions
/// held: its residual and tangent against central differences of its energy and residual, with
/// random multipliers and status positions, so that some points are pushed on a branch they
/// are apart on (a pulling traction) and some are free where they penetrate; on the branch of
/// the positions themselves it is the kernel, bit for bit.
#[test]
fn contact_on_a_branch_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    let h = 1e-7;
    let (mut pulled, mut freed) = (0, 0);
    for _ in 0..20 {
        let (re, x, contact) = element_on_tilted_plane(&mut rng);
        let contact = contact.with_enforcement(Enforcement::augmented());
        let history: Vec<f64> = (0..4)
            .flat_map(|_| {
                let kappa = 300.0 * rng.random_range(1.0..20.0);
                [rng.random_range(0.0..1.0), kappa, f64::NAN]
            })
            .collect();
        // status positions: the element moved by up to ±0.6 along the normal (its gaps are of that
        // size), node by node
        let normal = Vec3::from(contact.planes[0].normal);
        let branch = x.map(|p| p + normal * rng.random_range(-0.6..0.6));
        for g in 0..4 {
            let at = contact.point(&history, g, 0);
            let gap = contact.planes[0].gap(re.position(g, &x).into());
            let pushed_at_branch = contact
                .traction_at(contact.planes[0].gap(re.position(g, &branch).into()), at)
                > 0.0;
            let pushed_here = contact.traction_at(gap, at) > 0.0;
            pulled += usize::from(pushed_at_branch && !pushed_here);
            freed += usize::from(!pushed_at_branch && pushed_here);
        }
        let eval = |x: &[Vec3; 4]| {
            let (mut r, mut k) = (SVector::<f64, 12>::zeros(), SMatrix::<f64, 12, 12>::zeros());
            let e = contact.kernel_on_branch(&re, x, Some(&branch), &history, &mut r, Some(&mut k));
            (e, r, k)
        };
        check_element_fd(&x, h, "contact on a branch", eval);
        // on its own branch: the kernel
        let (mut r1, mut k1) = (SVector::<f64, 12>::zeros(), SMatrix::<f64, 12, 12>::zeros());
        let (mut r2, mut k2) = (SVector::<f64, 12>::zeros(), SMatrix::<f64, 12, 12>::zeros());
        let e1 = contact.kernel(&re, &x, &history, &mut r1, Some(&mut k1));
        let e2 = contact.kernel_on_branch(&re, &x, Some(&x), &history, &mut r2, Some(&mut k2));
        assert_eq!((e1, r1, k1), (e2, r2, k2));
    }
    assert!(pulled > 0 && freed > 0, "pulled {pulled}, freed {freed}");
}

/// Patch test: a flat (tilted, distorted) element under a uniform in-plane stretch reproduces the
/// law's resultants exactly (the bilinear field contains every affine map).
#[test]
fn uniform_stretch_patch_reproduces_the_law_resultants() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    for _ in 0..10 {
        // a distorted flat quad in the plane z = 0
        let x0 = random_quad(&mut rng).map(|p| [p[0], p[1], 0.0]);
        let re = RefElement::new(0, [0, 1, 2, 3], &x0).unwrap();
        let (l1, l2) = (rng.random_range(1.0..2.5), rng.random_range(0.8..1.8));
        let th: f64 = rng.random_range(0.0..3.0);
        let (c, s) = (th.cos(), th.sin());
        // x = Q diag(l1, l2) Qᵀ X, then a rigid rotation about x by 0.7 rad (out of plane)
        let (cr, sr) = (0.7f64.cos(), 0.7f64.sin());
        let map = |p: [f64; 3]| {
            let u = c * p[0] + s * p[1];
            let v = -s * p[0] + c * p[1];
            let (u, v) = (l1 * u, l2 * v);
            let (x, y) = (c * u - s * v, s * u + c * v);
            Vec3::new(x, cr * y, sr * y)
        };
        let x = x0.map(map);
        let [n1, n2] = law.resultants(l1, l2).unwrap();
        for g in 0..4 {
            let ps = point_state(&law, &re, g, &x).unwrap();
            assert!((ps.stretches[0] - l1.max(l2)).abs() < 1e-12);
            assert!((ps.stretches[1] - l1.min(l2)).abs() < 1e-12);
            assert!((ps.principal[0] - n1.max(n2)).abs() < 1e-12 * n1.abs().max(1.0));
            assert!((ps.principal[1] - n1.min(n2)).abs() < 1e-12 * n1.abs().max(1.0));
        }
    }
}

/// A flat membrane pressed on a plane: a flat (distorted) element lying δ inside the plane
/// n·x = d, tilted arbitrarily. Exact: energy κδ²A/2 (A the element area), total force κδA along
/// n only (frictionless), and no force at all when it lies outside.
#[test]
fn flat_membrane_pressed_on_a_plane() {
    let (kappa, delta) = (250.0, 2e-3);
    // the plane z = 0 rotated by 0.4 rad about x: normal n, offset 0
    let (c, s) = (0.4f64.cos(), 0.4f64.sin());
    let n = [0.0, -s, c];
    let local = [[0.0, 0.0], [1.3, 0.1], [1.1, 0.9], [-0.2, 0.8]];
    // in-plane axes e1 = x, e2 = (0, c, s); the element sits at n·x = −δ
    let place = |d: f64| local.map(|[u, v]| [u, v * c + d * n[1], v * s + d * n[2]]);
    let x = place(-delta);
    let re = RefElement::new(0, [0, 1, 2, 3], &x).unwrap();
    let contact = Contact {
        planes: vec![Plane {
            normal: n,
            offset: 0.0,
        }],
        penalty: kappa,
        enforcement: Enforcement::Penalty,
        points: Default::default(),
    };
    let mut r = Vector12::zeros();
    let mut k = Matrix12::zeros();
    let e = contact.kernel(&re, &x.map(Vec3::from), &[], &mut r, Some(&mut k));
    let area = tubemem_mesh::quad_area(&x);
    assert!((e - 0.5 * kappa * delta * delta * area).abs() < 1e-12 * e);
    // total force on the membrane (minus the residual) is κδA along n
    let f: [f64; 3] = [0, 1, 2].map(|i| -(0..4).map(|a| r[3 * a + i]).sum::<f64>());
    for i in 0..3 {
        assert!(
            (f[i] - kappa * delta * area * n[i]).abs() < 1e-12 * kappa * delta * area,
            "{f:?}"
        );
    }
    // outside the plane: no contact
    let xo = place(delta).map(Vec3::from);
    let mut r2 = Vector12::zeros();
    assert_eq!(contact.kernel(&re, &xo, &[], &mut r2, None), 0.0);
    assert!(r2.iter().all(|v| *v == 0.0));
}

/// The taut / wrinkled / slack classification of the output, including the exact zeros the
/// relaxed law produces (N2 = 0 when wrinkled, both 0 when slack).
#[test]
fn wrinkle_state_classification_works() {
    use tubemem_material::relaxed::Relaxed;
    let c = |n1: f64, n2: f64| {
        CellValues {
            hoop_stretch: 1.0,
            axial_stretch: 1.0,
            n1,
            n2,
        }
        .regime()
    };
    assert_eq!(c(1.0, 0.5), Regime::Taut);
    assert_eq!(c(1.0, 0.0), Regime::Wrinkled);
    assert_eq!(c(1.0, -0.2), Regime::Wrinkled);
    assert_eq!(c(0.0, 0.0), Regime::Slack);
    assert_eq!(c(-0.1, -0.3), Regime::Slack);
    let r = Relaxed::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap());
    let [n1, n2] = r.resultants(1.5, 0.6).unwrap(); // λ2 below the natural width: wrinkled
    assert_eq!(c(n1, n2), Regime::Wrinkled);
    let [n1, n2] = r.resultants(0.9, 0.8).unwrap(); // slack
    assert_eq!(c(n1, n2), Regime::Slack);
}

/// Check the assembled tangent's action A·v against central differences of the assembled
/// residual along `v` (step 1e-6; tolerance 1e-6 relative to max |A·v|: truncation ~1e-11,
/// rounding ~1e-9 relative).
pub(crate) fn check_tangent_along(model: &Model, x: &[[f64; 3]], load: &Load, p: f64, v: &[f64]) {
    let av = model.tangent_times(x, load, p, v).unwrap();
    let h = 1e-6;
    let shifted = |t: f64| {
        let mut y = x.to_vec();
        model.dofs().apply(&mut y, v, t);
        model.residual(&y, load, p).unwrap()
    };
    let (rp, rm) = (shifted(h), shifted(-h));
    let scale = av.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    for i in 0..model.n_eq() {
        let fd = (rp[i] - rm[i]) / (2.0 * h);
        assert!(
            (fd - av[i]).abs() <= 1e-6 * scale,
            "{load:?} row {i}: {} vs {fd}",
            av[i]
        );
    }
}

/// The assembled tangents against central differences of the assembled residual, along random
/// directions, for pressure, closed-gas and squeeze loading (closed gas includes the
/// never-assembled rank-one term (p/V) g gᵀ; squeeze adds penalty contact with a plate that
/// penetrates some Gauss points).
#[test]
fn assembled_tangents_match_finite_differences_including_gas() {
    check_assembled_tangents(
        capped_tube(1.0, 3.0, 8, 6, Symmetry::Quarter).unwrap(),
        21,
        3,
    );
}

/// The check of [`assembled_tangents_match_finite_differences_including_gas`] on `mesh` (a
/// capped tube), `directions` random directions per loading.
pub(crate) fn check_assembled_tangents(mesh: tubemem_mesh::Mesh, seed: u64, directions: usize) {
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    check_assembled_tangents_of(Model::new(mesh, Box::new(law)).unwrap(), seed, directions);
}

/// [`check_assembled_tangents`] on a built model (ABB 𝒩 = 30).
pub(crate) fn check_assembled_tangents_of(mut model: Model, seed: u64, directions: usize) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut st = model.reference_state();
    model.solve(&mut st, &Load::pressure(0.4)).unwrap();
    // move off equilibrium a little, so that every term is exercised
    for p in st.x.iter_mut() {
        for c in p.iter_mut() {
            *c += rng.random_range(-0.01..0.01);
        }
    }
    // keep the constrained coordinates where they were
    for (i, p) in model.mesh().nodes.iter().enumerate() {
        for k in 0..3 {
            if model.dofs().eq(i, k).is_none() {
                st.x[i][k] = p[k];
            }
        }
    }
    let v_part = model.mesh().volume_at(&st.x);
    let ymax = st.x.iter().map(|p| p[1]).fold(0.0, f64::max);
    let pv = 0.4 * model.multiplicity() * v_part;
    let squeeze = Load::with_contact(Loading::Gas { pv }, Contact::plates(0.7 * ymax, 50.0));
    // the plate does penetrate some Gauss points
    let with = model
        .assemble(&st.x, false, squeeze.contact.as_ref())
        .unwrap();
    let without = model.assemble(&st.x, false, None).unwrap();
    assert!(with.energy > without.energy, "no contact in the test state");
    // the load column of a closed-gas arc-length path, ∂R/∂λ for plates at y = ±λ, against
    // central differences of the residual in λ (step 1e-6; the penalty force is piecewise
    // linear in λ, so the difference is exact but where a Gauss point's gap crosses zero
    // within the step, which the tolerance of the tangent checks covers)
    let moving = crate::contact::MovingPlanes::plates(50.0);
    let lambda = 0.7 * ymax;
    let q = model.plane_rate(&st, &moving, lambda);
    let at = |l: f64| {
        model
            .residual(
                &st.x,
                &Load::with_contact(Loading::Gas { pv }, moving.at(l)),
                0.0,
            )
            .unwrap()
    };
    let h = 1e-6;
    let (rp, rm) = (at(lambda + h), at(lambda - h));
    let scale = q.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    assert!(scale > 0.0, "no plate force in the test state");
    for i in 0..model.n_eq() {
        let fd = (rp[i] - rm[i]) / (2.0 * h);
        assert!(
            (fd - q[i]).abs() <= 1e-6 * scale,
            "∂R/∂λ row {i}: {} vs {fd}",
            q[i]
        );
    }
    for load in [Load::pressure(0.4), Load::new(Loading::Gas { pv }), squeeze] {
        for _ in 0..directions {
            let v: Vec<f64> = (0..model.n_eq())
                .map(|_| rng.random_range(-1.0..1.0))
                .collect();
            check_tangent_along(&model, &st.x, &load, 0.4, &v);
        }
    }
}

/// The assembled tangent of a plugged tube (shared plug equations, disc face volume) against
/// finite differences, as above.
#[test]
fn plugged_tube_tangent_matches_finite_differences() {
    check_plugged_tangents(plugged_tube(1.0, 3.0, 8, 6, Symmetry::None).unwrap(), 22);
}

/// The check of [`plugged_tube_tangent_matches_finite_differences`] on `mesh` (a plugged tube).
pub(crate) fn check_plugged_tangents(mesh: tubemem_mesh::Mesh, seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let mut model = Model::new(mesh, Box::new(law)).unwrap();
    let mut st = model.reference_state();
    model.solve(&mut st, &Load::pressure(0.3)).unwrap();
    let v_total = model.mesh().volume_at(&st.x);
    for load in [
        Load::pressure(0.3),
        Load::new(Loading::Gas { pv: 0.3 * v_total }),
    ] {
        let v: Vec<f64> = (0..model.n_eq())
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        check_tangent_along(&model, &st.x, &load, 0.3, &v);
    }
}

/// Closed gas (Boyle, eq. 60) through Sherman–Morrison: from an inflated sphere, add 10 % gas
/// (p·V constant raised by 10 %); the gas equilibrium must be the volume-controlled equilibrium
/// at the volume it reaches (same state, same pressure, to Newton's tolerance), satisfy
/// p·V = constant, and converge quadratically (few iterations) although the rank-one term is
/// never assembled.
#[test]
fn closed_gas_equilibrium_matches_volume_control() {
    let law = tubemem_material::laws::neo_hookean(1.0).unwrap();
    let mut model = Model::new(sphere(1.0, 6, Symmetry::Eighth).unwrap(), Box::new(law)).unwrap();
    let mut st = model.reference_state();
    model.solve(&mut st, &Load::pressure(0.8)).unwrap();
    let v1 = model.total_volume(&st.x);
    let pv = 1.1 * st.p * v1;
    let mut gas = st.clone();
    let info = model
        .solve(&mut gas, &Load::new(Loading::Gas { pv }))
        .unwrap();
    assert!(
        info.iterations <= 8,
        "gas Newton took {} iterations",
        info.iterations
    );
    let vg = model.total_volume(&gas.x);
    assert!((gas.p * vg - pv).abs() < 1e-9 * pv);
    assert!(vg > v1);
    let mut vol = st.clone();
    model
        .solve(&mut vol, &Load::new(Loading::Volume(vg)))
        .unwrap();
    assert!(
        (vol.p - gas.p).abs() < 1e-8 * gas.p,
        "{} vs {}",
        vol.p,
        gas.p
    );
    let dx = vol
        .x
        .iter()
        .zip(&gas.x)
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    assert!(dx < 1e-8, "positions differ by {dx}");
}

/// Deterministic whatever the thread count: element kernels run in parallel, but every sum is
/// taken in element order, and the factor is computed in a fixed order whatever its threads, so
/// 1 and 2 threads give bitwise-identical results.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let model = Model::new(
        capped_tube(1.0, 6.0, 16, 24, Symmetry::Quarter).unwrap(),
        Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
    )
    .unwrap();
    let solve = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut m = Model::new(
                    model.mesh().clone(),
                    Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
                )
                .unwrap();
                // the factorization on as many threads as the pool
                m.set_factor_threads(threads);
                let mut st = m.reference_state();
                m.solve(&mut st, &Load::pressure(0.3)).unwrap();
                let a = m.assemble(&st.x, true, None).unwrap();
                (st.x, a.f_int, a.k_int)
            })
    };
    let (x1, f1, k1) = solve(1);
    let (x2, f2, k2) = solve(2);
    let bits = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits());
    assert!(x1.iter().zip(&x2).all(|(p, q)| bits(p, q)), "states differ");
    assert!(bits(&f1, &f2) && bits(&k1, &k2), "assembly differs");
}

/// Locking (finite extensibility) is reported as what it is: a stage asked to stretch an ABB
/// membrane with 𝒩 = 3 (locking at I1 = 3𝒩 = 9, λ ≈ 2.9 in equibiaxial stretch) far beyond
/// its limit ends in a stage error whose root cause is the material's locking error, naming the
/// element; the message chain says "locking".
#[test]
fn a_locking_failure_names_the_element_and_says_locking() {
    let law = AnssariBenamBucchi::new(1.0, 3.0).unwrap();
    let mut model = Model::new(sphere(1.0, 4, Symmetry::Eighth).unwrap(), Box::new(law)).unwrap();
    let mut st = model.reference_state();
    let v0 = model.total_volume(&st.x);
    let stage = Stage {
        index: 1,
        from: v0,
        to: 64.0 * v0, // λ = 4 on a sphere: I1 = 2λ² + λ⁻⁴ ≈ 32 ≫ 9
        settings: StepSettings {
            initial_steps: 2,
            max_cuts: 3,
            ..Default::default()
        },
    };
    let err = run_stage(
        &mut model,
        &mut st,
        &stage,
        |v| Load::new(Loading::Volume(v)),
        |_, _, _| Ok::<(), std::convert::Infallible>(()),
    )
    .unwrap_err();
    let e = match err {
        crate::stepping::StageError::Solve(e) => e,
        crate::stepping::StageError::Observer { source, .. } => match source {},
    };
    let (element, cause) = e.material_cause().expect("the root cause is the material");
    assert!(element < model.elements().len());
    assert!(matches!(cause, MaterialError::Locking { .. }), "{cause:?}");
    let text = crate::error_chain(&e);
    assert!(
        text.contains("locking") && text.contains(&format!("element {element}")),
        "{text}"
    );
    assert!(matches!(e, FemError::Stage { stage: 1, .. }), "{e:?}");
}

/// Bad models are refused with a typed error: a node no element uses (it would have no
/// stiffness), and a controlled dof that a constraint fixes.
#[test]
fn bad_models_are_refused() {
    let law = || Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap());
    let mut mesh = sphere(1.0, 2, Symmetry::None).unwrap();
    mesh.nodes.push([5.0, 5.0, 5.0]);
    let n = mesh.nodes.len() - 1;
    assert!(matches!(Model::new(mesh, law()), Err(FemError::UnusedNode { node }) if node == n));
    let mut model = Model::new(sphere(1.0, 2, Symmetry::Eighth).unwrap(), law()).unwrap();
    // a node on the symmetry plane x = 0 cannot be driven in x
    let node = (0..model.mesh().nodes.len())
        .find(|&i| model.dofs().eq(i, 0).is_none())
        .unwrap();
    let mut st = model.reference_state();
    st.p = 0.1;
    let err = model
        .solve(
            &mut st,
            &Load::new(Loading::Node {
                node,
                component: 0,
                target: 1.0,
            }),
        )
        .unwrap_err();
    assert!(matches!(
        err,
        NewtonError::Problem {
            source: FemError::FixedControlDof { .. },
            ..
        }
    ));
}

/// The step limit: a stage that would need more than `max_steps` converged steps stops with a
/// typed error that says how far it got.
#[test]
fn the_step_limit_stops_a_stage() {
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let mut model = Model::new(sphere(1.0, 2, Symmetry::Eighth).unwrap(), Box::new(law)).unwrap();
    let mut st = model.reference_state();
    let stage = Stage {
        index: 1,
        from: 0.0,
        to: 0.5,
        settings: StepSettings {
            initial_steps: 100,
            max_steps: 3,
            ..Default::default()
        },
    };
    let err = run_stage(&mut model, &mut st, &stage, Load::pressure, |_, _, _| {
        Ok::<(), std::convert::Infallible>(())
    })
    .unwrap_err();
    match err {
        crate::stepping::StageError::Solve(FemError::StepLimit {
            steps, fraction, ..
        }) => {
            assert_eq!(steps, 3);
            assert!(fraction > 0.0 && fraction < 1.0);
        }
        e => panic!("{e:?}"),
    }
}

/// The one-pass profile is the per-ring extraction: on an inflated, squeezed quarter tube,
/// `ring_profile` gives, ring by ring, exactly (bitwise) what `ring_state` at `Ring::at` gives
/// (same elements, same summation order), and its contact width at mid-span is the mid-span
/// contact record's; a ring that the plate does not reach has width 0.
#[test]
fn the_one_pass_profile_is_the_per_ring_extraction() {
    use crate::post::{midspan_contact, ring_profile, ring_state, Ring};
    let mut m = Model::new(
        capped_tube(1.0, 6.0, 16, 24, Symmetry::Quarter).unwrap(),
        Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
    )
    .unwrap();
    let mut st = m.reference_state();
    m.solve(&mut st, &Load::pressure(0.5)).unwrap();
    let ymax = st.x.iter().map(|p| p[1]).fold(0.0, f64::max);
    // a plate just below the top of the inflated tube: only the cylinder touches it
    let contact = Contact::plates(0.98 * ymax, 200.0);
    m.solve(
        &mut st,
        &Load::with_contact(Loading::Pressure(0.5), contact.clone()),
    )
    .unwrap();
    let rings = ring_profile(&m, &st, Some(&contact)).unwrap();
    assert!(rings.len() >= 13, "{}", rings.len());
    for r in &rings {
        let per_ring = ring_state(&m, &st, &Ring::at(&m, r.z_ref)).unwrap();
        assert_eq!(r.values, per_ring, "ring at Z = {}", r.z_ref);
    }
    let mid = rings.iter().find(|r| r.z_ref == 0.0).unwrap();
    let mc = midspan_contact(&m, &st, &contact).unwrap();
    assert_eq!(mid.contact_width, mc.chi_geometric);
    assert_eq!(mid.contact_force, mc.force);
    assert!(mid.contact_width > 0.0 && mid.contact_force > 0.0);
    // the highest ring (a cap equator) is below the plate: no contact there
    let top = rings.last().unwrap();
    assert!(
        top.z_ref > 2.9 && top.contact_width == 0.0 && top.contact_force == 0.0,
        "{top:?}"
    );
}

/// Arc-length continuation through the pressure maximum of an inflated neo-Hookean sphere
/// (eighth model): Rivlin's closed form ϖ = 2(λ⁻¹ − λ⁻⁷) has its maximum 2(7^(−1/6) − 7^(−7/6))
/// at λ = 7^(1/6). Pressure control cannot pass it; the continuation goes on to λ = 1.8 (the
/// target, on the volume) and locates the maximum to |Δs| ≤ 1e-8. The located maximum converges
/// to Rivlin's under refinement at the element's order 2 (facet error O(h²)): the errors at m = 4
/// and 8 elements per cube-face edge fall by a factor within [3, 5] (2² = 4 ± 25 %), and every
/// converged point on either side of the maximum lies on the discrete path (p·V consistent with
/// the located maximum: no converged pressure above it).
#[test]
fn arc_length_passes_and_locates_the_pressure_maximum_of_a_sphere() {
    let errors = sphere_limit_errors(tubemem_mesh::ElementKind::Quad4, &[4, 8]);
    let ratio = errors[0] / errors[1];
    assert!(
        (3.0..=5.0).contains(&ratio),
        "limit-pressure errors {errors:?}, ratio {ratio}"
    );
}

/// The relative errors of the located pressure maximum of the eighth sphere against Rivlin's,
/// for elements of `kind` at `ms` elements per cube-face edge (the checks of the test above
/// made at every m).
pub(crate) fn sphere_limit_errors(kind: tubemem_mesh::ElementKind, ms: &[usize]) -> Vec<f64> {
    use crate::continuation::{follow, ArcEvent, ArcSettings, CriticalKind, MembranePath, Target};
    let lc = 7f64.powf(1.0 / 6.0);
    let pmax = 2.0 * (1.0 / lc - lc.powi(-7));
    let mut errors = Vec::new();
    for &m in ms {
        let mesh = tubemem_mesh::tube::sphere_of(kind, 1.0, m, Symmetry::Eighth).unwrap();
        let law = tubemem_material::laws::neo_hookean(1.0).unwrap();
        let mut model = Model::new(mesh.clone(), Box::new(law)).unwrap();
        let mut st = model.reference_state();
        model.solve(&mut st, &Load::pressure(0.2)).unwrap();
        // the volume ratio of the discrete sphere (the monitored target)
        let v0 = mesh.volume();
        let volume = |s: &crate::model::State| mesh.volume_at(&s.x) / v0;
        let mut path =
            MembranePath::new(&mut model, crate::continuation::ArcLoading::Pressure(None));
        let target = Target {
            name: "volume ratio",
            monitor: &volume,
            value: 1.8f64.powi(3),
        };
        let mut pressures = Vec::new();
        let mut stretch_at_target = 0.0;
        let crit = follow(&mut path, st, &target, &ArcSettings::default(), |_, e| {
            if let ArcEvent::Step(s) = e {
                pressures.push(s.load);
                if s.at_target {
                    stretch_at_target = s.monitor.cbrt();
                }
            }
            Ok::<(), String>(())
        })
        .unwrap();
        assert!(
            // the volume-ratio target to `target_rtol` 1e-10, a third of that in the stretch
            (stretch_at_target - 1.8).abs() < 1e-10,
            "{stretch_at_target}"
        );
        let maxima: Vec<_> = crit
            .iter()
            .filter(|c| c.kind == CriticalKind::LimitMax)
            .collect();
        assert_eq!(maxima.len(), 1, "{crit:?}");
        let c = maxima[0];
        assert!(c.bracket <= 1e-8);
        // every point is an equilibrium to Newton's relative residual 1e-9: none lies above the
        // located maximum by more than a few of those (5e-9 relative)
        assert!(pressures.iter().all(|&p| p <= c.load * (1.0 + 5e-9)));
        // the sphere's discrete pressure has one negative pivot past the maximum (the
        // inflation mode), none before
        assert_eq!((c.negative_before, c.negative_after), (0, 1));
        errors.push((c.load - pmax).abs() / pmax);
        eprintln!(
            "{kind:?} m = {m}: located ϖmax = {:.10} (Rivlin {pmax:.10}), λ = {:.6}, {} steps, bracket {:.1e}",
            c.load,
            (mesh.volume_at(&c.state.x) / v0).cbrt(),
            pressures.len(),
            c.bracket
        );
    }
    errors
}

/// A squeeze continued by arc length in (x, plate position) with the gas closed reaches the
/// same equilibrium as load steps in the plate position: on a quarter tube inflated to ϖ = 0.4
/// and squeezed to 0.8 of its half-height, the two end states agree to the Newton tolerance,
/// and the located target is the plates' position to 1e-10.
#[test]
fn a_closed_gas_squeeze_by_arc_length_is_the_load_stepped_squeeze() {
    use crate::contact::MovingPlanes;
    use crate::continuation::{follow, ArcEvent, ArcLoading, ArcSettings, MembranePath, Target};
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let mut model = Model::new(
        capped_tube(1.0, 3.0, 16, 12, Symmetry::Quarter).unwrap(),
        Box::new(law),
    )
    .unwrap();
    let mut st = model.reference_state();
    model.solve(&mut st, &Load::pressure(0.4)).unwrap();
    let pv = st.p * model.total_volume(&st.x);
    let h0 = st.x.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
    let target = 0.8 * h0;
    let planes = MovingPlanes::plates(0.4 * 1.2 / 1e-3);
    // load steps in h
    let mut stepped = st.clone();
    for k in 1..=8 {
        let h = h0 + (target - h0) * k as f64 / 8.0;
        model
            .solve(
                &mut stepped,
                &Load::with_contact(Loading::Gas { pv }, planes.at(h)),
            )
            .unwrap();
    }
    // arc length
    let mut start = st.clone();
    start.planes = h0;
    let monitor = |s: &crate::model::State| s.planes;
    let goal = Target {
        name: "plates",
        monitor: &monitor,
        value: target,
    };
    let mut path = MembranePath::new(
        &mut model,
        ArcLoading::ClosedGas {
            pv,
            planes: planes.clone(),
        },
    );
    let mut end = None;
    let mut steps = 0;
    follow(&mut path, start, &goal, &ArcSettings::default(), |_, e| {
        if let ArcEvent::Step(s) = e {
            steps += 1;
            if s.at_target {
                end = Some(s.state.clone());
            }
        }
        Ok::<(), String>(())
    })
    .unwrap();
    let end = end.unwrap();
    assert!((end.planes - target).abs() <= 1e-10 * target);
    let dx = end
        .x
        .iter()
        .zip(&stepped.x)
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    eprintln!(
        "{steps} arc steps; ϖ {} vs {}; positions differ by {dx:.2e}",
        end.p, stepped.p
    );
    // both solves stop at Newton's relative residual 1e-9; through the stiffness that leaves
    // differences of that order (measured 2026-11-30: 1.2e-10 in ϖ, 3.3e-11 in positions)
    assert!((end.p - stepped.p).abs() <= 1e-8 * stepped.p);
    assert!(dx <= 1e-8);
}

/// Moving a bulge is refused with the reason: on a symmetry-reduced tube (no rings to shift
/// whole), on a tube without a bulge, and by a move longer than the uniform part ahead of it.
/// On a made-up bulge (a radial bump of the reference rings 4 to 8 of 25) a move of 2 rows
/// puts the bump on rings 6 to 10 and keeps the caps where they were.
#[test]
fn a_bulge_is_moved_by_whole_rows_or_refused_with_the_reason() {
    use crate::slide::{translate_bulge, Rings};
    let law = || Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap());
    let eighth = Model::new(
        capped_tube(1.0, 6.0, 8, 24, Symmetry::Eighth).unwrap(),
        law(),
    )
    .unwrap();
    let e = Rings::new(&eighth).unwrap_err();
    assert!(e.to_string().contains("whole capped tube"), "{e}");
    let model = Model::new(capped_tube(1.0, 6.0, 8, 24, Symmetry::None).unwrap(), law()).unwrap();
    let rings = Rings::new(&model).unwrap();
    assert_eq!(rings.rings.len(), 25);
    let flat = model.reference_state();
    let e = translate_bulge(&model, &rings, &flat, 1).unwrap_err();
    assert!(e.to_string().contains("there is none"), "{e}");
    let mut bumped = flat.clone();
    for ring in &rings.rings[4..=8] {
        for &i in ring {
            bumped.x[i][0] *= 2.0;
            bumped.x[i][1] *= 2.0;
        }
    }
    let e = translate_bulge(&model, &rings, &bumped, 20).unwrap_err();
    assert!(e.to_string().contains("shorter than"), "{e}");
    let moved = translate_bulge(&model, &rings, &bumped, 2).unwrap();
    let wide: Vec<usize> = rings
        .radii(&moved.state)
        .iter()
        .enumerate()
        .filter(|(_, r)| **r > 1.5)
        .map(|(l, _)| l)
        .collect();
    assert_eq!(wide, (6..=10).collect::<Vec<_>>());
    // its fronts halfway between the rings 5 | 6 and 10 | 11 (ring l at Z = −3 + l/4)
    let fronts = rings.fronts(model.mesh(), &moved.state);
    assert_eq!(fronts.len(), 2);
    assert!((fronts[0] + 1.625).abs() < 1e-12 && (fronts[1] + 0.375).abs() < 1e-12);
    assert!(rings.fronts(model.mesh(), &flat).is_empty());
    // the caps (nodes off the cylinder) kept their positions up to the body's z-translation
    // that keeps the pinned node's z: the uniform part here is the reference (λz = 1), so none
    let cyl: std::collections::HashSet<usize> = rings.rings.iter().flatten().copied().collect();
    for i in (0..flat.x.len()).filter(|i| !cyl.contains(i)) {
        for k in 0..3 {
            assert!((moved.state.x[i][k] - flat.x[i][k]).abs() < 1e-12);
        }
    }
}

/// Nodal contact points ([`crate::contact::ContactPoints::Nodal`]): residual and tangent
/// against central differences of the energy and residual, on the 4- and 9-node elements, with
/// the penalty alone and augmented (random multipliers and local penalties at the nodes).
#[test]
fn nodal_contact_tangent_matches_finite_differences() {
    use crate::contact::ContactPoints;
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    let mut penetrating = 0;
    for k in 0..20 {
        let (re, x, contact) = element_on_tilted_plane(&mut rng);
        let contact = contact.with_points(ContactPoints::Nodal);
        let contact = if k % 2 == 0 {
            contact
        } else {
            contact.with_enforcement(Enforcement::augmented())
        };
        let history: Vec<f64> = if k % 2 == 0 {
            vec![]
        } else {
            (0..4)
                .flat_map(|a| {
                    let gap = contact.planes[0].gap(x[a].into());
                    let kappa = 300.0 * rng.random_range(1.0..20.0);
                    let s = rng.random_range(-0.05..0.3);
                    [(kappa * (gap + s)).max(0.0), kappa, f64::NAN]
                })
                .collect()
        };
        let eval = |x: &[Vec3; 4]| contact_eval::<4, 12>(&contact, &re, x, &history);
        let (_, r, _) = eval(&x);
        penetrating += usize::from(r.iter().any(|v| *v != 0.0));
        check_element_fd(&x, 1e-7, "nodal contact", eval);
    }
    assert!(penetrating >= 10, "the planes push at most of the states");
}

/// The nodal weights are ∫N_a dA0: on a flat parallelogram each 4-node weight is a quarter of
/// the area, and on a flat 9-node rectangle they are Simpson's, 1/36, 4/36 and 16/36 of the
/// area at the corners, the mid-sides and the centre; on any element they sum to its area (the
/// Gauss rule's). A flat membrane lying δ inside a plane then carries the exact force κδA at
/// nodal points too, along n only. Tolerances 1e-14 and 1e-12 relative: rounding only (the
/// weights are exact for these affine elements).
#[test]
fn nodal_weights_are_the_shape_function_integrals() {
    use crate::contact::ContactPoints;
    // a parallelogram in z = 0
    let x4 = [
        [0.0, 0.0, 0.0],
        [2.0, 0.5, 0.0],
        [2.6, 1.7, 0.0],
        [0.6, 1.2, 0.0],
    ];
    let re = RefElement::new(0, [0, 1, 2, 3], &x4).unwrap();
    let area = tubemem_mesh::quad_area(&x4);
    for p in re.nodal.iter() {
        assert!((p.w - 0.25 * area).abs() < 1e-14 * area);
    }
    // a 3 × 2 rectangle as a 9-node element (node order: corners, mid-sides, centre)
    let (a, b) = (3.0, 2.0);
    let xi = [
        (-1.0, -1.0),
        (1.0, -1.0),
        (1.0, 1.0),
        (-1.0, 1.0),
        (0.0, -1.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (-1.0, 0.0),
        (0.0, 0.0),
    ];
    let x9 = xi.map(|(u, v)| [0.5 * a * u, 0.5 * b * v, 0.0]);
    let re9 = RefElement::new(0, [0, 1, 2, 3, 4, 5, 6, 7, 8], &x9).unwrap();
    let expect = [1.0, 1.0, 1.0, 1.0, 4.0, 4.0, 4.0, 4.0, 16.0].map(|s| s / 36.0 * a * b);
    for (p, e) in re9.nodal.iter().zip(expect) {
        assert!((p.w - e).abs() < 1e-14 * a * b, "{} vs {e}", p.w);
    }
    for p in re9.nodal.iter() {
        assert!(p.n.iter().filter(|v| **v == 1.0).count() == 1);
        assert!(p.n.iter().filter(|v| **v == 0.0).count() == 8);
    }
    // pressed δ into the plane z = 0 (normal +e_z, the membrane on z ≥ 0)
    let (kappa, delta) = (250.0, 2e-3);
    let contact = Contact {
        planes: vec![Plane {
            normal: [0.0, 0.0, 1.0],
            offset: delta,
        }],
        penalty: kappa,
        enforcement: Enforcement::Penalty,
        points: ContactPoints::Nodal,
    };
    let mut r = SVector::<f64, 27>::zeros();
    contact.kernel(&re9, &x9.map(Vec3::from), &[], &mut r, None);
    let fz: f64 = -(0..9).map(|a| r[3 * a + 2]).sum::<f64>();
    assert!((fz - kappa * delta * a * b).abs() < 1e-12 * kappa * delta * a * b);
    assert!((0..9).all(|a| r[3 * a] == 0.0 && r[3 * a + 1] == 0.0));
}

/// Soft rigid-mode pins (`Model::soften_rigid_pins`): on a quarter tube the axis node's x pin
/// (the cap's pole) becomes an equation held by a spring, the y pin and the symmetry planes stay
/// fixed; with a spring of stiffness 10 (so that central differences see it) the assembled
/// energy, residual and tangent, gas and plates included, pass the same finite-difference check
/// as without.
#[test]
fn soft_rigid_pins_are_springs_on_the_axis_nodes() {
    let mesh = capped_tube(1.0, 3.0, 8, 6, Symmetry::Quarter).unwrap();
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let pinned = Model::new(mesh.clone(), Box::new(law.clone())).unwrap();
    let mut soft = Model::new(mesh.clone(), Box::new(law)).unwrap();
    soft.soften_rigid_pins([true, false], 10.0).unwrap();
    let axis: Vec<usize> = (0..mesh.nodes.len())
        .filter(|&i| mesh.nodes[i][0] == 0.0 && mesh.nodes[i][1] == 0.0)
        .collect();
    assert_eq!(
        axis.len(),
        1,
        "the quarter tube's axis node: the pole of its cap"
    );
    let pins = soft.dofs().soft_pins().to_vec();
    assert_eq!(pins.len(), 1);
    assert_eq!((pins[0].node, pins[0].component), (axis[0], 0));
    assert!(pinned.dofs().eq(axis[0], 0).is_none() && soft.dofs().eq(axis[0], 1).is_none());
    assert_eq!(soft.n_eq(), pinned.n_eq() + 1);
    check_assembled_tangents_of(soft, 22, 3);
}
