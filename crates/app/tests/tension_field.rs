//! The `tension-field` verify kind: the annulus pulled at both rims against tension-field
//! theory through a suite, as a user writes it. With the relaxed law the FE finds the wrinkled
//! zone and carries no compression; with `wrinkling = "none"` it converges to Lamé's solution
//! and a tension-field tolerance on it fails (the kind can fail); an annulus without a
//! wrinkled zone is refused before anything runs.

use std::path::{Path, PathBuf};
use tubemem_app::verify::suite::read_suite;
use tubemem_app::verify::{run_check, Status, VerifyOptions};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tubemem-tf-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const CASE: &str = "[geometry]\nradius = 1.0\nlength = 8.0\n\n[material]\nmodel = \"mooney-rivlin\"\nshear_modulus = 2.5\nalpha = 0.1\n\n[mesh]\naround = 16\nalong = 16\nelement = \"quad9\"\n\n[solver]\nwrinkling = \"WRINKLING\"\n\n[[stage]]\nkind = \"inflate\"\ncontrol = \"pressure\"\ntarget_pressure = 0.3\nsteps = 2\n";

fn check(
    d: &Path,
    wrinkling: &str,
    extra: &str,
) -> Result<tubemem_app::verify::suite::Check, String> {
    std::fs::write(d.join("case.toml"), CASE.replace("WRINKLING", wrinkling)).unwrap();
    std::fs::write(
        d.join("suite.toml"),
        format!("[[check]]\nname = \"annulus\"\nkind = \"tension-field\"\ncase = \"case.toml\"\nmeshes = 2\nstart = 1\n{extra}"),
    )
    .unwrap();
    read_suite(&d.join("suite.toml"))
        .map(|mut s| s.1.remove(0))
        .map_err(|e| tubemem_app::error_chain(&e))
}

// the tolerances: the 9-node refinement study of verify/paper.toml's tension-field-quad9 at 16
// around (|L_FE/L − 1| = 3.3e-4, stress 2.86e-3), safety factor 1.5; the shear modulus 2.5 and
// Mooney–Rivlin law change nothing at these strains (the tractions are per μH)
const HELD: &str = "tolerance.wrinkle_radius = { value = 5e-4, source = \"study\" }\ntolerance.stress = { value = 4.3e-3, source = \"study\" }\n";

#[test]
fn the_relaxed_law_finds_the_wrinkled_zone() {
    let d = dir("relaxed");
    let r = run_check(
        &check(&d, "relaxed", HELD).unwrap(),
        &d.join("out"),
        &VerifyOptions::default(),
    );
    for m in &r.measures {
        println!("  {} {:.3e} {}", m.quantity, m.measured, m.note);
    }
    assert_eq!(r.status, Status::Pass, "{}", r.message);
    let hoop = r
        .measures
        .iter()
        .find(|m| m.quantity.starts_with("smallest hoop"))
        .unwrap();
    assert!(hoop.measured > -1e-6, "compression {}", hoop.measured);
    assert!(r.plot.is_some());
}

#[test]
fn without_relaxation_the_fe_is_lames_and_fails_tension_field_theory() {
    let d = dir("none");
    let r = run_check(
        &check(&d, "none", HELD).unwrap(),
        &d.join("out"),
        &VerifyOptions::default(),
    );
    assert_eq!(r.status, Status::Fail, "{}", r.message);
    let hoop = r
        .measures
        .iter()
        .find(|m| m.quantity.starts_with("smallest hoop"))
        .unwrap();
    // Lamé's hoop resultant at the hub is −1.27 T_out; the Gauss points sit just outside it
    assert!(hoop.measured < -1.0, "{}", hoop.measured);
    // and Lamé's own solution holds (verify/paper.toml's study: 9.55e-3 at 16 around, × 1.5)
    let lame = "tolerance.lame_stress = { value = 1.5e-2, source = \"study\" }\n";
    let r = run_check(
        &check(&d, "none", lame).unwrap(),
        &d.join("out2"),
        &VerifyOptions::default(),
    );
    assert_eq!(r.status, Status::Pass, "{}", r.message);
}

#[test]
fn an_annulus_without_wrinkles_is_refused() {
    let d = dir("taut");
    let e = check(
        &d,
        "relaxed",
        &format!("annulus = {{ r_in = 1.0, r_out = 4.0, t_in = 1.1e-4, t_out = 1e-4 }}\n{HELD}"),
    )
    .unwrap_err();
    assert!(e.contains("no wrinkled zone"), "{e}");
    assert!(e.contains("suite.toml"), "{e}");
}
