//! The capped-tube refinement table of the README (a documented command, not a check):
//! `cargo run --release --example tube_refinement`
//!
//! ABB 𝒩 = 30, L/R = 20, eighth model, inflated to λs* = 1.3 at 32, 64, 96 and 128 around:
//! the FE mid-span against GPS (eq. 66) and PS (eq. 70).
use tubemem_fixtures::{abb30, inflate_capped_tube};
use tubemem_gps::{inflate, Hypothesis};
use tubemem_mesh::Symmetry;

fn main() {
    let law = abb30();
    for (around, along) in [(32, 80), (64, 160), (96, 240), (128, 320)] {
        let t = std::time::Instant::now();
        let tube = inflate_capped_tube(20.0, around, along, Symmetry::Eighth, 1.3);
        let ms = tube.midspan;
        let g = inflate(&law, Hypothesis::Gps, ms.lambda_s).expect("GPS");
        let p = inflate(&law, Hypothesis::Ps, ms.lambda_s).expect("PS");
        println!(
            "around {around} along {along}: {} equations, {} steps, {:.2} s",
            tube.model.n_eq(),
            tube.steps,
            t.elapsed().as_secs_f64()
        );
        println!(
            "  FE : w {:.6} ls {:.6} lz {:.6} ns {:.6} nz {:.6} nsz {:.2e}",
            ms.w, ms.lambda_s, ms.lambda_z, ms.n_s, ms.n_z, ms.n_sz
        );
        println!(
            "  GPS: w {:.6} ls {:.6} lz {:.6} ns {:.6} nz {:.6}   PS: w {:.6}",
            g.w, g.lambda_s, g.lambda_z, g.n_s, g.n_z, p.w
        );
        println!(
            "  rel: w {:.2e} (n-gon factor 1/cos(π/n) − 1 = {:.2e}) lz {:.2e} ns {:.2e} nz {:.2e}",
            ms.w / g.w - 1.0,
            1.0 / (std::f64::consts::PI / around as f64).cos() - 1.0,
            ms.lambda_z / g.lambda_z - 1.0,
            ms.n_s / g.n_s - 1.0,
            ms.n_z / g.n_z - 1.0
        );
    }
}
