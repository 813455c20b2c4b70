//! The whole tube's bulge moved toward a cap at constant volume: the energy and the cap's push,
//! the evidence behind README "The whole tube and branch switching".
//!
//! ```text
//! cargo run --release -p tubemem-fem --example bulge_slide -- LENGTH PER_R AROUND VOLUME_RATIO [MOVE_R]
//! ```
//!
//! The whole capped tube (no symmetry plane), ABB 𝒩 = 30, `AROUND` elements around and `PER_R`
//! per R along, is inflated by arc length until its volume is `VOLUME_RATIO` times the
//! reference volume (a bulge with two fronts). The bulge is then moved toward the +Z cap by
//! whole rows ([`tubemem_fem::slide::translate_bulge`], 1 R at a time, less near the cap) and
//! relaxed at the same volume with its position held ([`Model::solve_held`]), up to `MOVE_R`
//! (default: as far as it goes). Printed:
//! - the decay of the profile's tail at the +Z cap (ring radius minus the uniform part's, per R);
//! - for each move: the fronts (ring radius halfway between the narrowest and the widest), ϖ,
//!   the membrane energy W − W(centred) at the same volume, the hold's reaction f along the
//!   move (f > 0: the energy grows as the bulge approaches the cap — the cap pushes it back),
//!   the held mode's eigenvalue over K's largest diagonal entry, and Newton's iterations;
//! - the growth of W − W(centred) per R of approach.
mod common;

use tubemem_fem::model::State;
use tubemem_fem::slide::{translate_bulge, Rings};

fn main() -> std::process::ExitCode {
    common::main_with(
        "bulge_slide",
        "bulge_slide LENGTH PER_R AROUND VOLUME_RATIO [MOVE_R]",
        run,
    )
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = common::Args::new();
    let (length, per, around, ratio) = (
        args.positive(0, "LENGTH")?,
        args.positive(1, "PER_R")?,
        args.positive(2, "AROUND")?,
        args.positive(3, "VOLUME_RATIO")?,
    );
    let max_move = if args.len() > 4 {
        args.positive(4, "MOVE_R")?
    } else {
        f64::INFINITY
    };
    let stage = common::stage(ratio);
    let (mut model, mut state) = common::whole_tube(length, per, around, &stage)?;
    let rings = Rings::new(&model)?;
    let v0 = model.mesh().volume() * model.multiplicity();
    let mesh = model.mesh().clone();
    let mult = model.multiplicity();
    let monitor = move |s: &State| mult * mesh.volume_at(&s.x) / v0;
    let t0 = std::time::Instant::now();
    let mut steps = 0;
    common::follow(&mut model, &mut state, &stage, &monitor, |step, _, _, _| {
        steps = step
    })
    .map_err(|e| match e {
        tubemem_fem::stepping::StageError::Solve(e) => format!("inflation: {e}"),
        _ => "inflation".to_string(),
    })?;
    let volume = mult * model.mesh().volume_at(&state.x);
    let w0 = model.assemble(&state.x, false, None)?.energy;
    println!(
        "L/R = {length}, {per} per R along, {around} around: V/V0 = {:.6} after {steps} steps ({:.1} s), ϖ = {:.10}, W = {w0:.10}, fronts {:?}",
        volume / v0,
        t0.elapsed().as_secs_f64(),
        state.p,
        rings.fronts(model.mesh(), &state)
    );
    // the tail at the +Z cap: ring radius less the uniform part's, halfway to the bulge
    let radii = rings.radii(&state);
    let n = radii.len();
    let (_, last) = rings.bulge(&state).ok_or("no bulge at that volume")?;
    let uniform = radii[(last + n - 1) / 2];
    let rows = per as usize;
    println!("cap tail: distance from the cap junction (R), r − r_uniform, ratio per R");
    let mut tail = vec![];
    for j in 0..6 {
        let i = n - 1 - j * rows;
        tail.push(radii[i] - uniform);
        println!(
            "  {j} {:+.4e} {}",
            radii[i] - uniform,
            if j > 0 {
                format!("{:.3}", tail[j - 1] / tail[j])
            } else {
                String::new()
            }
        );
    }
    println!("moved (R), fronts, ϖ, W − W(centred), reaction f, held eigenvalue, Newton its");
    let mut current = state.clone();
    let mut moved = 0usize;
    let mut step = rows as isize;
    let mut energies = vec![];
    while (moved as f64) / per < max_move {
        let t = match translate_bulge(&model, &rings, &current, step) {
            Ok(t) => t,
            Err(_) if step > 1 => {
                step /= 2;
                continue;
            }
            Err(e) => {
                println!("stop: {e}");
                break;
            }
        };
        let mut trial = t.state;
        match model.solve_held(&mut trial, volume, &t.direction) {
            Ok((report, held)) => {
                // the bulge must have gone where it was put: within half the move (near the
                // cap the held relaxation pushes it back and the move means nothing more)
                let before = rings.fronts(model.mesh(), &current);
                let after = rings.fronts(model.mesh(), &trial);
                let went = after.last().zip(before.last()).map(|(a, b)| a - b);
                if went.is_none_or(|d| (d - step as f64 / per).abs() > 0.5 * step as f64 / per) {
                    println!(
                        "stop: a move of {step} rows moved the front by {:?} R (the cap holds it off)",
                        went
                    );
                    break;
                }
                moved += step as usize;
                let dw = held.energy - w0;
                println!(
                    "  {:.3} {:?} {:.10} {dw:+.4e} {:+.4e} {:+.3e} {}",
                    moved as f64 / per,
                    rings.fronts(model.mesh(), &trial),
                    trial.p,
                    held.force,
                    held.relative_eigenvalue,
                    report.iterations
                );
                if moved.is_multiple_of(rows) {
                    energies.push((dw, held.force));
                }
                current = trial;
            }
            Err(e) if step > 1 => {
                println!(
                    "  (a move of {step} rows failed: {}; halving)",
                    common::chain(&e)
                );
                step /= 2;
            }
            Err(e) => {
                println!("stop: {}", common::chain(&e));
                break;
            }
        }
    }
    // W − W(centred) is round-off (1e-14 of W) until the front is about 10 R from the cap, and
    // is referenced to the path's end (converged to Newton's tolerance only); the reaction is
    // local to each held state
    println!("growth per R of approach of the reaction f and of W − W(centred) (where f > 1e-12):");
    for w in energies.windows(2) {
        if w[0].1 > 1e-12 {
            println!("  f {:.3}   ΔW {:.3}", w[1].1 / w[0].1, w[1].0 / w[0].0);
        }
    }
    Ok(())
}
