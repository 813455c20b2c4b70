//! What the end-to-end tests of the binary share: running it, and their scratch folders.
#![allow(dead_code)] // each test file uses a part

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run the `tubemem` binary with `args`.
pub fn tubemem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tubemem"))
        .args(args)
        .env_remove("RUST_BACKTRACE")
        .output()
        .expect("the tubemem binary runs")
}

/// A fresh scratch folder of this test process, named `name`.
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tubemem-cli-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `tubemem run CASE --out OUT EXTRA…`.
pub fn run_in(case: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "run",
        case.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    tubemem(&args)
}

/// `files` of run folder `b` byte-identical to `a`'s (a file the run writes only when it has
/// rows, fronts.csv, absent from both), and with `frames` every VTU frame too.
pub fn assert_same_run(a: &Path, b: &Path, files: &[&str], frames: bool) {
    for f in files {
        assert!(
            std::fs::read(a.join(f)).ok() == std::fs::read(b.join(f)).ok(),
            "{f} differs after the restart"
        );
        assert!(
            a.join(f).exists() || *f == "fronts.csv",
            "{f} is missing from the run"
        );
    }
    if frames {
        for f in std::fs::read_dir(a.join("vtu")).unwrap() {
            let name = f.unwrap().file_name();
            assert!(
                std::fs::read(a.join("vtu").join(&name)).unwrap()
                    == std::fs::read(b.join("vtu").join(&name)).unwrap(),
                "{name:?} differs"
            );
        }
    }
}

/// A scratch folder `name` with `text` as its `case.toml`, run once to the end into `ref`:
/// (folder, case file, reference run folder).
pub fn reference_run(name: &str, text: &str) -> (PathBuf, PathBuf, PathBuf) {
    let d = tmp(name);
    let case = d.join("case.toml");
    std::fs::write(&case, text).unwrap();
    let reference = d.join("ref");
    let o = run_in(&case, &reference, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (d, case, reference)
}

/// `tubemem run CASE --out OUT EXTRA…`, which must succeed (its stderr is the failure's
/// message).
pub fn run_ok(case: &Path, out: &Path, extra: &[&str]) -> Output {
    let o = run_in(case, out, extra);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// `tubemem run CASE --out OUT` started in the background, its output discarded.
pub fn spawn_run(case: &Path, out: &Path) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_tubemem"))
        .args([
            "run",
            case.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap()
}

/// A scratch folder `name` with `text` as its `case.toml`; the case file's path.
pub fn write_case(name: &str, text: &str) -> PathBuf {
    check_against_schema(text);
    let d = tmp(name);
    let p = d.join("case.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// The case-file schema of `tubemem schema` (`tubemem_app::case::schema`), compiled once.
fn schema() -> &'static jsonschema::Validator {
    static V: std::sync::OnceLock<jsonschema::Validator> = std::sync::OnceLock::new();
    V.get_or_init(|| {
        jsonschema::validator_for(&tubemem_app::case::schema())
            .expect("the case schema is a valid JSON Schema")
    })
}

/// Every case a test writes is held to `tubemem schema` both ways: a case the schema refuses
/// is one tubemem refuses, and a case the schema takes is not refused for its keys or types
/// (a `CaseError::Syntax`); the cross-key rules (a squeeze needs `target_rho`, ranges) are
/// `Case::parse`'s alone. A TOML syntax error is left to the test that wrote it.
pub fn check_against_schema(text: &str) {
    let Ok(value) = text.parse::<toml::Table>() else {
        return;
    };
    let json = serde_json::to_value(&value).expect("TOML converts to JSON");
    let parsed = tubemem_app::case::Case::parse(text);
    let refusal = schema()
        .iter_errors(&json)
        .next()
        .map(|e| format!("{e} at {}", e.instance_path()));
    match refusal {
        Some(e) => assert!(
            parsed.is_err(),
            "the schema refuses a case tubemem takes ({e})"
        ),
        None => assert!(
            !matches!(parsed, Err(tubemem_app::case::CaseError::Syntax(_))),
            "the schema takes a case whose keys or types tubemem refuses: {}",
            parsed.err().map(|e| e.to_string()).unwrap_or_default()
        ),
    }
}

/// The small tube shared with the Python tests.
pub const SMALL_CASE: &str = include_str!("../../../../cases/small_abb30_ls1.2.toml");

/// A steps.csv read by header name: each row a map from column to field.
pub struct Steps {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Steps {
    pub fn read(path: &std::path::Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| l.split(',').map(String::from).collect::<Vec<_>>())
            .collect();
        Self { header, rows }
    }
    pub fn field<'a>(&self, row: &'a [String], col: &str) -> &'a str {
        let k = self
            .header
            .iter()
            .position(|h| h == col)
            .unwrap_or_else(|| panic!("steps.csv has no column `{col}`"));
        &row[k]
    }
    pub fn num(&self, row: &[String], col: &str) -> f64 {
        self.field(row, col)
            .parse()
            .unwrap_or_else(|_| panic!("`{col}` is not a number"))
    }
}

/// `text` with `from` replaced by `to`. `from` must be in `text`: an edit that matched nothing
/// would test the unedited case, and a test of a refusal would then pass or fail for the
/// wrong reason.
pub fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` is not in the case to edit");
    text.replace(from, to)
}

/// Case `text` written as `dir/NAME.toml` and run into `dir/NAME` with `extra` arguments:
/// (case file, run folder, the run's output).
pub fn run_text(dir: &Path, name: &str, text: &str, extra: &[&str]) -> (PathBuf, PathBuf, Output) {
    check_against_schema(text);
    let case = dir.join(format!("{name}.toml"));
    std::fs::write(&case, text).unwrap();
    let out = dir.join(name);
    let o = run_in(&case, &out, extra);
    (case, out, o)
}

/// Every case text of `cases` is refused by `tubemem run` with its needle in the message: a
/// non-zero exit, no panic, nothing on stdout. Returns the messages, in order.
pub fn refused(dir: &Path, cases: &[(String, &str)]) -> Vec<String> {
    cases
        .iter()
        .enumerate()
        .map(|(k, (text, needle))| {
            let (_, _, o) = run_text(dir, &format!("refused{k}"), text, &[]);
            let err = String::from_utf8_lossy(&o.stderr).into_owned();
            assert!(!o.status.success(), "case {k} ran: {text}");
            assert!(
                !err.contains("panicked") && !err.contains("backtrace"),
                "case {k} panicked: {err}"
            );
            assert!(
                err.contains(needle),
                "case {k}: expected `{needle}` in: {err}"
            );
            assert!(
                o.stdout.is_empty(),
                "case {k} printed a result despite failing"
            );
            err
        })
        .collect()
}
