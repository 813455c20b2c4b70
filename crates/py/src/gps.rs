//! The closed form: free inflation, flattening, the section at a given pressure, limit points
//! and resultants, for numbers or numpy arrays.

use crate::convert::to_py;
use crate::errors::{gps_err, material_err, TubememError};
use crate::table::Table;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use tubemem_gps::GpsError;
use tubemem_gps::Hypothesis;
use tubemem_material::MaterialSpec;
use tubemem_material::MembraneLaw;

/// The paper's law: Anssari-Benam–Bucchi with μ = 1 and 𝒩 = 30.
pub(crate) const DEFAULT_MATERIAL: MaterialSpec = MaterialSpec::Abb {
    shear_modulus: 1.0,
    kuhn: 30.0,
};

/// A closed-form computation run without the interpreter lock, its result as a Python object.
pub(crate) fn detached<'py, T: serde::Serialize + Send>(
    py: Python<'py>,
    f: impl FnOnce() -> Result<T, GpsError> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let value = py.detach(f).map_err(gps_err)?;
    to_py(py, &value)
}

pub(crate) fn law(material: Option<&Bound<'_, PyAny>>) -> PyResult<Box<dyn MembraneLaw>> {
    let spec = match material {
        Some(m) if !m.is_none() => crate::material::spec_of(m)?,
        _ => DEFAULT_MATERIAL,
    };
    spec.build().map_err(material_err)
}

pub(crate) fn hypothesis(name: &str) -> PyResult<Hypothesis> {
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
pub(crate) fn gps_inflate<'py>(
    py: Python<'py>,
    stretch: &Bound<'py, PyAny>,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let law = law(material)?;
    let hyp = self::hypothesis(hypothesis)?;
    if let Ok(v) = real_scalar(stretch, "stretch")? {
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

/// `obj` as one real number (Ok(Err) where it is not a scalar: an array goes the vectorized
/// way); a bool or a string is refused, not read as 1.0 or parsed.
fn real_scalar(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Result<f64, ()>> {
    use pyo3::types::{PyBool, PyString};
    if obj.is_instance_of::<PyBool>() || obj.is_instance_of::<PyString>() {
        return Err(PyTypeError::new_err(format!(
            "{what}: a number or an array of numbers, not {}",
            obj.repr()
                .map_or_else(|_| "?".to_string(), |r| r.to_string())
        )));
    }
    Ok(obj.extract::<f64>().map_err(|_| ()))
}

/// Evaluate `f` at every entry of the array-like `input` (any shape) and return a dict of numpy
/// arrays of that shape, one per key. An entry that fails raises with its index.
pub(crate) fn vectorized<'py>(
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
    // text ("1.3") and booleans would be converted to numbers by the float conversion below
    if !matches!(kind.as_str(), "i" | "u" | "f") {
        return Err(PyTypeError::new_err(format!(
            "{what}: a number or an array of numbers, not {} (numpy dtype kind {kind:?})",
            input
                .get_type()
                .name()
                .map_or_else(|_| "?".to_string(), |n| n.to_string())
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
pub(crate) fn curve_table<'py, S: Send>(
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

/// A curve's `points` (default 100): at least 2, at most [`tubemem_gps::MAX_CURVE_POINTS`].
pub(crate) fn point_count(points: Option<&Bound<'_, PyAny>>) -> PyResult<usize> {
    let Some(p) = points else {
        return Ok(100);
    };
    crate::convert::int_arg(
        p,
        "points",
        2,
        tubemem_gps::MAX_CURVE_POINTS,
        "a curve needs at least 2 points and may have at most 10,000,000 points",
    )
}

/// `points` free-inflation states equally spaced in λs from `stretch_from` to `stretch_to`: a
/// `Table` with the columns of `gps_inflate` (numpy arrays; `.to_pandas()`).
#[pyfunction]
#[pyo3(signature = (stretch_to, points=None, stretch_from=1.0, material=None, hypothesis="gps"))]
pub(crate) fn gps_inflation_curve<'py>(
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

/// The tube inflated to λs* = `initial_stretch`, squeezed between two plates to half-gap `rho`:
/// with `control="gas"` (the default) the gas closed in (Boyle; GPS eqs. 76–77, PS eqs.
/// 78–79), with `control="pressure"` a regulated supply (eqs. 76 at the pressure held at its
/// inflated value, or ramped to `pressure`). Dict with w, lambda_s, lambda_z, n_s, n_z, rho,
/// chi, force (ϖχ, eq. 80) and displacement (λs* − ρ, eq. 81); regulated, also stiffness: the
/// plates' −d(force)/d(2ρ) at that pressure (a gripper's dF/dgap, force over πμH per R). `rho`
/// may be a numpy array: the dict then holds arrays of its shape.
#[pyfunction]
#[pyo3(signature = (initial_stretch, rho, material=None, hypothesis="gps", *, control="gas", pressure=None))]
pub(crate) fn gps_flatten<'py>(
    py: Python<'py>,
    initial_stretch: f64,
    rho: &Bound<'py, PyAny>,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
    control: &str,
    pressure: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let law = law(material)?;
    let hyp = self::hypothesis(hypothesis)?;
    let regulated = match (control, pressure) {
        ("gas", None) => false,
        ("pressure", _) => true,
        ("gas", Some(_)) => {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "pressure: belongs to control=\"pressure\" (a regulated supply); with the gas closed in the pressure follows from Boyle's law",
            ))
        }
        (other, _) => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "control: {other:?} is not a supply: \"gas\" (closed in, Boyle) or \"pressure\" (regulated)"
            )))
        }
    };
    use tubemem_app::curves::{flattening_values, FLATTENING_HEADER};
    let mut keys: Vec<&str> = FLATTENING_HEADER.split(',').collect();
    if regulated {
        use tubemem_gps::regulated::{free_start, plate_stiffness, squeeze_at_pressure};
        // the regulated state and the plates' stiffness −d(force)/d(2ρ) at its pressure
        let one = |r: f64| -> Result<(tubemem_gps::FlatteningState, f64), tubemem_gps::GpsError> {
            let start = free_start(law.as_ref(), hyp, initial_stretch)?;
            let s = squeeze_at_pressure(law.as_ref(), hyp, start, r, pressure.unwrap_or(start.w))?;
            Ok((
                s.as_flattening(initial_stretch),
                plate_stiffness(law.as_ref(), hyp, &s)?,
            ))
        };
        if let Ok(r) = real_scalar(rho, "rho")? {
            let (s, k) = one(r).map_err(gps_err)?;
            let d = to_py(py, &s)?;
            d.set_item("stiffness", k)?;
            return Ok(d);
        }
        keys.push("stiffness");
        return vectorized(
            py,
            rho,
            "rho",
            |r| {
                one(r).map(|(s, k)| {
                    let mut v = flattening_values(&s).to_vec();
                    v.push(k);
                    v
                })
            },
            &keys,
        );
    }
    let one = |r: f64| tubemem_gps::flatten(law.as_ref(), hyp, initial_stretch, r);
    if let Ok(r) = real_scalar(rho, "rho")? {
        let s = one(r).map_err(gps_err)?;
        return to_py(py, &s);
    }
    vectorized(
        py,
        rho,
        "rho",
        |r| one(r).map(|s| flattening_values(&s)),
        &keys,
    )
}

/// Plates at half-gap `rho` < 1 hold the stress-free tube, which is inflated between them to the
/// pressure `w` (a regulated supply): dict with w, rho, lambda_s, lambda_z, n_s, n_z, chi,
/// force. Above the critical pressure of the plates (`gps_critical_pressure`) a ValueError
/// says the section snaps.
#[pyfunction]
#[pyo3(signature = (rho, w, material=None, hypothesis="gps"))]
pub(crate) fn gps_between_plates<'py>(
    py: Python<'py>,
    rho: f64,
    w: f64,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let (law, hyp) = (law(material)?, self::hypothesis(hypothesis)?);
    let s = tubemem_gps::regulated::between_plates(law.as_ref(), hyp, rho, w).map_err(gps_err)?;
    to_py(py, &s)
}

/// The critical pressure of the section between plates at half-gap `rho`: the first maximum of
/// ϖ along its states (a pressure-controlled section snaps above it), dict {lambda_s, lambda_z,
/// w}, or None where ϖ rises until the law locks (or λs = 50).
#[pyfunction]
#[pyo3(signature = (rho, material=None, hypothesis="gps"))]
pub(crate) fn gps_critical_pressure<'py>(
    py: Python<'py>,
    rho: f64,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let (law, hyp) = (law(material)?, self::hypothesis(hypothesis)?);
    let c = tubemem_gps::regulated::critical_pressure(law.as_ref(), hyp, rho).map_err(gps_err)?;
    to_py(py, &c)
}

/// `points` flattening states equally spaced in ρ from λs* down to `rho_to`: a `Table` with the
/// columns of `gps_flatten` (the curves of the paper's Figs. 6–7).
#[pyfunction]
#[pyo3(signature = (initial_stretch, rho_to, points=None, material=None, hypothesis="gps"))]
pub(crate) fn gps_flattening_curve<'py>(
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
pub(crate) fn gps_section_at_pressure<'py>(
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
pub(crate) fn gps_limits<'py>(
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
pub(crate) fn resultants(
    l1: f64,
    l2: f64,
    material: Option<&Bound<'_, PyAny>>,
) -> PyResult<(f64, f64)> {
    let law = law(material)?;
    let [n1, n2] = law.resultants(l1, l2).map_err(material_err)?;
    Ok((n1, n2))
}
