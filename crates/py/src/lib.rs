//! Python bindings: `import tubemem`.
//!
//! The closed form (`gps_*`, `resultants`) and the 3D FE runs (`run`, `run_case`,
//! `run_case_text`) of the Rust crates, with results as dicts and `Table`s of numpy columns (the
//! same keys as `summary.json` and the `tubemem gps` CSV columns). Materials are dicts in the case-file form, e.g.
//! `{"model": "abb", "shear_modulus": 1.0, "kuhn": 30}`; `None` means that one (the paper's law).
//!
//! Errors: invalid input raises `ValueError` (naming the parameter and its admissible range);
//! a closed form or FE run that fails raises `tubemem.TubememError` (a `RuntimeError`), whose
//! message carries the whole context chain (stage, step, residual, case key and line). Long
//! runs release the interpreter lock.
//!
//! Dicts cross the boundary as JSON (serde on this side, `json` on the Python side): every
//! result type already serializes for `summary.json`, so there is one conversion to keep right.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use tubemem_gps::{GpsError, Hypothesis};
use tubemem_material::{MaterialError, MaterialSpec, MembraneLaw};

create_exception!(
    tubemem,
    TubememError,
    PyRuntimeError,
    "A closed-form solve or finite element run that failed; the message names the stage, step and residual."
);

/// The paper's law: Anssari-Benam–Bucchi with μ = 1 and 𝒩 = 30.
const DEFAULT_MATERIAL: MaterialSpec = MaterialSpec::Abb {
    shear_modulus: 1.0,
    kuhn: 30.0,
};

fn gps_err(e: GpsError) -> PyErr {
    let msg = tubemem_app::error_chain(&e);
    match e {
        GpsError::InvalidInput { .. } | GpsError::Walls { .. } => PyValueError::new_err(msg),
        // a material parameter out of range, or a stretch asked for beyond the locking limit,
        // is bad input
        GpsError::Material {
            source: MaterialError::InvalidParameter { .. } | MaterialError::Locking { .. },
            ..
        } => PyValueError::new_err(msg),
        _ => TubememError::new_err(msg),
    }
}

fn material_err(e: MaterialError) -> PyErr {
    match e {
        // a stretch beyond the locking limit, asked for directly, is bad input too
        MaterialError::InvalidParameter { .. }
        | MaterialError::InvalidState { .. }
        | MaterialError::Locking { .. } => {
            PyValueError::new_err(tubemem_material::tidy_numbers(&e.to_string()))
        }
        _ => TubememError::new_err(tubemem_material::tidy_numbers(&e.to_string())),
    }
}

/// A Python object to a serde value, through `json.dumps`.
fn from_py<T: serde::de::DeserializeOwned>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<T> {
    let json = obj.py().import("json")?;
    let kwargs = pyo3::types::PyDict::new(obj.py());
    kwargs.set_item("allow_nan", false)?;
    // NaN and infinity are not values a material may have; say so rather than let the JSON
    // reader point at a column the user never wrote
    let text: String = json
        .call_method("dumps", (obj,), Some(&kwargs))
        .map_err(|_| {
            PyValueError::new_err(format!(
                "{what}: a value is not a finite number (NaN or infinity) or not a plain number, string or dict: {obj}"
            ))
        })?
        .extract()?;
    serde_json::from_str(&text)
        .map_err(|e| PyValueError::new_err(tubemem_material::tidy_numbers(&format!("{what}: {e}"))))
}

/// A serde value to a Python object, through `json.loads`.
fn to_py<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| TubememError::new_err(format!("cannot serialize a result: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// A closed-form computation run without the interpreter lock, its result as a Python object.
fn detached<'py, T: serde::Serialize + Send>(
    py: Python<'py>,
    f: impl FnOnce() -> Result<T, GpsError> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let value = py.detach(f).map_err(gps_err)?;
    to_py(py, &value)
}

fn law(material: Option<&Bound<'_, PyAny>>) -> PyResult<Box<dyn MembraneLaw>> {
    let spec = match material {
        Some(m) if !m.is_none() => from_py::<MaterialSpec>(m, "material")?,
        _ => DEFAULT_MATERIAL,
    };
    spec.build().map_err(material_err)
}

fn hypothesis(name: &str) -> PyResult<Hypothesis> {
    match name.to_ascii_lowercase().as_str() {
        "gps" => Ok(Hypothesis::Gps),
        "ps" => Ok(Hypothesis::Ps),
        _ => Err(PyValueError::new_err(format!(
            "hypothesis = {name:?}: must be \"gps\" (generalized plane strain) or \"ps\" (plane strain)"
        ))),
    }
}

/// Free inflation at hoop stretch `stretch` (eq. 66 under GPS, eq. 70 under PS):
/// dict with w, lambda_s, lambda_z, n_s, n_z (dimensionless, R = μH = 1). `stretch` may be a
/// numpy array (any shape): the dict then holds numpy arrays of that shape, and an entry that
/// has no solution raises with its index.
#[pyfunction]
#[pyo3(signature = (stretch, material=None, hypothesis="gps"))]
fn gps_inflate<'py>(
    py: Python<'py>,
    stretch: &Bound<'py, PyAny>,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let law = law(material)?;
    let hyp = self::hypothesis(hypothesis)?;
    if let Ok(v) = stretch.extract::<f64>() {
        let s = tubemem_gps::inflate(law.as_ref(), hyp, v).map_err(gps_err)?;
        return to_py(py, &s);
    }
    use tubemem_app::curves::{inflation_values, INFLATION_HEADER};
    let keys: Vec<&str> = INFLATION_HEADER.split(',').collect();
    vectorized(
        py,
        stretch,
        "stretch",
        |v| tubemem_gps::inflate(law.as_ref(), hyp, v).map(|s| inflation_values(&s)),
        &keys,
    )
}

/// Evaluate `f` at every entry of the array-like `input` (any shape) and return a dict of numpy
/// arrays of that shape, one per key. An entry that fails raises with its index.
fn vectorized<'py>(
    py: Python<'py>,
    input: &Bound<'py, PyAny>,
    what: &str,
    f: impl Fn(f64) -> Result<Vec<f64>, GpsError> + Send + Sync,
    keys: &[&str],
) -> PyResult<Bound<'py, PyAny>> {
    use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
    let np = py.import("numpy")?;
    let bad = || PyValueError::new_err(format!("{what}: a number or an array of numbers"));
    // one conversion to an array; complex values would be truncated to their real parts by the
    // float conversion that follows (no copy where it is float64 already)
    let raw = np.call_method1("asarray", (input,)).map_err(|_| bad())?;
    let kind: String = raw
        .getattr("dtype")
        .and_then(|d| d.getattr("kind"))
        .and_then(|k| k.extract())
        .unwrap_or_default();
    if kind == "c" {
        return Err(PyValueError::new_err(format!(
            "{what}: complex numbers are not stretches or pressures (give real numbers)"
        )));
    }
    // contiguous float64 (a strided view, e.g. `a[::2]`, is copied once)
    let arr = np
        .call_method1("ascontiguousarray", (raw, "float64"))
        .map_err(|_| bad())?;
    let arr = arr.cast::<PyArrayDyn<f64>>().map_err(|_| bad())?;
    let shape = arr.shape().to_vec();
    // the curves' size cap, before the values are copied or solved
    let count: usize = shape.iter().product();
    if count > tubemem_gps::MAX_CURVE_POINTS {
        return Err(PyValueError::new_err(format!(
            "{what}: {count} values; an array may have at most 10,000,000 (as a curve's points)"
        )));
    }
    let values: Vec<f64> = arr.to_vec().map_err(|_| {
        PyValueError::new_err(format!("{what}: the array must be contiguous numbers"))
    })?;
    let rows: Vec<Vec<f64>> = py
        .detach(|| {
            values
                .iter()
                .enumerate()
                .map(|(k, &v)| f(v).map_err(|e| (k, e)))
                .collect::<Result<Vec<_>, _>>()
        })
        .map_err(|(k, e)| {
            let err = gps_err(e);
            let msg = format!("{what}[{k}] = {}: {}", values[k], err.value(py));
            if err.is_instance_of::<PyValueError>(py) {
                PyValueError::new_err(msg)
            } else {
                TubememError::new_err(msg)
            }
        })?;
    let out = pyo3::types::PyDict::new(py);
    for (j, key) in keys.iter().enumerate() {
        let col: Vec<f64> = rows.iter().map(|r| r[j]).collect();
        let a = numpy::PyArray1::from_vec(py, col).reshape(shape.clone())?;
        out.set_item(key, a)?;
    }
    let table = Table {
        columns: keys.iter().map(|k| k.to_string()).collect(),
        data: out.unbind(),
        rows: values.len(),
    };
    Ok(Bound::new(py, table)?.into_any())
}

/// A closed-form curve as a [`Table`] with the CSV header's columns.
fn curve_table<'py, S: Send>(
    py: Python<'py>,
    header: &str,
    values: impl Fn(&S) -> Vec<f64>,
    f: impl FnOnce() -> Result<Vec<S>, GpsError> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let states = py.detach(f).map_err(gps_err)?;
    let cols = header
        .split(',')
        .enumerate()
        .map(|(j, name)| {
            (
                name.to_string(),
                states.iter().map(|s| values(s)[j]).collect::<Vec<f64>>(),
            )
        })
        .collect();
    Ok(Bound::new(py, Table::from_columns(py, cols)?)?.into_any())
}

/// A curve's `points` (default 100): any Python or numpy integer; a negative or huge one is a
/// ValueError naming it (not an OverflowError of the conversion), a non-integer a TypeError.
fn point_count(points: Option<&Bound<'_, PyAny>>) -> PyResult<usize> {
    let Some(p) = points else {
        return Ok(100);
    };
    if p.is_instance_of::<pyo3::types::PyBool>() {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "points: an integer number of points, not a bool",
        ));
    }
    let n: i128 = match p.call_method0("__index__").and_then(|i| i.extract::<i64>()) {
        Ok(n) => n.into(),
        // an integer beyond i64 (its __index__ works, the conversion overflows)
        Err(_) if p.call_method0("__index__").is_ok() => i128::MAX,
        Err(_) => {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "points = {p}: an integer number of points"
            )))
        }
    };
    if n < 2 {
        return Err(PyValueError::new_err(format!(
            "points = {p}: a curve needs at least 2 points"
        )));
    }
    usize::try_from(n)
        .ok()
        .filter(|&n| n <= tubemem_gps::MAX_CURVE_POINTS)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "points = {p}: a curve may have at most 10,000,000 points"
            ))
        })
}

/// `points` free-inflation states equally spaced in λs from `stretch_from` to `stretch_to`: a
/// `Table` with the columns of `gps_inflate` (numpy arrays; `.to_pandas()`).
#[pyfunction]
#[pyo3(signature = (stretch_to, points=None, stretch_from=1.0, material=None, hypothesis="gps"))]
fn gps_inflation_curve<'py>(
    py: Python<'py>,
    stretch_to: f64,
    points: Option<&Bound<'py, PyAny>>,
    stretch_from: f64,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let points = point_count(points)?;
    let (law, hyp) = (law(material)?, self::hypothesis(hypothesis)?);
    use tubemem_app::curves::{inflation_values, INFLATION_HEADER};
    curve_table(py, INFLATION_HEADER, inflation_values, || {
        tubemem_gps::inflation_curve(law.as_ref(), hyp, stretch_from, stretch_to, points)
    })
}

/// The tube inflated to λs* = `initial_stretch`, the gas closed in (Boyle), squeezed between two
/// plates to half-gap `rho` (GPS eqs. 76–77, PS eqs. 78–79): dict with w, lambda_s, lambda_z, n_s,
/// n_z, rho, chi, force (ϖχ, eq. 80) and displacement (λs* − ρ, eq. 81). `rho` may be a numpy
/// array: the dict then holds arrays of its shape.
#[pyfunction]
#[pyo3(signature = (initial_stretch, rho, material=None, hypothesis="gps"))]
fn gps_flatten<'py>(
    py: Python<'py>,
    initial_stretch: f64,
    rho: &Bound<'py, PyAny>,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let law = law(material)?;
    let hyp = self::hypothesis(hypothesis)?;
    if let Ok(r) = rho.extract::<f64>() {
        let s = tubemem_gps::flatten(law.as_ref(), hyp, initial_stretch, r).map_err(gps_err)?;
        return to_py(py, &s);
    }
    use tubemem_app::curves::{flattening_values, FLATTENING_HEADER};
    let keys: Vec<&str> = FLATTENING_HEADER.split(',').collect();
    vectorized(
        py,
        rho,
        "rho",
        |r| {
            tubemem_gps::flatten(law.as_ref(), hyp, initial_stretch, r)
                .map(|s| flattening_values(&s))
        },
        &keys,
    )
}

/// `points` flattening states equally spaced in ρ from λs* down to `rho_to`: a `Table` with the
/// columns of `gps_flatten` (the curves of the paper's Figs. 6–7).
#[pyfunction]
#[pyo3(signature = (initial_stretch, rho_to, points=None, material=None, hypothesis="gps"))]
fn gps_flattening_curve<'py>(
    py: Python<'py>,
    initial_stretch: f64,
    rho_to: f64,
    points: Option<&Bound<'py, PyAny>>,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let points = point_count(points)?;
    let (law, hyp) = (law(material)?, self::hypothesis(hypothesis)?);
    use tubemem_app::curves::{flattening_values, FLATTENING_HEADER};
    curve_table(py, FLATTENING_HEADER, flattening_values, || {
        tubemem_gps::flattening_curve(law.as_ref(), hyp, initial_stretch, rho_to, points)
    })
}

/// The GPS cross-section squeezed to half-gap `rho` under the given pressure `w` (eq. 76 without
/// the gas law): dict with w, rho, lambda_s, lambda_z, n_s, n_z, chi, force. `guess` = (λs, λz)
/// picks the branch where several stretches carry the same pressure (pass the GPS flattening at
/// the same ρ).
#[pyfunction]
#[pyo3(signature = (rho, w, guess, material=None))]
fn gps_section_at_pressure<'py>(
    py: Python<'py>,
    rho: f64,
    w: f64,
    guess: (f64, f64),
    material: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let law = law(material)?;
    let s = tubemem_gps::section_at_pressure(law.as_ref(), rho, w, [guess.0, guess.1])
        .map_err(gps_err)?;
    to_py(py, &s)
}

/// Limit points of the free-inflation curve and the Maxwell (bulge propagation) pressure:
/// dict with max, min ({lambda_s, lambda_z, w} or None), maxwell ({w, lambda_s_lower,
/// lambda_s_upper} or None) and scanned_to.
#[pyfunction]
#[pyo3(signature = (material=None, hypothesis="gps"))]
fn gps_limits<'py>(
    py: Python<'py>,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let (law, hyp) = (law(material)?, self::hypothesis(hypothesis)?);
    detached(py, || tubemem_gps::limits::limit_points(law.as_ref(), hyp))
}

/// Cauchy stress resultants (N_1, N_2)/(μH) of the membrane law at principal stretches
/// (`l1`, `l2`), eq. (18).
#[pyfunction]
#[pyo3(signature = (l1, l2, material=None))]
fn resultants(l1: f64, l2: f64, material: Option<&Bound<'_, PyAny>>) -> PyResult<(f64, f64)> {
    let law = law(material)?;
    let [n1, n2] = law.resultants(l1, l2).map_err(material_err)?;
    Ok((n1, n2))
}

/// A run's outcome: its typed report (the summary dict and the step arrays are made from it,
/// not read back from disk), or `TubememError` with the whole cause chain.
fn run_outcome(
    outcome: tubemem_app::report::RunOutcome,
    out: &std::path::Path,
) -> PyResult<tubemem_app::report::RunReport> {
    match outcome.error {
        None => Ok(outcome.report),
        // the exception policy: bad input is ValueError, a solve that fails TubememError
        Some(e) if e.is_input_error() => Err(PyValueError::new_err(e.chain())),
        Some(e) => Err(TubememError::new_err(failure_message(&e, out))),
    }
}

/// A failed run's message: its whole chain, and where its converged steps are.
fn failure_message(e: &tubemem_app::AppError, out: &std::path::Path) -> String {
    format!(
        "{}; the converged steps are in {}",
        e.chain(),
        out.display()
    )
}

/// The writer of a run of `case` into `out`, with the case's checkpoint and frame settings.
fn run_writer(
    case: &tubemem_app::case::Case,
    out: &std::path::Path,
    mode: tubemem_app::output::FolderMode,
    inputs: &[&std::path::Path],
) -> Result<tubemem_app::output::RunWriter, tubemem_app::AppError> {
    Ok(
        tubemem_app::output::RunWriter::create(out, mode, case.hash(), inputs)?
            .checkpoint_every(case.solver.checkpoint_every)
            .frames_of(case.output),
    )
}

/// A converged step, sent from the run's thread to the interpreter's.
struct StepNote {
    stage: usize,
    step: usize,
    w: f64,
    lambda_s: f64,
    newton_iterations: usize,
    residual: f64,
    fraction: f64,
}

/// The observer that forwards every converged step to the interpreter's thread.
struct Notify(std::sync::mpsc::Sender<StepNote>);

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
fn run_parsed<'py>(
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
fn run_case<'py>(
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
fn run_case_text<'py>(
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
fn default_case() -> &'static str {
    tubemem_app::main_job::DEFAULT_CASE
}

/// The steps of a report as (steps.csv column, values) pairs, NaN where a column does not apply.
fn step_columns(report: &tubemem_app::report::RunReport) -> Vec<(&'static str, Vec<f64>)> {
    let rows: Vec<Vec<Option<f64>>> = report
        .steps()
        .map(|s| {
            let mut row = tubemem_app::output::step_row(s);
            if let Some(sc) = &report.scales {
                row.extend(tubemem_app::output::si_values(sc, s));
            }
            row
        })
        .collect();
    let si = report.scales.map_or("", |_| tubemem_app::output::SI_HEADER);
    tubemem_app::output::STEPS_HEADER
        .split(',')
        .chain(si.split(',').filter(|c| !c.is_empty()))
        .enumerate()
        .map(|(j, name)| {
            (
                name,
                rows.iter().map(|r| r[j].unwrap_or(f64::NAN)).collect(),
            )
        })
        .collect()
}

/// Rows under a CSV header as (column, values) pairs.
fn header_columns(header: &str, rows: &[Vec<f64>]) -> Vec<(String, Vec<f64>)> {
    header
        .split(',')
        .enumerate()
        .map(|(j, name)| (name.to_string(), rows.iter().map(|r| r[j]).collect()))
        .collect()
}

/// The located critical points of a run: the columns of critical_points.csv.
fn critical_columns(report: &tubemem_app::report::RunReport) -> Vec<(String, Vec<f64>)> {
    let rows: Vec<Vec<f64>> = report
        .critical_points()
        .map(|c| tubemem_app::output::critical_row(c).to_vec())
        .collect();
    header_columns(tubemem_app::output::CRITICAL_HEADER, &rows)
}

/// The columns that count (stages, steps, rows, iterations, …): integers in a DataFrame.
const INTEGER_COLUMNS: [&str; 9] = [
    "case",
    "row",
    "stage",
    "step",
    "front",
    "kind",
    "newton_iterations",
    "negative_pivots",
    "critical",
];

/// Make the [`INTEGER_COLUMNS`] of DataFrame `df` integers: int64 where every value is a whole
/// number, pandas' nullable Int64 where some are missing (a failed sweep member's row).
fn integer_columns(df: &Bound<'_, PyAny>) -> PyResult<()> {
    let columns: Vec<String> = df.getattr("columns")?.call_method0("tolist")?.extract()?;
    for c in INTEGER_COLUMNS {
        if !columns.iter().any(|x| x == c) {
            continue;
        }
        let col = df.get_item(c)?;
        let missing: bool = col.call_method0("isna")?.call_method0("any")?.extract()?;
        let present = col.call_method0("dropna")?;
        let whole: bool = present
            .call_method0("round")?
            .call_method1("eq", (&present,))?
            .call_method0("all")?
            .extract()?;
        if whole {
            let to = if missing { "Int64" } else { "int64" };
            df.set_item(c, col.call_method1("astype", (to,))?)?;
        }
    }
    Ok(())
}

/// The bulge fronts of a run's steps: the columns of fronts.csv.
fn front_columns(report: &tubemem_app::report::RunReport) -> Vec<(String, Vec<f64>)> {
    let rows: Vec<Vec<f64>> = report
        .steps()
        .enumerate()
        .flat_map(|(k, r)| tubemem_app::output::front_rows(k + 1, r))
        .map(|r| r.to_vec())
        .collect();
    header_columns(tubemem_app::output::FRONTS_HEADER, &rows)
}

/// Named numpy columns of equal shape: a closed-form curve, a vectorized closed form, the
/// steps or profiles of a run. `t["w"]` is a column, `t.columns` their names, `len(t)` the
/// number of rows, `t.to_pandas()` a DataFrame (columns flattened), `t.to_dict()` a plain dict.
#[pyclass(name = "Table", module = "tubemem", mapping)]
struct Table {
    columns: Vec<String>,
    data: Py<pyo3::types::PyDict>,
    rows: usize,
}

impl Table {
    /// A table of 1-D columns.
    fn from_columns(py: Python<'_>, cols: Vec<(String, Vec<f64>)>) -> PyResult<Self> {
        let data = pyo3::types::PyDict::new(py);
        let rows = cols.first().map_or(0, |c| c.1.len());
        let mut columns = vec![];
        for (name, col) in cols {
            data.set_item(&name, numpy::PyArray1::from_vec(py, col))?;
            columns.push(name);
        }
        Ok(Table {
            columns,
            data: data.unbind(),
            rows,
        })
    }
}

#[pymethods]
impl Table {
    fn __getitem__<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        self.data.bind(py).get_item(key)?.ok_or_else(|| {
            pyo3::exceptions::PyKeyError::new_err(format!(
                "{key:?}: the columns are {}",
                self.columns.join(", ")
            ))
        })
    }
    /// Iterates over the column names, as a dict or a DataFrame does.
    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        pyo3::types::PyList::new(py, &self.columns)?
            .as_any()
            .try_iter()
            .map(|i| i.into_any())
    }
    fn __contains__(&self, key: &str) -> bool {
        self.columns.iter().any(|c| c == key)
    }
    fn __len__(&self) -> usize {
        self.rows
    }
    /// The column names, in order.
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.columns.clone()
    }
    fn keys(&self) -> Vec<String> {
        self.columns.clone()
    }
    /// A dict of the numpy columns.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        self.data.bind(py).copy()
    }
    /// A pandas DataFrame (pandas is imported on demand; n-d columns are flattened; the
    /// counting columns, `stage`, `step`, `row`, …, are integers).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat = pyo3::types::PyDict::new(py);
        for c in &self.columns {
            flat.set_item(c, self.__getitem__(py, c)?.call_method0("ravel")?)?;
        }
        let df = py.import("pandas")?.call_method1("DataFrame", (flat,))?;
        integer_columns(&df)?;
        Ok(df)
    }
    fn __repr__(&self) -> String {
        format!(
            "<tubemem.Table {} rows × {} columns: {}>",
            self.rows,
            self.columns.len(),
            self.columns.join(", ")
        )
    }
}

/// The per-step profiles of a run in long form: the columns of profiles/profiles.csv.
fn profile_columns(report: &tubemem_app::report::RunReport) -> Vec<(String, Vec<f64>)> {
    use tubemem_app::output::{ring_row, PROFILES_HEADER};
    let mut rows: Vec<Vec<f64>> = vec![];
    for (k, r) in report.steps().enumerate() {
        for ring in &r.profile {
            let mut row = vec![(k + 1) as f64, r.stage as f64, r.step as f64];
            row.extend(ring_row(ring));
            rows.push(row);
        }
    }
    header_columns(PROFILES_HEADER, &rows)
}

/// A finished FE run: `summary` (the dict of summary.json), `steps` (a `Table` of numpy arrays,
/// one per steps.csv column, NaN where a column does not apply), `profiles` (a `Table` in long
/// form: one row per ring and step, the columns of profiles/profiles.csv), `critical_points`
/// (a `Table`: the columns of critical_points.csv, one row per located critical point of an
/// arc-length stage), `fronts` (a `Table`: the columns of fronts.csv), `path` (the run
/// folder) and `to_pandas()` (the steps); `vtu(k)` is the path of VTU frame k (0 the reference
/// state; which steps have a frame follows `[output] vtu`), readable with meshio.
#[pyclass(name = "Run", module = "tubemem")]
struct Run {
    summary: Py<PyAny>,
    steps: Py<Table>,
    profiles: Py<Table>,
    critical_points: Py<Table>,
    fronts: Py<Table>,
    path: PathBuf,
    frames: usize,
}

#[pymethods]
impl Run {
    #[getter]
    fn summary(&self, py: Python<'_>) -> Py<PyAny> {
        self.summary.clone_ref(py)
    }
    #[getter]
    fn steps(&self, py: Python<'_>) -> Py<Table> {
        self.steps.clone_ref(py)
    }
    #[getter]
    fn profiles(&self, py: Python<'_>) -> Py<Table> {
        self.profiles.clone_ref(py)
    }
    #[getter]
    fn critical_points(&self, py: Python<'_>) -> Py<Table> {
        self.critical_points.clone_ref(py)
    }
    #[getter]
    fn fronts(&self, py: Python<'_>) -> Py<Table> {
        self.fronts.clone_ref(py)
    }
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }
    /// The steps as a pandas DataFrame (pandas is imported on demand).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.steps.borrow(py).to_pandas(py)
    }
    /// The VTU file of frame `k` (0: the reference state; k: after the k-th converged step).
    fn vtu(&self, k: usize) -> PyResult<PathBuf> {
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

/// A validated case. `Case(geometry=…, material=…, mesh=…, stage=[…], solver=…, output=…)` takes
/// the case file's tables as keyword arguments; `Case.from_dict(d)`, `Case.from_toml(text)` and
/// `Case.read(path)` the other forms. Validation happens on construction (ValueError naming the
/// table and key); `to_toml()` and `to_dict()` give it back. `tubemem.run` takes it.
#[pyclass(name = "Case", module = "tubemem")]
struct PyCase {
    toml: String,
    base_dir: PathBuf,
}

impl PyCase {
    fn parse(toml: String, base_dir: PathBuf) -> PyResult<Self> {
        tubemem_app::case::Case::parse(&toml)
            .map_err(|e| PyValueError::new_err(tubemem_app::error_chain(&e)))?;
        Ok(Self { toml, base_dir })
    }

    /// A case from a dict of its tables: its errors name dict paths (`material.kuhm`,
    /// `stage[1].target_rho`), not the lines of the TOML it is turned into.
    fn from_value(d: &Bound<'_, PyAny>, base_dir: PathBuf) -> PyResult<Self> {
        let value: serde_json::Value = from_py(d, "case")?;
        let table = toml::Value::try_from(value)
            .map_err(|e| PyValueError::new_err(format!("case: {e}")))?;
        let text =
            toml::to_string(&table).map_err(|e| PyValueError::new_err(format!("case: {e}")))?;
        match tubemem_app::case::Case::parse(&text) {
            Ok(_) => Ok(Self {
                toml: text,
                base_dir,
            }),
            Err(e) => Err(PyValueError::new_err(dict_message(
                &tubemem_app::error_chain(&e),
                &text,
            ))),
        }
    }
}

#[pymethods]
impl PyCase {
    #[new]
    #[pyo3(signature = (base_dir=None, **tables))]
    fn new(
        base_dir: Option<PathBuf>,
        tables: Option<&Bound<'_, pyo3::types::PyDict>>,
    ) -> PyResult<Self> {
        let py_tables = match tables {
            Some(t) => t.clone(),
            None => return Err(PyValueError::new_err("Case: give the case file's tables as keywords (geometry=…, material=…, mesh=…, stage=[…])")),
        };
        Self::from_value(py_tables.as_any(), base_dir.unwrap_or_default())
    }
    #[staticmethod]
    #[pyo3(signature = (d, base_dir=None))]
    fn from_dict(d: &Bound<'_, PyAny>, base_dir: Option<PathBuf>) -> PyResult<Self> {
        Self::from_value(d, base_dir.unwrap_or_default())
    }
    #[staticmethod]
    #[pyo3(signature = (text, base_dir=None))]
    fn from_toml(text: String, base_dir: Option<PathBuf>) -> PyResult<Self> {
        Self::parse(text, base_dir.unwrap_or_default())
    }
    /// Read a case file (user meshes are looked up relative to its folder).
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path)
            .map_err(|e| PyValueError::new_err(format!("cannot read {}: {e}", path.display())))?;
        Self::parse(text, path.parent().map(PathBuf::from).unwrap_or_default())
    }
    fn to_toml(&self) -> String {
        self.toml.clone()
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("tomllib")?
            .call_method1("loads", (self.toml.as_str(),))
    }
    /// The tube, its law, its mesh and its stages in one line ([`tubemem_app::case::Case::describe`]).
    fn __repr__(&self) -> String {
        match tubemem_app::case::Case::parse(&self.toml) {
            Ok(c) => format!("<tubemem.Case: {}>", c.describe()),
            Err(_) => format!("<tubemem.Case: {} bytes of TOML>", self.toml.len()),
        }
    }
    fn __eq__(&self, other: &Self) -> bool {
        self.toml == other.toml
    }
}

/// The dict path of line `line` (1-based) of the TOML text a case dict was turned into: its
/// table (`stage[k]` for the k-th `[[stage]]`, 0-based as the list) and its key.
fn dict_path(text: &str, line: usize) -> String {
    let mut table = String::new();
    let mut stages = 0usize;
    for (k, l) in text.lines().enumerate() {
        let t = l.trim();
        if let Some(name) = t.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
            let count = if name == "stage" {
                stages += 1;
                stages
            } else {
                1
            };
            table = format!("{name}[{}]", count - 1);
        } else if let Some(name) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            table = name.to_string();
        }
        if k + 1 == line {
            let key = t.split('=').next().unwrap_or("").trim();
            return match (table.is_empty(), key.is_empty() || t.starts_with('[')) {
                (true, _) => key.to_string(),
                (false, true) => table,
                (false, false) => format!("{table}.{key}"),
            };
        }
    }
    table
}

/// A case error as a Python user reads it: a TOML parse error of the generated text becomes
/// the dict path it points at and its reason; the case file's `[[stage]] N: \`key\`` and
/// `[table] \`key\`` become `stage[N-1].key` and `table.key`.
fn dict_message(msg: &str, text: &str) -> String {
    if let Some(rest) = msg.split("TOML parse error at line ").nth(1) {
        let line: usize = rest
            .split(|c: char| !c.is_ascii_digit())
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or(0);
        let reason = rest.lines().last().unwrap_or("").trim();
        let mut path = dict_path(text, line);
        // an unknown key reported at its table: the key itself
        if let Some(key) = reason
            .strip_prefix("unknown field `")
            .and_then(|r| r.split('`').next())
        {
            if !path.ends_with(&format!(".{key}")) {
                path = format!("{path}.{key}");
            }
        }
        return format!("case dict: {path}: {reason}");
    }
    format!("case dict: {}", pythonic(msg))
}

/// The case file's names in a message, as the dict paths and arguments of the Python API:
/// `[[stage]] N: \`key\`` → `stage[N-1].key`, `[[stage]] N` → `stage[N-1]`, `[table] \`key\``
/// → `table.key`, and the CLI's `--overwrite`, `--out`, `--resume` → `overwrite=True`, `out`,
/// the CLI's `tubemem run --resume`.
fn pythonic(msg: &str) -> String {
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("[[stage]] ") {
            let digits: String = after.chars().take_while(|c| c.is_ascii_digit()).collect();
            if let Ok(n) = digits.parse::<usize>() {
                let mut tail = &after[digits.len()..];
                let mut path = format!("stage[{}]", n.saturating_sub(1));
                if let Some(key) = tail
                    .strip_prefix(": `")
                    .and_then(|t| t.split_once('`'))
                    .filter(|(k, _)| k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
                {
                    path = format!("{path}.{}", key.0);
                    tail = key.1;
                }
                out.push_str(&path);
                rest = tail;
                continue;
            }
        }
        if let Some(after) = rest.strip_prefix('[') {
            if let Some((name, tail)) = after.split_once("] `") {
                if let Some((key, tail)) = tail.split_once('`') {
                    if !name.is_empty()
                        && name.chars().all(|c| c.is_ascii_lowercase() || c == '_')
                        && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                    {
                        out.push_str(&format!("{name}.{key}"));
                        rest = tail;
                        continue;
                    }
                }
            }
        }
        let c = rest.chars().next().unwrap_or(' ');
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    out.replace("--overwrite", "overwrite=True")
        .replace("another --out", "another `out`")
        .replace("--resume", "the CLI's `tubemem run --resume`")
}

/// A case given as a `Case`, a path to a TOML file, TOML text, or a dict of the case file's
/// tables.
fn case_from(
    py: Python<'_>,
    case: &Bound<'_, PyAny>,
    base_dir: Option<PathBuf>,
) -> PyResult<(tubemem_app::case::Case, String)> {
    let invalid =
        |e: tubemem_app::case::CaseError| PyValueError::new_err(tubemem_app::error_chain(&e));
    if let Ok(c) = case.cast::<PyCase>() {
        let c = c.borrow();
        let mut parsed = tubemem_app::case::Case::parse(&c.toml).map_err(invalid)?;
        parsed.base_dir = base_dir.unwrap_or_else(|| c.base_dir.clone());
        return Ok((parsed, "case from Python".into()));
    }
    if case.cast::<pyo3::types::PyDict>().is_ok() {
        let c = PyCase::from_value(case, PathBuf::new())?;
        let mut parsed = tubemem_app::case::Case::parse(&c.toml).map_err(invalid)?;
        parsed.base_dir = base_dir.unwrap_or_default();
        return Ok((parsed, "case dict from Python".into()));
    }
    let text: String = case
        .str()
        .and_then(|s| s.extract())
        .map_err(|_| PyValueError::new_err("case: a path, TOML text or a dict"))?;
    let path = PathBuf::from(&text);
    if !text.contains('\n') && path.is_file() {
        let c = tubemem_app::case::Case::read(&path).map_err(invalid)?;
        return Ok((c, path.display().to_string()));
    }
    let mut c = tubemem_app::case::Case::parse(&text).map_err(invalid)?;
    c.base_dir = base_dir.unwrap_or_default();
    let _ = py;
    Ok((c, "case text from Python".into()))
}

/// Run a case (a TOML file's path, TOML text, or a dict of its tables, e.g.
/// `{"geometry": {"radius": 1.0, "length": 20.0}, "material": {...}, "mesh": {...},
/// "stage": [{...}]}`) into `out`; returns a `Run` with the steps as arrays. Errors, progress and
/// Ctrl-C as for `run_case`.
#[pyfunction]
#[pyo3(signature = (case, out, base_dir=None, overwrite=false, progress=None))]
fn run<'py>(
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

/// One sweep member, run on the calling thread without the interpreter: the case (TOML text)
/// into `out` (written over: a sweep's folders are its own); the report, or the error's whole
/// chain (a failed solve also says where its converged steps are). `stop` interrupts it at its
/// next Newton iteration.
fn sweep_member(
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
fn member_dict<'py>(
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
fn _sweep_one<'py>(
    py: Python<'py>,
    index: usize,
    text: String,
    out: PathBuf,
) -> PyResult<Bound<'py, PyAny>> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let result = py.detach(|| sweep_member(index, &text, &out, &stop));
    member_dict(py, index, &out, &result)
}

/// A tqdm bar of `total` `unit`s (tqdm imported on demand: it is optional); `arg` is the
/// argument that asked for it, for the message when tqdm is missing.
fn tqdm_bar<'py>(
    py: Python<'py>,
    arg: &str,
    total: f64,
    unit: &str,
    desc: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let tqdm = py.import("tqdm.auto").map_err(|_| {
        pyo3::exceptions::PyImportError::new_err(format!(
            "{arg} needs the tqdm package: pip install tqdm"
        ))
    })?;
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("total", total)?;
    kwargs.set_item("unit", unit)?;
    kwargs.set_item("desc", desc)?;
    tqdm.getattr("tqdm")?.call((), Some(&kwargs))
}

/// The sweep's progress: a tqdm bar over the members, a callable given a dict per finished
/// member, or nothing.
enum SweepProgress<'py> {
    None,
    Bar(Bound<'py, PyAny>),
    Call(Bound<'py, PyAny>),
}

impl<'py> SweepProgress<'py> {
    fn new(py: Python<'py>, progress: Option<&Bound<'py, PyAny>>, total: usize) -> PyResult<Self> {
        let Some(p) = progress.filter(|p| !p.is_none()) else {
            return Ok(Self::None);
        };
        if let Ok(name) = p.extract::<String>() {
            if name != "tqdm" {
                return Err(PyValueError::new_err(format!(
                    "sweep(progress={name:?}): a callable, \"tqdm\" or None"
                )));
            }
            return Ok(Self::Bar(tqdm_bar(
                py,
                "sweep(progress=\"tqdm\")",
                total as f64,
                "case",
                "tubemem sweep",
            )?));
        }
        if !p.is_callable() {
            return Err(PyValueError::new_err(
                "sweep(progress=...): a callable, \"tqdm\" or None",
            ));
        }
        Ok(Self::Call(p.clone()))
    }

    /// Member `case` has finished (`error` None when it converged); `done` of `total` so far.
    fn finished(
        &self,
        py: Python<'py>,
        case: usize,
        done: usize,
        total: usize,
        error: Option<&str>,
    ) -> PyResult<()> {
        match self {
            Self::None => Ok(()),
            Self::Bar(b) => {
                b.call_method1("update", (1,))?;
                if error.is_some() {
                    b.call_method1("set_postfix_str", (format!("case {case} failed"),))?;
                }
                Ok(())
            }
            Self::Call(f) => {
                let d = pyo3::types::PyDict::new(py);
                d.set_item("case", case)?;
                d.set_item("done", done)?;
                d.set_item("total", total)?;
                d.set_item("error", error)?;
                f.call1((d,)).map(|_| ())
            }
        }
    }

    fn close(&self) -> PyResult<()> {
        if let Self::Bar(b) = self {
            b.call_method0("close")?;
        }
        Ok(())
    }
}

/// Run the members on `workers` threads of this process (each run releases the interpreter,
/// so they run in parallel; no worker process re-imports the caller's script, so a sweep runs
/// from a plain script, a notebook or the REPL alike). Ctrl-C or a progress callback that
/// raises stops the runs at their next Newton iteration; the finished ones stay on disk.
fn sweep_threads<'py>(
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
fn sweep<'py>(
    py: Python<'py>,
    cases: &Bound<'py, PyAny>,
    out: PathBuf,
    params: Option<&Bound<'py, PyAny>>,
    client: Option<&Bound<'py, PyAny>>,
    workers: Option<usize>,
    progress: Option<&Bound<'py, PyAny>>,
    processes: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
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
        (Some(0), _) | (None, Some(0)) => {
            return Err(PyValueError::new_err("sweep: workers = 0: at least 1"))
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

/// Run verification suites (TOML files, as `tubemem verify`) or, with `case=`, the study of one
/// case (closed form, three-mesh convergence with GCI, end effect, invariance core, references),
/// into `out`; writes results.json, report.md, report.html and junit.xml there and returns the
/// results as a dict (results.json's content: `verdict`, `passed`, `failed`, `checks` with each
/// check's `status`, `message`, `measures` and `details`). Bad suites raise ValueError; failing
/// checks do not raise (read `failed` and each check's `status`). The `reference` checks run
/// the scikit-fem references in `python` (default: this interpreter, where
/// `pip install ./python_ref` puts them) or from the `python_ref` folder given (default
/// `TUBEMEM_PYTHON_REF`, else a checkout's above the case or the working folder).
#[pyfunction]
#[pyo3(signature = (suites=None, out=PathBuf::from("tubemem-verify"), case=None, quick=false, jobs=0, filter=None, update_gold=false, python=None, python_ref=None))]
#[allow(clippy::too_many_arguments)]
fn verify<'py>(
    py: Python<'py>,
    suites: Option<Vec<PathBuf>>,
    out: PathBuf,
    case: Option<PathBuf>,
    quick: bool,
    jobs: usize,
    filter: Option<String>,
    update_gold: bool,
    python: Option<PathBuf>,
    python_ref: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    use tubemem_app::verify::{self as v, report::Results, VerifyOptions};
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
    let (names, results, verdict) = match (case, suites) {
        (Some(c), None) => {
            let s = py
                .detach(|| v::study::run_study(&c, &out, quick, &opts, &quiet))
                .map_err(|e| PyValueError::new_err(tubemem_app::error_chain(&e)))?;
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
            let r = py
                .detach(|| v::run_checks(&checks, &out, &opts, &quiet))
                .map_err(|e| TubememError::new_err(e.chain()))?;
            (names, r, None)
        }
        _ => {
            return Err(PyValueError::new_err(
                "give suites=[...] (suite files) or case=... (a case file), not both",
            ))
        }
    };
    let results = Results::new(names, t0.elapsed().as_secs_f64(), &results, verdict);
    v::report::write_all(&out, &results).map_err(|e| TubememError::new_err(e.chain()))?;
    to_py(py, &results)
}

/// The TOML text of a case given in any of `run`'s forms.
fn case_text(py: Python<'_>, case: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(c) = case.cast::<PyCase>() {
        return Ok(c.borrow().toml.clone());
    }
    if case.cast::<pyo3::types::PyDict>().is_ok() {
        return Ok(PyCase::from_value(case, PathBuf::new())?.toml);
    }
    let text: String = case.str()?.extract()?;
    let path = PathBuf::from(&text);
    if !text.contains('\n') && path.is_file() {
        return std::fs::read_to_string(&path)
            .map_err(|e| PyValueError::new_err(format!("cannot read {}: {e}", path.display())));
    }
    let _ = py;
    Ok(text)
}

/// tubemem: pressurized membrane tubes — the closed form under generalized plane strain (GPS)
/// and plane strain (PS), and the 3D nonlinear membrane finite element runs of whole capped
/// tubes, inflated and squeezed between plates.
///
/// Units are dimensionless: R = 1, μH = 1, w = ϖ = pR/(μH) (eq. 67), resultants N/(μH),
/// rho = r/R, chi = c/(πR) (eq. 72), force = ϖχ (eq. 80). Materials are dicts in the case-file
/// form ({"model": "abb", "shear_modulus": 1.0, "kuhn": 30}); None is the paper's law.
///
/// Closed form: gps_inflate, gps_flatten (numbers → dict; numpy arrays → Table),
/// gps_inflation_curve, gps_flattening_curve (→ Table), gps_section_at_pressure, gps_limits,
/// resultants. A Table is named numpy columns: t["w"], t.columns, t.to_pandas().
/// FE runs: run (a case as path, TOML text or dict → Run: steps and profiles as Tables),
/// run_case, run_case_text (→ the summary dict), default_case; progress= a callable, "tqdm" or
/// None (the `tubemem` logger at DEBUG level, silent by default).
///
/// Errors: ValueError for bad input (a parameter out of range, a stretch beyond the law's
/// locking limit, a malformed case naming its key); TubememError (a RuntimeError) for a solve or
/// run that fails, with the stage, step and cause. Ctrl-C stops a run (KeyboardInterrupt) with
/// its converged steps kept.
#[pymodule]
fn tubemem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("TubememError", m.py().get_type::<TubememError>())?;
    m.add_function(wrap_pyfunction!(gps_inflate, m)?)?;
    m.add_class::<Table>()?;
    m.add_function(wrap_pyfunction!(verify, m)?)?;
    m.add_function(wrap_pyfunction!(gps_inflation_curve, m)?)?;
    m.add_function(wrap_pyfunction!(gps_flatten, m)?)?;
    m.add_function(wrap_pyfunction!(gps_flattening_curve, m)?)?;
    m.add_function(wrap_pyfunction!(gps_section_at_pressure, m)?)?;
    m.add_function(wrap_pyfunction!(gps_limits, m)?)?;
    m.add_function(wrap_pyfunction!(resultants, m)?)?;
    m.add_function(wrap_pyfunction!(run_case, m)?)?;
    m.add_function(wrap_pyfunction!(run_case_text, m)?)?;
    m.add_function(wrap_pyfunction!(default_case, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_class::<Run>()?;
    m.add_class::<PyCase>()?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_one, m)?)?;
    Ok(())
}
