//! Issue #61's data-loss findings in `gps`, `fit` and `verify`: an output that is an input is
//! refused before anything is read or written, an existing file tubemem did not write is
//! replaced only with `--overwrite`, and a check's name cannot lead its run out of `--out`.

mod common;

use common::{tmp, tubemem};
use std::path::Path;

fn refused(args: &[&str], needle: &str) {
    let o = tubemem(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains(needle),
        "{args:?}: exit {:?}, expected `{needle}` in: {err}",
        o.status.code()
    );
}

fn unchanged(path: &Path, text: &str) {
    assert_eq!(
        std::fs::read_to_string(path).unwrap(),
        text,
        "{}",
        path.display()
    );
}

#[test]
fn gps_outputs_never_replace_their_inputs_or_a_users_file() {
    let d = tmp("policy-gps");
    let ring = d.join("ring.csv");
    let ring_text = "x,y\n1.0,0.0\n0.0,1.0\n";
    std::fs::write(&ring, ring_text).unwrap();
    let r = ring.to_str().unwrap();
    // --csv is the --ring it has not read yet
    refused(
        &[
            "gps",
            "confine",
            "--material",
            "neo-hookean",
            "--initial-stretch",
            "1.3",
            "--plane=0,1,1.2",
            "--plane=0,-1,1.2",
            "--points",
            "3",
            "--csv",
            r,
            "--figure",
            d.join("f.svg").to_str().unwrap(),
            "--ring",
            r,
        ],
        "is the input",
    );
    unchanged(&ring, ring_text);
    // a user's file at --csv: refused, then replaced with --overwrite; the command's own
    // file is replaced on a second run without it
    let user = d.join("mine.csv");
    std::fs::write(&user, "my notes\n").unwrap();
    let curve = |extra: &[&str]| {
        let mut a = vec![
            "gps",
            "inflate",
            "--material",
            "neo-hookean",
            "--to",
            "2",
            "--points",
            "5",
            "--csv",
            user.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        tubemem(&a)
    };
    assert!(!curve(&[]).status.success());
    unchanged(&user, "my notes\n");
    assert!(curve(&["--overwrite"]).status.success());
    assert!(curve(&[]).status.success(), "its own file is replaced");
}

#[test]
fn fit_plot_never_replaces_its_data() {
    let d = tmp("policy-fit");
    let data = d.join("data.png");
    let text = "stretch,nominal_stress_mpa\n1.0,0.0\n1.2,0.1\n1.4,0.18\n1.6,0.25\n1.8,0.31\n";
    std::fs::write(&data, text).unwrap();
    refused(
        &[
            "fit",
            "--law",
            "neo-hookean",
            "--uniaxial",
            data.to_str().unwrap(),
            "--plot",
            d.join("data").to_str().unwrap(),
        ],
        "is the input",
    );
    unchanged(&data, text);
}

#[test]
fn a_check_named_with_dots_cannot_leave_its_folder() {
    let d = tmp("policy-verify");
    for name in ["..", ".", "..."] {
        let suite = d.join("s.toml");
        std::fs::write(
            &suite,
            format!(
                "[[check]]\nname = \"{name}\"\ncase = \"../../cases/small_abb30_ls1.2.toml\"\nkind = \"closed-form\"\ntolerance.w = {{ value = 1.0, source = \"test\" }}\n"
            ),
        )
        .unwrap();
        let out = d.join("out");
        let o = tubemem(&[
            "verify",
            suite.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            o.status.code() == Some(2) && err.contains("not only dots"),
            "{name}: {err}"
        );
        assert!(!d.join("run").exists(), "{name}: a run beside --out");
    }
}
