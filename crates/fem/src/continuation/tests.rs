//! The continuation driver on two-unknown problems with closed-form paths.

use super::*;

/// A two-unknown problem R(u, λ) = f(u) − λ g = 0 with its stiffness K = ∂f/∂u, solved densely.
/// `fail` makes the corrector fail (to test cut-backs) when it returns true for the predicted
/// state and the arc length.
type Refusal = Box<dyn FnMut(&[f64; 3], f64) -> bool>;
type Residual = fn([f64; 2]) -> [f64; 2];
type Stiffness = fn([f64; 2]) -> [[f64; 2]; 2];

struct Two<F, K> {
    f: F,
    k: K,
    g: [f64; 2],
    fail: Refusal,
    corrections: usize,
}

fn solve2(k: [[f64; 2]; 2], r: [f64; 2]) -> [f64; 2] {
    let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    [
        (k[1][1] * r[0] - k[0][1] * r[1]) / det,
        (k[0][0] * r[1] - k[1][0] * r[0]) / det,
    ]
}

impl<F: Fn([f64; 2]) -> [f64; 2], K: Fn([f64; 2]) -> [[f64; 2]; 2]> Path for Two<F, K> {
    /// (u₁, u₂, λ)
    type State = [f64; 3];
    type Error = String;
    fn load(&self, s: &[f64; 3]) -> f64 {
        s[2]
    }
    fn weight(&self) -> f64 {
        1.0
    }
    fn difference(&self, a: &[f64; 3], b: &[f64; 3]) -> Vec<f64> {
        vec![a[0] - b[0], a[1] - b[1]]
    }
    fn predict(&self, base: &[f64; 3], tu: &[f64], tl: f64, ds: f64) -> [f64; 3] {
        [
            base[0] + ds * tu[0],
            base[1] + ds * tu[1],
            base[2] + ds * tl,
        ]
    }
    fn tangent(&mut self, s: &[f64; 3]) -> Result<Tangent, String> {
        let k = (self.k)([s[0], s[1]]);
        // LDLᵀ of the 2 × 2: pivots k₁₁ and det/k₁₁
        let d1 = k[0][0];
        let d2 = (k[0][0] * k[1][1] - k[0][1] * k[1][0]) / d1;
        let neg = usize::from(d1 < 0.0) + usize::from(d2 < 0.0);
        Ok(Tangent::new(solve2(k, self.g).to_vec(), &self.g, neg))
    }
    fn critical_mode(&mut self, s: &[f64; 3]) -> Result<Option<Vec<f64>>, String> {
        // the eigenvector of the symmetric part's eigenvalue of smallest magnitude
        let k = (self.k)([s[0], s[1]]);
        let (a, b, d) = (k[0][0], 0.5 * (k[0][1] + k[1][0]), k[1][1]);
        let m = 0.5 * (a + d);
        let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
        let mu = if (m - r).abs() < (m + r).abs() {
            m - r
        } else {
            m + r
        };
        let v = if b.abs() > 1e-300 {
            [b, mu - a]
        } else if (a - mu).abs() < (d - mu).abs() {
            [1.0, 0.0]
        } else {
            [0.0, 1.0]
        };
        Ok(Some(v.to_vec()))
    }
    fn correct(&mut self, s: &mut [f64; 3], arc: &Arc<'_, [f64; 3]>) -> Result<usize, String> {
        self.corrections += 1;
        if (self.fail)(s, arc.ds) {
            return Err(format!("refused at λ = {}", s[2]));
        }
        for it in 0..30 {
            let u = [s[0], s[1]];
            let f = (self.f)(u);
            let r = [f[0] - s[2] * self.g[0], f[1] - s[2] * self.g[1]];
            let d = self.difference(s, arc.base);
            let c = arc.w * (arc.tu[0] * d[0] + arc.tu[1] * d[1]) + arc.tl * (s[2] - arc.base[2])
                - arc.ds;
            if (r[0].hypot(r[1])) < 1e-13 && c.abs() < 1e-13 {
                return Ok(it);
            }
            // bordered: K du − g dλ = −r, w tuᵀdu + tl dλ = −c
            let k = (self.k)(u);
            let a = solve2(k, [-r[0], -r[1]]);
            let b = solve2(k, self.g);
            let hb = arc.w * (arc.tu[0] * b[0] + arc.tu[1] * b[1]) + arc.tl;
            let ha = arc.w * (arc.tu[0] * a[0] + arc.tu[1] * a[1]);
            let dl = (-c - ha) / hb;
            s[0] += a[0] + dl * b[0];
            s[1] += a[1] + dl * b[1];
            s[2] += dl;
            if !s.iter().all(|v| v.is_finite()) {
                return Err("non-finite".into());
            }
        }
        Err("no convergence".into())
    }
}

/// The shallow two-bar (von Mises) truss with a soft spring in series, loaded at the spring's
/// free end: w the apex deflection, v the loaded point. With Green strains the truss force is the
/// cubic λ = k̂ w (w − h)(w − 2h) (k̂ = EA/L₀³); the spring (k_s) carries the same force, so
/// v = w + λ/k_s. Closed form along the whole path, parametrized by w:
///   limit points of λ where dλ/dw = k̂(3w² − 6hw + 2h²) = 0: w = h(1 ∓ 1/√3);
///   snap-back of v where dv/dw = 1 + λ'(w)/k_s < 0, which happens for k_s < k̂h².
const KHAT: f64 = 1.0;
const H: f64 = 1.0;
const KS: f64 = 0.5;

fn truss_force(w: f64) -> f64 {
    KHAT * w * (w - H) * (w - 2.0 * H)
}
fn truss_stiffness(w: f64) -> f64 {
    KHAT * (3.0 * w * w - 6.0 * H * w + 2.0 * H * H)
}

fn truss() -> Two<Residual, Stiffness> {
    Two {
        // u = (w, v): R_w = λ_truss(w) − k_s (v − w), R_v = k_s (v − w) − λ
        f: |u: [f64; 2]| [truss_force(u[0]) - KS * (u[1] - u[0]), KS * (u[1] - u[0])],
        k: |u: [f64; 2]| [[truss_stiffness(u[0]) + KS, -KS], [-KS, KS]],
        g: [0.0, 1.0],
        fail: Box::new(|_, _| false),
        corrections: 0,
    }
}

#[test]
fn arc_length_follows_the_snap_back_of_a_truss_with_a_series_spring() {
    let mut p = truss();
    let v_of = |s: &[f64; 3]| s[1];
    let target = Target {
        name: "v",
        monitor: &v_of,
        value: 3.0,
    };
    let mut steps: Vec<([f64; 3], usize, bool)> = Vec::new();
    let mut events = Vec::new();
    let crit = follow(
        &mut p,
        [0.0; 3],
        &target,
        &ArcSettings::default(),
        |_, e| {
            match e {
                ArcEvent::Step(s) => {
                    steps.push((*s.state, s.negative_pivots, s.at_target));
                    events.push("step");
                }
                ArcEvent::Critical(_) => events.push("critical"),
            }
            Ok::<(), String>(())
        },
    )
    .unwrap();
    // every converged point lies on the closed-form path (Newton's tolerance, 1e-13)
    for (s, _, _) in &steps {
        assert!((s[2] - truss_force(s[0])).abs() < 1e-12, "{s:?}");
        assert!((s[1] - s[0] - s[2] / KS).abs() < 1e-12, "{s:?}");
    }
    // the path went through the snap-back: v decreased over some steps, and w went past the
    // second limit point
    assert!(steps.windows(2).any(|p| p[1].0[1] < p[0].0[1]));
    let last = steps.last().unwrap();
    assert!(last.2, "the last step is at the target");
    // the target to `target_rtol` = 1e-10 relative
    assert!((last.0[1] - 3.0).abs() <= 1e-10 * 3.0, "{:?}", last.0);
    // the two limit points, at the closed form's w = h(1 ∓ 1/√3); |Δs| ≤ 1e-8 there means an
    // error of O(Δs²) in λ (an extremum) and O(Δs) in w
    assert_eq!(crit.len(), 2, "{crit:?}");
    let wm = H * (1.0 - 1.0 / 3f64.sqrt());
    let wn = H * (1.0 + 1.0 / 3f64.sqrt());
    assert_eq!(crit[0].kind, CriticalKind::LimitMax);
    assert_eq!(crit[1].kind, CriticalKind::LimitMin);
    assert!(
        crit[0].bracket <= 1e-8 && crit[1].bracket <= 1e-8,
        "{:?}",
        crit.iter()
            .map(|c| (c.bracket, c.s, c.load))
            .collect::<Vec<_>>()
    );
    assert!((crit[0].state[0] - wm).abs() < 1e-7, "{:?}", crit[0].state);
    assert!((crit[1].state[0] - wn).abs() < 1e-7, "{:?}", crit[1].state);
    assert!((crit[0].load - truss_force(wm)).abs() < 1e-12);
    assert!((crit[1].load - truss_force(wn)).abs() < 1e-12);
    // K has one negative pivot exactly between the limit points (det K = k_s λ'(w))
    assert_eq!((crit[0].negative_before, crit[0].negative_after), (0, 1));
    assert_eq!((crit[1].negative_before, crit[1].negative_after), (1, 0));
    for (s, neg, _) in &steps {
        let expected = usize::from(truss_stiffness(s[0]) < 0.0);
        assert_eq!(*neg, expected, "{s:?}");
    }
    // critical points are reported in path order, between the steps that bracket them
    assert!(events.contains(&"critical"));
}

/// The pitchfork of the two tests below.
fn pitchfork() -> Two<Residual, Stiffness> {
    Two {
        f: |u: [f64; 2]| [u[0], u[1] * (1.0 - u[0]) + u[1].powi(3)],
        k: |u: [f64; 2]| [[1.0, 0.0], [-u[1], 1.0 - u[0] + 3.0 * u[1] * u[1]]],
        g: [1.0, 0.0],
        fail: Box::new(|_, _| false),
        corrections: 0,
    }
}

/// A pitchfork: R₁ = u₁ − λ, R₂ = u₂(1 − λ) + u₂³ (g = (1, 0)). On the primary path u₂ = 0, K =
/// diag(1, 1 − λ) loses positive definiteness at λ = 1 with its mode (0, 1) orthogonal to g, and
/// λ keeps rising: a bifurcation, not a limit point.
#[test]
fn a_pivot_change_without_a_load_turn_is_a_bifurcation_located_to_the_tolerance() {
    let mut p = pitchfork();
    let l_of = |s: &[f64; 3]| s[2];
    let target = Target {
        name: "λ",
        monitor: &l_of,
        value: 1.7,
    };
    let crit = follow(
        &mut p,
        [0.0; 3],
        &target,
        &ArcSettings::default(),
        |_, _| Ok::<(), String>(()),
    )
    .unwrap();
    assert_eq!(crit.len(), 1, "{crit:?}");
    assert_eq!(crit[0].kind, CriticalKind::Bifurcation);
    assert_eq!((crit[0].negative_before, crit[0].negative_after), (0, 1));
    assert!(crit[0].bracket <= 1e-8);
    // the located point is the first past the change, within the bracket of λ = 1 (here s = λ)
    assert!(
        crit[0].load >= 1.0 && crit[0].load - 1.0 <= 2e-8,
        "{}",
        crit[0].load
    );
}

/// A corrector that fails for long steps in a window of the path halves the step and goes on;
/// every converged step reaches the observer, numbered without gaps. A corrector that fails
/// for good stops the stage with the step, the load and the cause, after the converged steps
/// were all reported.
#[test]
fn failed_steps_are_cut_back_and_no_converged_step_is_lost() {
    let mut p = truss();
    p.fail = Box::new(|s, ds| s[2] > 0.2 && s[2] < 0.3 && ds > 0.01);
    let v_of = |s: &[f64; 3]| s[1];
    let target = Target {
        name: "v",
        monitor: &v_of,
        value: 3.0,
    };
    let mut numbers = Vec::new();
    let mut cut = 0;
    follow(
        &mut p,
        [0.0; 3],
        &target,
        &ArcSettings::default(),
        |_, e| {
            if let ArcEvent::Step(s) = e {
                numbers.push(s.step);
                cut += s.cuts;
            }
            Ok::<(), String>(())
        },
    )
    .unwrap();
    assert!(cut > 0, "the window forced cut-backs");
    assert_eq!(numbers, (1..=numbers.len()).collect::<Vec<_>>());

    let mut p = truss();
    p.fail = Box::new(|s, _| s[2] > 0.25);
    let mut reported = Vec::new();
    let err = follow(
        &mut p,
        [0.0; 3],
        &target,
        &ArcSettings::default(),
        |_, e| {
            if let ArcEvent::Step(s) = e {
                reported.push(*s.state);
            }
            Ok::<(), String>(())
        },
    )
    .unwrap_err();
    match err {
        ArcError::Stalled {
            step, load, source, ..
        } => {
            assert_eq!(step, reported.len() + 1);
            assert_eq!(load, reported.last().unwrap()[2]);
            assert!(source.contains("refused"), "{source}");
        }
        e => panic!("{e}"),
    }
    assert!(!reported.is_empty());
    let msg = ArcError::<String, String>::StepLimit {
        steps: 3,
        load: 0.5,
        monitor: 1.0,
    }
    .to_string();
    assert!(msg.contains("without reaching the target"), "{msg}");
}

/// Branch switching at the pitchfork: the path leaves u₂ = 0 at λ = 1 along the critical mode
/// (0, 1) and follows the bifurcated branch u₂² = λ − 1, on which K₂₂ = 2(λ − 1) > 0 (stable,
/// no negative pivot), to λ = 1.7, where u₂ = ±√0.7.
#[test]
fn branch_switching_follows_the_stable_branch_of_a_pitchfork() {
    let mut p = pitchfork();
    let l_of = |s: &[f64; 3]| s[2];
    let target = Target {
        name: "λ",
        monitor: &l_of,
        value: 1.7,
    };
    let settings = ArcSettings {
        switch_fraction: Some(0.5),
        ..ArcSettings::default()
    };
    let mut after = Vec::new();
    let mut switched_seen = false;
    let crit = follow(&mut p, [0.0; 3], &target, &settings, |_, e| {
        match e {
            ArcEvent::Critical(c) => switched_seen = c.switched.is_some(),
            ArcEvent::Step(s) if switched_seen => after.push((*s.state, s.negative_pivots)),
            _ => {}
        }
        Ok::<(), String>(())
    })
    .unwrap();
    assert_eq!(crit.len(), 1);
    assert!(crit[0].switched.is_some_and(|d| d > 0.0));
    assert!(!after.is_empty());
    // on the closed-form branch to the corrector's tolerance (1e-13 on R and the constraint);
    // the target λ to `target_rtol` 1e-10, and u₂ = √(λ − 1) then to 1e-10/(2·√0.7) < 1e-9
    for (s, neg) in &after {
        assert!(
            (s[1] * s[1] - (s[2] - 1.0)).abs() < 1e-12,
            "{s:?} off u₂² = λ − 1"
        );
        assert_eq!(*neg, 0, "{s:?}");
    }
    let last = after.last().unwrap().0;
    assert!((last[2] - 1.7).abs() < 1e-10 && (last[1].abs() - 0.7f64.sqrt()).abs() < 1e-9);
}

/// A fresh stage sets out towards its target: from a point on the truss's rising branch
/// (w = 0.2) with the target v = 0.05 behind it, the path goes back down, and ends on the
/// closed-form path at v = 0.05 without passing a limit point.
#[test]
fn a_fresh_stage_sets_out_towards_its_target() {
    let mut p = truss();
    let w0 = 0.2;
    let start = [w0, w0 + truss_force(w0) / KS, truss_force(w0)];
    let v_of = |s: &[f64; 3]| s[1];
    let target = Target {
        name: "v",
        monitor: &v_of,
        value: 0.05,
    };
    let mut last = start;
    let crit = follow(&mut p, start, &target, &ArcSettings::default(), |_, e| {
        if let ArcEvent::Step(s) = e {
            last = *s.state;
        }
        Ok::<(), String>(())
    })
    .unwrap();
    assert!(crit.is_empty(), "{crit:?}");
    assert!(
        // the target to `target_rtol` = 1e-10 relative; on the path to the corrector's 1e-13
        (last[1] - 0.05).abs() < 1e-10 * 0.05 && (last[2] - truss_force(last[0])).abs() < 1e-12,
        "{last:?}"
    );
    assert!(last[0] < w0);
}

/// Targets just before the truss's load maximum, reached in steps long enough to cross the
/// maximum as well: each stage ends at its target, on the rising branch, and reports no limit
/// point (it lies beyond the target). For δ = 1e-4 the last step's end lies past the maximum:
/// located before the target was, the maximum used to be reported.
#[test]
fn a_critical_point_beyond_the_target_is_not_reported() {
    let wm = H * (1.0 - 1.0 / 3f64.sqrt());
    let vm = wm + truss_force(wm) / KS;
    for delta in [1e-4, 3e-4, 1e-3, 3e-3, 1e-2] {
        let mut p = truss();
        let v_of = |s: &[f64; 3]| s[1];
        let target = Target {
            name: "v",
            monitor: &v_of,
            value: vm - delta,
        };
        let settings = ArcSettings {
            initial_steps: 1,
            max_ds_factor: 8.0,
            ..ArcSettings::default()
        };
        let mut last = [0.0; 3];
        let crit = follow(&mut p, [0.0; 3], &target, &settings, |_, e| {
            if let ArcEvent::Step(s) = e {
                last = *s.state;
            }
            Ok::<(), String>(())
        })
        .unwrap();
        assert!(crit.is_empty(), "δ = {delta}: {crit:?}");
        // the target to its tolerance, `target_rtol` = 1e-10 relative
        assert!(
            last[0] < wm && (last[1] - (vm - delta)).abs() < 1e-10 * vm,
            "δ = {delta}: {last:?}"
        );
    }
}
