//! Values crossing the boundary as JSON: serde on this side, `json` on the Python side (every
//! result type already serializes for `summary.json`, so there is one conversion to keep right).

use crate::errors::TubememError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A Python object to a serde value, through `json.dumps`.
pub(crate) fn from_py<T: serde::de::DeserializeOwned>(
    obj: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<T> {
    let py = obj.py();
    let json = py.import("json")?;
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("allow_nan", false)?;
    // numpy scalars (np.int64(3), np.float64(0.5): what indexing an array gives) as the
    // Python numbers they hold; anything else stays refused by the JSON writer
    let default = py.eval(
        c"lambda o: o.item() if (type(o).__module__ == 'numpy' and getattr(o, 'ndim', None) == 0 and getattr(o, 'dtype', None) is not None and o.dtype.kind in 'iuf') else (_ for _ in ()).throw(TypeError(f'{type(o).__name__} {o!r} is not a real number, string, list or dict'))",
        None,
        None,
    )?;
    kwargs.set_item("default", default)?;
    // NaN and infinity are not values a material may have; say so rather than let the JSON
    // reader point at a column the user never wrote
    let text: String = json
        .call_method("dumps", (obj,), Some(&kwargs))
        .map_err(|e| {
            let cause = e.value(py).to_string();
            let cause = if cause.contains("Out of range float") {
                "a value is not a finite number (NaN or infinity)".to_string()
            } else {
                cause
            };
            PyValueError::new_err(tubemem_material::shorten_lines(&format!("{what}: {cause}")))
        })?
        .extract()?;
    serde_json::from_str(&text)
        .map_err(|e| PyValueError::new_err(tubemem_material::tidy_numbers(&format!("{what}: {e}"))))
}

/// A serde value to a Python object, through `json.loads`.
pub(crate) fn to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| TubememError::new_err(format!("cannot serialize a result: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}
