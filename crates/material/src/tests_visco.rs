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

/// The material point's uniaxial history: a jump to λ held, the stress relaxes exactly as
/// G(t) times the base law's nominal stress (the width does not change: S₂ = G S⁰₂ = 0 at the
/// same width), to 1e-12; elastic limits of a slow and a fast ramp: `fit::nominal_stress` of
/// the base law and of g∞ × it (the long-term law) to 1e-3 and 1e-4 (ramps over 1e5 τ₂ and
/// 1e-6 τ₁, 400 steps: the residual memory is of order τ/T).
#[test]
fn a_uniaxial_history_relaxes_with_g_and_has_both_elastic_limits() {
    use crate::fit::{nominal_stress, Mode};
    use crate::viscoelastic::nominal_history;
    let p = two_terms();
    let law = AnssariBenamBucchi::new(2.0, 30.0).unwrap();
    let l = 2.5;
    let times = [0.0, 0.0, 0.5, 3.0, 20.0, 100.0];
    let stretch = [1.0, l, l, l, l, l];
    let s = nominal_history(&law, &p, false, &times, &stretch).unwrap();
    let elastic = nominal_stress(&law, Mode::Uniaxial, l).unwrap();
    for (k, &t) in times.iter().enumerate().skip(1) {
        assert!(
            (s[k] / (p.relaxation(t) * elastic) - 1.0).abs() < 1e-12,
            "t = {t}: {} vs {}",
            s[k],
            p.relaxation(t) * elastic
        );
    }
    let ramp = |total: f64| {
        let n = 400;
        let t: Vec<f64> = (0..=n).map(|i| total * i as f64 / n as f64).collect();
        let st: Vec<f64> = (0..=n)
            .map(|i| 1.0 + (l - 1.0) * i as f64 / n as f64)
            .collect();
        *nominal_history(&law, &p, false, &t, &st)
            .unwrap()
            .last()
            .unwrap()
    };
    let fast = ramp(1e-6);
    assert!(
        (fast / elastic - 1.0).abs() < 1e-4,
        "fast {fast} vs {elastic}"
    );
    let slow = ramp(1e6);
    assert!(
        (slow / (p.g_infinity() * elastic) - 1.0).abs() < 1e-3,
        "slow {slow} vs {}",
        p.g_infinity() * elastic
    );
    // equibiaxial: the jump gives the base law's equibiaxial stress
    let e = nominal_history(&law, &p, true, &[0.0, 0.0], &[1.0, 1.8]).unwrap()[1];
    let eb = nominal_stress(&law, Mode::Equibiaxial, 1.8).unwrap();
    assert!((e / eb - 1.0).abs() < 1e-12, "{e} vs {eb}");
}

/// The history fit (`fit::fit_histories_with`) recovers a known QLV law from its own
/// noise-free histories: a relaxation (ramp to λ = 3 in 2, held to 60) and a loading–unloading
/// at a rate (λ 1 → 2.5 → 1 over 20), Gent-free ABB μ = 2, 𝒩 = 30 (fixed) with g = (0.3, 0.2),
/// τ = (1, 10), from a start off by factors of 2: every parameter to 1e-6 relative (the terms
/// up to their order)
/// (exact data: the residual is round-off, the minimum is the truth), the per-test residuals
/// listed, the fit converged.
#[test]
fn a_history_fit_recovers_a_known_viscoelastic_law() {
    use crate::fit::{fit_histories_with, FitOptions, HistoryData, Mode};
    use crate::viscoelastic::nominal_history;
    use crate::MaterialSpec;
    let truth: MaterialSpec =
        serde_json::from_str(r#"{"model":"abb","shear_modulus":2.0,"kuhn":30.0}"#).unwrap();
    let law = truth.build().unwrap();
    let p = two_terms();
    let mut data = vec![];
    let relax_t: Vec<f64> = (0..=120).map(|i| 0.5 * i as f64).collect();
    let relax_l: Vec<f64> = relax_t
        .iter()
        .map(|&t| if t < 2.0 { 1.0 + t } else { 3.0 })
        .collect();
    let cyc_t: Vec<f64> = (0..=80).map(|i| 0.25 * i as f64).collect();
    let cyc_l: Vec<f64> = cyc_t
        .iter()
        .map(|&t| {
            if t <= 10.0 {
                1.0 + 0.15 * t
            } else {
                2.5 - 0.15 * (t - 10.0)
            }
        })
        .collect();
    for (name, t, l) in [("relaxation", relax_t, relax_l), ("cycle", cyc_t, cyc_l)] {
        let stress = nominal_history(law.as_ref(), &p, false, &t, &l).unwrap();
        data.push(HistoryData {
            name: name.into(),
            mode: Mode::Uniaxial,
            time: t,
            stretch: l,
            stress,
        });
    }
    let start: MaterialSpec =
        serde_json::from_str(r#"{"model":"abb","shear_modulus":1.0,"kuhn":30.0}"#).unwrap();
    let prony0 = [
        PronyTerm { g: 0.15, tau: 0.5 },
        PronyTerm { g: 0.4, tau: 20.0 },
    ];
    let mut opts = FitOptions::default();
    opts.fixed.insert("kuhn".into(), 30.0);
    let r = fit_histories_with(&start, &prony0, &data, &opts).unwrap();
    assert!(r.converged, "{}", r.stop_reason);
    let got = |n: &str| r.parameters.iter().find(|q| q.name == n).unwrap().value;
    assert!((got("shear_modulus") / 2.0 - 1.0).abs() < 1e-6);
    // the terms are found up to their order: compare them sorted by τ
    let mut terms: Vec<(f64, f64)> = (0..2)
        .map(|i| {
            (
                got(&format!("prony[{i}].tau")),
                got(&format!("prony[{i}].g")),
            )
        })
        .collect();
    terms.sort_by(|a, b| a.0.total_cmp(&b.0));
    for ((tau, g), (t0, g0)) in terms.iter().zip([(1.0, 0.3), (10.0, 0.2)]) {
        assert!(
            (tau / t0 - 1.0).abs() < 1e-6 && (g / g0 - 1.0).abs() < 1e-6,
            "{terms:?}"
        );
    }
    assert_eq!(r.tests.len(), 2);
    assert!(
        r.tests.iter().all(|t| t.max_relative < 1e-8),
        "{:?}",
        r.tests
    );
    assert_eq!(r.prony.as_ref().map(|p| p.len()), Some(2));
}
