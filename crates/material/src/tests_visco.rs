//! The QLV Prony law (`viscoelastic`) against closed-form histories.
#![allow(clippy::needless_range_loop)] // loops over the Voigt components of several tensors at once

use crate::laws::{neo_hookean, AnssariBenamBucchi};
use crate::viscoelastic::{step_stress_tangent, History, Prony, PronyError, PronyTerm};
use crate::MembraneLaw;

fn two_terms() -> Prony {
    Prony::new(vec![
        PronyTerm { g: 0.3, tau: 1.0 },
        PronyTerm { g: 0.2, tau: 10.0 },
    ])
    .unwrap()
}

/// Each refused series names its term and key, or the sum.
#[test]
fn a_prony_series_it_cannot_use_is_refused_naming_the_term() {
    let t = |g, tau| PronyTerm { g, tau };
    let e = Prony::new(vec![t(0.3, 1.0), t(0.2, -1.0)]).unwrap_err();
    assert!(
        matches!(
            e,
            PronyError::Term {
                term: 1,
                key: "tau",
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().starts_with("prony[1].tau = -1"), "{e}");
    let e = Prony::new(vec![t(f64::NAN, 1.0)]).unwrap_err();
    assert!(e.to_string().starts_with("prony[0].g = NaN"), "{e}");
    let e = Prony::new(vec![t(0.6, 1.0), t(0.4, 2.0)]).unwrap_err();
    assert!(
        matches!(e, PronyError::NoLongTerm { .. }) && e.to_string().contains("g∞"),
        "{e}"
    );
    assert!(matches!(
        Prony::new(vec![]),
        Err(PronyError::Count { count: 0 })
    ));
    assert!((two_terms().g_infinity() - 0.5).abs() < 1e-15);
}

/// A stress step at t = 0 held: S⁰ constant after the jump, so the recursion is exact and S(t)
/// = S⁰·(g∞ + Σ gᵢ e^{−t/τᵢ}) for any steps (here 7 unequal ones, and one long step), to
/// rounding (1e-14 relative).
#[test]
fn a_held_stress_relaxes_with_the_relaxation_function_at_any_step() {
    let p = two_terms();
    let s0 = [1.7, 0.9, 0.2];
    let mut h = History::unloaded(2).advanced(&p.step(0.0), s0);
    let s = h.stress(&p);
    for k in 0..3 {
        assert!(
            (s[k] - s0[k]).abs() < 1e-15,
            "instantaneous: the base law's"
        );
    }
    let mut t = 0.0;
    for dt in [0.01, 0.3, 1.0, 2.5, 0.05, 7.0, 40.0] {
        let step = p.step(dt);
        h = h.advanced(&step, s0);
        t += dt;
        let g = p.relaxation(t);
        for k in 0..3 {
            let got = h.stress(&p)[k];
            assert!(
                (got / (g * s0[k]) - 1.0).abs() < 1e-14,
                "t = {t}: {got} vs {}",
                g * s0[k]
            );
        }
    }
    // long after (t = 1e4: e^{−1000} and e^{−10000} of the terms left): g∞
    assert!((p.relaxation(1e4) - 0.5).abs() < 1e-15);
}

/// S⁰ linear in time, S⁰ = a t: the recursion integrates it exactly, hᵢ = gᵢ a τᵢ (1 − e^{−t/τᵢ}),
/// whatever the steps (1e-13 relative); S⁰ = sin t: the error falls as Δt², observed order
/// within 0.05 of 2 (the update's order for a smooth history).
#[test]
fn the_update_is_exact_for_a_linear_history_and_second_order_otherwise() {
    let p = two_terms();
    let a = [0.8, -0.3, 0.1];
    let mut h = History::unloaded(2);
    let mut t = 0.0;
    for dt in [0.1, 0.5, 2.0, 0.01, 3.0] {
        t += dt;
        h = h.advanced(&p.step(dt), a.map(|v| v * t));
    }
    for (i, term) in p.terms().iter().enumerate() {
        for k in 0..3 {
            let exact = term.g * a[k] * term.tau * (1.0 - (-t / term.tau).exp());
            assert!((h.h[i][k] / exact - 1.0).abs() < 1e-13, "term {i}, {k}");
        }
    }
    // S⁰ = sin t from rest: hᵢ(t) = gᵢ (k cos t + sin t − k e^{−kt})/(k² + 1), k = 1/τᵢ
    let err = |n: usize| {
        let (t_end, dt) = (5.0_f64, 5.0 / n as f64);
        let mut h = History::unloaded(2);
        let step = p.step(dt);
        for j in 1..=n {
            h = h.advanced(&step, [(j as f64 * dt).sin(), 0.0, 0.0]);
        }
        p.terms()
            .iter()
            .zip(&h.h)
            .map(|(term, hi)| {
                let k = 1.0 / term.tau;
                let exact = term.g * (k * t_end.cos() + t_end.sin() - k * (-k * t_end).exp())
                    / (k * k + 1.0);
                (hi[0] - exact).abs()
            })
            .fold(0.0, f64::max)
    };
    let (e1, e2) = (err(100), err(200));
    let order = (e1 / e2).log2();
    assert!((order - 2.0).abs() < 0.05, "order {order} ({e1:e}, {e2:e})");
}

/// The algorithmic tangent, α times the base law's, against central differences of the step's
/// stress in C (neo-Hookean and ABB 30, a history with both terms loaded, a rotated C; step
/// 1e-6: truncation and rounding both near 1e-10, bound 1e-6 relative as the laws' own FD test).
#[test]
fn the_step_tangent_matches_finite_differences() {
    let p = two_terms();
    let laws: Vec<Box<dyn MembraneLaw>> = vec![
        Box::new(neo_hookean(1.0).unwrap()),
        Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap()),
    ];
    for law in &laws {
        let c1 = [1.44, 1.1, 0.05];
        let s1 = law.stress_tangent(c1).unwrap().s;
        let hist = History::unloaded(2).advanced(&p.step(0.2), s1);
        let step = p.step(0.35);
        let c = [1.69, 1.2, 0.12];
        let st = step_stress_tangent(law.as_ref(), &step, &hist, c).unwrap();
        let h = 1e-6;
        let at = |k: usize, d: f64| {
            let mut cc = c;
            cc[k] += d;
            step_stress_tangent(law.as_ref(), &step, &hist, cc)
                .unwrap()
                .s
        };
        for i in 0..3 {
            for (j, scale) in [(0, 2.0), (1, 2.0), (2, 1.0)] {
                let fd = scale * (at(j, h)[i] - at(j, -h)[i]) / (2.0 * h);
                let d = st.tangent[i][j];
                assert!(
                    (d - fd).abs() <= 1e-6 * d.abs().max(1e-3),
                    "{} D{i}{j}: {d} vs {fd}",
                    law.name()
                );
            }
        }
        // and the stress is α S⁰ + B: at the history's own state with Δt = 0 it is S unchanged
        let same = step_stress_tangent(law.as_ref(), &p.step(0.0), &hist, c1)
            .unwrap()
            .s;
        let s = hist.stress(&p);
        for k in 0..3 {
            assert!((same[k] - s[k]).abs() < 1e-14 * s[k].abs().max(1.0));
        }
    }
}
