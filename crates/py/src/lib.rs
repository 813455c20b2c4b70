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

mod atlas;
mod case;
mod convert;
mod errors;
mod gps;
mod gps_history;
mod material;
mod outcome;
mod progress;
mod run;
mod sweep;
mod table;
mod verify;

use pyo3::prelude::*;

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
/// gps_between_plates, gps_critical_pressure (the regulated squeeze, issue #62), gps_history
/// (a viscoelastic law in time, issue #63),
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
    m.add("TubememError", m.py().get_type::<errors::TubememError>())?;
    m.add_function(wrap_pyfunction!(gps::gps_inflate, m)?)?;
    m.add_class::<table::Table>()?;
    m.add_function(wrap_pyfunction!(verify::verify, m)?)?;
    m.add_function(wrap_pyfunction!(gps::gps_inflation_curve, m)?)?;
    m.add_function(wrap_pyfunction!(gps::gps_flatten, m)?)?;
    m.add_function(wrap_pyfunction!(gps::gps_flattening_curve, m)?)?;
    m.add_function(wrap_pyfunction!(gps::gps_between_plates, m)?)?;
    m.add_function(wrap_pyfunction!(gps::gps_critical_pressure, m)?)?;
    m.add_function(wrap_pyfunction!(gps::gps_section_at_pressure, m)?)?;
    m.add_function(wrap_pyfunction!(gps::gps_limits, m)?)?;
    m.add_function(wrap_pyfunction!(gps::resultants, m)?)?;
    m.add_function(wrap_pyfunction!(gps_history::gps_history, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_case, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_case_text, m)?)?;
    m.add_function(wrap_pyfunction!(run::default_case, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_class::<run::Run>()?;
    m.add_class::<case::PyCase>()?;
    m.add_class::<material::PyMaterial>()?;
    m.add_function(wrap_pyfunction!(material::fit, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::_sweep_one, m)?)?;
    m.add_function(wrap_pyfunction!(atlas::atlas, m)?)?;
    m.add_function(wrap_pyfunction!(atlas::_atlas_member, m)?)?;
    Ok(())
}
