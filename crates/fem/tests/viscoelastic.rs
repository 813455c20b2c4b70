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
    let mut model = Model::new(mesh, Box::new(abb())).unwrap();
    if viscoelastic {
        model.set_viscoelastic(prony());
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
    // within the 1e-9
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
