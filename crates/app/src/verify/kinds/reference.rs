//! `reference`: the FE against the scikit-fem references of `python_ref`, run as a separate
//! Python process; skipped, with the reason, when they are not installed.

use super::{member, KindResult};
use crate::verify::suite::Check;
use crate::verify::{CheckResult, Measure, VerifyOptions};
use std::path::{Path, PathBuf};

kind!(
    /// The `reference` kind.
    Reference,
    "reference",
    reference
);

/// Where the `python_ref` folder is, when there is one to put on the module path: given
/// (`--python-ref`, `TUBEMEM_PYTHON_REF`), or the checkout's, searched upwards from `from` and
/// the working folder. None: the references are the `tubemem_ref` package installed in the
/// interpreter (`pip install ./python_ref`).
fn find_python_ref(opts: &VerifyOptions, from: &Path) -> Option<PathBuf> {
    if let Some(p) = &opts.python_ref {
        return Some(p.clone());
    }
    if let Some(p) = std::env::var_os("TUBEMEM_PYTHON_REF") {
        return Some(PathBuf::from(p));
    }
    let cwd = std::env::current_dir().ok();
    for start in [Some(from.to_path_buf()), cwd].into_iter().flatten() {
        let start = start.canonicalize().unwrap_or(start);
        for d in start.ancestors() {
            if d.join("python_ref")
                .join("tubemem_ref")
                .join("compare.py")
                .is_file()
            {
                return Some(d.join("python_ref"));
            }
        }
    }
    None
}

/// The interpreter that runs the references: `--python`, `TUBEMEM_PYTHON`, the `.venv` next to
/// the `python_ref` folder found, else `python3`.
fn python_for(opts: &VerifyOptions, python_ref: Option<&Path>) -> PathBuf {
    if let Some(p) = &opts.python {
        return p.clone();
    }
    if let Some(p) = std::env::var_os("TUBEMEM_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = python_ref
        .and_then(Path::parent)
        .map(|d| d.join(".venv").join("bin").join("python"));
    match venv {
        Some(v) if v.is_file() => v,
        _ => PathBuf::from("python3"),
    }
}

/// How to point `tubemem verify` at the references, for the messages of a skipped check.
pub const REFERENCES_HOWTO: &str = "install them in the interpreter (pip install ./python_ref) and pass it with --python or TUBEMEM_PYTHON, or name the python_ref folder with --python-ref or TUBEMEM_PYTHON_REF; the README's test command creates .venv with them";

fn reference(c: &Check, dir: &Path, opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let pref = find_python_ref(opts, &c.base_dir);
    let python = python_for(opts, pref.as_deref());
    // the module path: the folder found first (a checkout's own references win over an
    // installed copy), then whatever the interpreter has installed
    let path_arg = pref
        .as_ref()
        .map_or(String::new(), |p| p.display().to_string());
    let prelude = "import sys\nif sys.argv[1]: sys.path.insert(0, sys.argv[1])\n";
    let probe = std::process::Command::new(&python)
        .arg("-c")
        .arg(format!("{prelude}import tubemem_ref.compare, skfem, scipy"))
        .arg(&path_arg)
        .output();
    let whence = match &pref {
        Some(p) => format!("with {} on its path", p.display()),
        None => "(no python_ref folder found: the installed package was tried)".into(),
    };
    match probe {
        Err(e) => {
            return Ok(Some(format!(
                "no Python interpreter at {} ({e}): the scikit-fem references cannot run; {REFERENCES_HOWTO}",
                python.display()
            )))
        }
        Ok(o) if !o.status.success() => {
            let err = String::from_utf8_lossy(&o.stderr);
            let last = err.lines().last().unwrap_or("").to_string();
            return Ok(Some(format!(
                "the scikit-fem references do not import in {} {whence} ({last}); {REFERENCES_HOWTO}",
                python.display()
            )));
        }
        Ok(_) => {}
    }
    let run_dir = dir.join("run");
    let report = member(c, &c.case_text, &run_dir, r)?;
    let cmp = dir.join("compare");
    let script = format!("{prelude}import json, math\nimport tubemem_ref.compare as compare\nrows = compare.compare(sys.argv[2], sys.argv[3], plot=True)\nclean = [[None if isinstance(v, float) and not math.isfinite(v) else v for v in row] for row in rows]\nprint('TUBEMEM_JSON ' + json.dumps(clean))\n");
    let o = std::process::Command::new(&python)
        .arg("-c")
        .arg(script)
        .arg(&path_arg)
        .arg(&run_dir)
        .arg(&cmp)
        .output()
        .map_err(|e| format!("running {}: {e}", python.display()))?;
    let stdout = String::from_utf8_lossy(&o.stdout);
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        return Err(format!(
            "the references (tubemem_ref.compare) failed: {}",
            err.lines().last().unwrap_or("(no message)")
        ));
    }
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("TUBEMEM_JSON "))
        .ok_or("the references (tubemem_ref.compare) printed no result")?;
    let rows: Vec<Vec<serde_json::Value>> =
        serde_json::from_str(line).map_err(|e| format!("compare.py's result: {e}"))?;
    let num = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    for (q, tol) in &c.spec.tolerance {
        let mut worst: Option<(f64, String)> = None;
        for row in &rows {
            let (stage, quantity) = (num(&row[0]), row[2].as_str().unwrap_or(""));
            let profile_row = match q.as_str() {
                "profile" => Some("profile max |Δλs|"),
                "profile_lambda_z" => Some("profile max |Δλz|"),
                _ => None,
            };
            let (value, note) = if profile_row.is_some_and(|p| quantity == p) {
                (
                    num(&row[3]),
                    format!(
                        "stage {stage}: {quantity} along the tube, at Z = {:.3}",
                        num(&row[4])
                    ),
                )
            } else if quantity == q {
                (
                    num(&row[6]).abs(),
                    format!(
                        "stage {stage}: FE {:.7} against scikit-fem {:.7}",
                        num(&row[3]),
                        num(&row[4])
                    ),
                )
            } else {
                continue;
            };
            if worst.as_ref().is_none_or(|(w, _)| value > *w) {
                worst = Some((value, note));
            }
        }
        match worst {
            Some((v, note)) => r.measures.push(Measure::held(q, v, tol, note)),
            None => r.measures.push(Measure::missing(
                q,
                tol,
                "the references gave no such comparison for this run",
            )),
        }
    }
    r.details = serde_json::json!({ "rows": rows, "material": report.material });
    // the reference's own profile plot, when it drew one
    if let Some(p) = (1..=report.stages.len())
        .map(|k| cmp.join(format!("profile_stage{k}.png")))
        .find(|p| p.is_file())
    {
        r.png = std::fs::read(p).ok();
    }
    Ok(None)
}
