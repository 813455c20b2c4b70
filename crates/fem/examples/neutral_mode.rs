//! The smallest eigenvalue of the pressure-control stiffness along the whole tube's symmetric
//! bulging path, and what its mode is: the evidence behind README "The whole tube and branch
//! switching".
//!
//! ```text
//! cargo run --release -p tubemem-fem --example neutral_mode -- LENGTH PER_R AROUND [EVERY]
//! ```
//!
//! The whole capped tube (no symmetry plane), ABB 𝒩 = 30, `AROUND` elements around and `PER_R`
//! per R along, is inflated by arc length towards mid-span λs = 6 (as `tubemem run` does for an
//! arc-length stage). At every `EVERY`-th converged step (default 1) it prints ϖ, the mid-span
//! λs, the negative pivots of K = K_int − ϖH, and, by 30 inverse iterations on K's LDLᵀ, the
//! eigenvalue μ of smallest magnitude over K's largest diagonal entry (unit mode φ), the share of φ's squared norm in axial
//! displacements, gᵀφ/‖g‖ (g = ∂V/∂x: zero for a mode that does not change the volume, such as
//! a translation of a symmetric bulge) and ‖K⁻¹g‖. The run's own end (the target, or why the
//! continuation stopped) comes last.
use tubemem_fem::continuation::{run_arc_stage, ArcLoading};
use tubemem_fem::model::{nearest_node, Load, Model};
use tubemem_fem::post::midspan;
use tubemem_fem::stepping::{prestress, Stage, StepSettings};
use tubemem_mesh::tube::capped_tube;
use tubemem_mesh::Symmetry;

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("neutral_mode: {e}\nusage: neutral_mode LENGTH PER_R AROUND [EVERY]");
            std::process::ExitCode::from(2)
        }
    }
}

/// The largest mesh this example builds: 2 million nodes (the CLI's own resource guards do not
/// apply here).
const MAX_NODES: f64 = 2e6;

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, name: &str| -> Result<f64, String> {
        let a = args.get(i).ok_or(format!("missing {name}"))?;
        a.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or(format!("{name} = {a:?}: a positive number"))
    };
    let (length, per, around) = (arg(0, "LENGTH")?, arg(1, "PER_R")?, arg(2, "AROUND")?);
    let every = if args.len() > 3 {
        arg(3, "EVERY")? as usize
    } else {
        1
    }
    .max(1);
    if around * per * length > MAX_NODES {
        return Err(format!(
            "{around} around × {} along is more than {MAX_NODES} nodes",
            per * length
        )
        .into());
    }
    let mesh = capped_tube(
        1.0,
        length,
        around as usize,
        (per * length) as usize,
        Symmetry::None,
    )?;
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0)?;
    let mut model = Model::new(mesh, Box::new(law))?;
    println!(
        "L/R = {length}, {per} per R along, {around} around, {} equations",
        model.n_eq()
    );
    let node = nearest_node(model.mesh(), [1.0, 0.0, 0.0]);
    let mut state = model.reference_state();
    let stage = Stage {
        index: 1,
        from: 1.0,
        to: 6.0,
        settings: StepSettings::default(),
    };
    prestress::<()>(&mut model, &mut state, &stage).map_err(|e| match e {
        tubemem_fem::stepping::StageError::Solve(e) => format!("pre-stress: {e}"),
        _ => "pre-stress".to_string(),
    })?;
    let monitor = move |s: &tubemem_fem::model::State| s.x[node][0];
    let mut states = vec![];
    let t0 = std::time::Instant::now();
    let end = run_arc_stage(
        &mut model,
        &mut state,
        &stage,
        None,
        ArcLoading::Pressure(None),
        &monitor,
        1.0,
        None,
        |_, s, info| {
            if info.step % every == 0 || info.fraction >= 1.0 {
                states.push((info.step, s.clone(), info.newton.inertia.negative_pivots));
            }
            Ok::<(), ()>(())
        },
        |_, _| Ok(()),
    );
    let seconds = t0.elapsed().as_secs_f64();
    println!("step ϖ λs negative_pivots μ/max(diag K) axial_share gᵀφ/‖g‖ ‖K⁻¹g‖");
    for (step, s, neg) in &states {
        let ms = midspan(&model, s)?;
        let load = Load::pressure(s.p);
        let (m, _) = model.mode_report(s, &load, tubemem_fem::continuation::NEUTRAL_ITERATIONS)?;
        let (b, _, _) = model.pressure_tangent(s, &load)?;
        println!(
            "{step} {:.8} {:.5} {neg} {:.3e} {:.3} {:.2e} {:.3e}",
            s.p,
            ms.lambda_s,
            m.relative_eigenvalue,
            m.axial_share,
            m.volume_change,
            b.iter().map(|a| a * a).sum::<f64>().sqrt()
        );
    }
    match end {
        Ok(_) => println!("reached λs = 6 ({seconds:.1} s)"),
        Err(tubemem_fem::stepping::StageError::Solve(e)) => {
            println!("stopped after {seconds:.1} s: {e}")
        }
        Err(_) => println!("stopped after {seconds:.1} s"),
    }
    Ok(())
}
