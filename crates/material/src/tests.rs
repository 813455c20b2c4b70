//! Unit tests of the material laws. Sources of truth: paper eqs. (22)–(23) and (86)–(87), the
//! linear theory of incompressible membranes (plane stress, ν = ½, E = 3μ), and central finite
//! differences (truncation error O(h²) ≈ 1e-8 relative at h = 1e-5 for these smooth energies, so
//! FD checks use a 1e-6 relative tolerance).

use super::*;
use laws::{neo_hookean, AnssariBenamBucchi, MooneyRivlin};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn all_laws() -> Vec<Box<dyn MembraneLaw>> {
    vec![
        Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
        Box::new(AnssariBenamBucchi::new(2.5, 3.0).unwrap()),
        Box::new(MooneyRivlin::new(1.0, 0.1).unwrap()),
        Box::new(neo_hookean(1.0).unwrap()),
        Box::new(AutoDiff::new(energies::AbbEnergy { kuhn: 30.0 }, 1.0).unwrap()),
        Box::new(AutoDiff::new(energies::MooneyRivlinEnergy { alpha: 0.3 }, 1.0).unwrap()),
    ]
}

/// Random stretch pairs that stay below every tested locking limit (I1 < 9 for 𝒩 = 3).
fn random_stretches(rng: &mut ChaCha8Rng) -> (f64, f64) {
    (rng.random_range(0.75..2.0), rng.random_range(0.75..2.0))
}

fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

/// eq. (23): the factor n of the Anssari-Benam–Bucchi resultants, written from the paper.
fn eq23_n(l1: f64, l2: f64, kn: f64) -> f64 {
    let p = l1 * l1 * l2 * l2;
    (1.0 - kn) * (1.0 + p * (l1 * l1 + l2 * l2 - 9.0 * kn))
        / (l1.powi(3) * l2.powi(3) * (1.0 - 3.0 * kn) * (1.0 + p * (l1 * l1 + l2 * l2 - 3.0 * kn)))
}

#[test]
fn abb_resultants_reproduce_eqs_22_23() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for &kn in &[3.0, 30.0, 1e4] {
        let law = AnssariBenamBucchi::new(1.0, kn).unwrap();
        for _ in 0..200 {
            let (l1, l2) = random_stretches(&mut rng);
            let [n1, n2] = law.resultants(l1, l2).unwrap();
            let n = eq23_n(l1, l2, kn);
            let e1 = n * (l1.powi(4) * l2 * l2 - 1.0);
            let e2 = n * (l1 * l1 * l2.powi(4) - 1.0);
            assert!(
                close(n1, e1, 1e-12, 1e-14),
                "N1 {n1} vs eq.22 {e1} at ({l1},{l2}), 𝒩={kn}"
            );
            assert!(
                close(n2, e2, 1e-12, 1e-14),
                "N2 {n2} vs eq.22 {e2} at ({l1},{l2}), 𝒩={kn}"
            );
        }
    }
}

#[test]
fn mooney_rivlin_resultants_reproduce_eqs_86_87() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for &al in &[0.0, 0.1, 0.7] {
        let law = MooneyRivlin::new(1.0, al).unwrap();
        for _ in 0..200 {
            let (l1, l2) = random_stretches(&mut rng);
            let [n1, n2] = law.resultants(l1, l2).unwrap();
            let j3 = (l1 * l2).powi(3);
            let e1 = (l1 / l2 - 1.0 / j3) * (1.0 + al * l2 * l2);
            let e2 = (l2 / l1 - 1.0 / j3) * (1.0 + al * l1 * l1);
            assert!(close(n1, e1, 1e-12, 1e-14), "MR N1 {n1} vs eq.86 {e1}");
            assert!(close(n2, e2, 1e-12, 1e-14), "MR N2 {n2} vs eq.87 {e2}");
        }
    }
}

#[test]
fn reference_state_is_stress_free() {
    for law in all_laws() {
        let [n1, n2] = law.resultants(1.0, 1.0).unwrap();
        let st = law.stress_tangent([1.0, 1.0, 0.0]).unwrap();
        assert!(
            n1.abs() < 1e-14 && n2.abs() < 1e-14,
            "{}: N = {n1}, {n2}",
            law.name()
        );
        assert!(
            st.s.iter().all(|s| s.abs() < 1e-14),
            "{}: S = {:?}",
            law.name(),
            st.s
        );
        assert!(law.energy(1.0, 1.0).unwrap().abs() < 1e-14);
    }
}

/// Linear incompressible plane stress: N1/(μ0 H) = 4ε1 + 2ε2, so pure shear ε1 = −ε2 = ε gives
/// N1 = 2 μ0 ε: μ0 = N1/(2ε). Tolerance: the nonlinear terms are O(ε) relative, ε = 1e-6.
#[test]
fn small_strain_shear_modulus_is_mu() {
    let eps = 1e-6;
    let cases: Vec<(Box<dyn MembraneLaw>, f64)> = vec![
        (Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()), 1.0),
        (Box::new(AnssariBenamBucchi::new(1.0, 1.5).unwrap()), 1.0),
        (Box::new(neo_hookean(1.0).unwrap()), 1.0),
        // eq. (83) as printed: μ0 = μ(1 + α) (see the MooneyRivlin docs).
        (Box::new(MooneyRivlin::new(1.0, 0.25).unwrap()), 1.25),
    ];
    for (law, mu0) in cases {
        let [n1, n2] = law.resultants(1.0 + eps, 1.0 - eps).unwrap();
        assert!(
            close(n1 / (2.0 * eps), mu0, 1e-5, 0.0),
            "{}: {}",
            law.name(),
            n1 / (2.0 * eps)
        );
        assert!(close(-n2 / (2.0 * eps), mu0, 1e-5, 0.0));
        // Tangent at C = I: μ0 [[4, 2, 0], [2, 4, 0], [0, 0, 1]] (E = 3μ0, ν = ½, G = μ0).
        let d = law.stress_tangent([1.0, 1.0, 0.0]).unwrap().tangent;
        let expect = [[4.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 1.0]];
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    close(d[i][j], mu0 * expect[i][j], 1e-12, 1e-12),
                    "{} D{i}{j}",
                    law.name()
                );
            }
        }
    }
}

#[test]
fn ab_derivatives_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let h = 1e-5;
    for law in all_laws() {
        for _ in 0..50 {
            // Keep λ1 and λ2 apart: FD steps in (a, b) must not cross a² = 4b (equal stretches).
            let (l1, l2) = random_stretches(&mut rng);
            let l2 = if (l1 - l2).abs() < 0.05 { l1 + 0.1 } else { l2 };
            let (a, b) = (l1 * l1 + l2 * l2, l1 * l1 * l2 * l2);
            let d = law.derivatives(a, b).unwrap();
            let f = |a: f64, b: f64| law.derivatives(a, b).unwrap();
            let fd_wa = (f(a + h, b).w - f(a - h, b).w) / (2.0 * h);
            let fd_wb = (f(a, b + h).w - f(a, b - h).w) / (2.0 * h);
            let fd_waa = (f(a + h, b).w_a - f(a - h, b).w_a) / (2.0 * h);
            let fd_wab = (f(a, b + h).w_a - f(a, b - h).w_a) / (2.0 * h);
            let fd_wba = (f(a + h, b).w_b - f(a - h, b).w_b) / (2.0 * h);
            let fd_wbb = (f(a, b + h).w_b - f(a, b - h).w_b) / (2.0 * h);
            let n = law.name();
            assert!(close(d.w_a, fd_wa, 1e-6, 1e-9), "{n} W_a");
            assert!(close(d.w_b, fd_wb, 1e-6, 1e-9), "{n} W_b");
            assert!(close(d.w_aa, fd_waa, 1e-6, 1e-9), "{n} W_aa");
            assert!(close(d.w_ab, fd_wab, 1e-6, 1e-9), "{n} W_ab");
            assert!(close(d.w_ab, fd_wba, 1e-6, 1e-9), "{n} W_ba");
            assert!(close(d.w_bb, fd_wbb, 1e-6, 1e-9), "{n} W_bb");
        }
    }
}

#[test]
fn principal_derivatives_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let h = 1e-6;
    for law in all_laws() {
        for _ in 0..50 {
            let (l1, l2) = random_stretches(&mut rng);
            let p = law.principal(l1, l2).unwrap();
            let q = |x: f64, y: f64| law.principal(x, y).unwrap();
            let g0 = (q(l1 + h, l2).w - q(l1 - h, l2).w) / (2.0 * h);
            let g1 = (q(l1, l2 + h).w - q(l1, l2 - h).w) / (2.0 * h);
            assert!(close(p.grad[0], g0, 1e-6, 1e-9) && close(p.grad[1], g1, 1e-6, 1e-9));
            for j in 0..2 {
                let (dx, dy) = if j == 0 { (h, 0.0) } else { (0.0, h) };
                for i in 0..2 {
                    let fd =
                        (q(l1 + dx, l2 + dy).grad[i] - q(l1 - dx, l2 - dy).grad[i]) / (2.0 * h);
                    assert!(
                        close(p.hess[i][j], fd, 1e-6, 1e-9),
                        "{} hess {i}{j}",
                        law.name()
                    );
                }
            }
        }
    }
}

fn rotated_c(l1: f64, l2: f64, th: f64) -> [f64; 3] {
    let (c, s) = (th.cos(), th.sin());
    let (e1, e2) = (l1 * l1, l2 * l2);
    [
        c * c * e1 + s * s * e2,
        s * s * e1 + c * c * e2,
        c * s * (e1 - e2),
    ]
}

#[test]
fn stress_and_tangent_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let h = 1e-6;
    for law in all_laws() {
        for _ in 0..50 {
            let (l1, l2) = random_stretches(&mut rng);
            let c = rotated_c(l1, l2, rng.random_range(0.0..std::f64::consts::PI));
            let st = law.stress_tangent(c).unwrap();
            let at = |k: usize, dh: f64| {
                let mut cc = c;
                cc[k] += dh;
                law.stress_tangent(cc).unwrap()
            };
            // S11 = 2 ∂W/∂C11, S22 = 2 ∂W/∂C22; W depends on C12 = C21 twice, so S12 = ∂W/∂C12.
            // Step 1e-5 for the energy: rounding ε|W|/h ≈ 2e-10, truncation h²|W‴| ≈ 1e-10.
            let he = 1e-5;
            let fd = |k: usize| (at(k, he).w - at(k, -he).w) / (2.0 * he);
            let n = law.name();
            assert!(close(st.s[0], 2.0 * fd(0), 1e-6, 1e-9), "{n} S11");
            assert!(close(st.s[1], 2.0 * fd(1), 1e-6, 1e-9), "{n} S22");
            assert!(
                close(st.s[2], fd(2), 1e-6, 1e-9),
                "{n} S12 {} vs {}",
                st.s[2],
                fd(2)
            );
            // dE11 = ½dC11, dE22 = ½dC22, 2dE12 = dC12.
            for i in 0..3 {
                let d_c11 = (at(0, h).s[i] - at(0, -h).s[i]) / (2.0 * h);
                let d_c22 = (at(1, h).s[i] - at(1, -h).s[i]) / (2.0 * h);
                let d_c12 = (at(2, h).s[i] - at(2, -h).s[i]) / (2.0 * h);
                assert!(
                    close(st.tangent[i][0], 2.0 * d_c11, 1e-6, 1e-8),
                    "{n} D{i}0"
                );
                assert!(
                    close(st.tangent[i][1], 2.0 * d_c22, 1e-6, 1e-8),
                    "{n} D{i}1"
                );
                assert!(close(st.tangent[i][2], d_c12, 1e-6, 1e-8), "{n} D{i}2");
            }
            // Major symmetry (the tangent is a Hessian).
            for i in 0..3 {
                for j in 0..3 {
                    assert!(close(st.tangent[i][j], st.tangent[j][i], 1e-12, 1e-12));
                }
            }
        }
    }
}

/// Automatic differentiation agrees with the hand-derived derivatives to rounding.
#[test]
fn automatic_differentiation_matches_analytic_laws() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let pairs: Vec<(Box<dyn MembraneLaw>, Box<dyn MembraneLaw>)> = vec![
        (
            Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
            Box::new(AutoDiff::new(energies::AbbEnergy { kuhn: 30.0 }, 1.0).unwrap()),
        ),
        (
            Box::new(MooneyRivlin::new(1.0, 0.3).unwrap()),
            Box::new(AutoDiff::new(energies::MooneyRivlinEnergy { alpha: 0.3 }, 1.0).unwrap()),
        ),
    ];
    for (an, ad) in &pairs {
        for _ in 0..200 {
            let (l1, l2) = random_stretches(&mut rng);
            let (a, b) = (l1 * l1 + l2 * l2, l1 * l1 * l2 * l2);
            let (x, y) = (an.derivatives(a, b).unwrap(), ad.derivatives(a, b).unwrap());
            for (u, v) in [
                (x.w, y.w),
                (x.w_a, y.w_a),
                (x.w_b, y.w_b),
                (x.w_aa, y.w_aa),
                (x.w_ab, y.w_ab),
                (x.w_bb, y.w_bb),
            ] {
                assert!(close(u, v, 1e-11, 1e-13), "{}: {u} vs {v}", an.name());
            }
        }
    }
}

#[test]
fn abb_rejects_stretch_beyond_locking() {
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    // Equibiaxial λ: I1 = 2λ² + λ⁻⁴ reaches 3𝒩 = 90 at λ ≈ 6.7082.
    let ok = law.resultants(6.70, 6.70).unwrap();
    assert!(ok.iter().all(|x| x.is_finite() && *x > 0.0));
    for l in [6.7083, 7.0, 50.0] {
        match law.resultants(l, l) {
            Err(MaterialError::Locking { i1, limit, .. }) => {
                assert!(i1 >= limit && limit == 90.0);
            }
            other => panic!("expected a locking error at λ = {l}, got {other:?}"),
        }
    }
    let err = law.stress_tangent([100.0, 1.0, 0.0]).unwrap_err();
    assert!(err.to_string().contains("locking"), "{err}");
}

#[test]
fn laws_reject_invalid_parameters() {
    for kn in [1.0, 0.5, -3.0, f64::NAN, f64::INFINITY] {
        let e = AnssariBenamBucchi::new(1.0, kn).unwrap_err();
        assert!(
            matches!(e, MaterialError::InvalidParameter { name: "kuhn", .. }),
            "{e}"
        );
    }
    for mu in [0.0, -1.0, f64::NAN] {
        assert!(AnssariBenamBucchi::new(mu, 30.0).is_err());
        assert!(MooneyRivlin::new(mu, 0.1).is_err());
        assert!(neo_hookean(mu).is_err());
    }
    for al in [-0.1, f64::NAN] {
        let e = MooneyRivlin::new(1.0, al).unwrap_err();
        assert!(matches!(
            e,
            MaterialError::InvalidParameter { name: "alpha", .. }
        ));
    }
    let spec = MaterialSpec::Abb {
        shear_modulus: 1.0,
        kuhn: 0.9,
    };
    assert!(spec.build().unwrap_err().to_string().contains("kuhn"));
}

#[test]
fn laws_reject_invalid_stretches_without_nan() {
    for law in all_laws() {
        for (l1, l2) in [
            (0.0, 1.0),
            (-1.0, 1.2),
            (1.0, f64::NAN),
            (f64::INFINITY, 1.0),
        ] {
            let e = law.resultants(l1, l2).unwrap_err();
            assert!(
                matches!(e, MaterialError::InvalidState { .. }),
                "{}: {e}",
                law.name()
            );
        }
        // Inverted (det C ≤ 0) and impossible invariants.
        assert!(law.stress_tangent([1.0, 1.0, 1.0]).is_err());
        assert!(law.stress_tangent([1.0, -1.0, 0.0]).is_err());
        assert!(law.derivatives(1.0, 1.0).is_err()); // a² < 4b: no real stretches
    }
}

/// The hand-written dual number against num-dual's `Dual2SVec64<2>` (an independent
/// implementation of the same forward-mode second derivatives): W, its gradient and Hessian in
/// (a, b) = (tr C, det C) at 200 random admissible states of the ABB (𝒩 = 30) and Mooney–Rivlin
/// energies agree to 1e-13 relative (both are exact up to round-off; the operations are ordered
/// differently, so a few ulps of the largest term apart).
#[test]
fn hand_dual_matches_num_dual() {
    let abb = AutoDiff::new(energies::AbbEnergy { kuhn: 30.0 }, 1.0).unwrap();
    let mr = AutoDiff::new(energies::MooneyRivlinEnergy { alpha: 0.3 }, 1.0).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..200 {
        let (l1, l2): (f64, f64) = (rng.random_range(0.7..3.0), rng.random_range(0.7..3.0));
        let (a, b) = (l1 * l1 + l2 * l2, (l1 * l2).powi(2));
        let pairs = [
            (
                abb.derivatives_ab_hand(a, b).unwrap(),
                abb.derivatives_ab_num_dual(a, b).unwrap(),
            ),
            (
                mr.derivatives_ab_hand(a, b).unwrap(),
                mr.derivatives_ab_num_dual(a, b).unwrap(),
            ),
        ];
        for (h, n) in pairs {
            let hv = [h.w, h.w_a, h.w_b, h.w_aa, h.w_ab, h.w_bb];
            let nv = [n.w, n.w_a, n.w_b, n.w_aa, n.w_ab, n.w_bb];
            let scale = hv.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (x, y) in hv.iter().zip(nv) {
                assert!((x - y).abs() <= 1e-13 * scale, "{hv:?} vs {nv:?}");
            }
        }
    }
}

/// Issue #25, class 6: numbers in messages read as a user writes them. `Num` keeps a precision;
/// `tidy_numbers` rewrites a number of more than 17 digits (what Rust's `{}` makes of 1e308 or
/// 1e-300) in another crate's message, and leaves every other number and word alone.
#[test]
fn numbers_in_messages_read_as_written() {
    use crate::{tidy_numbers, Num};
    assert_eq!(format!("{:.6}", Num(1.5)), "1.500000");
    assert_eq!(format!("{:.3}", Num(4.069e303)), "4.069e303");
    assert_eq!(format!("{}", Num(1e308)), "1e308");
    assert_eq!(format!("{}", Num(-2.5e-9)), "-2.5e-9");
    let big = format!("invalid type: floating point `{}`, expected usize", 1e308);
    assert_eq!(
        tidy_numbers(&big),
        "invalid type: floating point `1e308`, expected usize"
    );
    let small = format!("`offset` = {} and {}", 1e-300, -1e300);
    assert_eq!(tidy_numbers(&small), "`offset` = 1e-300 and -1e300");
    let plain = "step 12 (load parameter 0.123456): 3 cut-backs, pid 4711, fnv1a64:00ff12, x2.5";
    assert_eq!(tidy_numbers(plain), plain);
    // 18 digits are more than a double holds: the shortest form of the same double
    assert_eq!(tidy_numbers("λ = 1.30000000000000004 ✓"), "λ = 1.3 ✓");
}
