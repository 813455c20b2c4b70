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
                match non_finite_path(obj) {
                    Some((path, v)) => format!("`{path}` = {v} is not a finite number"),
                    None => "a value is not a finite number (NaN or infinity)".to_string(),
                }
            } else {
                cause
            };
            PyValueError::new_err(tubemem_material::shorten_lines(&format!("{what}: {cause}")))
        })?
        .extract()?;
    serde_json::from_str(&text)
        .map_err(|e| PyValueError::new_err(tubemem_material::tidy_numbers(&format!("{what}: {e}"))))
}

/// Where in a dict/list structure the first float that is NaN or infinite sits, as a dict path
/// (`geometry.radius`, `stage[0].target_stretch`), with its value. An explicit stack, so a
/// hostile nesting cannot exhaust the native one.
fn non_finite_path(obj: &Bound<'_, PyAny>) -> Option<(String, String)> {
    use pyo3::types::{PyDict, PyFloat, PyList, PyTuple};
    let mut todo: Vec<(Bound<'_, PyAny>, String)> = vec![(obj.clone(), String::new())];
    let mut seen = 0usize;
    while let Some((o, path)) = todo.pop() {
        seen += 1;
        if seen > 1_000_000 {
            return None;
        }
        if let Ok(d) = o.cast::<PyDict>() {
            let items: Vec<_> = d.iter().collect();
            for (k, v) in items.into_iter().rev() {
                let key = k.to_string();
                let p = if path.is_empty() {
                    key
                } else {
                    format!("{path}.{key}")
                };
                todo.push((v, p));
            }
        } else if o.is_instance_of::<PyList>() || o.is_instance_of::<PyTuple>() {
            let items: Vec<_> = o.try_iter().ok()?.filter_map(Result::ok).collect();
            for (i, v) in items.into_iter().enumerate().rev() {
                todo.push((v, format!("{path}[{i}]")));
            }
        } else if o.is_instance_of::<PyFloat>() || o.get_type().module().is_ok_and(|m| m == "numpy")
        {
            if let Ok(x) = o.extract::<f64>() {
                if !x.is_finite() {
                    return Some((path, format!("{x}")));
                }
            }
        }
    }
    None
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

/// An integer argument `name` (any Python or numpy integer, not a bool) in [`min`, `max`]: a
/// negative or huge one is a ValueError naming it and `requirement` (not the OverflowError of
/// a conversion to an unsigned type), a non-integer a TypeError.
pub(crate) fn int_arg(
    p: &Bound<'_, PyAny>,
    name: &str,
    min: usize,
    max: usize,
    requirement: &str,
) -> PyResult<usize> {
    if p.is_instance_of::<pyo3::types::PyBool>() {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{name}: an integer, not a bool"
        )));
    }
    let n: i128 = match p.call_method0("__index__").and_then(|i| i.extract::<i64>()) {
        Ok(n) => n.into(),
        // an integer beyond i64 (its __index__ works, the conversion overflows)
        Err(_) if p.call_method0("__index__").is_ok() => i128::MAX,
        Err(_) => {
            let shown: String = p.to_string().chars().take(40).collect();
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "{name} = {shown}: an integer ({requirement})"
            )));
        }
    };
    usize::try_from(n)
        .ok()
        .filter(|&n| (min..=max).contains(&n))
        .ok_or_else(|| {
            let shown: String = p.to_string().chars().take(40).collect();
            PyValueError::new_err(format!("{name} = {shown}: {requirement}"))
        })
}
