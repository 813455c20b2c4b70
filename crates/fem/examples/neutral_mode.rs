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
mod common;

use tubemem_fem::model::{nearest_node, Load};
use tubemem_fem::post::midspan;

fn main() -> std::process::ExitCode {
    common::main_with(
        "neutral_mode",
        "neutral_mode LENGTH PER_R AROUND [EVERY]",
        run,
    )
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = common::Args::new();
    let (length, per, around) = (
        args.positive(0, "LENGTH")?,
        args.positive(1, "PER_R")?,
        args.positive(2, "AROUND")?,
    );
    let every = if args.len() > 3 {
        args.positive(3, "EVERY")? as usize
    } else {
        1
    }
    .max(1);
    let stage = common::stage(6.0);
    let (mut model, mut state) = common::whole_tube(length, per, around, &stage)?;
    println!(
        "L/R = {length}, {per} per R along, {around} around, {} equations",
        model.n_eq()
    );
    let node = nearest_node(model.mesh(), [1.0, 0.0, 0.0]);
    let monitor = move |s: &tubemem_fem::model::State| s.x[node][0];
    let mut states = vec![];
    let t0 = std::time::Instant::now();
    let end = common::follow(
        &mut model,
        &mut state,
        &stage,
        &monitor,
        |step, s, neg, f| {
            if step % every == 0 || f >= 1.0 {
                states.push((step, s.clone(), neg));
            }
        },
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
