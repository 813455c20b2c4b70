//! Unit tests of the law library beyond the paper's laws (Yeoh, Gent, Gent–Gent, Arruda–Boyce,
//! Ogden, Saint-Venant–Kirchhoff, and the energies written as text).
//!
//! Sources of truth, each independent of the code under test:
//! * the resultants written from each law's published energy by hand: for a law of I1 alone,
//!   N1 = 2 W̄'(I1) (λ1/λ2 − 1/(λ1λ2)³) (from ∂I1/∂λ1 = 2λ1 − 2/(λ1³λ2²) and eq. 18); for
//!   Ogden, N1 = [w'(λ1) − w'(λ3) λ3/λ1]/λ2 with w'(λ) = Σ μp λ^(αp−1); for plane-stress SVK,
//!   N1 = 2 (λ1/λ2) [E1 + k (E1 + E2)], k = ν/(1 − ν), Eα = (λα² − 1)/2;
//! * the Arruda–Boyce inverse Langevin function by bisection on coth β − 1/β (not the law's
//!   Newton);
//! * the linear theory at the reference state (incompressible: μ0 [[4, 2, 0], [2, 4, 0],
//!   [0, 0, 1]]; plane stress: E/(1 − ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, (1 − ν)/2]]);
//! * central finite differences (h = 1e-5: truncation O(h²) ≈ 1e-8 relative, so 1e-6).

use super::*;
use laws::expression::{InvariantLaw, PrincipalLaw};
use laws::{ArrudaBoyce, Gent, GentGent, Ogden, SaintVenantKirchhoff, Yeoh};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;

fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

fn params(p: &[(&str, f64)]) -> BTreeMap<String, f64> {
    p.iter().map(|(k, v)| (k.to_string(), *v)).collect()
}

/// The Treloar-like three-term Ogden fit (Ogden 1972, Table 1): μp in kg/cm², αp.
const OGDEN_MU: [f64; 3] = [6.3, 0.012, -0.1];
const OGDEN_ALPHA: [f64; 3] = [1.3, 5.0, -2.0];

fn new_laws() -> Vec<Box<dyn MembraneLaw>> {
    vec![
        Box::new(Yeoh::new(0.5, -0.01, 1e-3).unwrap()),
        Box::new(Yeoh::new(0.2, 0.0, 0.0).unwrap()),
        Box::new(Gent::new(1.0, 50.0).unwrap()),
        Box::new(Gent::new(2.0, 10.0).unwrap()),
        Box::new(GentGent::new(1.0, 40.0, 0.3).unwrap()),
        Box::new(ArrudaBoyce::new(1.0, 30.0).unwrap()),
        Box::new(ArrudaBoyce::new(1.0, 5.0).unwrap()),
        Box::new(Ogden::new(&OGDEN_MU, &OGDEN_ALPHA).unwrap()),
        Box::new(Ogden::new(&[1.0], &[2.0]).unwrap()),
        Box::new(SaintVenantKirchhoff::new(2.6, 0.3).unwrap()),
        Box::new(SaintVenantKirchhoff::new(2.9998, 0.4999).unwrap()),
        Box::new(
            InvariantLaw::new(
                "-(jm / 2) * ln(1 - (I1 - 3) / jm) + c * ln(I2 / 3)",
                &params(&[("jm", 40.0), ("c", 0.3)]),
                1.0,
            )
            .unwrap(),
        ),
        Box::new(
            PrincipalLaw::new(
                "m1/a1 * (l^a1 - 1) + m2/a2 * (l^a2 - 1)",
                &params(&[("m1", 1.3), ("a1", 1.3), ("m2", 0.05), ("a2", 5.0)]),
                1.0,
            )
            .unwrap(),
        ),
    ]
}

/// Random stretch pairs within every law's range above (I1 < 15 for N = 5, Jm = 10: I1 ≤ 8.1).
fn random_stretches(rng: &mut ChaCha8Rng) -> (f64, f64) {
    (rng.random_range(0.75..2.0), rng.random_range(0.75..2.0))
}

/// β = L⁻¹(y) by bisection on coth β − 1/β (independent of the law's Newton).
fn inverse_langevin_by_bisection(y: f64) -> f64 {
    let (mut lo, mut hi): (f64, f64) = (1e-12, 1e3);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        let l = 1.0 / m.tanh() - 1.0 / m;
        if l < y {
            lo = m;
        } else {
            hi = m;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn resultants_match_each_laws_published_energy() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    // laws of I1 alone: W̄'(I1) from the published energy, per μ
    type I1Law = (Box<dyn MembraneLaw>, Box<dyn Fn(f64) -> f64>);
    let i1_laws: Vec<I1Law> = vec![
        (
            Box::new(Yeoh::new(0.5, -0.01, 1e-3).unwrap()),
            Box::new(|i1: f64| (0.5 - 0.02 * (i1 - 3.0) + 3e-3 * (i1 - 3.0).powi(2)) / 1.0),
        ),
        (
            Box::new(Gent::new(1.0, 50.0).unwrap()),
            Box::new(|i1: f64| 0.5 / (1.0 - (i1 - 3.0) / 50.0)),
        ),
        (
            Box::new(ArrudaBoyce::new(1.0, 30.0).unwrap()),
            Box::new(|i1: f64| {
                let lr = (i1 / 90.0).sqrt();
                inverse_langevin_by_bisection(lr) / (6.0 * lr)
            }),
        ),
    ];
    for (law, w1) in &i1_laws {
        for _ in 0..100 {
            let (l1, l2) = random_stretches(&mut rng);
            let i1 = l1 * l1 + l2 * l2 + 1.0 / (l1 * l1 * l2 * l2);
            let j3 = (l1 * l2).powi(3);
            let [n1, n2] = law.resultants(l1, l2).unwrap();
            let e1 = 2.0 * w1(i1) * (l1 / l2 - 1.0 / j3);
            let e2 = 2.0 * w1(i1) * (l2 / l1 - 1.0 / j3);
            assert!(
                close(n1, e1, 1e-11, 1e-14),
                "{}: N1 {n1} vs {e1}",
                law.name()
            );
            assert!(
                close(n2, e2, 1e-11, 1e-14),
                "{}: N2 {n2} vs {e2}",
                law.name()
            );
        }
    }
    // Gent–Gent: + C2 ln(I2/3): ∂I2/∂λ1 = −2/λ1³ + 2 λ1 λ2²
    let gg = GentGent::new(1.0, 40.0, 0.3).unwrap();
    // Ogden, normalized by μ = ½ Σ μp αp
    let og = Ogden::new(&OGDEN_MU, &OGDEN_ALPHA).unwrap();
    let mu: f64 = 0.5
        * OGDEN_MU
            .iter()
            .zip(OGDEN_ALPHA)
            .map(|(m, a)| m * a)
            .sum::<f64>();
    let wp = |l: f64| -> f64 {
        OGDEN_MU
            .iter()
            .zip(OGDEN_ALPHA)
            .map(|(m, a)| m * l.powf(a - 1.0))
            .sum::<f64>()
            / mu
    };
    for nu in [0.0, 0.3, 0.4999] {
        let svk = SaintVenantKirchhoff::new(2.0 * (1.0 + nu), nu).unwrap();
        let k = nu / (1.0 - nu);
        for _ in 0..100 {
            let (l1, l2) = random_stretches(&mut rng);
            let (e1, e2) = (0.5 * (l1 * l1 - 1.0), 0.5 * (l2 * l2 - 1.0));
            let [n1, n2] = svk.resultants(l1, l2).unwrap();
            assert!(close(
                n1,
                2.0 * l1 / l2 * (e1 + k * (e1 + e2)),
                1e-12,
                1e-14
            ));
            assert!(close(
                n2,
                2.0 * l2 / l1 * (e2 + k * (e1 + e2)),
                1e-12,
                1e-14
            ));
        }
    }
    for _ in 0..200 {
        let (l1, l2) = random_stretches(&mut rng);
        let i1 = l1 * l1 + l2 * l2 + 1.0 / (l1 * l1 * l2 * l2);
        let i2 = 1.0 / (l1 * l1) + 1.0 / (l2 * l2) + l1 * l1 * l2 * l2;
        let g1 = 0.5 / (1.0 - (i1 - 3.0) / 40.0);
        let g2 = 0.3 / i2;
        let n1 = (g1 * (2.0 * l1 - 2.0 / (l1.powi(3) * l2 * l2))
            + g2 * (-2.0 / l1.powi(3) + 2.0 * l1 * l2 * l2))
            / l2;
        assert!(close(gg.resultants(l1, l2).unwrap()[0], n1, 1e-11, 1e-14));
        let l3 = 1.0 / (l1 * l2);
        let o1 = (wp(l1) - wp(l3) * l3 / l1) / l2;
        let o2 = (wp(l2) - wp(l3) * l3 / l2) / l1;
        let [m1, m2] = og.resultants(l1, l2).unwrap();
        assert!(
            close(m1, o1, 1e-11, 1e-13),
            "Ogden N1 {m1} vs {o1} at ({l1}, {l2})"
        );
        assert!(close(m2, o2, 1e-11, 1e-13), "Ogden N2 {m2} vs {o2}");
    }
}

#[test]
fn new_laws_are_stress_free_and_linear_at_the_reference() {
    for law in new_laws() {
        let st = law.stress_tangent([1.0, 1.0, 0.0]).unwrap();
        assert!(
            st.s.iter().all(|s| s.abs() < 1e-13),
            "{}: S = {:?}",
            law.name(),
            st.s
        );
        assert!(
            law.energy(1.0, 1.0).unwrap().abs() < 1e-13,
            "{}",
            law.name()
        );
    }
    // incompressible laws: μ0/μ [[4, 2, 0], [2, 4, 0], [0, 0, 1]], μ0/μ from each law
    let ab = ArrudaBoyce::new(1.0, 30.0).unwrap();
    let b0 = inverse_langevin_by_bisection(1.0 / 30f64.sqrt());
    let cases: Vec<(Box<dyn MembraneLaw>, f64)> = vec![
        (Box::new(Yeoh::new(0.5, -0.01, 1e-3).unwrap()), 1.0),
        (Box::new(Gent::new(1.0, 50.0).unwrap()), 1.0),
        (Box::new(GentGent::new(1.0, 40.0, 0.3).unwrap()), 1.0 + 0.2),
        (Box::new(ab), b0 * 30f64.sqrt() / 3.0),
        (Box::new(Ogden::new(&OGDEN_MU, &OGDEN_ALPHA).unwrap()), 1.0),
        (
            Box::new(PrincipalLaw::new("2/a^2 * (l^a - 1)", &params(&[("a", 2.5)]), 1.0).unwrap()),
            1.0,
        ),
    ];
    let lin = [[4.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 1.0]];
    for (law, mu0) in cases {
        let d = law.stress_tangent([1.0, 1.0, 0.0]).unwrap().tangent;
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    close(d[i][j], mu0 * lin[i][j], 1e-11, 1e-12),
                    "{} D{i}{j} = {} vs {}",
                    law.name(),
                    d[i][j],
                    mu0 * lin[i][j]
                );
            }
        }
    }
    // plane-stress SVK, per μ = E/(2(1 + ν)): 2/(1 − ν) [[1, ν, 0], [ν, 1, 0], [0, 0, (1 − ν)/2]]
    for nu in [0.0, 0.3, 0.4999] {
        let law = SaintVenantKirchhoff::new(2.0 * (1.0 + nu), nu).unwrap();
        let d = law.stress_tangent([1.0, 1.0, 0.0]).unwrap().tangent;
        let f = 2.0 / (1.0 - nu);
        let want = [[f, f * nu, 0.0], [f * nu, f, 0.0], [0.0, 0.0, 1.0]];
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    close(d[i][j], want[i][j], 1e-13, 1e-14),
                    "SVK ν = {nu} D{i}{j}"
                );
            }
        }
    }
}

/// Every derivative of every new law against central differences, in (a, b) where the
/// stretches are apart (FD steps must not cross a² = 4b), and in (λ1, λ2) everywhere,
/// equal stretches included (where the separable laws switch to their series).
#[test]
fn new_law_derivatives_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let h = 1e-5;
    for law in new_laws() {
        let n = law.name();
        for k in 0..60 {
            let (l1, l2) = random_stretches(&mut rng);
            let l2 = if (l1 - l2).abs() < 0.05 { l1 + 0.1 } else { l2 };
            let (a, b) = (l1 * l1 + l2 * l2, l1 * l1 * l2 * l2);
            let d = law.derivatives(a, b).unwrap();
            let f = |a: f64, b: f64| law.derivatives(a, b).unwrap();
            let fd = |g: &dyn Fn(f64, f64) -> f64, da: f64, db: f64| {
                (g(a + da, b + db) - g(a - da, b - db)) / (2.0 * h)
            };
            assert!(
                close(d.w_a, fd(&|a, b| f(a, b).w, h, 0.0), 1e-6, 1e-9),
                "{n} W_a"
            );
            assert!(
                close(d.w_b, fd(&|a, b| f(a, b).w, 0.0, h), 1e-6, 1e-9),
                "{n} W_b"
            );
            assert!(
                close(d.w_aa, fd(&|a, b| f(a, b).w_a, h, 0.0), 1e-6, 1e-9),
                "{n} W_aa"
            );
            assert!(
                close(d.w_ab, fd(&|a, b| f(a, b).w_a, 0.0, h), 1e-6, 1e-9),
                "{n} W_ab"
            );
            assert!(
                close(d.w_ab, fd(&|a, b| f(a, b).w_b, h, 0.0), 1e-6, 1e-9),
                "{n} W_ba"
            );
            assert!(
                close(d.w_bb, fd(&|a, b| f(a, b).w_b, 0.0, h), 1e-6, 1e-9),
                "{n} W_bb"
            );
            // principal-stretch derivatives, at equal or nearly equal stretches every third
            let (p1, p2) = match k % 3 {
                0 => (l1, l1),
                1 => (l1, l1 * (1.0 + 0.049)),
                _ => (l1, l2),
            };
            let p = law.principal(p1, p2).unwrap();
            let q = |x: f64, y: f64| law.principal(x, y).unwrap();
            let hh = 1e-6;
            let g0 = (q(p1 + hh, p2).w - q(p1 - hh, p2).w) / (2.0 * hh);
            let g1 = (q(p1, p2 + hh).w - q(p1, p2 - hh).w) / (2.0 * hh);
            assert!(
                close(p.grad[0], g0, 1e-6, 1e-9),
                "{n} grad0 at ({p1}, {p2})"
            );
            assert!(
                close(p.grad[1], g1, 1e-6, 1e-9),
                "{n} grad1 at ({p1}, {p2})"
            );
            for j in 0..2 {
                let (dx, dy) = if j == 0 { (hh, 0.0) } else { (0.0, hh) };
                for i in 0..2 {
                    let fd =
                        (q(p1 + dx, p2 + dy).grad[i] - q(p1 - dx, p2 - dy).grad[i]) / (2.0 * hh);
                    assert!(
                        close(p.hess[i][j], fd, 1e-5, 1e-8),
                        "{n} hess {i}{j} at ({p1}, {p2}): {} vs {fd}",
                        p.hess[i][j]
                    );
                }
            }
        }
    }
}

/// The separable laws' two evaluations agree where they meet (d/s = 0.05): the series is not
/// a different law from the direct formulas.
#[test]
fn separable_series_and_direct_formulas_agree_at_the_switch() {
    let law = Ogden::new(&OGDEN_MU, &OGDEN_ALPHA).unwrap();
    for s in [0.7, 1.0, 1.9] {
        let b = |r: f64| s * s * (1.0 - r * r); // d/s = r
        let (lo, hi) = (
            law.derivatives(2.0 * s, b(0.05 * (1.0 - 1e-12))).unwrap(),
            law.derivatives(2.0 * s, b(0.05 * (1.0 + 1e-12))).unwrap(),
        );
        for (x, y) in [
            (lo.w, hi.w),
            (lo.w_a, hi.w_a),
            (lo.w_b, hi.w_b),
            (lo.w_aa, hi.w_aa),
            (lo.w_ab, hi.w_ab),
            (lo.w_bb, hi.w_bb),
        ] {
            assert!(close(x, y, 1e-11, 1e-12), "s = {s}: {x} vs {y}");
        }
    }
}

/// The energies written as text give the built-in laws' numbers to round-off.
#[test]
fn expression_laws_reproduce_the_built_in_laws() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let gent = Gent::new(1.0, 50.0).unwrap();
    let gent_text = InvariantLaw::new(
        "-(jm / 2) * ln(1 - (I1 - 3) / jm)",
        &params(&[("jm", 50.0)]),
        1.0,
    )
    .unwrap();
    let nh = laws::neo_hookean(1.0).unwrap();
    let nh_text = InvariantLaw::new("(I1 - 3) / 2", &BTreeMap::new(), 1.0).unwrap();
    let mu: f64 = 0.5
        * OGDEN_MU
            .iter()
            .zip(OGDEN_ALPHA)
            .map(|(m, a)| m * a)
            .sum::<f64>();
    let og = Ogden::new(&OGDEN_MU, &OGDEN_ALPHA).unwrap();
    let og_text = PrincipalLaw::new(
        "(m1/a1*(l^a1 - 1) + m2/a2*(l^a2 - 1) + m3/a3*(l^a3 - 1)) / mu",
        &params(&[
            ("m1", OGDEN_MU[0]),
            ("m2", OGDEN_MU[1]),
            ("m3", OGDEN_MU[2]),
            ("a1", OGDEN_ALPHA[0]),
            ("a2", OGDEN_ALPHA[1]),
            ("a3", OGDEN_ALPHA[2]),
            ("mu", mu),
        ]),
        mu,
    )
    .unwrap();
    for (x, y, tol) in [
        (
            &gent as &dyn MembraneLaw,
            &gent_text as &dyn MembraneLaw,
            1e-13,
        ),
        (&nh, &nh_text, 1e-13),
        (&og, &og_text, 1e-12),
    ] {
        for _ in 0..200 {
            let (l1, l2) = random_stretches(&mut rng);
            let (a, b) = (l1 * l1 + l2 * l2, l1 * l1 * l2 * l2);
            let (d, e) = (x.derivatives(a, b).unwrap(), y.derivatives(a, b).unwrap());
            for (p, q) in [
                (d.w, e.w),
                (d.w_a, e.w_a),
                (d.w_b, e.w_b),
                (d.w_aa, e.w_aa),
                (d.w_ab, e.w_ab),
                (d.w_bb, e.w_bb),
            ] {
                assert!(close(p, q, tol, tol), "{}: {p} vs {q}", y.name());
            }
        }
    }
}

#[test]
fn bad_laws_are_refused_with_their_reason() {
    type Built = Result<Box<dyn MembraneLaw>, MaterialError>;
    let cases: Vec<(Built, &str)> = vec![
        (Yeoh::new(0.0, 0.0, 0.0).map(|l| Box::new(l) as _), "`c10`"),
        (
            Yeoh::new(0.5, 0.0, f64::NAN).map(|l| Box::new(l) as _),
            "`c30`",
        ),
        (Gent::new(1.0, 0.0).map(|l| Box::new(l) as _), "`jm`"),
        (
            GentGent::new(1.0, 10.0, -1.0).map(|l| Box::new(l) as _),
            "`c2`",
        ),
        (
            ArrudaBoyce::new(1.0, 1.0).map(|l| Box::new(l) as _),
            "Kuhn segments",
        ),
        (
            Ogden::new(&[1.0, 2.0], &[2.0]).map(|l| Box::new(l) as _),
            "same length",
        ),
        (
            Ogden::new(&[1.0, -2.0], &[2.0, 3.0]).map(|l| Box::new(l) as _),
            "`mu[1]`",
        ),
        (
            Ogden::new(&[1.0], &[0.0]).map(|l| Box::new(l) as _),
            "`alpha[0]`",
        ),
        (
            SaintVenantKirchhoff::new(1.0, 0.6).map(|l| Box::new(l) as _),
            "(−1, 0.5]",
        ),
        (
            InvariantLaw::new("-(I1 - 3) / 2", &BTreeMap::new(), 1.0).map(|l| Box::new(l) as _),
            "not positive definite",
        ),
        (
            InvariantLaw::new("ln(I1 - 3)", &BTreeMap::new(), 1.0).map(|l| Box::new(l) as _),
            "not a finite number",
        ),
        (
            InvariantLaw::new("(I1 - 3) / 2 * jn", &params(&[("jm", 1.0)]), 1.0)
                .map(|l| Box::new(l) as _),
            "column 16: unknown name `jn`",
        ),
        (
            PrincipalLaw::new("-(l^2 - 1)", &BTreeMap::new(), 1.0).map(|l| Box::new(l) as _),
            "not positive definite",
        ),
        (
            PrincipalLaw::new("(I1 - 3)", &BTreeMap::new(), 1.0).map(|l| Box::new(l) as _),
            "the variables are l",
        ),
        // found by the fuzz run (issue #61): minors of a 1e150 tangent overflowed to NaN; now
        // those of ℂ / max|ℂij|, each finite
        (
            PrincipalLaw::new("1e150*(l-3)^2", &BTreeMap::new(), 1.0).map(|l| Box::new(l) as _),
            "leading minors of ℂ / 4.000e150: -1.000e0",
        ),
        (
            InvariantLaw::new("-1e150 * (I1 - 3)", &BTreeMap::new(), 1.0).map(|l| Box::new(l) as _),
            "not positive definite",
        ),
    ];
    for (r, needle) in cases {
        let msg = r.expect_err(needle).to_string();
        assert!(msg.contains(needle), "expected `{needle}` in: {msg}");
        if msg.contains("leading minors") {
            assert!(!msg.contains("NaN") && !msg.contains("inf"), "{msg}");
        }
    }
    // locking is a typed error at the limit
    assert!(matches!(
        Gent::new(1.0, 5.0).unwrap().resultants(2.0, 2.0),
        Err(MaterialError::Locking { .. })
    ));
    assert!(matches!(
        ArrudaBoyce::new(1.0, 3.0).unwrap().resultants(2.2, 2.2),
        Err(MaterialError::Locking { .. })
    ));
}

/// Every spec builds the law it names, and a case file's table reads into it.
#[test]
fn specs_build_their_laws_and_read_from_case_tables() {
    let specs = [
        r#"{"model": "yeoh", "c10": 0.5, "c20": -0.01, "c30": 0.001}"#,
        r#"{"model": "gent", "shear_modulus": 1.0, "jm": 50}"#,
        r#"{"model": "gent-gent", "shear_modulus": 1.0, "jm": 50, "c2": 0.2}"#,
        r#"{"model": "arruda-boyce", "shear_modulus": 1.0, "kuhn": 8}"#,
        r#"{"model": "ogden", "mu": [6.3, 0.012, -0.1], "alpha": [1.3, 5.0, -2.0]}"#,
        r#"{"model": "saint-venant-kirchhoff", "young_modulus": 2.9998, "poisson_ratio": 0.4999}"#,
        r#"{"model": "svk", "young_modulus": 2.6, "poisson_ratio": 0.3}"#,
        r#"{"model": "invariants", "energy": "-(jm/2)*ln(1-(I1-3)/jm)", "parameters": {"jm": 50}, "shear_modulus": 1}"#,
        r#"{"model": "principal", "energy": "2/a^2*(l^a - 1)", "parameters": {"a": 3}, "shear_modulus": 1}"#,
    ];
    for s in specs {
        let spec: MaterialSpec = serde_json::from_str(s).unwrap_or_else(|e| panic!("{s}: {e}"));
        let law = spec.build().unwrap_or_else(|e| panic!("{s}: {e}"));
        assert!(
            close(law.shear_modulus(), spec.shear_modulus(), 1e-15, 0.0),
            "{s}"
        );
        // the relaxed law wraps every one of them
        let relaxed = spec.build_with(Wrinkling::Relaxed).unwrap();
        let [n1, _] = relaxed.resultants(1.3, 1.1).unwrap();
        assert_eq!(n1, law.resultants(1.3, 1.1).unwrap()[0], "{s}");
    }
    let bad: Result<MaterialSpec, _> =
        serde_json::from_str(r#"{"model": "yeoh", "c10": 0.5, "c40": 1.0}"#);
    assert!(bad.unwrap_err().to_string().contains("c40"));
}

/// The tension-field relaxation of every new law: in the wrinkled regime N2 = 0, N1 the
/// uniaxial value at the natural width, and every derivative against central differences
/// (away from the regime's boundary, where the second derivatives jump); h = 1e-6. (The
/// plane-stress SVK sheet has a natural width only while λ1² < 1 + 1/ν, λ2² = 1 − ν(λ1² − 1):
/// beyond, N2 > 0 at every λ2 and the state is taut; the stretches below stay within it.)
#[test]
fn the_relaxation_of_every_new_law_is_tension_free_and_its_derivatives_check() {
    use relaxed::{Regime, Relaxed};
    for law in new_laws() {
        let n = law.name();
        let r = Relaxed::new(law);
        for (l1, f) in [(1.3, 0.6), (1.6, 0.5)] {
            let mu = r.natural_width(l1).unwrap();
            assert!(
                r.law.resultants(l1, mu).unwrap()[1].abs() < 1e-12,
                "{n}: natural width"
            );
            let (a, b) = (l1 * l1 + (f * mu).powi(2), (l1 * f * mu).powi(2));
            assert_eq!(r.regime(a, b).unwrap(), Regime::Wrinkled, "{n}");
            let [n1, n2] = r.resultants(l1, f * mu).unwrap();
            assert!(n2.abs() < 1e-12, "{n}: N2 = {n2}");
            let w1 = r.law.principal(l1, mu).unwrap().grad[0];
            assert!(close(n1, w1 / (f * mu), 1e-10, 0.0), "{n}: N1");
            let h = 1e-6;
            let d = r.derivatives(a, b).unwrap();
            let g = |a: f64, b: f64| r.derivatives(a, b).unwrap();
            assert!(
                close(
                    d.w_a,
                    (g(a + h, b).w - g(a - h, b).w) / (2.0 * h),
                    1e-6,
                    1e-9
                ),
                "{n} W_a"
            );
            assert!(
                close(
                    d.w_b,
                    (g(a, b + h).w - g(a, b - h).w) / (2.0 * h),
                    1e-6,
                    1e-9
                ),
                "{n} W_b"
            );
            assert!(
                close(
                    d.w_aa,
                    (g(a + h, b).w_a - g(a - h, b).w_a) / (2.0 * h),
                    1e-6,
                    1e-9
                ),
                "{n} W_aa"
            );
            assert!(
                close(
                    d.w_ab,
                    (g(a, b + h).w_a - g(a, b - h).w_a) / (2.0 * h),
                    1e-6,
                    1e-9
                ),
                "{n} W_ab"
            );
            assert!(
                close(
                    d.w_bb,
                    (g(a, b + h).w_b - g(a, b - h).w_b) / (2.0 * h),
                    1e-6,
                    1e-9
                ),
                "{n} W_bb"
            );
        }
    }
}

/// Issue #60 item 5: Yeoh with C30 < 0 (Elsayed et al. 2014's Ecoflex fits and many others) is
/// accepted, stable up to the I1 where its membrane tangent stops being positive definite, and
/// refuses states beyond it. The limit is held two ways: (1) it is at most the equibiaxial
/// ray's own limit, solved here from the closed form of the tangent on that ray,
/// W′(2 + 10λ⁻⁶) + 2W″(2λ − 2λ⁻⁵)² = 0 (the eigenvalue of ∂²W/∂λα∂λβ along (1, 1)), and
/// (2) the law's own Hessian (`principal`, through the chain rule of `derivatives_ab`) is
/// positive definite at 2000 states spread below the limit.
#[test]
fn yeoh_with_a_negative_c30_is_stable_up_to_its_limit_and_refuses_beyond() {
    let (c10, c20, c30) = (0.5, 0.02, -2e-4);
    let law = Yeoh::new(c10, c20, c30).unwrap();
    let limit = law.stable_limit().expect("C30 < 0 has a limit");
    // W'(x), W''(x) per μ (μ = 2 C10 = 1)
    let w1 = |x: f64| c10 + 2.0 * c20 * x + 3.0 * c30 * x * x;
    let w2 = |x: f64| 2.0 * c20 + 6.0 * c30 * x;
    let eq = |l: f64| {
        let x = 2.0 * l * l + l.powi(-4) - 3.0;
        w1(x) * (2.0 + 10.0 * l.powi(-6)) + 2.0 * w2(x) * (2.0 * l - 2.0 * l.powi(-5)).powi(2)
    };
    let (mut lo, mut hi) = (1.0f64, 10.0f64);
    assert!(eq(lo) > 0.0 && eq(hi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if eq(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let equibiaxial_limit = 2.0 * lo * lo + lo.powi(-4);
    assert!(
        limit <= equibiaxial_limit * (1.0 + 1e-9) && limit > 3.5,
        "limit I1 = {limit}, equibiaxial ray's {equibiaxial_limit}"
    );
    // below the limit: positive-definite Hessians (a deterministic spread of states)
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut checked = 0;
    while checked < 2000 {
        let l1 = 1.0 + 4.0 * next();
        let l2 = l1.powf(-0.5 + 1.5 * next());
        let i1 = l1 * l1 + l2 * l2 + 1.0 / (l1 * l1 * l2 * l2);
        if i1 >= limit * (1.0 - 1e-6) {
            continue;
        }
        let h = law.principal(l1, l2).unwrap().hess;
        assert!(
            h[0][0] > 0.0 && h[0][0] * h[1][1] - h[0][1] * h[1][0] > 0.0,
            "λ = ({l1}, {l2}), I1 = {i1}: {h:?}"
        );
        checked += 1;
    }
    // beyond it: refused, naming the limit
    let l = (0.5 * (limit + 1.0)).sqrt();
    let e = law.principal(l * 1.01, l * 1.01).unwrap_err();
    assert!(
        matches!(e, MaterialError::Unstable { .. })
            && e.to_string().contains("stable only for I1 <"),
        "{e}"
    );
    // a law stable only near the reference state is a law, with its small range stated
    let narrow = Yeoh::new(0.5, -100.0, 0.1).unwrap().stable_limit().unwrap();
    assert!(narrow > 3.0 && narrow < 3.01, "{narrow}");
    // the shipped case's law (C20 < 0 with C20² < 3 C10 C30) stays stable far beyond its use
    let shipped = Yeoh::new(0.5, -0.01, 0.001).unwrap();
    assert!(
        shipped.stable_limit().is_none_or(|x| x > 100.0),
        "{:?}",
        shipped.stable_limit()
    );
}

/// Issue #61 (found by the fuzz run): a law's name quotes at most an excerpt of a long energy
/// (a run's header had printed a 50 KB energy whole).
#[test]
fn a_long_energy_is_named_by_an_excerpt() {
    let long = vec!["(l - 3)"; 7000].join(" + ");
    let law = PrincipalLaw::new(&long, &BTreeMap::new(), 1.0).unwrap();
    let name = law.name();
    assert!(
        name.len() < 300 && name.contains("(69997 characters)"),
        "{name}"
    );
    let short = InvariantLaw::new("(I1 - 3) / 2", &BTreeMap::new(), 1.0).unwrap();
    assert_eq!(short.name(), "energy W = (I1 - 3) / 2");
}

/// Found by the fuzz run (issue #61): a law 100 times stiffer than its declared μ (an energy
/// written as a sum of 100 terms) has round-off in N2 beyond the taut cone's allowance at
/// C = I; relaxed, that state had gone to the wrinkled branch with equal stretches and divided
/// by zero (a run failed with "λ1 = NaN" at its reference state). Equal stretches at or above
/// the reference state are taut; shrunk equally they are slack.
#[test]
fn a_stiff_text_law_relaxed_is_taut_at_its_reference_state() {
    let e = vec!["(I1 - 3)"; 100].join(" + ");
    let r = crate::relaxed::Relaxed::new(InvariantLaw::new(&e, &BTreeMap::new(), 1.0).unwrap());
    for (a, b) in [(2.0, 1.0), (2.0 + 4e-16, 1.0 + 2e-16), (2.0 - 4e-16, 1.0)] {
        assert_eq!(
            r.regime(a, b).unwrap(),
            crate::relaxed::Regime::Taut,
            "{a} {b}"
        );
        let d = r.derivatives_ab(a, b).unwrap();
        assert!([d.w, d.w_a, d.w_b, d.w_aa, d.w_ab, d.w_bb]
            .iter()
            .all(|v| v.is_finite()));
    }
    assert_eq!(
        r.regime(2.0 * 0.81, 0.81 * 0.81).unwrap(),
        crate::relaxed::Regime::Slack
    );
}
