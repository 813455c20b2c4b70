//! Inflation of a long capped tube through its pressure maximum and the bulge that follows, by
//! arc-length continuation (`tubemem_fem::continuation`), against two independent sources:
//!
//! * the axisymmetric capped tube of `python_ref` (scikit-fem, P2 meridian, written from the
//!   membrane equations independently of the Rust code): its pressure maximum on the
//!   mid-span-stretch-controlled path, by golden section to 1e-7 in λs
//!   (`tubemem_ref.axisym.pressure_maximum(L, 1.54, 1.69, cylinder_elements=8L)`; 16L elements
//!   change it by < 1e-11): at L/R = 20, ϖmax = 0.7577382340795 at λs = 1.6097482, i.e.
//!   GPS × (1 + 1.12060e-3); at L/R = 40, ϖmax = 0.7569746324873 at λs = 1.5975167, i.e.
//!   GPS × (1 + 1.11733e-4);
//! * issue 12's closed-form values: the GPS limit point ϖ = 0.7568900627 at λs = 1.5916500471 and
//!   the Maxwell state ϖ = 0.4508393877 with the upper coexisting λs = 5.90684.
//!
//! The FE tube is an n-gon prism away from its caps, whose pressure is that of the smooth tube
//! times 1/cos(π/n) exactly (`tube.rs`); that factor is taken out before comparing. The
//! tolerance 1e-4 on the maximum and the plateau is issue 12's requirement; what is measured is
//! given beside each assertion.
use tubemem_fem::continuation::{run_arc_stage, CriticalKind};
use tubemem_fem::model::{nearest_node, Model};
use tubemem_fem::post::midspan;
use tubemem_fem::stepping::{prestress, Stage, StepSettings};
use tubemem_fixtures::abb30;
use tubemem_mesh::tube::capped_tube;
use tubemem_mesh::Symmetry;

const GPS_MAX_W: f64 = 0.7568900627;
const MAXWELL_W: f64 = 0.4508393877;
const MAXWELL_LAMBDA_S: f64 = 5.90684;

struct Located {
    kind: CriticalKind,
    w: f64,
    lambda_s: f64,
    bracket: f64,
    negative: (usize, usize),
}

struct BulgeRun {
    criticals: Vec<Located>,
    final_lambda_s: f64,
    steps: usize,
}

/// The eighth model of an L/R tube, 32 around, 4 elements per R along, from the pre-stress
/// ϖ = 0.01 by arc length to mid-span λs = 6.
fn bulge(length: f64) -> BulgeRun {
    let mesh = capped_tube(1.0, length, 32, (4.0 * length) as usize, Symmetry::Eighth).unwrap();
    let mut model = Model::new(mesh, Box::new(abb30())).unwrap();
    let node = nearest_node(model.mesh(), [1.0, 0.0, 0.0]);
    let mut state = model.reference_state();
    let stage = Stage {
        index: 1,
        from: 1.0,
        to: 6.0,
        settings: StepSettings::default(),
    };
    prestress::<()>(&mut model, &mut state, &stage).unwrap();
    let mut criticals = vec![];
    let mut steps = 0;
    let monitor = move |s: &tubemem_fem::model::State| s.x[node][0];
    run_arc_stage(
        &mut model,
        &mut state,
        &stage,
        None,
        tubemem_fem::continuation::ArcLoading::Pressure(None),
        &monitor,
        1.0,
        None,
        |_, _, _| {
            steps += 1;
            Ok::<(), ()>(())
        },
        |m, c| {
            criticals.push(Located {
                kind: c.kind,
                w: c.load,
                lambda_s: midspan(m, &c.state).unwrap().lambda_s,
                bracket: c.bracket,
                negative: (c.negative_before, c.negative_after),
            });
            Ok(())
        },
    )
    .unwrap();
    BulgeRun {
        criticals,
        final_lambda_s: midspan(&model, &state).unwrap().lambda_s,
        steps,
    }
}

fn polygon() -> f64 {
    1.0 / (std::f64::consts::PI / 32.0).cos()
}

#[test]
fn arc_length_locates_the_pressure_maximum_and_the_maxwell_plateau_of_a_bulging_tube() {
    for (length, ax_shift, ax_lambda_s) in
        [(20.0, 1.12060e-3, 1.6097482), (40.0, 1.11733e-4, 1.5975167)]
    {
        let run = bulge(length);
        assert!(
            (run.final_lambda_s - 6.0).abs() < 1e-9,
            "{}",
            run.final_lambda_s
        );
        // the target to `target_rtol` 1e-10 (above); a continuation that stalls or crawls
        // fails the step bound (27 and 47 steps measured, 100 allowed)
        assert!(run.steps < 100, "{} steps", run.steps);
        let first = &run.criticals[0];
        assert_eq!(first.kind, CriticalKind::LimitMax);
        assert!(first.bracket <= 1e-8);
        // K loses positive definiteness at the maximum: the inflation mode
        assert_eq!(first.negative, (0, 1));
        // measured: 5.9e-6 (L/R = 20) and < 1e-5 (40) from the axisymmetric shift
        let shift = first.w / (GPS_MAX_W * polygon()) - 1.0;
        assert!(
            (shift - ax_shift).abs() < 1e-4,
            "L/R = {length}: FE shift {shift:.4e} vs axisymmetric {ax_shift:.4e}"
        );
        // measured: 9e-6 relative
        assert!(
            (first.lambda_s / ax_lambda_s - 1.0).abs() < 1e-4,
            "L/R = {length}: λs at the maximum {} vs {ax_lambda_s}",
            first.lambda_s
        );
        // the plateau: every later limit point lies at the Maxwell pressure (measured 6e-6 at
        // L/R = 20, where the front is at the caps at the minimum, and 1e-9 at 40)
        let later = &run.criticals[1..];
        assert!(!later.is_empty());
        for c in later {
            let e = c.w / (MAXWELL_W * polygon()) - 1.0;
            assert!(
                e.abs() < 1e-4,
                "L/R = {length}: {:?} at ϖ {} ({e:+.2e})",
                c.kind,
                c.w
            );
        }
        let min = later
            .iter()
            .find(|c| c.kind == CriticalKind::LimitMin)
            .unwrap();
        assert_eq!(min.negative, (1, 0));
        if length >= 40.0 {
            // inside the propagating bulge (measured 1.9e-5 below Maxwell's λs)
            assert!(
                (min.lambda_s / MAXWELL_LAMBDA_S - 1.0).abs() < 1e-4,
                "bulge stretch {}",
                min.lambda_s
            );
        }
    }
}

/// The decay per R of the cap's boundary layer of the smooth axisymmetric tube at λs = 1.15969,
/// 4 R from the junction (`python_ref`: `axisym.cap_tail_decay(40.0, 1.15969,
/// cylinder_elements=320)`; `test_cap_tail_decay_is_mesh_converged` keeps this quote).
const SMOOTH_CAP_TAIL_DECAY: f64 = 13.0007;

/// The whole tube's bulge moved toward a cap at constant volume (`tubemem_fem::slide`,
/// `Model::solve_held`): L/R = 40, 8 around, 8 elements per R along, inflated by arc length to
/// 10 times its volume (a bulge with fronts near Z = ±2.2 R; the caps' junctions at ±20 R).
///
/// * Far from the caps the move is free: the energy at equal volume is that of the centred
///   bulge to round-off (measured 2026-11-30: |ΔW| ≤ 4.0e-12 of W = 573, i.e. 7e-15; bound
///   1e-13), and the held mode's eigenvalue is round-off (≤ 1.5e-16 of the diagonal, bound
///   `NEUTRAL`).
/// * Near a cap the energy grows and the hold's reaction pushes the bulge back (f > 0): the caps
///   repel the fronts, so the centred bulge is the energy minimum of the family and no
///   off-centre branch is stable. The push grows as the front approaches the cap at the rate
///   the profile's own tails decay (an interaction through the overlap of the front's tail and
///   the cap's, both decaying at the uniform part's slowest rate): f grows by 12.930, 12.928,
///   12.930, 12.931 per R over the moves 8 → 12 (fronts 9.8 → 5.8 R from the junction), the
///   cap's tail decays by 12.934 and 12.911 per R at 2–4 R; held within 1 % (5× the measured
///   spread). Against an independent source, the smooth axisymmetric tube of `python_ref` at the
///   same stretch (λs = 1.15969: the cap's layer decays by 13.0007 per R at 4 R,
///   `axisym.cap_tail_decay(40, 1.15969)`, 320 cylinder elements, converged to 2e-5): within
///   2.5 %, the discretization error measured by refinement (2026-11-30, `bulge_slide 40 PER_R 8
///   10`): along z the growth is 13.35, 12.93, 12.83 at 4, 8, 16 per R (second order, so +1.0 %
///   at 8 per R over the limit 12.80), and the 8-gon's limit is 1.5 % below the smooth tube's.
///   ΔW itself is referenced to the end of the path, converged to Newton's 1e-9 only,
///   so its ratios carry that offset (12.65 … 13.08) and are not tested. An attracting cap — the
///   premise of a stable off-centre branch — fails the sign; a different interaction, the rate.
#[test]
fn a_whole_tube_bulge_moved_toward_a_cap_costs_energy_growing_as_its_tails_decay() {
    use tubemem_fem::continuation::ArcLoading;
    use tubemem_fem::model::{State, NEUTRAL};
    use tubemem_fem::slide::{translate_bulge, Rings};
    let (length, per) = (40.0, 8.0);
    let mesh = capped_tube(1.0, length, 8, (per * length) as usize, Symmetry::None).unwrap();
    let mut model = Model::new(mesh, Box::new(abb30())).unwrap();
    let rings = Rings::new(&model).unwrap();
    let mut state = model.reference_state();
    let mesh = model.mesh().clone();
    let v0 = mesh.volume_at(&state.x);
    let stage = Stage {
        index: 1,
        from: 1.0,
        to: 10.0,
        settings: StepSettings::default(),
    };
    prestress::<()>(&mut model, &mut state, &stage).unwrap();
    let monitor = move |s: &State| mesh.volume_at(&s.x) / v0;
    run_arc_stage(
        &mut model,
        &mut state,
        &stage,
        None,
        ArcLoading::Pressure(None),
        &monitor,
        1.0,
        None,
        |_, _, _| Ok::<(), ()>(()),
        |_, _| Ok(()),
    )
    .unwrap();
    let volume = model.mesh().volume_at(&state.x);
    let w0 = model.assemble(&state.x, false, None).unwrap().energy;
    // the cap's tail: ring radius less the uniform part's, 2, 3 and 4 R from the junction
    let radii = rings.radii(&state);
    let n = radii.len();
    let (_, last) = rings.bulge(&state).unwrap();
    let uniform = radii[(last + n - 1) / 2];
    let tail = |d: usize| radii[n - 1 - 8 * d] - uniform;
    let decay = [tail(2) / tail(3), tail(3) / tail(4)];
    // move 1 R at a time, up to 13 R (the near front then 4.8 R from the junction)
    let mut current = state;
    let mut push = vec![];
    for step in 1..=13 {
        let t = translate_bulge(&model, &rings, &current, 8).unwrap();
        let mut trial = t.state;
        let (_, held) = model
            .solve_held(&mut trial, volume, &t.direction)
            .unwrap_or_else(|e| panic!("move {step}: {e}"));
        let dw = held.energy - w0;
        if step <= 5 {
            assert!(dw.abs() < 1e-13 * w0, "move {step}: {dw}");
            assert!(held.relative_eigenvalue.abs() < NEUTRAL, "move {step}");
        }
        if step >= 9 {
            assert!(
                held.force > 0.0 && dw > 0.0,
                "move {step}: f {}, ΔW {dw}",
                held.force
            );
            assert!(held.relative_eigenvalue > 0.0, "move {step}");
        }
        push.push(held.force);
        current = trial;
    }
    // moves 8 → 12 (push[7] … push[11])
    for k in 8..12 {
        let growth = push[k] / push[k - 1];
        assert!(
            (growth / SMOOTH_CAP_TAIL_DECAY - 1.0).abs() < 0.025,
            "move {}: growth {growth} against the smooth tube's {SMOOTH_CAP_TAIL_DECAY}",
            k + 1
        );
        for d in decay {
            assert!(
                (growth / d - 1.0).abs() < 0.01,
                "move {}: growth {growth} against the tail's {decay:?}",
                k + 1
            );
        }
    }
}
