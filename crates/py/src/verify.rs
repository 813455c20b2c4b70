//! `tubemem.verify`: verification suites, or the study of one case.

use crate::convert::to_py;
use crate::errors::TubememError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Run verification suites (TOML files, as `tubemem verify`) or, with `case=`, the study of one
/// case (closed form, three-mesh convergence with GCI, end effect, invariance core, references),
/// into `out`; writes results.json, report.md, report.html and junit.xml there and returns the
/// results as a dict (results.json's content: `verdict`, `passed`, `failed`, `checks` with each
/// check's `status`, `message`, `measures` and `details`). Bad suites raise ValueError; failing
/// checks do not raise (read `failed` and each check's `status`). The `reference` checks run
/// the scikit-fem references in `python` (default: this interpreter, where
/// `pip install ./python_ref` puts them) or from the `python_ref` folder given (default
/// `TUBEMEM_PYTHON_REF`, else a checkout's above the case or the working folder). `epsilon`
/// (with `case=`) is the accuracy asked for, relative (default 1e-3), as `--epsilon`.
#[pyfunction]
#[pyo3(signature = (suites=None, out=PathBuf::from("tubemem-verify"), case=None, quick=false, jobs=None, filter=None, update_gold=false, python=None, python_ref=None, epsilon=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn verify<'py>(
    py: Python<'py>,
    suites: Option<Vec<PathBuf>>,
    out: PathBuf,
    case: Option<PathBuf>,
    quick: bool,
    jobs: Option<&Bound<'py, PyAny>>,
    filter: Option<String>,
    update_gold: bool,
    python: Option<PathBuf>,
    python_ref: Option<PathBuf>,
    epsilon: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    use tubemem_app::verify::{self as v, report::Results, VerifyOptions};
    let jobs = jobs
        .map(|j| {
            crate::convert::int_arg(
                j,
                "jobs",
                0,
                4096,
                "the checks run at once, from 0 (one per core) to 4096",
            )
        })
        .transpose()?
        .unwrap_or(0);
    let python = match python {
        Some(p) => Some(p),
        None => Some(
            py.import("sys")?
                .getattr("executable")?
                .extract::<PathBuf>()?,
        )
        .filter(|p| !p.as_os_str().is_empty()),
    };
    let opts = VerifyOptions {
        jobs,
        filter,
        update_gold,
        python,
        python_ref,
    };
    let t0 = std::time::Instant::now();
    let quiet = |_: v::Event| {};
    // Ctrl-C: the checks not started are skipped and the runs in progress stop at their next
    // Newton iteration (as in the CLI); the report of what ran is written, then
    // KeyboardInterrupt is raised
    let flag = v::interrupt_flag();
    flag.store(false, std::sync::atomic::Ordering::Relaxed);
    let mut raised: Option<PyErr> = None;
    let (names, results, verdict) = match (case, suites) {
        (Some(c), None) => {
            let s = watch(py, &flag, &mut raised, || {
                let study = v::study::StudyOptions {
                    quick,
                    epsilon: epsilon.unwrap_or(v::study::DEFAULT_EPSILON),
                };
                v::study::run_study(&c, &out, &study, &opts, &quiet)
            })?
            .map_err(|e| match raised.take() {
                Some(k) => k,
                None => PyValueError::new_err(tubemem_app::error_chain(&e)),
            })?;
            (
                vec![format!("study of {}", c.display())],
                s.results,
                Some(s.verdict),
            )
        }
        (None, Some(list)) if !list.is_empty() => {
            let mut checks = vec![];
            let mut names = vec![];
            for s in &list {
                let (n, c) =
                    v::suite::read_suite(s).map_err(|e| PyValueError::new_err(e.to_string()))?;
                names.push(n);
                checks.extend(c);
            }
            let r = watch(py, &flag, &mut raised, || {
                v::run_checks(&checks, &out, &opts, &quiet)
            })?
            .map_err(|e| match raised.take() {
                Some(k) => k,
                // an error of the whole run is one of its set-up (check failures are results):
                // a bad value, named as the Python call names it (`out`, not `--out`)
                None => PyValueError::new_err(crate::case::pythonic(&e.chain())),
            })?;
            (names, r, None)
        }
        _ => {
            return Err(PyValueError::new_err(
                "give suites=[...] (suite files) or case=... (a case file), not both",
            ))
        }
    };
    let results = Results::new(names, t0.elapsed().as_secs_f64(), &results, verdict);
    v::report::write_all(&out, &results)
        .map_err(|e| TubememError::new_err(crate::case::pythonic(&e.chain())))?;
    if let Some(e) = raised {
        // the report of what ran is on disk; say where, then raise the interrupt
        let msg = format!(
            "verification interrupted: the report of the checks that ran is in {}",
            out.display()
        );
        let _ = py
            .import("sys")
            .and_then(|s| s.getattr("stderr"))
            .and_then(|s| s.call_method1("write", (msg + "\n",)));
        return Err(e);
    }
    to_py(py, &results)
}

/// Run `work` on a thread while this one checks Python's signals every 50 ms: on Ctrl-C (or
/// any signal handler raising) `flag` is set, so the work stops within a Newton iteration,
/// and the exception is kept in `raised`.
fn watch<T: Send>(
    py: Python<'_>,
    flag: &std::sync::atomic::AtomicBool,
    raised: &mut Option<PyErr>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    std::thread::scope(|s| {
        let h = s.spawn(work);
        while !h.is_finished() {
            py.detach(|| std::thread::sleep(std::time::Duration::from_millis(50)));
            if let Err(e) = py.check_signals() {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
                raised.get_or_insert(e);
            }
        }
        h.join()
            .map_err(|_| TubememError::new_err("the verification's thread stopped abnormally"))
    })
}
