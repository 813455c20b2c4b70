//! The pressure-controlled squeeze, the inflation between fixed plates and the mixed path,
//! against references written out here from the paper's explicit resultants and solved by
//! bisection, not by the code under test.
//!
//! For the Anssari-Benam–Bucchi law (and neo-Hookean, its 𝒩 → ∞ limit) the resultants are eq.
//! (58), N_s = n (λs⁴λz² − 1), N_z = n (λs²λz⁴ − 1), one factor n(λs, λz) (eq. 59). The
//! states between plates at half-gap ρ satisfy N_z = q N_s, q = 1 − ρ/(2λs) (eqs. 76), where
//! the factor cancels: with u = λz², λs² u² − q λs⁴ u + (q − 1) = 0, whose positive root is
//! explicit; then ϖ = N_s/ρ. Free inflation (eq. 66) is the same with q = 1/2. So every
//! reference state here is explicit in λs, and the one unknown is found by bisection to 1e-15.
//!
//! Tolerances: bisection references agree with the Newton solutions to the conditioning of the
//! section's equations (about 1e2) times the Newton tolerance (1e-12) with margin: 1e-9
//! relative. The critical pressure is a maximum, where ϖ is flat: its value to 1e-11, its
//! stretch to 1e-5 (a maximum located by bisection on a central difference with h = 1e-6,
//! whose error is h² × ϖ'''/ϖ'' ≈ 1e-12 in slope).

use tubemem_gps::regulated::{
    between_plates, critical_pressure, flatten_at_pressure, flatten_closed_from, free_start,
    plate_stiffness, regulated_curve, regulated_curve_until, squeeze_at_pressure,
};
use tubemem_gps::{flatten, GpsError, Hypothesis};
use tubemem_material::laws::{neo_hookean, AnssariBenamBucchi};

/// eq. (59) (𝒩 = `kn`; `None`: neo-Hookean, n = 1/(λsλz)³).
fn factor(ls: f64, lz: f64, kn: Option<f64>) -> f64 {
    match kn {
        None => 1.0 / (ls * lz).powi(3),
        Some(kn) => {
            let p = ls * ls * lz * lz;
            (1.0 - kn) * (1.0 + p * (ls * ls + lz * lz - 9.0 * kn))
                / ((ls * lz).powi(3)
                    * (1.0 - 3.0 * kn)
                    * (1.0 + p * (ls * ls + lz * lz - 3.0 * kn)))
        }
    }
}

/// (N_s, N_z) of eq. (58).
fn resultants(ls: f64, lz: f64, kn: Option<f64>) -> (f64, f64) {
    let n = factor(ls, lz, kn);
    (
        n * (ls.powi(4) * lz * lz - 1.0),
        n * (ls * ls * lz.powi(4) - 1.0),
    )
}

/// λz with N_z = q N_s (GPS), explicit.
fn lz_for(ls: f64, q: f64) -> f64 {
    let (a, b, c) = (ls * ls, -q * ls.powi(4), q - 1.0);
    ((-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)).sqrt()
}

/// The state between plates at ρ with hoop stretch λs: (ϖ, λz).
fn between(ls: f64, rho: f64, kn: Option<f64>, hyp: Hypothesis) -> (f64, f64) {
    let lz = match hyp {
        Hypothesis::Gps => lz_for(ls, 1.0 - rho / (2.0 * ls)),
        Hypothesis::Ps => 1.0,
    };
    (resultants(ls, lz, kn).0 / rho, lz)
}

/// Free inflation at λs: (ϖ, λz).
fn free(ls: f64, kn: Option<f64>, hyp: Hypothesis) -> (f64, f64) {
    let lz = match hyp {
        Hypothesis::Gps => lz_for(ls, 0.5),
        Hypothesis::Ps => 1.0,
    };
    (resultants(ls, lz, kn).0 / ls, lz)
}

fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let fa = f(a).signum();
    assert_ne!(fa, f(b).signum(), "the bracket [{a}, {b}] holds no root");
    while b - a > 1e-15 * b.abs().max(1.0) {
        let m = 0.5 * (a + b);
        if f(m).signum() == fa {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

fn abb30() -> AnssariBenamBucchi {
    AnssariBenamBucchi::new(1.0, 30.0).unwrap()
}

#[test]
fn the_regulated_squeeze_of_the_papers_tube_is_the_explicit_section_at_the_held_pressure() {
    let law = abb30();
    for hyp in [Hypothesis::Gps, Hypothesis::Ps] {
        let (w0, _) = free(1.3, Some(30.0), hyp);
        for rho in [1.25, 1.0, 0.8, 0.5] {
            let s = flatten_at_pressure(&law, hyp, 1.3, rho).unwrap();
            let ls = bisect(
                |ls| between(ls, rho, Some(30.0), hyp).0 - w0,
                rho.max(1.0) + 1e-12,
                4.0,
            );
            let (_, lz) = between(ls, rho, Some(30.0), hyp);
            assert!(rel(s.w, w0) < 1e-12, "{hyp:?} ρ {rho}: ϖ {} held {w0}", s.w);
            assert!(
                rel(s.lambda_s, ls) < 1e-9,
                "{hyp:?} ρ {rho}: λs {} vs {ls}",
                s.lambda_s
            );
            assert!(
                rel(s.lambda_z, lz) < 1e-9,
                "{hyp:?} ρ {rho}: λz {} vs {lz}",
                s.lambda_z
            );
            assert!(rel(s.chi, ls - rho) < 1e-9, "{hyp:?} ρ {rho}: χ");
            assert!(
                rel(s.force, w0 * (ls - rho)) < 1e-9,
                "{hyp:?} ρ {rho}: force"
            );
        }
    }
}

#[test]
fn a_squeeze_with_the_pressure_ramped_ends_at_the_section_of_its_final_pressure() {
    // the state at (ρ, ϖ) on the stable branch does not depend on the path to it
    let law = abb30();
    let start = free_start(&law, Hypothesis::Gps, 1.3).unwrap();
    let ramped = squeeze_at_pressure(&law, Hypothesis::Gps, start, 0.8, 0.5).unwrap();
    let ls = bisect(
        |ls| between(ls, 0.8, Some(30.0), Hypothesis::Gps).0 - 0.5,
        1.0 + 1e-12,
        4.0,
    );
    assert!(
        rel(ramped.lambda_s, ls) < 1e-9,
        "{} vs {ls}",
        ramped.lambda_s
    );
    assert_eq!(ramped.w, 0.5);
}

#[test]
fn neo_hookean_between_fixed_plates_has_a_critical_pressure_at_the_maximum_of_its_states() {
    let law = neo_hookean(1.0).unwrap();
    let rho = 0.8;
    let w = |ls: f64| between(ls, rho, None, Hypothesis::Gps).0;
    let h = 1e-6;
    let ls_c = bisect(|ls| (w(ls + h) - w(ls - h)) / (2.0 * h), 1.5, 3.0);
    let c = critical_pressure(&law, Hypothesis::Gps, rho)
        .unwrap()
        .expect("neo-Hookean GPS between plates has a pressure maximum");
    assert!(rel(c.w, w(ls_c)) < 1e-11, "ϖc {} vs {}", c.w, w(ls_c));
    assert!(
        (c.lambda_s - ls_c).abs() < 1e-5,
        "λs {} vs {ls_c}",
        c.lambda_s
    );
    // below it, the inflation between the plates is the explicit state; above it, refused
    let s = between_plates(&law, Hypothesis::Gps, rho, 1.2).unwrap();
    let ls = bisect(|ls| w(ls) - 1.2, 1.0 + 1e-12, ls_c);
    assert!(rel(s.lambda_s, ls) < 1e-9, "λs {} vs {ls}", s.lambda_s);
    assert!(rel(s.chi, ls - rho) < 1e-9);
    match between_plates(&law, Hypothesis::Gps, rho, 1.1 * c.w) {
        Err(GpsError::Unstable { w_critical, .. }) => {
            assert!(rel(w_critical, c.w) < 1e-11)
        }
        other => panic!("above ϖc: {other:?}"),
    }
}

#[test]
fn stiffening_and_plane_strain_sections_have_no_critical_pressure() {
    // ABB 𝒩 = 30 locks (I1 → 90) while ϖ still rises; PS neo-Hookean: ϖρ = λs − λs⁻³ rises
    // for ever. The explicit states say the same (checked on a grid of 0.001 up to λs = 6.7).
    for rho in [0.5, 0.8] {
        let mut prev = 0.0;
        for k in 1..5700 {
            let ls = 1.0 + 0.001 * k as f64;
            let w = between(ls, rho, Some(30.0), Hypothesis::Gps).0;
            assert!(w > prev, "ABB 30 ρ {rho}: ϖ falls at λs {ls}");
            prev = w;
        }
        assert_eq!(
            critical_pressure(&abb30(), Hypothesis::Gps, rho).unwrap(),
            None
        );
        assert_eq!(
            critical_pressure(&neo_hookean(1.0).unwrap(), Hypothesis::Ps, rho).unwrap(),
            None
        );
    }
}

#[test]
fn the_mixed_path_closes_the_gas_in_the_regulated_state_and_obeys_boyle_from_there() {
    let law = abb30();
    let hyp = Hypothesis::Gps;
    let regulated = flatten_at_pressure(&law, hyp, 1.3, 1.0).unwrap();
    let closed = flatten_closed_from(&law, hyp, regulated, 0.8).unwrap();
    // Boyle (eq. 77₂): ϖ ρ(2λs − ρ) λz is the regulated state's
    let m = regulated.w
        * regulated.rho
        * (2.0 * regulated.lambda_s - regulated.rho)
        * regulated.lambda_z;
    let boyle = |ls: f64| {
        let (w, lz) = between(ls, 0.8, Some(30.0), hyp);
        w * 0.8 * (2.0 * ls - 0.8) * lz - m
    };
    let ls = bisect(boyle, 1.0, 4.0);
    let (w, lz) = between(ls, 0.8, Some(30.0), hyp);
    assert!(
        rel(closed.lambda_s, ls) < 1e-9,
        "λs {} vs {ls}",
        closed.lambda_s
    );
    assert!(rel(closed.lambda_z, lz) < 1e-9);
    assert!(rel(closed.w, w) < 1e-9, "ϖ {} vs {w}", closed.w);
    // the gas closed, the pressure rises as the plates close further
    assert!(closed.w > regulated.w);
    // closing the gas in a free tube is the closed-gas squeeze of the paper
    let from_free =
        flatten_closed_from(&law, hyp, free_start(&law, hyp, 1.3).unwrap(), 0.8).unwrap();
    let paper = flatten(&law, hyp, 1.3, 0.8).unwrap();
    assert!(rel(from_free.lambda_s, paper.lambda_s) < 1e-12);
    assert!(rel(from_free.force, paper.force) < 1e-12);
}

#[test]
fn bad_plates_and_pressures_are_refused_with_the_reason() {
    let law = abb30();
    let start = free_start(&law, Hypothesis::Gps, 1.3).unwrap();
    for (rho, w) in [
        (f64::NAN, 0.5),
        (-1.0, 0.5),
        (0.8, 0.0),
        (0.8, f64::INFINITY),
        (1.4, 0.5),
    ] {
        let e = squeeze_at_pressure(&law, Hypothesis::Gps, start, rho, w).unwrap_err();
        assert!(
            matches!(e, GpsError::InvalidInput { .. }),
            "ρ {rho} ϖ {w}: {e}"
        );
    }
    let e = between_plates(&law, Hypothesis::Gps, 1.2, 0.5).unwrap_err();
    assert!(e.to_string().contains("ρ < 1"), "{e}");
}

/// Walls that hold the stress-free tube: the confinement at a given pressure in two plates at
/// ρ = 0.8 is the inflation between fixed plates (two codes: the walls' general solver, and
/// the states at fixed ρ).
#[test]
fn walls_touching_the_stress_free_tube_are_the_inflation_between_fixed_plates() {
    use tubemem_gps::confine::{confine_at_pressure, Wall};
    let law = abb30();
    let walls = [
        Wall::new(0.0, 1.0, 0.8).unwrap(),
        Wall::new(0.0, -1.0, 0.8).unwrap(),
    ];
    for w in [0.1, 0.5, 1.0] {
        let c = confine_at_pressure(&law, Hypothesis::Gps, &walls, w).unwrap();
        let b = between_plates(&law, Hypothesis::Gps, 0.8, w).unwrap();
        assert!(
            rel(c.lambda_s, b.lambda_s) < 1e-9,
            "ϖ {w}: {} vs {}",
            c.lambda_s,
            b.lambda_s
        );
        assert!(rel(c.lambda_z, b.lambda_z) < 1e-9, "ϖ {w}");
        assert!(
            rel(c.walls[0].force, b.force) < 1e-9,
            "ϖ {w}: {} vs {}",
            c.walls[0].force,
            b.force
        );
    }
}

/// The plates' stiffness at fixed pressure (`plate_stiffness`, implicit differentiation of eqs.
/// 76) against a central difference of the explicit states of eq. (58) at ρ ± 1e-4 (each state
/// bisected to 1e-15): ABB 30 and neo-Hookean, GPS and PS. Bound 1e-7: the difference's
/// truncation, δ² = 1e-8 times the force's third derivative over its first (order 1 here),
/// well above its rounding (1e-15/1e-4).
#[test]
fn the_plates_stiffness_at_fixed_pressure_is_the_derivative_of_the_explicit_force() {
    let nh = neo_hookean(1.0).unwrap();
    let abb = abb30();
    for (law, kn) in [
        (&abb as &dyn tubemem_material::MembraneLaw, Some(30.0)),
        (&nh, None),
    ] {
        for hyp in [Hypothesis::Gps, Hypothesis::Ps] {
            let (w0, _) = free(1.3, kn, hyp);
            for rho in [1.2, 1.0, 0.8] {
                let force = |r: f64| {
                    let ls = bisect(|ls| between(ls, r, kn, hyp).0 - w0, r.max(1.0) + 1e-12, 4.0);
                    w0 * (ls - r)
                };
                let d = 1e-4;
                let fd = -(force(rho + d) - force(rho - d)) / (2.0 * 2.0 * d);
                let s = flatten_at_pressure(law, hyp, 1.3, rho).unwrap();
                let k = plate_stiffness(law, hyp, &s).unwrap();
                assert!(rel(k, fd) < 1e-7, "{hyp:?} {kn:?} ρ {rho}: {k} vs {fd}");
                assert!(k > 0.0, "the force grows as the plates close");
            }
        }
    }
}

/// The paper's tube inflated to λs* = 6 (ABB 𝒩 = 30, GPS: past the inflation's pressure
/// minimum) and squeezed with the pressure held: the section between the plates stops being
/// stable before ρ = 3 and the path says so (it had said the residual was not a finite
/// number); the states before it are all stable. PS goes all the way.
#[test]
fn the_regulated_squeeze_from_six_snaps_and_says_so() {
    let law = abb30();
    let (states, stop) = regulated_curve_until(&law, Hypothesis::Gps, 6.0, 3.0, 201, None).unwrap();
    let held = states[0].w;
    match stop {
        Some(GpsError::Snaps { w, lambda_s, .. }) => {
            assert!(rel(w, held) < 1e-12);
            let last = states.last().unwrap();
            assert!(last.rho > 3.0 && last.rho < 6.0, "{}", last.rho);
            assert!(lambda_s > last.rho, "in contact: λs {lambda_s}");
        }
        other => panic!("{other:?}"),
    }
    let e = regulated_curve(&law, Hypothesis::Gps, 6.0, 3.0, 201, None).unwrap_err();
    assert!(e.to_string().contains("snaps"), "{e}");
    let (ps, stop) = regulated_curve_until(&law, Hypothesis::Ps, 6.0, 3.0, 201, None).unwrap();
    assert!(stop.is_none() && ps.len() == 201);
}
