//! `tubemem verify` as a user runs it: every check kind passes where it should and fails, with
//! a clear message, where it must; the exit codes; the reports (junit.xml's structure is
//! checked by the Python tests with a real XML parser; here: its testcases and messages); the
//! HTML is self-contained.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const SMALL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../cases/small_abb30_ls1.2.toml"
);

fn tubemem(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tubemem"));
    c.args(args);
    for (k, v) in envs {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tubemem-verify-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Write a suite into `dir` and run it; (exit code, stderr, results.json).
fn verify(
    dir: &Path,
    suite: &str,
    extra: &[&str],
    envs: &[(&str, &str)],
) -> (i32, String, serde_json::Value) {
    let s = dir.join("suite.toml");
    std::fs::write(&s, suite.replace("SMALL", SMALL)).unwrap();
    let out = dir.join("out");
    let mut args = vec![
        "verify",
        s.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = tubemem(&args, envs);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    let results = std::fs::read_to_string(out.join("results.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(serde_json::Value::Null);
    (o.status.code().unwrap_or(-1), err, results)
}

fn status<'a>(r: &'a serde_json::Value, name: &str) -> (&'a str, &'a str) {
    let c = r["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no check {name} in {r}"));
    (
        c["status"].as_str().unwrap(),
        c["message"].as_str().unwrap(),
    )
}

/// Each kind on the small tube (16 around, L/R = 8, λs* = 1.2): where it should pass it
/// passes, and the same check with a tolerance it cannot meet fails and says which quantity,
/// by how much and against which source.
#[test]
fn every_kind_passes_where_it_should_and_fails_where_it_must() {
    let d = tmp("kinds");
    let suite = r#"
[[check]]
name = "cf-pass"
case = "SMALL"
kind = "closed-form"
tolerance.w = { value = 2.1e-2, source = "16-gon factor 1.96e-2 + end effect at L/R = 8" }

[[check]]
name = "cf-fail"
case = "SMALL"
kind = "closed-form"
tolerance.w = { value = 1e-6, source = "a tolerance the 16-gon cannot meet" }

[[check]]
name = "conv-pass"
case = "SMALL"
kind = "convergence"
start = -1
quantities = ["w"]
expected_order = { value = 2.0, within = 0.3, source = "polygon error O(n⁻²)" }

[[check]]
name = "conv-fail"
case = "SMALL"
kind = "convergence"
start = -1
quantities = ["w"]
expected_order = { value = 4.0, within = 0.3, source = "a wrong expectation" }

[[check]]
name = "end-pass"
kind = "end-effect"
case = { geometry = { radius = 1.0, length = 8.0 }, material = { model = "abb", shear_modulus = 1.0, kuhn = 30 }, mesh = { around = 16, along = 64, symmetry = "eighth" }, stage = [ { kind = "inflate", control = "volume", target_stretch = 1.3, steps = 4 } ] }
lengths = [4.0, 6.0, 8.0, 10.0]
law = "exponential"
decay_rate = { value = 0.78, within = 0.1, source = "axisymmetric reference k = 0.78 (8 elements per R along, as the paper suite)" }

[[check]]
name = "end-fail"
kind = "end-effect"
case = { geometry = { radius = 1.0, length = 8.0 }, material = { model = "abb", shear_modulus = 1.0, kuhn = 30 }, mesh = { around = 16, along = 64, symmetry = "eighth" }, stage = [ { kind = "inflate", control = "volume", target_stretch = 1.3, steps = 4 } ] }
lengths = [4.0, 6.0, 8.0, 10.0]
law = "exponential"
decay_rate = { value = 3.0, within = 0.1, source = "a wrong expectation" }

[[check]]
name = "inv-pass"
case = "SMALL"
kind = "invariance"
epsilon = 1e-2
min_core_fraction = { value = 0.3, source = "criterion" }

[[check]]
name = "inv-short"
kind = "invariance"
epsilon = 1e-3
min_core_fraction = { value = 0.5, source = "criterion: half the tube" }
case = { geometry = { radius = 1.0, length = 3.0 }, material = { model = "abb", shear_modulus = 1.0, kuhn = 30 }, mesh = { around = 16, along = 12, symmetry = "eighth" }, stage = [ { kind = "inflate", control = "volume", target_stretch = 1.2, steps = 4 } ] }
"#;
    let (code, err, r) = verify(&d, suite, &["--jobs", "2"], &[]);
    assert_eq!(code, 1, "a check failed: exit 1\n{err}");
    for name in ["cf-pass", "conv-pass", "end-pass", "inv-pass"] {
        assert_eq!(status(&r, name).0, "pass", "{name}: {}", status(&r, name).1);
    }
    let (s, m) = status(&r, "cf-fail");
    assert!(
        s == "fail"
            && m.contains("w: ")
            && m.contains("> 1.000e-6")
            && m.contains("a tolerance the 16-gon cannot meet"),
        "{m}"
    );
    let (s, m) = status(&r, "conv-fail");
    assert!(
        s == "fail" && m.contains("observed order 2.") && m.contains("expected 4"),
        "{m}"
    );
    let (s, m) = status(&r, "end-fail");
    assert!(
        s == "fail" && m.contains("fitted decay rate per R 0.") && m.contains("expected 3"),
        "{m}"
    );
    let (s, m) = status(&r, "inv-short");
    assert!(
        s == "fail"
            && m.contains("core fraction")
            && m.contains("< 5.000e-1")
            && m.contains("boundary layer"),
        "{m}"
    );
    // progress: a counter and a status per check
    assert!(
        err.contains("[8/8]") && err.contains("FAIL") && err.contains("PASS"),
        "{err}"
    );
    // the fitted law is in the details
    let end = r["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "end-pass")
        .unwrap();
    let k = end["details"]["fit"]["k"].as_f64().unwrap();
    // the details carry the fit itself: k within the decay_rate check's 0.78 ± 0.1 above, widened
    // to a range that only a wrong field (A, c, a residual) would leave
    assert!((0.5..1.1).contains(&k), "{k}");
    // junit: one testcase per check, failures with their message
    let junit = std::fs::read_to_string(d.join("out/junit.xml")).unwrap();
    assert_eq!(junit.matches("<testcase ").count(), 8);
    assert_eq!(junit.matches("<failure ").count(), 4);
    assert!(
        junit.contains("name=\"cf-fail\"") && junit.contains("a tolerance the 16-gon cannot meet")
    );
    // the HTML report is one self-contained file: plots inline, no URL to fetch
    let html = std::fs::read_to_string(d.join("out/report.html")).unwrap();
    assert!(html.contains("data:image/png;base64,"));
    for needle in [
        "http://",
        "https://",
        "src=\"/",
        "src=\"file",
        "<link",
        "<script src",
    ] {
        assert!(!html.contains(needle), "external reference {needle}");
    }
    for f in ["report.md", "results.json"] {
        assert!(d.join("out").join(f).is_file());
    }
    // --filter runs the matching checks only; all pass: exit 0
    let (code, _, r) = verify(&d, suite, &["--filter", "pass"], &[]);
    assert_eq!(code, 0);
    assert_eq!(r["checks"].as_array().unwrap().len(), 4);
}

/// Gold: the run reproduces its gold files; a perturbed gold file fails naming the row and the
/// column; gold files are written only with --update-gold, and their absence says so.
#[test]
fn gold_files_are_compared_and_written_on_request_only() {
    let d = tmp("gold");
    let suite = r#"
[[check]]
name = "small-gold"
case = "SMALL"
kind = "gold"
rel_err = 1e-8
"#;
    let (code, _, r) = verify(&d, suite, &[], &[]);
    assert_eq!(code, 1);
    let (s, m) = status(&r, "small-gold");
    assert!(s == "error" && m.contains("--update-gold"), "{m}");
    assert!(
        !d.join("gold").exists(),
        "nothing written without --update-gold"
    );
    let (code, _, _) = verify(&d, suite, &["--update-gold"], &[]);
    assert_eq!(code, 0);
    let (code, _, r) = verify(&d, suite, &[], &[]);
    assert_eq!(code, 0, "{}", status(&r, "small-gold").1);
    // perturb one value of the gold steps.csv by 1e-6 relative
    let p = d.join("gold/small-gold/steps.csv");
    let text = std::fs::read_to_string(&p).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut f: Vec<String> = lines[2].split(',').map(String::from).collect();
    let w: f64 = f[2].parse().unwrap();
    f[2] = format!("{}", w * (1.0 + 1e-6));
    lines[2] = f.join(",");
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
    let (code, _, r) = verify(&d, suite, &[], &[]);
    assert_eq!(code, 1);
    let (s, m) = status(&r, "small-gold");
    assert!(
        s == "fail" && m.contains("steps.csv row 2 `w`") && m.contains("against gold"),
        "{m}"
    );
}

/// The references are skipped, with the reason, when Python cannot run them; never passed.
#[test]
fn references_without_python_are_skipped_with_the_reason() {
    let d = tmp("noref");
    let suite = r#"
[[check]]
name = "ref"
case = "SMALL"
kind = "reference"
tolerance.profile = { value = 2e-3, source = "regression bound" }
"#;
    let (code, _, r) = verify(&d, suite, &[], &[("TUBEMEM_PYTHON", "/nonexistent/python")]);
    assert_eq!(code, 0, "a skipped check does not fail the run");
    let (s, m) = status(&r, "ref");
    assert!(s == "skipped" && m.contains("no Python interpreter"), "{m}");
    let junit = std::fs::read_to_string(d.join("out/junit.xml")).unwrap();
    assert!(junit.contains("<skipped message=\"no Python interpreter"));
}

/// Usage and setup errors exit with 2 and say what is wrong, where.
#[test]
fn bad_suites_exit_with_2_and_a_clear_message() {
    let d = tmp("bad");
    for (suite, needle) in [
        ("[[check]]\nname = \"x\"\ncase = \"SMALL\"\nkind = \"closed-form\"\ntolerance.w = { value = 1e-3, source = \"\" }\n", "has no `source`"),
        ("[[check]]\nname = \"x\"\ncase = \"SMALL\"\nkind = \"closed-form\"\ntolerance.pressure = { value = 1e-3, source = \"s\" }\n", "unknown quantity `pressure`"),
        ("[[check]]\nname = \"x\"\ncase = \"SMALL\"\nkind = \"magic\"\n", "unknown variant `magic`"),
        ("[[check]]\nname = \"x\"\ncase = \"missing.toml\"\nkind = \"gold\"\n", "missing.toml"),
        ("[[check]]\nname = \"x\"\ncase = \"SMALL\"\nkind = \"end-effect\"\nlengths = [4.0]\nlaw = \"inverse\"\n", "at least three"),
        ("[[check]]\nname = \"x\"\ncase = { geometry = { radius = 1.0, length = 8.0 } }\nkind = \"gold\"\n", "its case"),
        // issue #61: keys of another kind are refused, not ignored; a gold tolerance is checked
        ("[[check]]\nname = \"x\"\ncase = \"SMALL\"\nkind = \"closed-form\"\ntolerance.w = { value = 1e-3, source = \"s\" }\nrel_err = nan\n", "`rel_err` belongs to gold checks"),
        ("[[check]]\nname = \"x\"\ncase = \"SMALL\"\nkind = \"gold\"\nrel_err = nan\n", "`rel_err` = NaN: must be a finite relative tolerance"),
        ("[[check]]\nname = \"x\"\ncase = \"SMALL\"\nkind = \"gold\"\nabs_zero = -1.0\n", "`abs_zero` = -1: must be finite"),
    ] {
        let (code, err, _) = verify(&d, suite, &[], &[]);
        assert_eq!(code, 2, "{suite}\n{err}");
        assert!(err.contains(needle), "{needle}: {err}");
    }
    let o = tubemem(&["verify", "--out", d.join("o").to_str().unwrap()], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--case"));
}

/// The study of a user's case: below the limit point GPS describes the mid-span of a 16-around,
/// L/R = 16 tube;
/// a Mooney–Rivlin tube inflated past its pressure maximum (λs* = 2.0 > 1.708) is said not to
/// be described, with the instability named; a case that does not parse is exit 2.
#[test]
fn the_case_study_says_whether_gps_describes_the_tube() {
    let d = tmp("study");
    let case = |name: &str, text: String| {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    // L/R = 16, 8 elements per R along: at L/R = 8 the caps' boundary layers (about 3 R each
    // at ε = 1e-3) leave only a third of the tube invariant
    let base = std::fs::read_to_string(SMALL)
        .unwrap()
        .replace("length = 8.0", "length = 16.0")
        .replace("along = 24", "along = 128");
    let good = case("good.toml", base.clone());
    let o = tubemem(
        &[
            "verify",
            "--case",
            good.to_str().unwrap(),
            "--out",
            d.join("good").to_str().unwrap(),
        ],
        &[("TUBEMEM_PYTHON", "/nonexistent/python")],
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        out.starts_with("At mid-span GPS describes this tube"),
        "{out}"
    );
    assert_eq!(
        check_names(&d.join("good")),
        [
            "end-effect",
            "invariance",
            "reference",
            "convergence",
            "closed-form"
        ]
    );
    let bulged = case(
        "bulged.toml",
        base.replace(
            "model = \"abb\"\nshear_modulus = 1.0\nkuhn = 30",
            "model = \"mooney-rivlin\"\nshear_modulus = 1.0\nalpha = 0.1",
        )
        .replace("target_stretch = 1.2", "target_stretch = 2.0")
        .replace("steps = 4", "steps = 10"),
    );
    let o = tubemem(
        &[
            "verify",
            "--case",
            bulged.to_str().unwrap(),
            "--out",
            d.join("bulged").to_str().unwrap(),
            "--quick",
        ],
        &[("TUBEMEM_PYTHON", "/nonexistent/python")],
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(
        out.contains("GPS does NOT describe")
            && out.contains("past the GPS pressure maximum")
            && out.contains("1.708"),
        "{out}"
    );
    let bad = case("bad.toml", "[geometry]\nradius = 1.0\n".into());
    let o = tubemem(
        &[
            "verify",
            "--case",
            bad.to_str().unwrap(),
            "--out",
            d.join("bad").to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
}

/// Issue #24 item 2: `verify --case … --quick --filter reference` had panicked (exit 101, an
/// index out of bounds: the study read its checks by position). Each filter runs the checks it
/// selects, and where it leaves out what the closed-form comparison needs, the verdict says so.
#[test]
fn a_filtered_study_runs_what_it_selects_and_says_what_it_left_out() {
    let d = tmp("study-filter");
    for (filter, ran, left) in [
        ("reference", vec!["reference"], "both"),
        ("invariance", vec!["invariance"], "both"),
        ("end", vec!["end-effect"], "convergence"),
    ] {
        let out_dir = d.join(filter);
        let o = tubemem(
            &[
                "verify",
                "--case",
                SMALL,
                "--quick",
                "--filter",
                filter,
                "--out",
                out_dir.to_str().unwrap(),
            ],
            &[("TUBEMEM_PYTHON", "/nonexistent/python")],
        );
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            matches!(o.status.code(), Some(0 | 1)),
            "--filter {filter}: {:?}\n{out}\n{}",
            o.status.code(),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            out.contains(&format!("--filter \"{filter}\" left {left} out")),
            "--filter {filter}: {out}"
        );
        assert_eq!(check_names(&out_dir), ran, "--filter {filter}");
    }
}

/// The names of the checks in `dir/results.json`, in order.
fn check_names(dir: &std::path::Path) -> Vec<String> {
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    r["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap().to_string())
        .collect()
}
