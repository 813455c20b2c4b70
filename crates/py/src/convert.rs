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
pub(crate) fn to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| TubememError::new_err(format!("cannot serialize a result: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}
