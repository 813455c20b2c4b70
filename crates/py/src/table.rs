//! `tubemem.Table`: named numpy columns, and the columns of a run's steps, profiles, critical
//! points and fronts.

use pyo3::prelude::*;

/// The steps of a report as (steps.csv column, values) pairs, NaN where a column does not apply.
pub(crate) fn step_columns(
    report: &tubemem_app::report::RunReport,
) -> Vec<(&'static str, Vec<f64>)> {
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
pub(crate) fn header_columns(header: &str, rows: &[Vec<f64>]) -> Vec<(String, Vec<f64>)> {
    header
        .split(',')
        .enumerate()
        .map(|(j, name)| (name.to_string(), rows.iter().map(|r| r[j]).collect()))
        .collect()
}

/// The located critical points of a run: the columns of critical_points.csv.
pub(crate) fn critical_columns(report: &tubemem_app::report::RunReport) -> Vec<(String, Vec<f64>)> {
    let rows: Vec<Vec<f64>> = report
        .critical_points()
        .map(|c| tubemem_app::output::critical_row(c).to_vec())
        .collect();
    header_columns(tubemem_app::output::CRITICAL_HEADER, &rows)
}

/// The columns that count (stages, steps, rows, iterations, …): integers in a DataFrame.
pub(crate) const INTEGER_COLUMNS: [&str; 9] = [
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
pub(crate) fn integer_columns(df: &Bound<'_, PyAny>) -> PyResult<()> {
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
pub(crate) fn front_columns(report: &tubemem_app::report::RunReport) -> Vec<(String, Vec<f64>)> {
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
pub(crate) struct Table {
    pub(crate) columns: Vec<String>,
    pub(crate) data: Py<pyo3::types::PyDict>,
    pub(crate) rows: usize,
}

impl Table {
    /// A table of 1-D columns.
    pub(crate) fn from_columns(py: Python<'_>, cols: Vec<(String, Vec<f64>)>) -> PyResult<Self> {
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
    pub(crate) fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
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
pub(crate) fn profile_columns(report: &tubemem_app::report::RunReport) -> Vec<(String, Vec<f64>)> {
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
