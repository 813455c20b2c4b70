//! Issue #63: the GPS free inflation in time with a QLV Prony law (`tubemem_gps::visco`),
//! against the exact limits and closed-form histories, and its temporal order.

use tubemem_gps::visco::{
    inflation_history, integrate, loop_area, Control, Segment, Supply, TimePoint,
};
use tubemem_gps::{flatten, inflate, section_at_pressure, Hypothesis};
use tubemem_material::laws::{neo_hookean, AnssariBenamBucchi};
use tubemem_material::viscoelastic::{Prony, PronyTerm};
use tubemem_material::MembraneLaw;

fn prony() -> Prony {
    Prony::new(vec![
        PronyTerm { g: 0.3, tau: 1.0 },
        PronyTerm { g: 0.2, tau: 10.0 },
    ])
    .unwrap()
}

fn abb() -> AnssariBenamBucchi {
    AnssariBenamBucchi::new(1.0, 30.0).unwrap()
}

fn seg(control: Control, target: Option<f64>, duration: f64) -> Segment {
    Segment {
        control,
        target,
        duration,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Creep at constant ϖ = 0.3 after a jump: at t = 0⁺ the state is the base law's elastic GPS
/// state at ϖ (α = 1 in a step of Δt = 0), long after (10⁴ τ_max) the state of g∞ × the base
/// law, i.e. the base law's at ϖ/g∞ (eqs. 66 are linear in the law's scale): both against
/// `inflate` at the found λs, to 1e-12 and 1e-9 (the issue's; the solves stop at 1e-13). λs
/// grows monotonically in between (creep; to the solve's 1e-13). GPS and PS, neo-Hookean and ABB 30. (ϖ/g∞ = 0.6 stays
/// below both laws' GPS pressure maximum, 0.757 and 0.750 (`tubemem gps limits`): at ϖ = 0.5
/// the tube creeps past it and bulges, which the closed form reports as the law's locking.)
#[test]
fn creep_starts_at_the_base_laws_state_and_ends_at_the_long_term_laws() {
    let p = prony();
    let gi = p.g_infinity();
    let laws: Vec<Box<dyn MembraneLaw>> =
        vec![Box::new(abb()), Box::new(neo_hookean(1.0).unwrap())];
    for law in &laws {
        for hyp in [Hypothesis::Gps, Hypothesis::Ps] {
            let w = 0.3;
            let pts = integrate(
                law.as_ref(),
                &p,
                hyp,
                &[
                    seg(Control::Pressure, Some(w), 0.0),
                    seg(Control::Pressure, None, 1e5),
                ],
                400,
            )
            .unwrap();
            let first = pts[1];
            let e = inflate(law.as_ref(), hyp, first.lambda_s).unwrap();
            assert!(
                rel(e.w, w) < 1e-12 && rel(e.lambda_z, first.lambda_z) < 1e-12,
                "{} {hyp:?} t=0+: {e:?} {first:?}",
                law.name()
            );
            let last = pts.last().unwrap();
            let e = inflate(law.as_ref(), hyp, last.lambda_s).unwrap();
            assert!(
                rel(e.w * gi, w) < 1e-9,
                "{} {hyp:?} t→∞: {} vs {}",
                law.name(),
                e.w * gi,
                w
            );
            assert!(rel(e.lambda_z, last.lambda_z) < 1e-9);
            if let Some(q) = pts[1..]
                .windows(2)
                .find(|q| q[1].lambda_s < q[0].lambda_s - 1e-13)
            {
                panic!("{} {hyp:?}: creep not monotone: {q:?}", law.name());
            }
            assert!(
                pts[1..].iter().all(|q| rel(q.w, w) < 1e-12),
                "the pressure is held (to the solve's 1e-13)"
            );
        }
    }
}

/// Relaxation at fixed volume after a jump: C stays constant (the axial balance N_s = 2N_z is
/// homogeneous in the stress, which only scales by G(t)), so λs, λz stay at their instantaneous
/// values and ϖ(t) = G(t) ϖ(0⁺), exactly (1e-12) at every step whatever its length.
#[test]
fn relaxation_at_fixed_volume_follows_the_relaxation_function() {
    let p = prony();
    let law = abb();
    let v = 1.3f64.powi(2) * 1.05;
    let pts = integrate(
        &law,
        &p,
        Hypothesis::Gps,
        &[
            seg(Control::Volume, Some(v), 0.0),
            seg(Control::Volume, None, 50.0),
        ],
        37,
    )
    .unwrap();
    let w0 = pts[1].w;
    for q in &pts[1..] {
        assert!(
            rel(q.w, p.relaxation(q.time) * w0) < 1e-12,
            "t = {}: {} vs {}",
            q.time,
            q.w,
            p.relaxation(q.time) * w0
        );
        assert!(
            rel(q.lambda_s, pts[1].lambda_s) < 1e-12 && rel(q.lambda_z, pts[1].lambda_z) < 1e-12
        );
    }
    assert!(rel(pts[1].lambda_s.powi(2) * pts[1].lambda_z, v) < 1e-14);
}

/// A ramped creep (ϖ 0 → 0.3 over one τ₁, held 20 τ₁): the error against a 2^14-step run falls
/// as Δt² (observed order within 0.1 of 2 between 32, 64 and 128 steps per segment), and
/// `inflation_history`'s estimate is honest: the true error of the history it
/// returns is below 2 × its estimate and at most the tolerance asked, 1e-9.
#[test]
fn the_history_converges_at_second_order_and_its_estimate_is_honest() {
    let p = prony();
    let law = abb();
    let program = [
        seg(Control::Pressure, Some(0.3), 1.0),
        seg(Control::Pressure, None, 20.0),
    ];
    let end = |pts: &[TimePoint]| *pts.last().unwrap();
    let reference = end(&integrate(&law, &p, Hypothesis::Gps, &program, 1 << 14).unwrap());
    let err = |n: usize| {
        let e = end(&integrate(&law, &p, Hypothesis::Gps, &program, n).unwrap());
        (e.lambda_s - reference.lambda_s).abs()
    };
    let (e32, e64, e128) = (err(32), err(64), err(128));
    for (a, b) in [(e32, e64), (e64, e128)] {
        let order = (a / b).log2();
        assert!((order - 2.0).abs() < 0.1, "order {order} ({a:e}, {b:e})");
    }
    let h = inflation_history(&law, &p, Hypothesis::Gps, &program, 16, 1e-9).unwrap();
    let got = end(&h.points);
    let true_err = (got.lambda_s - reference.lambda_s)
        .abs()
        .max((got.lambda_z - reference.lambda_z).abs());
    assert!(h.error_estimate <= 1e-9, "{}", h.error_estimate);
    assert!(
        true_err < 2.0 * h.error_estimate.max(1e-12) && true_err <= 1e-9,
        "true {true_err:e}, estimate {:e}",
        h.error_estimate
    );
}

/// A program it cannot run is refused naming the key.
#[test]
fn a_program_it_cannot_run_is_refused() {
    let p = prony();
    let law = abb();
    let msg = |segs: &[Segment]| {
        integrate(&law, &p, Hypothesis::Gps, segs, 4)
            .unwrap_err()
            .to_string()
    };
    assert!(msg(&[]).contains("at least one segment"));
    assert!(msg(&[seg(Control::Pressure, None, 1.0)])
        .contains("the first segment inflates the unloaded tube"));
    assert!(msg(&[seg(Control::Pressure, Some(0.5), -1.0)]).contains("duration"));
    assert!(msg(&[seg(Control::Stretch, Some(0.5), 1.0)]).contains("target"));
    assert!(msg(&[
        seg(Control::Pressure, Some(0.5), 0.0),
        seg(Control::Pressure, None, 0.0)
    ])
    .contains("a hold needs a duration"));
}

fn plates(supply: Supply, target: Option<f64>, duration: f64) -> Segment {
    seg(Control::Plates(supply), target, duration)
}

/// A squeeze as a jump after an inflation as a jump (all at t = 0⁺): the state is the base
/// law's elastic flattening with the gas closed at λs* (`flatten`, eqs. 76–77): the step has
/// α = 1 and no history stress. To 1e-9 (`flatten` stops at 1e-10). Then held with the
/// pressure regulated for 10⁴ τ_max: the long-term state is the base law's section between
/// the plates at ϖ/g∞ (`section_at_pressure`), to 1e-9.
#[test]
fn a_sudden_squeeze_is_the_elastic_flattening_and_its_long_hold_the_long_term_section() {
    let p = prony();
    let law = abb();
    let ls0 = 1.3;
    let program = [
        seg(Control::Stretch, Some(ls0), 0.0),
        plates(Supply::Gas, Some(1.0), 0.0),
    ];
    let pts = integrate(&law, &p, Hypothesis::Gps, &program, 4).unwrap();
    let got = pts[2];
    let e = flatten(&law, Hypothesis::Gps, ls0, 1.0).unwrap();
    for (name, a, b) in [
        ("λs", got.lambda_s, e.lambda_s),
        ("λz", got.lambda_z, e.lambda_z),
        ("ϖ", got.w, e.w),
        ("force", got.force, e.force),
    ] {
        assert!(rel(a, b) < 1e-9, "{name}: {a} vs {b}");
    }
    let held = [
        seg(Control::Stretch, Some(ls0), 0.0),
        plates(Supply::Pressure, Some(1.0), 0.0),
        plates(Supply::Pressure, None, 1e5),
    ];
    let pts = integrate(&law, &p, Hypothesis::Gps, &held, 400).unwrap();
    let last = *pts.last().unwrap();
    let long = section_at_pressure(
        &law,
        1.0,
        last.w / p.g_infinity(),
        [last.lambda_s, last.lambda_z],
    )
    .unwrap();
    assert!(
        rel(last.lambda_s, long.lambda_s) < 1e-9 && rel(last.lambda_z, long.lambda_z) < 1e-9,
        "{last:?} vs {long:?}"
    );
    assert!(rel(last.force, p.g_infinity() * long.force) < 1e-9);
}

/// A squeeze–release cycle at a plate speed (gas closed; inflated by a jump to λs = 1.3 and
/// held there 20 τ₂, relaxed to 2e-9 of g₂; plates from first contact to ρ = 1.0 and back in
/// T each): the work the plates do over the cycle (`loop_area`) is positive, the law
/// dissipates; it vanishes in the two elastic limits, a cycle much faster than τ₁ (the
/// instantaneous law about the relaxed state) and much slower than τ₂ (the long-term law):
/// below 2 % of its largest value at T = 0.3 to 10 at T = 1e-3 and 1e4. Measured
/// (scripts/visco-study.py, the same cycle): 4.3e-7 and 1.7e-6 against 3.5e-4, 0.12 % and
/// 0.48 %, the residual memory of order T/τ₁ and τ₂/T; the bound is four times the larger.
#[test]
fn a_squeeze_release_cycle_dissipates_and_its_loop_closes_in_both_elastic_limits() {
    let p = prony();
    let law = abb();
    let area = |t: f64| {
        let program = [
            seg(Control::Stretch, Some(1.3), 0.0),
            seg(Control::Stretch, None, 200.0),
            plates(Supply::Gas, Some(1.0), t),
            plates(Supply::Gas, Some(1.3), t),
        ];
        let pts = integrate(&law, &p, Hypothesis::Gps, &program, 256).unwrap();
        loop_area(&pts)
    };
    let mid: Vec<f64> = [0.3, 1.0, 3.0, 10.0].iter().map(|&t| area(t)).collect();
    let peak = mid.iter().cloned().fold(0.0, f64::max);
    assert!(mid.iter().all(|&a| a > 0.0), "{mid:?}");
    for t in [1e-3, 1e4] {
        let a = area(t);
        assert!(a.abs() < 0.02 * peak, "T = {t}: {a} against {peak}");
    }
}
