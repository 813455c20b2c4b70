//! Progress displays: a tqdm bar, or a callable given a dict per finished sweep member.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A tqdm bar of `total` `unit`s (tqdm imported on demand: it is optional); `arg` is the
/// argument that asked for it, for the message when tqdm is missing.
pub(crate) fn tqdm_bar<'py>(
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
pub(crate) enum SweepProgress<'py> {
    None,
    Bar(Bound<'py, PyAny>),
    Call(Bound<'py, PyAny>),
}

impl<'py> SweepProgress<'py> {
    pub(crate) fn new(
        py: Python<'py>,
        progress: Option<&Bound<'py, PyAny>>,
        total: usize,
    ) -> PyResult<Self> {
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
    pub(crate) fn finished(
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

    pub(crate) fn close(&self) -> PyResult<()> {
        if let Self::Bar(b) = self {
            b.call_method0("close")?;
        }
        Ok(())
    }
}
