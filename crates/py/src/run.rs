//! `tubemem.run` and `Run`: a case run on a thread of its own while the interpreter reports
//! its steps and watches for Ctrl-C.

use crate::case::{case_from, pythonic};
use crate::convert::to_py;
use crate::errors::TubememError;
use crate::outcome::{run_outcome, run_writer};
use crate::progress::tqdm_bar;
use crate::table::{critical_columns, front_columns, profile_columns, step_columns, Table};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// A converged step, sent from the run's thread to the interpreter's.
pub(crate) struct StepNote {
    pub(crate) stage: usize,
    pub(crate) step: usize,
    pub(crate) w: f64,
    pub(crate) lambda_s: f64,
    pub(crate) newton_iterations: usize,
    pub(crate) residual: f64,
    pub(crate) fraction: f64,
}

/// The observer that forwards every converged step to the interpreter's thread.
pub(crate) struct Notify(std::sync::mpsc::Sender<StepNote>);

impl tubemem_app::observer::Observer for Notify {
    fn step(
        &mut self,
        v: &tubemem_app::observer::StepView,
    ) -> Result<(), tubemem_app::observer::BoxError> {
        let r = v.record;
        // a closed channel means the interpreter side has gone: nothing to tell
        let _ = self.0.send(StepNote {
            stage: r.stage,
            step: r.step,
            w: r.midspan.w,
            lambda_s: r.midspan.lambda_s,
            newton_iterations: r.newton_iterations,
            residual: r.residuals.last().copied().unwrap_or(0.0),
            fraction: v.fraction,
        });
        Ok(())
    }
}

/// Run a parsed case into `out` on a thread of its own, while the interpreter's thread waits
/// without the interpreter lock, reports each step (to `progress`, or to the `tubemem` logger
/// at DEBUG level: silent by default) and checks for Ctrl-C every 50 ms. Ctrl-C stops the run at
/// its next Newton iteration (every converged step stays on disk, and the run records that it
/// was interrupted) and is then raised as `KeyboardInterrupt`.
pub(crate) fn run_parsed<'py>(
    py: Python<'py>,
    case: &tubemem_app::case::Case,
    label: &str,
    out: &std::path::Path,
    overwrite: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<(tubemem_app::report::RunReport, usize)> {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::mpsc::RecvTimeoutError;
    use std::sync::Arc;
    use tubemem_app::output::FolderMode;
    let mode = if overwrite {
        FolderMode::Overwrite
    } else {
        FolderMode::Fresh
    };
    // progress = "tqdm": a tqdm bar over the stages (tqdm imported on demand: optional)
    let mut progress = progress;
    let mut bar: Option<Bound<'py, PyAny>> = None;
    if let Some(name) = progress.and_then(|p| p.extract::<String>().ok()) {
        if name != "tqdm" {
            return Err(PyValueError::new_err(format!(
                "progress = {name:?}: a callable, \"tqdm\" or None"
            )));
        }
        bar = Some(tqdm_bar(
            py,
            "progress=\"tqdm\"",
            case.plan().len() as f64,
            "stage",
            "tubemem",
        )?);
        progress = None;
    }
    // the case file (when the label is its path) and its mesh: never written over
    let inputs = tubemem_app::output_file::case_inputs(std::path::Path::new(label), case);
    let inputs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    let mut writer = run_writer(case, out, mode, &inputs)
        .map_err(|e| PyValueError::new_err(pythonic(&e.chain())))?;
    let flag = Arc::new(AtomicBool::new(false));
    let options = tubemem_app::run::RunOptions {
        interrupt: Some(flag.clone()),
        ..Default::default()
    };
    let logger = py
        .import("logging")?
        .call_method1("getLogger", ("tubemem",))?;
    let (tx, mut rx) = std::sync::mpsc::channel::<StepNote>();
    let mut raised: Option<PyErr> = None;
    let outcome = std::thread::scope(|scope| {
        let run = scope.spawn(|| {
            let mut notify = Notify(tx);
            tubemem_app::run::run_with(case, label, &options, &mut [&mut writer, &mut notify])
        });
        loop {
            let r = &mut rx;
            let next = py.detach(move || r.recv_timeout(std::time::Duration::from_millis(50)));
            match next {
                Ok(n) => {
                    let reported = match (progress, &bar) {
                        (_, Some(b)) if raised.is_none() => (|| -> PyResult<()> {
                            b.setattr("n", (n.stage - 1) as f64 + n.fraction)?;
                            b.call_method1(
                                "set_postfix_str",
                                (format!(
                                    "stage {} step {}: w={:.5} residual {:.1e}",
                                    n.stage, n.step, n.w, n.residual
                                ),),
                            )?;
                            b.call_method0("refresh")?;
                            Ok(())
                        })(),
                        (_, Some(_)) => Ok(()),
                        (Some(cb), None) if raised.is_none() => {
                            let d = pyo3::types::PyDict::new(py);
                            let fill = || -> PyResult<()> {
                                d.set_item("stage", n.stage)?;
                                d.set_item("step", n.step)?;
                                d.set_item("w", n.w)?;
                                d.set_item("lambda_s", n.lambda_s)?;
                                d.set_item("newton_iterations", n.newton_iterations)?;
                                d.set_item("residual", n.residual)?;
                                d.set_item("fraction", n.fraction)?;
                                cb.call1((d.clone(),))?;
                                Ok(())
                            };
                            fill()
                        }
                        (Some(_), None) => Ok(()),
                        (None, None) => logger
                            .call_method1(
                                "debug",
                                (format!(
                                    "stage {} step {}: w = {:.6}, lambda_s = {:.6}, {} Newton iterations, residual {:.1e} ({:.0} %)",
                                    n.stage, n.step, n.w, n.lambda_s, n.newton_iterations, n.residual, 100.0 * n.fraction
                                ),),
                            )
                            .map(|_| ()),
                    };
                    if let Err(e) = reported {
                        // the callback raised: stop the run, then raise it
                        flag.store(true, Ordering::Relaxed);
                        raised.get_or_insert(e);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if let Err(e) = py.check_signals() {
                flag.store(true, Ordering::Relaxed);
                raised.get_or_insert(e);
            }
        }
        run.join()
    });
    if let Some(b) = &bar {
        b.call_method0("close")?;
    }
    let outcome =
        outcome.map_err(|_| TubememError::new_err("the run's thread stopped abnormally"))?;
    if let Some(e) = raised {
        return Err(e);
    }
    Ok((run_outcome(outcome, out)?, writer.frames()))
}

/// Run a case file (TOML, as for `tubemem run`), writing steps.csv, summary.json, profiles/ and
/// the VTU series to `out`; returns the summary as a dict. On failure the converged steps are
/// already in `out` and `TubememError` says which stage, step and residual, and why. A folder
/// that already holds a run is refused (`ValueError`) unless `overwrite=True`.
#[pyfunction]
#[pyo3(signature = (case, out, overwrite=false, progress=None))]
pub(crate) fn run_case<'py>(
    py: Python<'py>,
    case: PathBuf,
    out: PathBuf,
    overwrite: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let parsed = tubemem_app::case::Case::read(&case)
        .map_err(|e| PyValueError::new_err(tubemem_app::error_chain(&e)))?;
    let (report, _) = run_parsed(
        py,
        &parsed,
        &case.display().to_string(),
        &out,
        overwrite,
        progress,
    )?;
    to_py(py, &report.summary())
}

/// Run a case given as TOML text (user mesh files are looked up relative to `base_dir`); as
/// `run_case` otherwise.
#[pyfunction]
#[pyo3(signature = (text, out, base_dir=None, overwrite=false, progress=None))]
pub(crate) fn run_case_text<'py>(
    py: Python<'py>,
    text: &str,
    out: PathBuf,
    base_dir: Option<PathBuf>,
    overwrite: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut case = tubemem_app::case::Case::parse(text).map_err(|e| {
        PyValueError::new_err(format!(
            "in the case text: {}",
            tubemem_app::error_chain(&e)
        ))
    })?;
    case.base_dir = base_dir.unwrap_or_default();
    let (report, _) = run_parsed(
        py,
        &case,
        "case text from Python",
        &out,
        overwrite,
        progress,
    )?;
    to_py(py, &report.summary())
}

/// The embedded default case (`cases/squeeze_abb30_ls1.3_quad9.toml`, the main job's) as TOML text.
#[pyfunction]
pub(crate) fn default_case() -> &'static str {
    tubemem_app::main_job::DEFAULT_CASE
}

/// A finished FE run: `summary` (the dict of summary.json), `steps` (a `Table` of numpy arrays,
/// one per steps.csv column, NaN where a column does not apply), `profiles` (a `Table` in long
/// form: one row per ring and step, the columns of profiles/profiles.csv), `critical_points`
/// (a `Table`: the columns of critical_points.csv, one row per located critical point of an
/// arc-length stage), `fronts` (a `Table`: the columns of fronts.csv), `path` (the run
/// folder) and `to_pandas()` (the steps); `vtu(k)` is the path of VTU frame k (0 the reference
/// state; which steps have a frame follows `[output] vtu`), readable with meshio.
#[pyclass(name = "Run", module = "tubemem")]
pub(crate) struct Run {
    #[pyo3(get)]
    pub(crate) summary: Py<PyAny>,
    #[pyo3(get)]
    pub(crate) steps: Py<Table>,
    #[pyo3(get)]
    pub(crate) profiles: Py<Table>,
    #[pyo3(get)]
    pub(crate) critical_points: Py<Table>,
    #[pyo3(get)]
    pub(crate) fronts: Py<Table>,
    #[pyo3(get)]
    pub(crate) path: PathBuf,
    pub(crate) frames: usize,
}

#[pymethods]
impl Run {
    /// The steps as a pandas DataFrame (pandas is imported on demand).
    pub(crate) fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.steps.borrow(py).to_pandas(py)
    }
    /// The VTU file of frame `k` (0: the reference state; k: after the k-th converged step).
    fn vtu(&self, k: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
        let k = crate::convert::int_arg(
            k,
            "k",
            0,
            usize::MAX,
            &format!("the run has frames 0 to {}", self.frames.saturating_sub(1)),
        )?;
        if k >= self.frames {
            return Err(PyValueError::new_err(format!(
                "frame {k}: the run has frames 0 to {}",
                self.frames.saturating_sub(1)
            )));
        }
        Ok(self.path.join("vtu").join(format!("step_{k:05}.vtu")))
    }
    fn __repr__(&self, py: Python<'_>) -> String {
        let n = self.steps.borrow(py).rows;
        format!("<tubemem.Run {} ({n} steps)>", self.path.display())
    }
}

/// Run a case (a TOML file's path, TOML text, or a dict of its tables, e.g.
/// `{"geometry": {"radius": 1.0, "length": 20.0}, "material": {...}, "mesh": {...},
/// "stage": [{...}]}`) into `out`; returns a `Run` with the steps as arrays. Errors, progress and
/// Ctrl-C as for `run_case`.
#[pyfunction]
#[pyo3(signature = (case, out, base_dir=None, overwrite=false, progress=None))]
pub(crate) fn run<'py>(
    py: Python<'py>,
    case: &Bound<'py, PyAny>,
    out: PathBuf,
    base_dir: Option<PathBuf>,
    overwrite: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Run> {
    let (parsed, label) = case_from(py, case, base_dir)?;
    let (report, frames) = run_parsed(py, &parsed, &label, &out, overwrite, progress)?;
    let steps = step_columns(&report)
        .into_iter()
        .map(|(name, col)| (name.to_string(), col))
        .collect();
    Ok(Run {
        summary: to_py(py, &report.summary())?.unbind(),
        steps: Py::new(py, Table::from_columns(py, steps)?)?,
        profiles: Py::new(py, Table::from_columns(py, profile_columns(&report))?)?,
        critical_points: Py::new(py, Table::from_columns(py, critical_columns(&report))?)?,
        fronts: Py::new(py, Table::from_columns(py, front_columns(&report))?)?,
        path: out,
        frames,
    })
}
