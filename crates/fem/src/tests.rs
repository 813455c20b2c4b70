//! Kernel tests: every tangent against central finite differences (step 1e-6; truncation
//! ≈ 1e-12 and rounding ≈ 1e-10 relative to the entries, so 1e-6 relative + 1e-7 absolute),
//! and the patch test against the law's resultants.

use crate::element::{membrane_kernel, point_state, RefElement};
use crate::volume::volume_kernel;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tubemem_material::laws::{AnssariBenamBucchi, MooneyRivlin};
use tubemem_material::MembraneLaw;

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

fn deform(x: &[[f64; 3]; 4], rng: &mut ChaCha8Rng) -> [[f64; 3]; 4] {
    // a stretch with some shear and out-of-plane motion
    x.map(|p| {
        [
            1.3 * p[0] + 0.1 * p[1] + rng.random_range(-0.05..0.05),
            0.05 * p[0] + 1.15 * p[1] + rng.random_range(-0.05..0.05),
            0.2 * p[0] - 0.1 * p[1] + p[2] + rng.random_range(-0.05..0.05),
        ]
    })
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + 1e-7 * scale
}

#[test]
fn membrane_tangents_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let laws: Vec<Box<dyn MembraneLaw>> = vec![
        Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
        Box::new(MooneyRivlin::new(1.0, 0.2).unwrap()),
    ];
    let h = 1e-6;
    for law in &laws {
        for _ in 0..20 {
            let x0 = random_quad(&mut rng);
            let re = RefElement::new(0, [0, 1, 2, 3], &x0).unwrap();
            let x = deform(&x0, &mut rng);
            let mut r = [0.0; 12];
            let mut k = [0.0; 144];
            membrane_kernel(law.as_ref(), &re, &x, &mut r, Some(&mut k)).unwrap();
            let scale = k.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for j in 0..12 {
                let (mut xp, mut xm) = (x, x);
                xp[j / 3][j % 3] += h;
                xm[j / 3][j % 3] -= h;
                let (mut rp, mut rm) = ([0.0; 12], [0.0; 12]);
                let ep = membrane_kernel(law.as_ref(), &re, &xp, &mut rp, None).unwrap();
                let em = membrane_kernel(law.as_ref(), &re, &xm, &mut rm, None).unwrap();
                assert!(
                    close(r[j], (ep - em) / (2.0 * h), scale),
                    "{} r[{j}]",
                    law.name()
                );
                for i in 0..12 {
                    let fd = (rp[i] - rm[i]) / (2.0 * h);
                    assert!(
                        close(k[i * 12 + j], fd, scale),
                        "{} K[{i}][{j}] = {} vs {fd}",
                        law.name(),
                        k[i * 12 + j]
                    );
                }
            }
            for i in 0..12 {
                for j in 0..12 {
                    assert!((k[i * 12 + j] - k[j * 12 + i]).abs() <= 1e-12 * scale);
                }
            }
        }
    }
}

#[test]
fn volume_gradient_and_hessian_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let h = 1e-6;
    for _ in 0..50 {
        let x = deform(&random_quad(&mut rng), &mut rng);
        let mut g = [0.0; 12];
        let mut hs = [0.0; 144];
        volume_kernel(&x, &mut g, Some(&mut hs));
        for j in 0..12 {
            let (mut xp, mut xm) = (x, x);
            xp[j / 3][j % 3] += h;
            xm[j / 3][j % 3] -= h;
            let (mut gp, mut gm) = ([0.0; 12], [0.0; 12]);
            let vp = volume_kernel(&xp, &mut gp, None);
            let vm = volume_kernel(&xm, &mut gm, None);
            assert!(close(g[j], (vp - vm) / (2.0 * h), 1.0), "dV/dx[{j}]");
            for i in 0..12 {
                assert!(
                    close(hs[i * 12 + j], (gp[i] - gm[i]) / (2.0 * h), 1.0),
                    "d2V[{i}][{j}]"
                );
                assert!((hs[i * 12 + j] - hs[j * 12 + i]).abs() < 1e-14);
            }
        }
    }
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
            [x, cr * y, sr * y]
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

mod solver {
    use crate::model::{run_stage, Control, Model, Stage};
    use tubemem_material::laws::{neo_hookean, MooneyRivlin};
    use tubemem_material::MembraneLaw;
    use tubemem_mesh::{tube::sphere, Symmetry};

    /// Rivlin: a membrane sphere of radius R under pressure stays spherical, r = λR, with
    /// N = N1(λ, λ) and p r = 2N, i.e. ϖ = 2 N1(λ, λ)/λ.
    fn rivlin(law: &dyn MembraneLaw, l: f64) -> f64 {
        2.0 * law.resultants(l, l).unwrap()[0] / l
    }

    pub fn sphere_curve(
        law: Box<dyn MembraneLaw>,
        m: usize,
        lmax: f64,
        steps: usize,
    ) -> Vec<(f64, f64, usize)> {
        let mesh = sphere(1.0, m, Symmetry::Eighth).unwrap();
        let mut model = Model::new(mesh, law).unwrap();
        let mut st = model.reference_state();
        let v0 = model.multiplicity() * model.mesh.volume();
        let mut out = vec![];
        let stage = Stage {
            index: 0,
            from: v0,
            to: v0 * lmax.powi(3),
            initial_steps: steps,
            max_cuts: 10,
        };
        run_stage(
            &mut model,
            &mut st,
            &stage,
            Control::Volume,
            |_, _, v, s, info| {
                out.push(((v / v0).cbrt(), s.p, info.negative_pivots));
                Ok(())
            },
        )
        .unwrap();
        out
    }

    /// Source: Rivlin's sphere (above). The FE error is the discretization of the sphere by
    /// bilinear quads: measured here, by refinement, as a λ-independent relative offset of
    /// 3.4e-2 (m = 4), 8.55e-3 (m = 8), 2.1e-3 (m = 16) per cube-face edge — second order. The
    /// test holds m = 8 to 1e-2 over the whole curve (through the maximum at λ = 7^(1/6) for
    /// neo-Hookean) and checks the observed order between m = 4 and 8 is 2 ± 0.1.
    #[test]
    fn sphere_inflation_matches_rivlin_through_the_pressure_maximum() {
        let cases: Vec<(Box<dyn MembraneLaw>, Box<dyn MembraneLaw>)> = vec![
            (
                Box::new(neo_hookean(1.0).unwrap()),
                Box::new(neo_hookean(1.0).unwrap()),
            ),
            (
                Box::new(MooneyRivlin::new(1.0, 0.1).unwrap()),
                Box::new(MooneyRivlin::new(1.0, 0.1).unwrap()),
            ),
        ];
        for (law, exact) in cases {
            let name = law.name();
            let worst = |c: &[(f64, f64, usize)]| {
                c.iter()
                    .map(|&(l, p, _)| {
                        (p - rivlin(exact.as_ref(), l)).abs() / rivlin(exact.as_ref(), l)
                    })
                    .fold(0.0, f64::max)
            };
            let c8 = sphere_curve(law, 8, 2.0, 20);
            let e8 = worst(&c8);
            assert!(e8 < 1e-2, "{name}: {e8}");
            // the curve passes the pressure maximum (λ = 7^(1/6) ≈ 1.383 for neo-Hookean)
            assert!(c8.first().unwrap().0 < 1.2 && c8.last().unwrap().0 > 1.99);
            let peak = c8.iter().map(|c| c.1).fold(0.0, f64::max);
            assert!(
                peak > c8.last().unwrap().1 * 1.05,
                "{name}: no pressure maximum crossed"
            );
            // volume control keeps the sphere stable: no negative eigenvalue on V = const
            assert!(c8.iter().all(|c| c.2 == 0), "{name}");
            let fresh: Box<dyn MembraneLaw> = if name == "neo-Hookean" {
                Box::new(neo_hookean(1.0).unwrap())
            } else {
                Box::new(MooneyRivlin::new(1.0, 0.1).unwrap())
            };
            let e4 = worst(&sphere_curve(fresh, 4, 2.0, 20));
            let order = (e4 / e8).log2();
            assert!(
                (order - 2.0).abs() < 0.1,
                "{name}: observed order {order} (e4 {e4}, e8 {e8})"
            );
        }
    }
}

#[test]
#[ignore]
fn sphere_refinement_table() {
    for m in [4, 8, 16] {
        let c = solver::sphere_curve(
            Box::new(tubemem_material::laws::neo_hookean(1.0).unwrap()),
            m,
            2.0,
            10,
        );
        let e = c
            .iter()
            .map(|&(l, p, _)| {
                let ex = 2.0 * (1.0 - l.powi(-6)) / l;
                (p - ex).abs() / ex
            })
            .fold(0.0, f64::max);
        eprintln!("m = {m}: worst relative error {e:.4e}");
    }
}

pub(crate) mod tube {
    use crate::model::{nearest_node, run_stage, Control, Model, Stage};
    use crate::post::{midspan, MidSpan};
    use tubemem_material::laws::AnssariBenamBucchi;
    use tubemem_mesh::{tube::capped_tube, Symmetry};

    /// Inflate a capped tube (R = 1, cylinder length `l`) to mid-span stretch `target` by
    /// controlling the radial coordinate of the mid-span node (R, 0, 0).
    pub fn inflate(
        l: f64,
        around: usize,
        along: usize,
        sym: Symmetry,
        target: f64,
    ) -> (Model, MidSpan, usize) {
        inflate_mesh(capped_tube(1.0, l, around, along, sym).unwrap(), target)
    }

    /// The same for any tube mesh.
    pub fn inflate_mesh(mesh: tubemem_mesh::Mesh, target: f64) -> (Model, MidSpan, usize) {
        let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
        let mut model = Model::new(mesh, Box::new(law)).unwrap();
        let node = nearest_node(&model.mesh, [1.0, 0.0, 0.0]);
        let mut st = model.reference_state();
        let mut steps = 0;
        let stage = Stage {
            index: 0,
            from: 1.0,
            to: target,
            initial_steps: 6,
            max_cuts: 12,
        };
        run_stage(
            &mut model,
            &mut st,
            &stage,
            |v| Control::Node {
                node,
                component: 0,
                target: v,
            },
            |_, _, _, _, _| {
                steps += 1;
                Ok(())
            },
        )
        .unwrap();
        let ms = midspan(&model, &st).unwrap();
        (model, ms, steps)
    }
}

/// Capped tube, ABB 𝒩 = 30, L/R = 20, inflated to λs* = 1.3 (eighth model).
///
/// Source: the GPS closed form, eq. (66). Far from the caps the discrete tube is a uniform prism
/// with an n-gon cross-section (n = elements around). For that prism the hoop and axial
/// equilibria give N_s = p·r·cos(π/n) and N_z = N_s/2 exactly (the pressure acts on the chords and
/// on the polygon's area), so λz, N_s, N_z equal GPS while ϖ is high by 1/cos(π/n) − 1: the O(h²)
/// discretization error of the pressure. Measured: ϖ error 4.84e-3 (n = 32) and 1.21e-3 (n = 64),
/// λz, N_s, N_z within 6e-8 at both, N_sz ~ 1e-16. Tolerances: 0.2 % for ϖ at n = 64 (issue #3);
/// 1e-6 for λz, N_s, N_z and for ϖ·cos(π/n) (50× the measured level, far below any modelling
/// error such as a wrong cap force or λz, which would show at 1e-2); order 2 ± 0.05.
#[test]
fn capped_tube_midspan_matches_gps_at_ls_1_3() {
    use tubemem_gps::{inflate, Hypothesis};
    use tubemem_mesh::Symmetry;
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let mut errs = vec![];
    for (around, along) in [(32, 80), (64, 160)] {
        let (_, ms, _) = tube::inflate(20.0, around, along, Symmetry::Eighth, 1.3);
        let g = inflate(&law, Hypothesis::Gps, ms.lambda_s).unwrap();
        assert!((ms.lambda_s - 1.3).abs() < 1e-9);
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        assert!(
            rel(ms.lambda_z, g.lambda_z) < 1e-6,
            "λz {} vs {}",
            ms.lambda_z,
            g.lambda_z
        );
        assert!(rel(ms.n_s, g.n_s) < 1e-6 && rel(ms.n_z, g.n_z) < 1e-6);
        assert!(ms.n_sz.abs() < 1e-10);
        let apothem = (std::f64::consts::PI / around as f64).cos();
        assert!(
            rel(ms.w * apothem, g.w) < 1e-6,
            "ϖ cos(π/n) {} vs {}",
            ms.w * apothem,
            g.w
        );
        errs.push(rel(ms.w, g.w));
        // plane strain misses λz entirely: 5.4 % here
        let p = inflate(&law, Hypothesis::Ps, ms.lambda_s).unwrap();
        assert!(rel(p.lambda_z, ms.lambda_z) > 0.05);
    }
    assert!(
        errs[1] < 2e-3,
        "issue #3: within 0.2 % at 64 around ({})",
        errs[1]
    );
    let order = (errs[0] / errs[1]).log2();
    assert!((order - 2.0).abs() < 0.05, "order {order}");
}

/// The full tube (no symmetry planes, rigid modes removed by the pins of `Model::new`) gives the
/// eighth model's answer: the pins carry no load. Tolerance: Newton's 1e-9 relative residual.
#[test]
fn full_tube_agrees_with_eighth_model() {
    use tubemem_mesh::Symmetry;
    let (_, a, _) = tube::inflate(6.0, 16, 24, Symmetry::Eighth, 1.2);
    let (mf, b, _) = tube::inflate(6.0, 16, 24, Symmetry::None, 1.2);
    assert_eq!(mf.mesh.symmetry, Symmetry::None);
    for (x, y) in [
        (a.w, b.w),
        (a.lambda_s, b.lambda_s),
        (a.lambda_z, b.lambda_z),
        (a.n_s, b.n_s),
        (a.n_z, b.n_z),
        (a.volume, b.volume),
    ] {
        assert!((x - y).abs() < 1e-7 * x.abs().max(1.0), "{x} vs {y}");
    }
}

/// Closed gas (Boyle, eq. 60) through Sherman–Morrison: from an inflated sphere, add 10 % gas
/// (p·V constant raised by 10 %); the gas equilibrium must be the volume-controlled equilibrium
/// at the volume it reaches (same state, same pressure, to Newton's tolerance), satisfy
/// p·V = constant, and converge quadratically (few iterations) although the rank-one term is
/// never assembled.
#[test]
fn closed_gas_equilibrium_matches_volume_control() {
    use crate::model::{Control, Model};
    use tubemem_mesh::{tube::sphere, Symmetry};
    let law = tubemem_material::laws::neo_hookean(1.0).unwrap();
    let mut model = Model::new(sphere(1.0, 6, Symmetry::Eighth).unwrap(), Box::new(law)).unwrap();
    let mut st = model.reference_state();
    model.solve(&mut st, Control::Pressure(0.8)).unwrap();
    let v1 = model.multiplicity() * model.mesh.volume_at(&st.x);
    let pv = 1.1 * st.p * v1;
    let mut gas = st.clone();
    let info = model.solve(&mut gas, Control::Gas { pv }).unwrap();
    assert!(
        info.iterations <= 8,
        "gas Newton took {} iterations",
        info.iterations
    );
    let vg = model.multiplicity() * model.mesh.volume_at(&gas.x);
    assert!((gas.p * vg - pv).abs() < 1e-9 * pv);
    assert!(vg > v1);
    let mut vol = st.clone();
    model.solve(&mut vol, Control::Volume(vg)).unwrap();
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

/// Refinement table for the README (a documented command, not a check):
/// `cargo test --release -p tubemem-fem tube_refinement_table -- --ignored --nocapture`
#[test]
#[ignore]
fn tube_refinement_table() {
    use tubemem_gps::{inflate, Hypothesis};
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    for (around, along) in [(32, 80), (64, 160), (96, 240), (128, 320)] {
        let t = std::time::Instant::now();
        let (model, ms, steps) =
            tube::inflate(20.0, around, along, tubemem_mesh::Symmetry::Eighth, 1.3);
        let g = inflate(&law, Hypothesis::Gps, ms.lambda_s).unwrap();
        let p = inflate(&law, Hypothesis::Ps, ms.lambda_s).unwrap();
        eprintln!(
            "around {around} along {along}: {} dofs, {steps} steps, {:?}",
            model.n_eq,
            t.elapsed()
        );
        eprintln!(
            "  FE : w {:.6} ls {:.6} lz {:.6} ns {:.6} nz {:.6} nsz {:.2e}",
            ms.w, ms.lambda_s, ms.lambda_z, ms.n_s, ms.n_z, ms.n_sz
        );
        eprintln!(
            "  GPS: w {:.6} ls {:.6} lz {:.6} ns {:.6} nz {:.6}",
            g.w, g.lambda_s, g.lambda_z, g.n_s, g.n_z
        );
        eprintln!("  PS : w {:.6}", p.w);
        eprintln!(
            "  rel: w {:.2e} lz {:.2e} ns {:.2e} nz {:.2e}",
            ms.w / g.w - 1.0,
            ms.lambda_z / g.lambda_z - 1.0,
            ms.n_s / g.n_s - 1.0,
            ms.n_z / g.n_z - 1.0
        );
    }
}

/// Deterministic whatever the thread count: element kernels run in parallel, but every sum is
/// taken in element order, so 1 and 2 threads give bitwise-identical results.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    use tubemem_mesh::Symmetry;
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| tube::inflate(6.0, 16, 24, Symmetry::Quarter, 1.25))
    };
    let (m1, a, _) = run(1);
    let (_, b, _) = run(2);
    assert_eq!(a, b, "mid-span values differ between 1 and 2 threads");
    let st = m1.reference_state();
    let x1 = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| m1.assemble(&st.x, false).unwrap().f_int);
    let x2 = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| m1.assemble(&st.x, false).unwrap().f_int);
    assert!(x1.iter().zip(&x2).all(|(p, q)| p.to_bits() == q.to_bits()));
}

/// The assembled tangents against central differences of the assembled residual, along random
/// directions, for pressure, closed-gas and squeeze loading (closed gas includes the
/// never-assembled rank-one term (p/V) g gᵀ; squeeze adds penalty contact with a plate that
/// penetrates some Gauss points). Step 1e-6; tolerance 1e-6 relative to |A v| (FD truncation ~1e-11,
/// rounding ~1e-9 relative here).
#[test]
fn assembled_tangents_match_finite_differences_including_gas() {
    use crate::model::{Control, Model};
    use rand::{Rng, SeedableRng};
    use tubemem_mesh::{tube::capped_tube, Symmetry};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let mut model = Model::new(
        capped_tube(1.0, 3.0, 8, 6, Symmetry::Quarter).unwrap(),
        Box::new(law),
    )
    .unwrap();
    let mut st = model.reference_state();
    model.solve(&mut st, Control::Pressure(0.4)).unwrap();
    // move off equilibrium a little, so that every term is exercised
    for p in st.x.iter_mut() {
        for c in p.iter_mut() {
            *c += rng.random_range(-0.01..0.01);
        }
    }
    // keep the symmetry-plane coordinates on their planes
    for (i, p) in model.mesh.nodes.iter().enumerate() {
        for k in 0..3 {
            if model.eq[3 * i + k].is_none() {
                st.x[i][k] = p[k];
            }
        }
    }
    let v_part = model.mesh.volume_at(&st.x);
    let ymax = st.x.iter().map(|p| p[1]).fold(0.0, f64::max);
    model.penalty = 50.0;
    let squeeze = Control::Squeeze {
        pv: 0.4 * model.multiplicity() * v_part,
        half_gap: 0.7 * ymax,
    };
    // the plate does penetrate some Gauss points
    let with = model
        .assemble_with(&st.x, false, &squeeze.plates())
        .unwrap();
    let without = model.assemble(&st.x, false).unwrap();
    assert!(with.energy > without.energy, "no contact in the test state");
    for control in [
        Control::Pressure(0.4),
        Control::Gas {
            pv: 0.4 * model.multiplicity() * v_part,
        },
        squeeze,
    ] {
        for _ in 0..3 {
            let v: Vec<f64> = (0..model.n_eq)
                .map(|_| rng.random_range(-1.0..1.0))
                .collect();
            check_tangent_along(&model, &st.x, control, 0.4, &v);
        }
    }
}

/// Rigid plugs instead of caps (an open cylinder tied to two rigid discs that translate
/// axially and carry p·A): far from the plugs the tube is the same n-gon prism, so the
/// mid-span matches GPS exactly as for the capped tube (same tolerances and reasons as
/// `capped_tube_midspan_matches_gps_at_ls_1_3`). The ring at the plug keeps radius R, so the
/// boundary layer is longer than with caps.
#[test]
fn plugged_tube_midspan_matches_gps() {
    use tubemem_gps::{inflate, Hypothesis};
    use tubemem_mesh::{tube::plugged_tube, Symmetry};
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let n = 32;
    let (model, ms, _) = tube::inflate_mesh(
        plugged_tube(1.0, 20.0, n, 80, Symmetry::Eighth).unwrap(),
        1.3,
    );
    assert_eq!(model.mesh.plugs.len(), 1);
    let g = inflate(&law, Hypothesis::Gps, ms.lambda_s).unwrap();
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(
        rel(ms.lambda_z, g.lambda_z) < 1e-6,
        "λz {} vs {}",
        ms.lambda_z,
        g.lambda_z
    );
    assert!(rel(ms.n_s, g.n_s) < 1e-6 && rel(ms.n_z, g.n_z) < 1e-6);
    let apothem = (std::f64::consts::PI / n as f64).cos();
    assert!(
        rel(ms.w * apothem, g.w) < 1e-6,
        "ϖ cos(π/n) {} vs {}",
        ms.w * apothem,
        g.w
    );
    // the ring at the plug stays at radius R
    let ring = &model.mesh.plugs[0];
    let st = model.reference_state();
    assert!(ring
        .iter()
        .all(|&i| (st.x[i][0].hypot(st.x[i][1]) - 1.0).abs() < 1e-12));
}

/// The assembled tangent of a plugged tube (shared plug equations, disc face volume) against
/// finite differences, as in `assembled_tangents_match_finite_differences_including_gas`.
#[test]
fn plugged_tube_tangent_matches_finite_differences() {
    use crate::model::{Control, Model};
    use rand::{Rng, SeedableRng};
    use tubemem_mesh::{tube::plugged_tube, Symmetry};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(22);
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let mut model = Model::new(
        plugged_tube(1.0, 3.0, 8, 6, Symmetry::None).unwrap(),
        Box::new(law),
    )
    .unwrap();
    let mut st = model.reference_state();
    model.solve(&mut st, Control::Pressure(0.3)).unwrap();
    let v_total = model.mesh.volume_at(&st.x);
    for control in [Control::Pressure(0.3), Control::Gas { pv: 0.3 * v_total }] {
        let v: Vec<f64> = (0..model.n_eq)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        check_tangent_along(&model, &st.x, control, 0.3, &v);
    }
}

/// Squeeze from λs* = 1.3 to ρ = 0.8 with the gas closed in (eighth model, 32 around,
/// 4 elements per R along). Returns (final mid-span, contact values, λs*, max penetration).
fn squeeze(
    l: f64,
    around: usize,
    tol: f64,
) -> (crate::post::MidSpan, crate::post::ContactValues, f64) {
    let (_, _, ms, c, ls0) = squeeze_model(l, around, tol);
    (ms, c, ls0)
}

/// [`squeeze`] with the model and its final state.
fn squeeze_model(
    l: f64,
    around: usize,
    tol: f64,
) -> (
    crate::model::Model,
    crate::model::State,
    crate::post::MidSpan,
    crate::post::ContactValues,
    f64,
) {
    use crate::contact::penalty_for;
    use crate::model::{nearest_node, run_stage, Control, Stage};
    use crate::post::{midspan, midspan_contact};
    let mesh = tubemem_mesh::tube::capped_tube(
        1.0,
        l,
        around,
        (4.0 * l) as usize,
        tubemem_mesh::Symmetry::Eighth,
    )
    .unwrap();
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let mut model = crate::model::Model::new(mesh, Box::new(law)).unwrap();
    let node = nearest_node(&model.mesh, [1.0, 0.0, 0.0]);
    let mut st = model.reference_state();
    let inflate = Stage {
        index: 1,
        from: 1.0,
        to: 1.3,
        initial_steps: 6,
        max_cuts: 12,
    };
    run_stage(
        &mut model,
        &mut st,
        &inflate,
        |v| Control::Node {
            node,
            component: 0,
            target: v,
        },
        |_, _, _, _, _| Ok(()),
    )
    .unwrap();
    let m0 = midspan(&model, &st).unwrap();
    let ls0 = m0.lambda_s;
    let pv = st.p * model.multiplicity() * model.mesh.volume_at(&st.x);
    model.penalty = penalty_for(st.p, m0.lambda_s * m0.lambda_z, tol);
    let h0 = st.x.iter().map(|p| p[1]).fold(0.0, f64::max);
    let sq = Stage {
        index: 2,
        from: h0,
        to: 0.8,
        initial_steps: 10,
        max_cuts: 12,
    };
    run_stage(
        &mut model,
        &mut st,
        &sq,
        |h| Control::Squeeze { pv, half_gap: h },
        |_, _, _, _, _| Ok(()),
    )
    .unwrap();
    let ms = midspan(&model, &st).unwrap();
    let c = midspan_contact(&model, &st, 0.8);
    (model, st, ms, c, ls0)
}

/// Source: GPS flattening, eqs. (76)–(77), at the FE's own λs* and the same ρ = 0.8.
/// What differs is physics GPS leaves out — the caps hold gas that the plates do not squeeze,
/// so the pressure rises less — plus discretization. Checked: (1) every error falls when L/R
/// doubles from 20 to 40 (the end effect); (2) at L/R = 40 the errors stay within bounds set from
/// this mesh's measured values with margin (measured with κ = ϖ*J*/1e-3: ϖ −0.34 %, λs −0.17 %,
/// λz −0.12 %, χ −1.2 %, force −1.6 %; bounds 0.6 %, 0.3 %, 0.3 %, 2 %, 2.5 %).
#[test]
fn squeeze_approaches_gps_as_the_tube_gets_longer() {
    use tubemem_gps::{flatten, Hypothesis};
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let errs = |l: f64| {
        let (ms, c, ls0) = squeeze(l, 32, 1e-3);
        let g = flatten(&law, Hypothesis::Gps, ls0, 0.8).unwrap();
        let r = |a: f64, b: f64| (a - b) / b;
        [
            r(ms.w, g.w),
            r(ms.lambda_s, g.lambda_s),
            r(ms.lambda_z, g.lambda_z),
            r(c.chi, g.chi),
            r(c.force, g.force),
        ]
    };
    let (e20, e40) = (errs(20.0), errs(40.0));
    let names = ["ϖ", "λs", "λz", "χ", "force"];
    for k in 0..5 {
        assert!(
            e40[k].abs() < e20[k].abs(),
            "{}: error {} at L/R = 40 not below {} at 20",
            names[k],
            e40[k],
            e20[k]
        );
    }
    let bounds = [6e-3, 3e-3, 3e-3, 2e-2, 2.5e-2];
    for k in 0..5 {
        assert!(
            e40[k].abs() < bounds[k],
            "{}: {} at L/R = 40",
            names[k],
            e40[k]
        );
    }
}

/// Penalty: the penetration is about p/κ, so ten times κ gives a tenth of the penetration
/// (measured ratio 9.79; bound: within 20 % of 10), and the mid-span pressure moves by less
/// than 0.5 % (measured 1.2e-3)
/// between κ = ϖ*/1e-3 and ϖ*/1e-4 (the penalty error is small against the end effect).
#[test]
fn penetration_falls_as_the_penalty_grows() {
    let (a, ca, _) = squeeze(10.0, 16, 1e-3);
    let (b, cb, _) = squeeze(10.0, 16, 1e-4);
    let ratio = ca.penetration / cb.penetration;
    assert!(
        (ratio / 10.0 - 1.0).abs() < 0.2,
        "penetration ratio {ratio}"
    );
    assert!((a.w / b.w - 1.0).abs() < 5e-3);
}

/// The taut / wrinkled / slack classification of the output, including the exact zeros the
/// relaxed law produces (N2 = 0 when wrinkled, both 0 when slack).
#[test]
fn wrinkle_state_classification_works() {
    use crate::post::CellValues;
    use tubemem_material::relaxed::Relaxed;
    use tubemem_material::MembraneLaw;
    let c = |n1: f64, n2: f64| {
        CellValues {
            hoop_stretch: 1.0,
            axial_stretch: 1.0,
            n1,
            n2,
        }
        .state()
    };
    assert_eq!(c(1.0, 0.5), 0);
    assert_eq!(c(1.0, 0.0), 1);
    assert_eq!(c(1.0, -0.2), 1);
    assert_eq!(c(0.0, 0.0), 2);
    assert_eq!(c(-0.1, -0.3), 2);
    let r = Relaxed::new(tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap());
    let [n1, n2] = r.resultants(1.5, 0.6).unwrap(); // λ2 below the natural width: wrinkled
    assert_eq!(c(n1, n2), 1);
    let [n1, n2] = r.resultants(0.9, 0.8).unwrap(); // slack
    assert_eq!(c(n1, n2), 2);
}

/// A pressurized sphere squeezed between two plates, gas closed in (eighth model).
/// Returns (ϖ, total force on one plate, contact area on it, free equator radius r, h, max |y − h|
/// over the nodes in contact, penetration, mean contact pressure at contact Gauss points whose
/// four nodes are all in contact).
fn squeezed_sphere(m: usize, tol: f64, h_frac: f64) -> (f64, f64, f64, f64, f64, f64, f64, f64) {
    use crate::contact::{penalty_for, traction};
    use crate::model::{nearest_node, run_stage, Control, Model, Stage};
    use tubemem_mesh::{cross, dot, tube::sphere, Symmetry};
    let law = tubemem_material::laws::neo_hookean(1.0).unwrap();
    let mut model = Model::new(sphere(1.0, m, Symmetry::Eighth).unwrap(), Box::new(law)).unwrap();
    let mut st = model.reference_state();
    model.solve(&mut st, Control::Pressure(1.0)).unwrap();
    let r0 = st.x.iter().map(|p| p[1]).fold(0.0, f64::max);
    let j0 = (r0 * r0).max(1.0); // equibiaxial area stretch λ²
    let pv = st.p * model.multiplicity() * model.mesh.volume_at(&st.x);
    model.penalty = penalty_for(st.p, j0, tol);
    let h = h_frac * r0;
    let stage = Stage {
        index: 1,
        from: r0,
        to: h,
        initial_steps: 10,
        max_cuts: 12,
    };
    run_stage(
        &mut model,
        &mut st,
        &stage,
        |hh| Control::Squeeze { pv, half_gap: hh },
        |_, _, _, _, _| Ok(()),
    )
    .unwrap();
    let kappa = model.penalty;
    let copies = 4.0; // the top plate of the eighth model: mirror in x and in z
    let (mut force, mut area, mut pen, mut pc, mut npc) = (0.0, 0.0, 0.0_f64, 0.0, 0usize);
    let mut in_contact = vec![false; st.x.len()];
    for el in &model.elements {
        let xe = el.nodes.map(|i| st.x[i]);
        let inner = el.nodes.iter().all(|&i| st.x[i][1] > h);
        for g in 0..4 {
            let p = [0, 1, 2].map(|k| (0..4).map(|a| el.n[g][a] * xe[a][k]).sum::<f64>());
            let gap = h - p[1];
            if gap < 0.0 {
                let f = el.gradient(g, &xe);
                let da = dot(cross(f[0], f[1]), cross(f[0], f[1])).sqrt();
                force += el.w[g] * traction(gap, kappa);
                area += el.w[g] * da;
                pen = pen.max(-gap);
                if inner {
                    pc += traction(gap, kappa) / da;
                    npc += 1;
                }
                for &i in &el.nodes {
                    if st.x[i][1] > h {
                        in_contact[i] = true;
                    }
                }
            }
        }
    }
    let flat = (0..st.x.len())
        .filter(|&i| in_contact[i])
        .map(|i| (st.x[i][1] - h).abs())
        .fold(0.0, f64::max);
    let r = st.x[nearest_node(&model.mesh, [1.0, 0.0, 0.0])][0];
    (
        st.p,
        copies * force,
        copies * area,
        r,
        h,
        flat,
        pen,
        if npc > 0 { pc / npc as f64 } else { f64::NAN },
    )
}

/// A pressurized neo-Hookean sphere (ϖ = 1 then gas closed in) squeezed between two plates to
/// h = 0.7 r (eighth model, κ = ϖJ/1e-4). Independent estimate: the exact result for a membrane
/// in frictionless contact with a plane (paper Sec. 3.2: the surface force vanishes where the
/// membrane lies on the plane, so the contact pressure equals the gas pressure there), hence the
/// plate force is F = ϖ·A_contact and the contact zone is flat. (The naive estimate
/// ϖπ(r² − h²), with r the free equator radius, is off by 58 %: the squeezed membrane is no
/// longer a sphere of radius r.) Measured at m = 8, 16, 32: interior contact pressure / ϖ − 1 =
/// +22 %, +11.5 %, +1.4 %; F/(ϖA) − 1 = +6.0 %, +6.4 %, +0.14 % (A counts Gauss points in
/// contact, an O(h) edge measure); F = 1.1556, 1.1744, 1.1825. Checked: the flat zone lies on
/// the plane within twice the penetration; the interior contact pressure error falls with
/// refinement and is below 3 % at m = 32; F/(ϖA) within 2 % at m = 32; F converges
/// (|F32 − F16| < |F16 − F8|).
#[test]
fn squeezed_sphere_contact_pressure_equals_the_gas_pressure() {
    let run = |m: usize| squeezed_sphere(m, 1e-4, 0.7);
    let (_, f8, ..) = run(8);
    let (w16, f16, _, _, _, _, _, pc16) = run(16);
    let (w32, f32, a32, _, _, flat32, pen32, pc32) = run(32);
    assert!(
        flat32 <= 2.0 * pen32,
        "the contact zone is not flat: {flat32} vs penetration {pen32}"
    );
    let (e16, e32) = ((pc16 / w16 - 1.0).abs(), (pc32 / w32 - 1.0).abs());
    assert!(
        e32 < e16 && e32 < 0.03,
        "contact pressure / ϖ − 1: {e16} (m = 16), {e32} (m = 32)"
    );
    assert!(
        (f32 / (w32 * a32) - 1.0).abs() < 0.02,
        "F/(ϖA) = {}",
        f32 / (w32 * a32)
    );
    assert!(
        (f32 - f16).abs() < (f16 - f8).abs(),
        "plate force does not converge: {f8}, {f16}, {f32}"
    );
}

/// A flat membrane pressed on a plane: a flat (distorted) element lying δ inside the plane
/// n·x = d, tilted arbitrarily. Exact: energy κδ²A/2 (A the element area), total force κδA along
/// n only (frictionless), and no force at all when it lies outside.
#[test]
fn flat_membrane_pressed_on_a_plane() {
    use crate::contact::{contact_kernel, Plane};
    use crate::element::RefElement;
    use tubemem_mesh::quad_area;
    let (kappa, delta) = (250.0, 2e-3);
    // the plane z = 0 rotated by 0.4 rad about x: normal n, offset 0
    let (c, s) = (0.4f64.cos(), 0.4f64.sin());
    let n = [0.0, -s, c];
    let local = [[0.0, 0.0], [1.3, 0.1], [1.1, 0.9], [-0.2, 0.8]];
    // in-plane axes e1 = x, e2 = (0, c, s); the element sits at n·x = −δ
    let place = |d: f64| local.map(|[u, v]| [u, v * c + d * n[1], v * s + d * n[2]]);
    let x = place(-delta);
    let re = RefElement::new(0, [0, 1, 2, 3], &x).unwrap();
    let plane = Plane {
        normal: n,
        offset: 0.0,
    };
    let mut r = [0.0; 12];
    let mut k = [0.0; 144];
    let e = contact_kernel(&re, &x, &[plane], kappa, &mut r, Some(&mut k));
    let area = quad_area(&x);
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
    let xo = place(delta);
    let mut r2 = [0.0; 12];
    assert_eq!(
        contact_kernel(&re, &xo, &[plane], kappa, &mut r2, None),
        0.0
    );
    assert!(r2.iter().all(|v| *v == 0.0));
}

/// Check the assembled tangent's action A·v against central differences of the assembled
/// residual along `v` (step 1e-6; tolerance 1e-6 relative to max |A·v|: truncation ~1e-11,
/// rounding ~1e-9 relative).
fn check_tangent_along(
    model: &crate::model::Model,
    x: &[[f64; 3]],
    control: crate::model::Control,
    p: f64,
    v: &[f64],
) {
    let av = model.tangent_times(x, control, p, v).unwrap();
    let h = 1e-6;
    let shifted = |t: f64| {
        let mut y = x.to_vec();
        for (d, e) in model.eq.iter().enumerate() {
            if let Some(k) = e {
                y[d / 3][d % 3] += t * v[*k];
            }
        }
        model.residual(&y, control, p).unwrap()
    };
    let (rp, rm) = (shifted(h), shifted(-h));
    let scale = av.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    for i in 0..model.n_eq {
        let fd = (rp[i] - rm[i]) / (2.0 * h);
        assert!(
            (fd - av[i]).abs() <= 1e-6 * scale,
            "{control:?} row {i}: {} vs {fd}",
            av[i]
        );
    }
}

/// The mid-span of the squeezed tube against the GPS cross-section under the FE's *own* gas
/// pressure (eq. 76 without the gas law, `tubemem_gps::section_at_pressure`). This is the
/// translation-invariance claim itself, with the end effect that travels through the shared gas
/// (the ends keep gas the plates do not squeeze, so ϖ rises less) taken out.
/// Measured here (L/R = 20, along = 4 L/R, ρ = 0.8, κ = ϖ*J*/1e-3), relative errors:
///
/// | around | ϖ vs Boyle GPS | λs vs local | λz vs local | χ vs local |
/// |---|---|---|---|---|
/// | 32 | −1.00 % | −7.7e-4 | −5.9e-4 | −1.00 % |
/// | 64 | −1.32 % | −1.8e-5 | −6.7e-5 | −0.31 % |
///
/// Bounds: at 64 around λs and λz within 2e-4 of the local section (3× the larger measured
/// value) and χ within 0.6 % (2× measured; the contact edge is resolved to O(h)); every local
/// error falls from 32 to 64 around; and the ϖ error against the Boyle GPS stays at least 20×
/// the local stretch errors: the end effect passes through the gas, not the section.
#[test]
fn squeezed_midspan_obeys_the_gps_section_at_its_own_pressure() {
    use tubemem_gps::{flatten, section_at_pressure, Hypothesis};
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let errs = |around: usize| {
        let (ms, c, ls0) = squeeze(20.0, around, 1e-3);
        let g = flatten(&law, Hypothesis::Gps, ls0, 0.8).unwrap();
        let l = section_at_pressure(&law, 0.8, ms.w, [g.lambda_s, g.lambda_z]).unwrap();
        let r = |a: f64, b: f64| (a - b) / b;
        [
            r(ms.w, g.w),
            r(ms.lambda_s, l.lambda_s),
            r(ms.lambda_z, l.lambda_z),
            r(c.chi, l.chi),
        ]
    };
    let (e32, e64) = (errs(32), errs(64));
    for k in 1..4 {
        assert!(e64[k].abs() < e32[k].abs(), "{k}: {e32:?} -> {e64:?}");
    }
    assert!(e64[1].abs() < 2e-4 && e64[2].abs() < 2e-4, "{e64:?}");
    assert!(e64[3].abs() < 6e-3, "{e64:?}");
    assert!(
        e64[0].abs() > 20.0 * e64[1].abs().max(e64[2].abs()),
        "{e64:?}"
    );
}

/// Force balance of the squeezed tube (L/R = 20, ρ = 0.8, κ = ϖ*J*/1e-3), two ways.
/// (1) The total plate force of the output (`total_force`, integrated contact pressure) equals
///     the plates' reaction: the sum along n of the contact nodal forces that the assembled
///     residual carries (`contact_kernel`), to rounding (1e-12 relative).
/// (2) Equilibrium of the upper half of the mid-span section, cut at y = 0 where the membrane
///     is vertical (symmetry): per unit length, plate force = gas pressure × the section's width
///     at the cut − the two hoop resultants there, i.e. π·force = 2ϖ x_eq − 2N_s. This holds for
///     any translation-invariant section (GPS: N_s = ϖρ and x_eq = ρ + πχ/2 give force = ϖχ,
///     eq. 80); here the three terms come from different FE outputs (contact traction, node
///     position, ring-averaged Cauchy resultant). Measured relative imbalance: −4.53 %, −1.03 %,
///     −0.24 % at 16, 32, 64 around — second order (ratios 4.4, 4.2). Checked: below 0.5 % at
///     64 around and falling by more than 3× from 32.
#[test]
fn plate_force_balances_the_contact_reaction_and_the_section() {
    use crate::contact::{contact_kernel, Plane};
    let top = Plane {
        normal: [0.0, -1.0, 0.0],
        offset: -0.8,
    };
    let imbalance = |around: usize| {
        let (model, st, ms, c, _) = squeeze_model(20.0, around, 1e-3);
        let mut reaction = 0.0;
        for el in &model.elements {
            let xe = el.nodes.map(|i| st.x[i]);
            let mut r = [0.0; 12];
            contact_kernel(el, &xe, &[top], model.penalty, &mut r, None);
            reaction += (0..4).map(|a| r[3 * a + 1]).sum::<f64>();
        }
        // the eighth model holds a quarter of one plate's contact
        let reaction = model.multiplicity() / 2.0 * reaction;
        assert!(
            (c.total_force - reaction).abs() < 1e-12 * reaction,
            "{} vs {reaction}",
            c.total_force
        );
        let ring = crate::post::midspan_ring(&model);
        let x_eq = ring.iter().map(|&i| st.x[i][0]).fold(0.0, f64::max);
        std::f64::consts::PI * c.force / (2.0 * ms.w * x_eq - 2.0 * ms.n_s) - 1.0
    };
    let (e32, e64) = (imbalance(32), imbalance(64));
    assert!(e64.abs() < 5e-3, "{e64}");
    assert!(e32.abs() > 3.0 * e64.abs(), "{e32} -> {e64}");
}
