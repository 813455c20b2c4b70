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
