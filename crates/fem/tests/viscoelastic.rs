//! Issue #63: the FE in time with a quasi-linear viscoelastic (Prony) law
//! (`tubemem_fem::memory`), against the GPS DAE of the same law (`tubemem_gps::visco`) and
//! the elastic FE in its two exact limits.

use tubemem_fem::model::{Load, Model, State};
use tubemem_fem::post::midspan;
use tubemem_gps::visco::{integrate, Control, Segment, TimePoint};
use tubemem_gps::Hypothesis;
use tubemem_material::laws::AnssariBenamBucchi;
use tubemem_material::viscoelastic::{Prony, PronyTerm};
use tubemem_mesh::tube::capped_tube_of;
use tubemem_mesh::{ElementKind, Symmetry};

/// The two-term relaxation of the GPS tests (g∞ = 0.5).
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

/// The paper's tube (ABB 𝒩 = 30), 9-node elements, `around` around, L/R = `length`, elements
/// along of the shipped cases' aspect (4 per R at 32 around), an eighth modelled.
fn tube(around: usize, length: f64, viscoelastic: bool) -> Model {
    tube_of(around, length, abb(), viscoelastic.then(prony))
}

/// [`tube`] with the base law `law` and, if given, the relaxation `prony`.
fn tube_of(
    around: usize,
    length: f64,
    law: impl tubemem_material::MembraneLaw + 'static,
    prony: Option<Prony>,
) -> Model {
    let along = (length * around as f64 / 8.0) as usize;
    let mesh = capped_tube_of(
        ElementKind::Quad9,
        1.0,
        length,
        around,
        along,
        Symmetry::Eighth,
    )
    .unwrap();
    let mut model = Model::new(mesh, Box::new(law)).unwrap();
    if let Some(p) = prony {
        model.set_viscoelastic(p);
    }
    model
}

/// Ramp the pressure to `w` in `substeps` jumps of zero length (each committed: jumps compose
/// exactly), as an elastic inflation is load-stepped.
fn jump_to(model: &mut Model, state: &mut State, w: f64, substeps: usize) {
    model.set_time_step(0.0).unwrap();
    for k in 1..=substeps {
        model
            .solve(state, &Load::pressure(w * k as f64 / substeps as f64))
            .unwrap();
        model.commit_time_step(state).unwrap();
    }
}

/// One step of `dt` at pressure `w`, committed; the mid-span (λs, λz).
fn step(model: &mut Model, state: &mut State, w: f64, dt: f64) -> (f64, f64) {
    model.set_time_step(dt).unwrap();
    model.solve(state, &Load::pressure(w)).unwrap();
    model.commit_time_step(state).unwrap();
    let m = midspan(model, state).unwrap();
    (m.lambda_s, m.lambda_z)
}

fn seg(target: Option<f64>, duration: f64) -> Segment {
    Segment {
        control: Control::Pressure,
        target,
        duration,
    }
}

/// Creep of the paper's tube (ABB 30, two Prony terms, g∞ = 0.5) at ϖ = 0.3 after a jump,
/// held 50 time units (5 τ₂) in 25 steps, 9-node elements, 32 around, L/R = 40: the mid-span
/// λs(t), λz(t) against the GPS DAE over the same steps (the same update, so the temporal
/// errors agree and what is left is the mesh's and the end's) within 1e-5 at every step, the
/// issue's bound. The jump's end is the elastic FE at ϖ (α = 1 and B = 0 to rounding).
#[test]
fn creep_of_the_papers_tube_follows_the_gps_dae_at_every_step() {
    let (w, hold, steps) = (0.3, 50.0, 25);
    let dae = integrate(
        &abb(),
        &prony(),
        Hypothesis::Gps,
        &[seg(Some(w), 0.0), seg(None, hold)],
        steps,
    )
    .unwrap();
    let mut model = tube(32, 40.0, true);
    let mut state = model.reference_state();
    jump_to(&mut model, &mut state, w, 4);
    let mut elastic = tube(32, 40.0, false);
    let mut el_state = elastic.reference_state();
    for k in 1..=4 {
        elastic
            .solve(&mut el_state, &Load::pressure(w * k as f64 / 4.0))
            .unwrap();
    }
    // the jump's substeps after the first have B = Σ gᵢ (S⁰ₖ − S⁰ₖ₋₁) + … − (1 − g∞) S⁰ₖ, zero but
    // for rounding (1e-16 of the stress), so the states agree to the solve's round-off
    let dx = state
        .x
        .iter()
        .zip(&el_state.x)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0_f64, f64::max);
    eprintln!("t = 0⁺: max |x − x_elastic| = {dx:e} R");
    assert!(dx < 1e-12, "t = 0⁺ is the elastic state: {dx:e}");
    let m = midspan(&model, &state).unwrap();
    let mut rows = vec![(0.0, m.lambda_s, m.lambda_z, dae[1])];
    for k in 0..steps {
        let (ls, lz) = step(&mut model, &mut state, w, hold / steps as f64);
        rows.push((dae[k + 2].time, ls, lz, dae[k + 2]));
    }
    let mut worst = 0.0_f64;
    for (t, ls, lz, d) in &rows {
        let (es, ez) = (ls / d.lambda_s - 1.0, lz / d.lambda_z - 1.0);
        eprintln!(
            "t = {t:6.2}: FE λs {ls:.9} λz {lz:.9}; DAE λs {:.9} λz {:.9}; rel {es:+.2e} {ez:+.2e}",
            d.lambda_s, d.lambda_z
        );
        worst = worst.max(es.abs()).max(ez.abs());
    }
    let (first, last): (&TimePoint, &TimePoint) = (&rows[0].3, &rows[rows.len() - 1].3);
    // the hold creeps: λs grows by far more than the bound
    assert!(last.lambda_s - first.lambda_s > 1e-2, "{first:?} {last:?}");
    assert!(worst < 1e-5, "worst FE/DAE − 1 = {worst:e}");
    // t → ∞: one step of 10¹² (γᵢ = τᵢ/Δt ≤ 1e-11) forgets the history and leaves g∞ × the
    // base law, i.e. the elastic tube at ϖ/g∞ (the equations are linear in the law's scale):
    // within the issue's 1e-9
    step(&mut model, &mut state, w, 1e12);
    let long = w / prony().g_infinity();
    for k in 1..=4 {
        let p = w + (long - w) * k as f64 / 4.0;
        elastic.solve(&mut el_state, &Load::pressure(p)).unwrap();
    }
    let (v, e) = (
        midspan(&model, &state).unwrap(),
        midspan(&elastic, &el_state).unwrap(),
    );
    let far = (v.lambda_s / e.lambda_s - 1.0)
        .abs()
        .max((v.lambda_z / e.lambda_z - 1.0).abs());
    eprintln!(
        "t → ∞: λs {} λz {} against the elastic tube at ϖ/g∞ = {long}: {far:e}",
        v.lambda_s, v.lambda_z
    );
    assert!(far < 1e-9, "{far:e}");
}

/// The FE's observed temporal order on a ramped creep (ϖ 0 → 0.3 over τ₁, held 10 τ₁;
/// 16 around, L/R = 20, 9-node): the end λs with N = 4, 8, 16, 32 steps per segment. The update
/// is exact for a base-law stress linear in time within a step and second order otherwise
/// (`tubemem_gps::visco::ORDER`); the FE and the DAE take the same update, so the FE's
/// temporal error is the DAE's: their difference stays at the mesh's error whatever N.
#[test]
fn the_fe_in_time_converges_at_the_updates_second_order() {
    let (w, ramp, hold) = (0.3, 1.0, 10.0);
    let mut fe = Vec::new();
    let mut dae = Vec::new();
    for n in [4, 8, 16, 32] {
        let mut model = tube(16, 20.0, true);
        let mut state = model.reference_state();
        let mut last = (0.0, 0.0);
        for k in 1..=n {
            last = step(
                &mut model,
                &mut state,
                w * k as f64 / n as f64,
                ramp / n as f64,
            );
        }
        for _ in 0..n {
            last = step(&mut model, &mut state, w, hold / n as f64);
        }
        fe.push(last.0);
        let d = integrate(
            &abb(),
            &prony(),
            Hypothesis::Gps,
            &[seg(Some(w), ramp), seg(None, hold)],
            n,
        )
        .unwrap();
        dae.push(d[d.len() - 1].lambda_s);
    }
    let order = |y: &[f64], i: usize| ((y[i] - y[i + 1]) / (y[i + 1] - y[i + 2])).abs().log2();
    let (fe_orders, dae_orders) = (
        [order(&fe, 0), order(&fe, 1)],
        [order(&dae, 0), order(&dae, 1)],
    );
    let gaps: Vec<f64> = fe.iter().zip(&dae).map(|(a, b)| a / b - 1.0).collect();
    eprintln!("end λs, FE {fe:?}, DAE {dae:?}");
    eprintln!("observed orders: FE {fe_orders:?}, DAE {dae_orders:?}; FE/DAE − 1 {gaps:?}");
    // second order: p within ±0.2 of 2 (the asymptotic range; the measured values are in the
    // closing note and the book)
    for p in fe_orders.iter().chain(&dae_orders) {
        assert!((p - 2.0).abs() < 0.2, "{fe_orders:?} {dae_orders:?}");
    }
    // the FE's temporal error is the DAE's: the FE−DAE gap moves by less than a hundredth of
    // the temporal error between the coarsest and the finest N
    let temporal = (fe[0] - fe[3]).abs();
    let spread = gaps.iter().fold(f64::NEG_INFINITY, |m, &g| m.max(g))
        - gaps.iter().fold(f64::INFINITY, |m, &g| m.min(g));
    assert!(
        spread < 0.01 * temporal,
        "spread {spread:e} vs temporal {temporal:e}"
    );
}

/// One row of a squeeze–hold–release cycle: the FE's mid-span and the GPS DAE driven by the
/// FE's own time steps, plate position and pressure.
#[derive(Clone, Copy, Debug)]
struct CycleRow {
    time: f64,
    rho: f64,
    w: f64,
    force: f64,
    dae_force: f64,
    lambda_s: f64,
    dae_lambda_s: f64,
    /// whether the mesh's node lines were on the step's contact edge (tracked, and the flat
    /// at least half an element wide)
    on_edge: bool,
}

/// The cycle: ϖ jumped to `w`, held 200 (20 τ₂) in `n` steps, then the gas closed in and two
/// plates moved from first contact (the mid-span λs) to ±`rho` over `t`, held there for `t`
/// and moved back over `t`, `n` steps each. The DAE ([`Stepper`]) takes each of the FE's steps
/// with the FE's Δt, ρ and ϖ (the closed gas of the whole tube, caps included, sets ϖ in the
/// FE; the DAE is compared at that pressure, as the elastic closed-gas squeeze is). A step
/// that Newton cannot take is split into halves, each committed; the nodes on the plates
/// move with them before each solve (the predictor: a release after a hold otherwise starts
/// with every contact point separated by more than λ/κ and no plate force at all).
fn cycle(around: usize, length: f64, w: f64, rho: f64, t: f64, n: usize) -> Vec<CycleRow> {
    cycle_with(around, length, w, rho, t, n, false)
}

/// The reference nodes of [`tube`] with the hoop node lines on the plates' contact edges at
/// the reference angle πχ/(2λs) from the plates' symmetry line (none: uniform).
fn fitted_nodes(around: usize, length: f64, chi: f64, lambda_s: f64) -> Vec<[f64; 3]> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let along = (length * around as f64 / 8.0) as usize;
    let a = PI * chi / (2.0 * lambda_s);
    let map = (chi > 0.0).then(|| {
        tubemem_mesh::hoop::HoopMap::fitted(
            around,
            &[FRAC_PI_2 - a, FRAC_PI_2 + a, 1.5 * PI - a, 1.5 * PI + a],
        )
        .unwrap()
    });
    tubemem_mesh::tube::capped_tube_fitted_of(
        ElementKind::Quad9,
        1.0,
        length,
        around,
        along,
        around / 8,
        Symmetry::Eighth,
        map.as_ref(),
    )
    .unwrap()
    .nodes
}

/// [`cycle`], with the contact edge tracked when `track`: before each step the hoop node lines
/// are put on the edge of the DAE's section at the step's ρ under the last pressure, and
/// after it on the edge under the converged pressure (solved again if the edge moved by more
/// than 0.005 of an element, the app's `TRACK_TOLERANCE`); the histories follow the moved
/// mesh (`Model::move_reference`).
fn cycle_with(
    around: usize,
    length: f64,
    w: f64,
    rho: f64,
    t: f64,
    n: usize,
    track: bool,
) -> Vec<CycleRow> {
    let mut free = vec![Free::PressureJump(w)];
    free.extend(std::iter::repeat_n(Free::Hold(200.0 / n as f64), n));
    let dt = t / n as f64;
    let legs = move |rho0: f64| -> Vec<(f64, f64)> {
        (1..=n)
            .map(|k| rho0 + (rho - rho0) * k as f64 / n as f64)
            .chain(std::iter::repeat_n(rho, n))
            .chain((1..=n).map(|k| rho + (rho0 - rho) * k as f64 / n as f64))
            .map(|r| (r, dt))
            .collect()
    };
    program(
        Tube {
            around,
            length,
            track,
        },
        &abb(),
        &prony(),
        &free,
        legs,
    )
    .1
}

/// The tube of a program: `around`, L/R = `length`, the contact edge tracked or not.
#[derive(Clone, Copy)]
struct Tube {
    around: usize,
    length: f64,
    track: bool,
}

/// A step of the free tube.
#[derive(Clone, Copy)]
enum Free {
    /// ϖ jumped to this value (four zero-length load steps)
    PressureJump(f64),
    /// from now on the enclosed volume held where it is (relaxation at fixed volume)
    FixVolume,
    /// the last load held for this time
    Hold(f64),
}

/// The FE of the tube (9-node, an eighth) with the base law `law` and the relaxation `prony`
/// through the free steps `free`, then the gas closed in and the plates moved through the
/// (ρ, Δt) of `plates` (given the mid-span λs where they start, at first contact). The DAE
/// ([`Stepper`]) takes each of the FE's steps with the FE's Δt, pressure and ρ (the closed gas
/// of the whole tube, caps included, sets ϖ in the FE; the DAE is compared at that pressure,
/// as the elastic closed-gas squeeze is). A plates step that Newton cannot take untracked is
/// split into halves, each committed; the nodes on the plates move with them before each
/// solve (the predictor: a release after a hold otherwise starts with every contact point
/// separated by more than λ/κ and no plate force at all).
fn program<L: tubemem_material::MembraneLaw + Clone + 'static>(
    tube: Tube,
    law: &L,
    prony: &Prony,
    free: &[Free],
    plates: impl Fn(f64) -> Vec<(f64, f64)>,
) -> (Vec<(f64, f64)>, Vec<CycleRow>) {
    use tubemem_fem::contact::{penalty_for, Contact, ContactPoints, Enforcement};
    use tubemem_fem::model::Loading;
    use tubemem_fem::post::midspan_contact;
    use tubemem_gps::visco::{StepLoad, Stepper};
    let Tube {
        around,
        length,
        track,
    } = tube;
    let mut dae = Stepper::new(law, prony, Hypothesis::Gps);
    let mut model = tube_of(around, length, law.clone(), Some(prony.clone()));
    let mut state = model.reference_state();
    let mut load = Load::pressure(0.0);
    // (time, ϖ) at the end of each free step
    let mut free_path = Vec::new();
    for f in free {
        match *f {
            Free::PressureJump(w) => {
                jump_to(&mut model, &mut state, w, 4);
                load = Load::pressure(w);
                dae.advance(0.0, StepLoad::Pressure(state.p)).unwrap();
            }
            Free::FixVolume => {
                load = Load::new(Loading::Volume(model.total_volume(&state.x)));
            }
            Free::Hold(dt) => {
                model.set_time_step(dt).unwrap();
                model.solve(&mut state, &load).unwrap();
                model.commit_time_step(&state).unwrap();
                dae.advance(dt, StepLoad::Pressure(state.p)).unwrap();
            }
        }
        free_path.push((dae.state().time, state.p));
    }
    let m = midspan(&model, &state).unwrap();
    let rho0 = m.lambda_s;
    let penalty = penalty_for(state.p, m.lambda_s * m.lambda_z, 1e-6);
    let pv = state.p * model.total_volume(&state.x);
    let plates_at = |r: f64| {
        Contact::plates(r, penalty)
            .with_enforcement(Enforcement::augmented())
            .with_points(ContactPoints::Nodal)
    };
    let mut at = rho0;
    let mut rows = Vec::new();
    let element = std::f64::consts::PI / around as f64 * 2.0;
    let mut fitted = 0.0_f64;
    for (target, dt) in plates(rho0) {
        if track {
            // the edge angle of the DAE's section at (ρ, ϖ), a prediction from the last state
            let edge = |w: f64| {
                let d = dae
                    .clone()
                    .advance(dt, StepLoad::PlatesAtPressure { rho: target, w })
                    .unwrap();
                (
                    d.chi,
                    d.lambda_s,
                    std::f64::consts::PI * d.chi / (2.0 * d.lambda_s),
                )
            };
            let mut refit = |model: &mut Model, state: &mut State, r: f64| -> bool {
                let (chi, ls, a) = edge(state.p);
                // a flat narrower than half an element stays on the mesh it is on (fitting it
                // would squeeze the element at the symmetry line to the flat's width)
                if a < 0.5 * element || (a - fitted).abs() <= 0.005 * element {
                    return false;
                }
                let nodes = fitted_nodes(around, length, chi, ls);
                let transfer = tubemem_mesh::hoop::Transfer::between(model.mesh(), &nodes).unwrap();
                model
                    .move_reference(nodes, &transfer, Some(&plates_at(r)), &mut [state])
                    .unwrap();
                fitted = a;
                true
            };
            refit(&mut model, &mut state, at);
            for q in state.x.iter_mut() {
                if q[1].abs() > at - 1e-6 {
                    q[1] += (target - at) * q[1].signum();
                }
            }
            model.set_time_step(dt).unwrap();
            let load = Load::with_contact(Loading::Gas { pv }, plates_at(target));
            if let Err(e) = model.solve(&mut state, &load) {
                panic!("tracked step from ρ = {at} to {target} (edge fitted at {fitted}): {e:?}");
            }
            // on the converged pressure's edge
            while refit(&mut model, &mut state, target) {
                model.solve(&mut state, &load).unwrap();
            }
            model.commit_time_step(&state).unwrap();
        }
        let mut parts = if track { 0 } else { 1 };
        while parts > 0 {
            let (mut trial, memory) = (state.clone(), model.memory().cloned().unwrap());
            let ok = (1..=parts).all(|k| {
                let r0 = at + (target - at) * (k - 1) as f64 / parts as f64;
                let r = at + (target - at) * k as f64 / parts as f64;
                for q in trial.x.iter_mut() {
                    if q[1].abs() > r0 - 1e-6 {
                        q[1] += (r - r0) * q[1].signum();
                    }
                }
                model.set_time_step(dt / parts as f64).unwrap();
                let load = Load::with_contact(Loading::Gas { pv }, plates_at(r));
                model.solve(&mut trial, &load).is_ok() && model.commit_time_step(&trial).is_ok()
            });
            if ok {
                state = trial;
                break;
            }
            model.restore_memory(memory).unwrap();
            parts *= 2;
            assert!(parts <= 64, "the step to ρ = {target} does not converge");
        }
        at = target;
        let d = dae
            .advance(
                dt,
                StepLoad::PlatesAtPressure {
                    rho: target,
                    w: state.p,
                },
            )
            .unwrap();
        let m = midspan(&model, &state).unwrap();
        let force = midspan_contact(&model, &state, &plates_at(target)).map_or(0.0, |c| c.force);
        rows.push(CycleRow {
            time: d.time,
            rho: target,
            w: state.p,
            force,
            dae_force: d.force,
            lambda_s: m.lambda_s,
            dae_lambda_s: d.lambda_s,
            on_edge: track && std::f64::consts::PI * d.chi / (2.0 * d.lambda_s) >= 0.5 * element,
        });
    }
    (free_path, rows)
}

/// The plates' work per plate and unit length over the rows (trapezoids of force × d(−ρ)),
/// the force–gap loop's area over a cycle back to first contact: FE's and the DAE's.
fn loop_areas(rows: &[CycleRow], rho0: f64) -> (f64, f64) {
    let mut last = (rho0, 0.0, 0.0);
    let mut areas = (0.0, 0.0);
    for r in rows {
        areas.0 += 0.5 * (last.1 + r.force) * (last.0 - r.rho);
        areas.1 += 0.5 * (last.2 + r.dae_force) * (last.0 - r.rho);
        last = (r.rho, r.force, r.dae_force);
    }
    areas
}

/// A squeeze–hold–release cycle of the paper's tube with the gas closed (ABB 30, two Prony
/// terms; ϖ = 0.3 held 20 τ₂, then plates from first contact to ρ = 1 over 3 τ₁, held 3 τ₁,
/// back over 3 τ₁; 9-node, L/R = 20): the mid-span force against the GPS DAE taken through
/// the FE's own steps at the FE's pressure and ρ, at 32 and 64 around, and the loop's area.
///
/// Measured (this test, 2026-12-08, 8 steps per leg): the largest |F − F_DAE| over the peak
/// force is 4.95e-3 at 32 around and 1.20e-3 at 64 (order 2.0), |λs/λs_DAE − 1| 1.77e-4 and
/// 4.76e-5, oscillating as the contact edge crosses the elements; 16 steps per leg and
/// L/R = 40 gave 5.5e-3 and 1.4e-3 to 1.5e-3 (the ignored `measure_cycle`), so the error is
/// neither the time steps' (the DAE takes the FE's) nor the ends'. It is the untracked contact
/// edge's: with the edge tracked the same cycle meets the issue's 1e-4
/// ([`with_the_contact_edge_tracked_the_cycle_meets_the_issues_1e_4`]). The loop's area agrees to
/// 3.8e-3 and 6.8e-3: it is about 4 % of the squeeze's work, so the legs' edge errors reach it
/// amplified about 25 times and do not cancel monotonically. Bounds: twice the measured
/// errors, and the force and λs errors at least halve from 32 to 64 around.
#[test]
fn a_squeeze_hold_release_cycle_follows_the_gps_dae_at_the_fes_pressure() {
    let mut worst = Vec::new();
    for around in [32, 64] {
        let rows = cycle(around, 20.0, 0.3, 1.0, 3.0, 8);
        let peak = rows.iter().fold(0.0_f64, |m, r| m.max(r.force));
        let (mut force, mut ls) = (0.0_f64, 0.0_f64);
        for r in &rows {
            force = force.max((r.force - r.dae_force).abs() / peak);
            ls = ls.max((r.lambda_s / r.dae_lambda_s - 1.0).abs());
        }
        let rho0 = rows.last().unwrap().rho;
        let (fe, dae) = loop_areas(&rows, rho0);
        eprintln!(
            "{around} around: |ΔF|/F_max {force:.2e}, |λs/λs_DAE − 1| {ls:.2e}; loop area FE {fe:.4e} DAE {dae:.4e} ({:+.2e}); ϖ {:.6} to {:.6}",
            fe / dae - 1.0,
            rows[0].w,
            rows.iter().fold(0.0_f64, |m, r| m.max(r.w))
        );
        // the law dissipates: the plates do positive work over the cycle
        assert!(dae > 0.0 && fe > 0.0, "loop areas {fe} {dae}");
        worst.push((force, ls, (fe / dae - 1.0).abs()));
    }
    let [(f32_, l32, a32), (f64_, l64, a64)] = [worst[0], worst[1]];
    assert!(f32_ < 1e-2 && l32 < 3.6e-4, "32 around: {f32_:e} {l32:e}");
    assert!(f64_ < 2.4e-3 && l64 < 9.6e-5, "64 around: {f64_:e} {l64:e}");
    assert!(
        f64_ < 0.5 * f32_ && l64 < 0.5 * l32,
        "refinement: {worst:?}"
    );
    assert!(a32 < 7.6e-3 && a64 < 1.4e-2, "loop areas: {a32:e} {a64:e}");
}

/// The cycle of [`a_squeeze_hold_release_cycle_follows_the_gps_dae_at_the_fes_pressure`] at
/// 64 around with the contact edge tracked (`cycle_with`): the issue's bound, the force
/// within 1e-4 of the DAE's (over the peak force) at every step whose flat spans at least half
/// an element, and λs within 1e-5 there. Measured (this test, 2026-12-08): at most 8.4e-6
/// and 1.6e-6 on those 21 of the 24 plates steps. The last step is back at first contact (no
/// flat, both forces 0). The other two, the first contact step and
/// the release's last step in contact, have a flat narrower than half an element, which the
/// tracker leaves on the mesh it is on (fitting it moves the node line next to the plates'
/// symmetry line onto the edge and squeezes that element to the flat's width: Newton then
/// fails from the carried state); they have the untracked error, measured 2.8e-4 and 1.8e-4,
/// bound 6e-4 (twice the larger). The loop's area (trapezoids over the same steps, FE and
/// DAE): FE/DAE − 1 = −2.43e-3, bound 5e-3 (twice); the narrow flats' force errors reach it
/// amplified, the area being about 4 % of the squeeze's work.
#[test]
fn with_the_contact_edge_tracked_the_cycle_meets_the_issues_1e_4() {
    let rows = cycle_with(64, 20.0, 0.3, 1.0, 3.0, 8, true);
    let peak = rows.iter().fold(0.0_f64, |m, r| m.max(r.force));
    let (mut on, mut off, mut ls) = (0.0_f64, 0.0_f64, 0.0_f64);
    for r in &rows {
        let e = (r.force - r.dae_force).abs() / peak;
        if r.on_edge {
            on = on.max(e);
            ls = ls.max((r.lambda_s / r.dae_lambda_s - 1.0).abs());
        } else {
            off = off.max(e);
        }
    }
    let tracked = rows.iter().filter(|r| r.on_edge).count();
    let (fe, dae) = loop_areas(&rows, rows.last().unwrap().rho);
    eprintln!(
        "tracked steps {tracked} of {}: |ΔF|/F_max {on:.2e}, |λs/λs_DAE − 1| {ls:.2e}; narrow flats {off:.2e}; loop area FE {fe:.5e} DAE {dae:.5e} ({:+.2e})",
        rows.len(),
        fe / dae - 1.0
    );
    // all but the two narrow flats and the last step, back at first contact (no flat, both
    // forces 0)
    assert!(
        tracked >= rows.len() - 3,
        "{tracked} of {} tracked",
        rows.len()
    );
    assert!(on < 1e-4 && ls < 1e-5, "tracked: {on:e} {ls:e}");
    assert!(off < 6e-4, "narrow flats: {off:e}");
    assert!((fe / dae - 1.0).abs() < 5e-3, "loop area {fe} vs {dae}");
}

/// The VHB 4910 tube held between plates: the neo-Hookean base law with the Prony series
/// fitted to the measured VHB data (the book's "Viscoelastic membranes": `tubemem fit --law
/// neo-hookean --prony-terms 3 --history …` on the 20 files; g = 0.609, 0.187, 0.080 and
/// τ = 1.45, 15.3, 127 s, g∞ = 0.123), in reduced units (μ cancels: ϖ = pR/(μH), force in
/// πμH). Inflated by a pressure jump to ϖ = 0.4 and relaxed at that volume for 250 s, then
/// the gas closed in and the plates closed in 1 s from first contact to ρ = 1.05 and held for
/// 225 s. FE (64 around, L/R = 20, the edge tracked) and the GPS DAE at the FE's pressure,
/// side by side at every step (printed).
///
/// At fixed volume every point keeps its C and every stress scales by G(t), so ϖ(t) =
/// G(t) ϖ(0⁺) holds for the FE as for the GPS section: checked at each free step to 1e-8
/// (the Newton tolerance's order; measured 8.2e-10). Measured (this test, 2026-12-08): ϖ
/// falls from 0.4 to 0.0541; the plates then meet a relaxed tube, and the grip's force ϖχ
/// relaxes little: 3.9 % in the first 50 s of the hold, then it recovers to 0.8 % below its
/// value at the end of the squeeze (FE 0.99188, GPS 0.99194; with the gas closed the plates'
/// load is the pressure's, ϖχ, and both ϖ and χ move as the membrane relaxes).
/// Force against the DAE over the peak: 6.7e-5 on the tracked steps (bound the issue's 1e-4),
/// 3.0e-3 on the three first squeeze steps, whose flat is narrower than half an element
/// (bound 6e-3, twice).
#[test]
fn a_vhb_tube_held_between_plates_relaxes_as_the_gps_dae_says() {
    let law = tubemem_material::laws::neo_hookean(1.0).unwrap();
    let vhb = Prony::new(vec![
        PronyTerm {
            g: 0.609,
            tau: 1.45,
        },
        PronyTerm {
            g: 0.187,
            tau: 15.3,
        },
        PronyTerm {
            g: 0.080,
            tau: 127.0,
        },
    ])
    .unwrap();
    let geometric = |steps: &[(usize, f64)]| -> Vec<f64> {
        steps
            .iter()
            .flat_map(|&(n, dt)| std::iter::repeat_n(dt, n))
            .collect()
    };
    let mut free = vec![Free::PressureJump(0.4), Free::FixVolume];
    free.extend(
        geometric(&[(4, 0.5), (4, 2.0), (4, 10.0), (4, 50.0)])
            .into_iter()
            .map(Free::Hold),
    );
    let (rho, squeeze, n) = (1.05, 1.0, 8);
    let hold = geometric(&[(4, 0.25), (4, 1.0), (4, 5.0), (8, 25.0)]);
    let plates = move |rho0: f64| -> Vec<(f64, f64)> {
        (1..=n)
            .map(|k| {
                (
                    rho0 + (rho - rho0) * k as f64 / n as f64,
                    squeeze / n as f64,
                )
            })
            .chain(hold.iter().map(|&dt| (rho, dt)))
            .collect()
    };
    let tube = Tube {
        around: 64,
        length: 20.0,
        track: true,
    };
    let (free_path, rows) = program(tube, &law, &vhb, &free, plates);
    let relaxed = free_path
        .iter()
        .skip(1)
        .map(|&(t, w)| (w / (0.4 * vhb.relaxation(t)) - 1.0).abs())
        .fold(0.0_f64, f64::max);
    eprintln!(
        "fixed volume: ϖ {} to {}, against 0.4 G(t) at every step within {relaxed:e}",
        free_path[0].1,
        free_path[free_path.len() - 1].1
    );
    assert!(relaxed < 1e-8, "{relaxed:e}");
    let peak = rows.iter().fold(0.0_f64, |m, r| m.max(r.force));
    let (mut on, mut off) = (0.0_f64, 0.0_f64);
    eprintln!("   t (s)      ρ        ϖ          force FE    force GPS   ΔF/F_max");
    for r in &rows {
        let e = (r.force - r.dae_force) / peak;
        eprintln!(
            "{:8.3} {:8.5} {:10.7} {:11.7} {:11.7} {e:+.2e}{}",
            r.time,
            r.rho,
            r.w,
            r.force,
            r.dae_force,
            if r.on_edge { "" } else { "  (narrow flat)" }
        );
        if r.on_edge {
            on = on.max(e.abs());
        } else {
            off = off.max(e.abs());
        }
    }
    let squeezed = rows[n - 1];
    let last = rows[rows.len() - 1];
    eprintln!(
        "force after the hold over force at the end of the squeeze: FE {:.5}, GPS {:.5}; worst tracked {on:.2e}, narrow {off:.2e}",
        last.force / squeezed.force,
        last.dae_force / squeezed.dae_force
    );
    let ratios = (
        last.force / squeezed.force,
        last.dae_force / squeezed.dae_force,
    );
    assert!((ratios.0 - ratios.1).abs() < 1e-4, "{ratios:?}");
    assert!(on < 1e-4, "tracked: {on:e}");
    assert!(off < 6e-3, "narrow flats: {off:e}");
}

/// The refinement and length study behind the bounds above (32 and 64 around, L/R = 20 and
/// 40; 16 steps per leg, `STEPS=n` to change; untracked, `TRACK=1` to track the contact edge;
/// about 2.5 min): `cargo test --release -p tubemem-fem --test viscoelastic measure_cycle --
/// --ignored --nocapture`. It prints; the tests above hold the bounds.
#[test]
#[ignore]
fn measure_cycle() {
    for (around, length) in [(32, 20.0), (64, 20.0), (32, 40.0), (64, 40.0)] {
        let track = std::env::var("TRACK").is_ok();
        let steps: usize = std::env::var("STEPS").map_or(16, |s| s.parse().unwrap());
        let rows = cycle_with(around, length, 0.3, 1.0, 3.0, steps, track);
        let (fe, dae) = loop_areas(&rows, rows.last().unwrap().rho);
        eprintln!(
            "loop area FE {fe:.5e} DAE {dae:.5e} ({:+.2e})",
            fe / dae - 1.0
        );
        let peak = rows.iter().fold(0.0_f64, |m, r| m.max(r.force));
        let mut worst = (0.0_f64, 0.0_f64);
        for r in &rows {
            let e = (r.force - r.dae_force) / peak;
            let es = r.lambda_s / r.dae_lambda_s - 1.0;
            worst = (worst.0.max(e.abs()), worst.1.max(es.abs()));
            eprintln!(
                "{around} {length}: t {:.3} rho {:.5} w {:.6} F {:.7} dae {:.7} dF/Fmax {e:+.2e} dls {es:+.2e}",
                r.time, r.rho, r.w, r.force, r.dae_force
            );
        }
        eprintln!(
            "{around} around L/R {length}: worst |dF|/Fmax {:e}, |dls| {:e}",
            worst.0, worst.1
        );
    }
}

/// Each Gauss point's (cos φ, sin φ) of the reference hoop direction in its frame, element
/// major.
fn hoop_bases(model: &Model) -> Vec<(f64, f64)> {
    let nodes = &model.mesh().nodes;
    let mut out = Vec::new();
    tubemem_fem::with_elements!(model.elements(), els => {
        for re in els.iter() {
            let x0 = re.gather(nodes);
            for gp in re.gauss.iter() {
                let p = gp.position(&x0);
                let t = nalgebra::Vector3::new(-p[1], p[0], 0.0).normalize();
                // t is tangent to the exact surface, nearly to the element's: its direction in
                // the tangent plane
                let (c, s) = (t.dot(&gp.frame[0]), t.dot(&gp.frame[1]));
                out.push((c / c.hypot(s), s / c.hypot(s)));
            }
        }
    });
    out
}

/// Moving the reference nodes along their hoops (a contact-edge refit) carries the Gauss
/// points' histories (`Memory::carry`) exactly where a history is the same at every point in
/// the (hoop, meridian) basis, as every point of a GPS section's is: a field set so on the
/// whole tube (S⁰ and two terms, no shear) is found again at every moved point, to 1e-12 of
/// its largest component (rounding).
#[test]
fn histories_carried_to_a_refitted_mesh_keep_a_uniform_section() {
    use tubemem_material::viscoelastic::History;
    let mut model = tube(16, 20.0, true);
    let mut state = model.reference_state();
    let hoop = [[0.4, 0.2, 0.0], [0.1, 0.05, 0.0], [0.03, 0.01, 0.0]];
    let frame = |[tt, mm, tm]: [f64; 3], (c, s): (f64, f64)| {
        [
            c * c * tt + s * s * mm - 2.0 * c * s * tm,
            s * s * tt + c * c * mm + 2.0 * c * s * tm,
            c * s * (tt - mm) + (c * c - s * s) * tm,
        ]
    };
    let set: Vec<History> = hoop_bases(&model)
        .into_iter()
        .map(|b| History {
            s0: frame(hoop[0], b),
            h: vec![frame(hoop[1], b), frame(hoop[2], b)],
        })
        .collect();
    model.set_histories(set).unwrap();
    let nodes = fitted_nodes(16, 20.0, 0.2, 1.25);
    let transfer = tubemem_mesh::hoop::Transfer::between(model.mesh(), &nodes).unwrap();
    let moved = nodes
        .iter()
        .zip(&model.mesh().nodes)
        .filter(|(a, b)| a != b)
        .count();
    model
        .move_reference(nodes, &transfer, None, &mut [&mut state])
        .unwrap();
    let memory = model.memory().unwrap();
    let mut worst = 0.0_f64;
    for (h, b) in memory.histories().iter().zip(hoop_bases(&model)) {
        let want = [frame(hoop[0], b), frame(hoop[1], b), frame(hoop[2], b)];
        let got = [h.s0, h.h[0], h.h[1]];
        for (w, g) in want.iter().zip(&got) {
            for k in 0..3 {
                worst = worst.max((w[k] - g[k]).abs());
            }
        }
    }
    eprintln!("{moved} nodes moved; largest change of a carried history {worst:e}");
    assert!(moved > 0);
    assert!(worst < 1e-12 * 0.4, "{worst:e}");
}
