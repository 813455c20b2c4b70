//! Release-mode timing of the FE solver (the README's "FE performance" figures):
//!
//! ```text
//! cargo run --release -p tubemem-fem --example newton_timing
//! ```
//! 1. a full capped tube (no symmetry) of about 100,000 unknowns: time per Newton iteration
//!    split into assembly, factorization and solve (median of 5), and the peak resident memory;
//! 2. the whole λs* = 1.3 inflation (eighth model, 96 around: mid-span ϖ error 5.4e-4 < 1e-3).
use std::time::Instant;
use tubemem_fem::model::{nearest_node, Load, Loading, Model};
use tubemem_fem::post::midspan;
use tubemem_fem::stepping::{run_stage, Stage, StepSettings};
use tubemem_material::laws::AnssariBenamBucchi;
use tubemem_mesh::{tube::capped_tube, Symmetry};

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM")).map(|l| {
                l.split_whitespace()
                    .nth(1)
                    .unwrap_or("0")
                    .parse::<f64>()
                    .unwrap_or(0.0)
            })
        })
        .unwrap_or(0.0)
        / 1024.0
}

fn main() {
    let threads = rayon::current_num_threads();
    // 2. whole case first (so its timing is not disturbed by the big model's memory)
    let t = Instant::now();
    let mesh = capped_tube(1.0, 20.0, 96, 240, Symmetry::Eighth).unwrap();
    let mut model =
        Model::new(mesh, Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap())).unwrap();
    let node = nearest_node(model.mesh(), [1.0, 0.0, 0.0]);
    let mut st = model.reference_state();
    let mut newton = 0;
    let stage = Stage {
        index: 1,
        from: 1.0,
        to: 1.3,
        settings: StepSettings {
            initial_steps: 6,
            ..Default::default()
        },
    };
    run_stage(
        &mut model,
        &mut st,
        &stage,
        |v| {
            Load::new(Loading::Node {
                node,
                component: 0,
                target: v,
            })
        },
        |_, _, info| {
            newton += info.newton.iterations;
            Ok::<(), std::convert::Infallible>(())
        },
    )
    .unwrap();
    let ms = midspan(&model, &st).unwrap();
    let gps = tubemem_gps::inflate(model.law(), tubemem_gps::Hypothesis::Gps, ms.lambda_s).unwrap();
    println!(
        "whole λs*=1.3 case, eighth model, 96 around × 240 along: {} equations, {:.3} s (mesh + {} Newton iterations), mid-span ϖ error {:.2e}, λz error {:.1e} [{threads} threads]",
        model.n_eq(),
        t.elapsed().as_secs_f64(),
        newton,
        ms.w / gps.w - 1.0,
        ms.lambda_z / gps.lambda_z - 1.0
    );

    // 1. ~100k unknowns
    let t = Instant::now();
    let mesh = capped_tube(1.0, 20.0, 128, 224, Symmetry::None).unwrap();
    let mut model =
        Model::new(mesh, Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap())).unwrap();
    let setup = t.elapsed().as_secs_f64();
    let mut st = model.reference_state();
    model.solve(&mut st, &Load::pressure(0.3)).unwrap();
    let mut runs: Vec<_> = (0..5).map(|_| model.time_iteration(&st).unwrap()).collect();
    let med = |f: &dyn Fn(&tubemem_fem::model::IterationTiming) -> f64,
               r: &mut Vec<tubemem_fem::model::IterationTiming>| {
        r.sort_by(|a, b| f(a).total_cmp(&f(b)));
        f(&r[2])
    };
    let a = med(&|x| x.assembly, &mut runs);
    let f = med(&|x| x.factorization, &mut runs);
    let s = med(&|x| x.solve, &mut runs);
    println!(
        "full tube 128 around × 224 along: {} elements, {} equations, setup (mesh, pattern, symbolic) {:.2} s; per Newton iteration (median of 5): assembly {:.3} s, factorization {:.3} s, solve {:.3} s; factor nnz {}; negative pivots {}; peak RSS {:.0} MiB [{threads} threads]",
        model.mesh().quads.len(),
        model.n_eq(),
        setup,
        a,
        f,
        s,
        runs[0].factor_nnz,
        runs[0].negative_pivots,
        peak_rss_mib()
    );
}
