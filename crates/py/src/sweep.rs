//! `tubemem.sweep`: many cases on threads of this process or on a Dask cluster, as one
//! DataFrame.

use crate::case::{case_from, case_text};
use crate::convert::to_py;
use crate::outcome::{failure_message, run_writer};
use crate::progress::SweepProgress;
use crate::table::{integer_columns, step_columns};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// One sweep member, run on the calling thread without the interpreter: the case (TOML text)
/// into `out` (written over: a sweep's folders are its own); the report, or the error's whole
/// chain (a failed solve also says where its converged steps are). `stop` interrupts it at its
/// next Newton iteration.
pub(crate) fn sweep_member(
    index: usize,
    text: &str,
    out: &std::path::Path,
    stop: &std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> Result<tubemem_app::report::RunReport, String> {
    let case = tubemem_app::case::Case::parse(text).map_err(|e| tubemem_app::error_chain(&e))?;
    let mut writer = run_writer(&case, out, tubemem_app::output::FolderMode::Overwrite, &[])
        .map_err(|e| e.chain())?;
    let options = tubemem_app::run::RunOptions {
        interrupt: Some(stop.clone()),
        ..Default::default()
    };
    let label = format!("sweep member {index}");
    let outcome = tubemem_app::run::run_with(&case, &label, &options, &mut [&mut writer]);
    match outcome.error {
        None => Ok(outcome.report),
        Some(e) if e.is_input_error() => Err(e.chain()),
        Some(e) => Err(failure_message(&e, out)),
    }
}

/// A sweep member's result as the dict that crosses to the caller (and back from a Dask
/// worker): its index, its folder, the steps as lists (one per steps.csv column), the summary,
/// and the error (None when it finished).
pub(crate) fn member_dict<'py>(
    py: Python<'py>,
    index: usize,
    out: &std::path::Path,
    result: &Result<tubemem_app::report::RunReport, String>,
) -> PyResult<Bound<'py, PyAny>> {
    let d = pyo3::types::PyDict::new(py);
    d.set_item("index", index)?;
    d.set_item("out", out.display().to_string())?;
    let steps = pyo3::types::PyDict::new(py);
    match result {
        Ok(report) => {
            for (name, col) in step_columns(report) {
                steps.set_item(name, col)?;
            }
            d.set_item("summary", to_py(py, &report.summary())?)?;
            d.set_item("error", py.None())?;
        }
        Err(msg) => {
            d.set_item("summary", py.None())?;
            d.set_item("error", msg)?;
        }
    }
    d.set_item("steps", steps)?;
    Ok(d.into_any())
}

/// One member of a sweep on a Dask worker: the case (TOML text) into `out`; returns the
/// member's dict (index, out, steps, summary, error), so that a failing member does not lose
/// the others.
#[pyfunction]
pub(crate) fn _sweep_one<'py>(
    py: Python<'py>,
    index: usize,
    text: String,
    out: PathBuf,
) -> PyResult<Bound<'py, PyAny>> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let result = py.detach(|| sweep_member(index, &text, &out, &stop));
    member_dict(py, index, &out, &result)
}

/// Run the members on `workers` threads of this process (each run releases the interpreter,
/// so they run in parallel; no worker process re-imports the caller's script, so a sweep runs
/// from a plain script, a notebook or the REPL alike). Ctrl-C or a progress callback that
/// raises stops the runs at their next Newton iteration; the finished ones stay on disk.
pub(crate) fn sweep_threads<'py>(
    py: Python<'py>,
    texts: &[String],
    outs: &[PathBuf],
    workers: usize,
    progress: &SweepProgress<'py>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::mpsc::RecvTimeoutError;
    type Outcome = Result<tubemem_app::report::RunReport, String>;
    let n = texts.len();
    let next = AtomicUsize::new(0);
    let stop = std::sync::Arc::new(AtomicBool::new(false));
    let (tx, mut rx) = std::sync::mpsc::channel::<(usize, Outcome)>();
    let mut results: Vec<Option<Outcome>> = (0..n).map(|_| None).collect();
    let mut raised: Option<PyErr> = None;
    let mut done = 0;
    std::thread::scope(|scope| {
        for _ in 0..workers {
            let tx = tx.clone();
            let (next, stop) = (&next, &stop);
            scope.spawn(move || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= n || stop.load(Ordering::Relaxed) {
                    break;
                }
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    sweep_member(i, &texts[i], &outs[i], stop)
                }))
                .unwrap_or_else(|_| Err(format!("sweep member {i}: the run stopped abnormally")));
                if tx.send((i, r)).is_err() {
                    break;
                }
            });
        }
        drop(tx);
        loop {
            let r = &mut rx;
            match py.detach(move || r.recv_timeout(std::time::Duration::from_millis(50))) {
                Ok((i, r)) => {
                    done += 1;
                    if raised.is_none() {
                        let error = r.as_ref().err().map(String::as_str);
                        if let Err(e) = progress.finished(py, i, done, n, error) {
                            stop.store(true, Ordering::Relaxed);
                            raised = Some(e);
                        }
                    }
                    results[i] = Some(r);
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if let Err(e) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                raised.get_or_insert(e);
            }
        }
    });
    progress.close()?;
    if let Some(e) = raised {
        return Err(e);
    }
    results
        .into_iter()
        .enumerate()
        .map(|(i, r)| {
            let r = r.unwrap_or_else(|| Err("not run: the sweep was stopped".into()));
            member_dict(py, i, &outs[i], &r)
        })
        .collect()
}

/// Run a list of cases (each a `Case`, TOML text, a path or a dict) into `out/case_NNN`, and
/// return a pandas DataFrame with one row per case and converged step: the case's index, its
/// parameters `params[i]` (a dict per case, optional) and the steps.csv columns (mid-span
/// values, the closed form at the step). By default the cases run on `workers` threads of this
/// process (default the CPU count; `processes` is its former name, kept as an alias): each run
/// releases the interpreter, and a plain script needs no `if __name__ == "__main__":` guard.
/// With `client=` (a `dask.distributed.Client`) they run on its cluster, the same code on a
/// laptop's `LocalCluster` or a multi-node cluster. `progress`: "tqdm", or a callable given
/// `{"case", "done", "total", "error"}` as each member finishes. A case that fails is a row
/// with its `error` and no steps; the others are kept.
#[pyfunction]
#[pyo3(signature = (cases, out, params=None, client=None, workers=None, progress=None, processes=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep<'py>(
    py: Python<'py>,
    cases: &Bound<'py, PyAny>,
    out: PathBuf,
    params: Option<&Bound<'py, PyAny>>,
    client: Option<&Bound<'py, PyAny>>,
    workers: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
    processes: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let count = |v: Option<&Bound<'py, PyAny>>, name: &str| {
        v.map(|w| crate::convert::int_arg(w, name, 1, 4096, "at least 1 (and at most 4096)"))
            .transpose()
    };
    let workers = count(workers, "workers")?;
    let processes = count(processes, "processes")?;
    let mut texts = vec![];
    for (i, c) in cases.try_iter()?.enumerate() {
        let c = c?;
        // validate every case before any runs: a typo fails the sweep at once, naming the case
        let named = |e: PyErr| PyValueError::new_err(format!("sweep: cases[{i}]: {}", e.value(py)));
        case_from(py, &c, None).map_err(named)?;
        texts.push(case_text(py, &c).map_err(named)?);
    }
    let n = texts.len();
    let param_list: Vec<Option<Bound<'py, PyAny>>> = match params {
        Some(p) => p
            .try_iter()?
            .map(|x| x.map(Some))
            .collect::<PyResult<_>>()?,
        None => vec![None; n],
    };
    if param_list.len() != n {
        return Err(PyValueError::new_err(format!(
            "sweep: params has {} entries for {n} cases (one dict per case)",
            param_list.len()
        )));
    }
    let workers = match (workers, processes) {
        (Some(w), Some(p)) if w != p => {
            return Err(PyValueError::new_err(format!(
                "sweep: workers={w} and processes={p} (its former name) disagree: give one"
            )))
        }
        (w, p) => w
            .or(p)
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |c| c.get())),
    };
    let progress = SweepProgress::new(py, progress, n)?;
    std::fs::create_dir_all(&out)
        .map_err(|e| PyValueError::new_err(format!("cannot create {}: {e}", out.display())))?;
    let outs: Vec<PathBuf> = (0..n).map(|i| out.join(format!("case_{i:03}"))).collect();
    let results: Vec<Bound<'py, PyAny>> = match client {
        Some(client) => {
            let one = py.import("tubemem")?.getattr("_sweep_one")?;
            let indices: Vec<usize> = (0..n).collect();
            let outs: Vec<String> = outs.iter().map(|o| o.display().to_string()).collect();
            let futures = client.call_method1("map", (one, indices, texts, outs))?;
            let mut gathered = vec![];
            // as each future finishes, for the progress; then in case order
            if !matches!(progress, SweepProgress::None) {
                let ac = py
                    .import("dask.distributed")?
                    .getattr("as_completed")?
                    .call1((&futures,))?;
                for (done, f) in ac.try_iter()?.enumerate() {
                    let r = f?.call_method0("result")?;
                    let case: usize = r.get_item("index")?.extract()?;
                    let error: Option<String> = r.get_item("error")?.extract()?;
                    progress.finished(py, case, done + 1, n, error.as_deref())?;
                }
                progress.close()?;
            }
            for r in client.call_method1("gather", (futures,))?.try_iter()? {
                gathered.push(r?);
            }
            gathered
        }
        None => sweep_threads(py, &texts, &outs, workers.min(n.max(1)), &progress)?,
    };
    let rows = pyo3::types::PyList::empty(py);
    for r in results {
        let index: usize = r.get_item("index")?.extract()?;
        let error = r.get_item("error")?;
        let steps = r.get_item("steps")?;
        let base = pyo3::types::PyDict::new(py);
        base.set_item("case", index)?;
        if let Some(Some(p)) = param_list.get(index) {
            base.call_method1("update", (p,))?;
        }
        base.set_item("error", &error)?;
        let count = steps.get_item("step").and_then(|c| c.len()).unwrap_or(0);
        if count == 0 {
            rows.append(&base)?;
        }
        for k in 0..count {
            let row = base.copy()?;
            for item in steps.call_method0("items")?.try_iter()? {
                let item = item?;
                let (name, col) = (item.get_item(0)?, item.get_item(1)?);
                row.set_item(name, col.get_item(k)?)?;
            }
            rows.append(row)?;
        }
    }
    let df = py.import("pandas")?.call_method1("DataFrame", (rows,))?;
    integer_columns(&df)?;
    Ok(df)
}
