//! The sphere refinement table of the README (a documented command, not a check):
//! `cargo run --release --example sphere_refinement`
//!
//! A neo-Hookean cube-sphere inflated under volume control to λ = 2 at m = 4, 8, 16 elements per
//! cube-face edge: the worst relative pressure error against Rivlin's exact ϖ = 2(1 − λ⁻⁶)/λ.
use tubemem_fixtures::sphere_curve;

fn main() {
    for m in [4, 8, 16] {
        let c = sphere_curve(
            Box::new(tubemem_material::laws::neo_hookean(1.0).expect("valid")),
            m,
            2.0,
            10,
        );
        let e = c
            .iter()
            .map(|p| {
                let ex = 2.0 * (1.0 - p.stretch.powi(-6)) / p.stretch;
                (p.w - ex).abs() / ex
            })
            .fold(0.0, f64::max);
        println!("m = {m}: worst relative error {e:.4e}");
    }
}
