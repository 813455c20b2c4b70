//! `tubemem.Material`: a validated membrane law (any model of the case files, an energy
//! written as text included) and `tubemem.fit`: its parameters from test data.

use crate::convert::{from_py, to_py};
use crate::errors::{material_err, TubememError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use tubemem_material::fit::{Mode, TestData};
use tubemem_material::{MaterialSpec, MembraneLaw};

/// A membrane law, validated on construction: `Material("gent", shear_modulus=1.0, jm=50)`,
/// `Material(model="invariants", energy="-(jm/2)*ln(1-(I1-3)/jm)", parameters={"jm": 50},
/// shear_modulus=1.0)`, or `Material.from_dict(d)` with a case file's material table. Every
/// closed-form function takes it as `material=`, and a `Case` as its `material` table.
#[pyclass(name = "Material", module = "tubemem", frozen)]
pub(crate) struct PyMaterial {
    pub(crate) spec: MaterialSpec,
    law: Box<dyn MembraneLaw>,
}

impl PyMaterial {
    pub(crate) fn of(spec: MaterialSpec) -> PyResult<Self> {
        let law = spec.build().map_err(material_err)?;
        Ok(Self { spec, law })
    }
}

/// The spec of a `material=` argument: a `Material`, or a dict of a material table.
pub(crate) fn spec_of(m: &Bound<'_, PyAny>) -> PyResult<MaterialSpec> {
    if let Ok(mat) = m.cast::<PyMaterial>() {
        return Ok(mat.get().spec.clone());
    }
    from_py::<MaterialSpec>(m, "material")
}

fn mode_of(name: &str) -> PyResult<Mode> {
    match name.replace(['-', ' '], "_").to_ascii_lowercase().as_str() {
        "uniaxial" => Ok(Mode::Uniaxial),
        "equibiaxial" => Ok(Mode::Equibiaxial),
        "pure_shear" | "planar" => Ok(Mode::PureShear),
        _ => Err(PyValueError::new_err(format!(
            "mode = {name:?}: \"uniaxial\", \"equibiaxial\" or \"pure_shear\""
        ))),
    }
}

#[pymethods]
impl PyMaterial {
    #[new]
    #[pyo3(signature = (model=None, **params))]
    fn new(
        py: Python<'_>,
        model: Option<&str>,
        params: Option<&Bound<'_, pyo3::types::PyDict>>,
    ) -> PyResult<Self> {
        let d = match params {
            Some(p) => p.copy()?,
            None => pyo3::types::PyDict::new(py),
        };
        if let Some(m) = model {
            if d.contains("model")? {
                return Err(PyValueError::new_err(
                    "Material: give the model once (as the first argument or model=)",
                ));
            }
            d.set_item("model", m)?;
        }
        if !d.contains("model")? {
            return Err(PyValueError::new_err(format!(
                "Material: name the model, one of {}",
                MaterialSpec::MODELS
                    .iter()
                    .map(|(m, _)| *m)
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        Self::of(from_py::<MaterialSpec>(d.as_any(), "material")?)
    }
    /// A material from a case file's material table as a dict.
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyAny>) -> PyResult<Self> {
        Self::of(from_py::<MaterialSpec>(d, "material")?)
    }
    /// The material table as a dict (as a case file writes it).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.spec)
    }
    /// The law's name with its parameters.
    #[getter]
    fn name(&self) -> String {
        self.law.name()
    }
    /// The modulus μ the dimensionless results are per (ϖ = pR/(μH)).
    #[getter]
    fn shear_modulus(&self) -> f64 {
        self.spec.shear_modulus()
    }
    /// The Cauchy resultants (N1, N2)/(μH) at principal stretches (l1, l2), eq. (18).
    fn resultants(&self, l1: f64, l2: f64) -> PyResult<(f64, f64)> {
        let [n1, n2] = self.law.resultants(l1, l2).map_err(material_err)?;
        Ok((n1, n2))
    }
    /// The energy W/(μH) per reference area at principal stretches (l1, l2).
    fn energy(&self, l1: f64, l2: f64) -> PyResult<f64> {
        self.law.energy(l1, l2).map_err(material_err)
    }
    /// The nominal stress (in the law's modulus units) of a test, "uniaxial", "equibiaxial" or
    /// "pure_shear", at each stretch of `stretch` (a number or an array): what `fit` compares
    /// with the data.
    fn nominal_stress<'py>(
        &self,
        py: Python<'py>,
        mode: &str,
        stretch: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mode = mode_of(mode)?;
        let np = py.import("numpy")?;
        let arr = np.call_method1("asarray", (stretch, "float64"))?;
        let flat: Vec<f64> = arr.call_method0("ravel")?.extract()?;
        let out = flat
            .iter()
            .map(|&l| tubemem_material::fit::nominal_stress(self.law.as_ref(), mode, l))
            .collect::<Result<Vec<f64>, _>>()
            .map_err(material_err)?;
        np.call_method1("asarray", (out,))?
            .call_method1("reshape", (arr.getattr("shape")?,))
    }
    fn __repr__(&self) -> String {
        format!("<tubemem.Material {}>", self.law.name())
    }
    fn __eq__(&self, other: &Self) -> bool {
        self.spec == other.spec
    }
}

/// One test's data: a path to a CSV file (stretch, nominal stress), or an (N, 2) array, or a
/// (stretch, stress) pair of arrays.
fn test_data(
    py: Python<'_>,
    mode: Mode,
    arg: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<(TestData, bool)> {
    if let Ok(p) = arg.extract::<PathBuf>() {
        if arg.is_instance_of::<pyo3::types::PyString>() || p.is_file() {
            return tubemem_app::fit::read_test_file(&p, mode, None)
                .map(|f| (f.data, f.unit.is_some()))
                .map_err(|e| {
                    PyValueError::new_err(format!("{what}: {}", tubemem_app::error_chain(&e)))
                });
        }
    }
    let np = py.import("numpy")?;
    let bad = || {
        PyValueError::new_err(format!("{what}: a CSV path, an (N, 2) array of (stretch, stress), or a (stretch, stress) pair of arrays"))
    };
    // real numbers only: a float conversion would drop imaginary parts and parse text
    let raw = np.call_method1("asarray", (arg,)).map_err(|_| bad())?;
    let kind: String = raw.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "i" | "u" | "f") {
        return Err(PyValueError::new_err(format!(
            "{what}: the data must be real numbers (numpy dtype kind {kind:?}: {}); complex values, text and booleans are refused",
            match kind.as_str() {
                "c" => "complex",
                "U" | "S" => "text",
                "b" => "boolean",
                _ => "not numbers",
            }
        )));
    }
    let arr = raw.call_method1("astype", ("float64",))?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    // a tuple of two sequences is the (stretch, stress) pair; an array (or a list) is (N, 2)
    // rows, or (2, N) where N ≠ 2; a 2 × 2 one is either, so it is refused
    let pair = arg.is_instance_of::<pyo3::types::PyTuple>();
    let (stretch, stress): (Vec<f64>, Vec<f64>) = match shape.as_slice() {
        [2, _] if pair => (arr.get_item(0)?.extract()?, arr.get_item(1)?.extract()?),
        [2, 2] => {
            return Err(PyValueError::new_err(format!(
                "{what}: a 2 × 2 array is ambiguous (two (stretch, stress) rows, or the stretch and stress rows?): give a (stretch, stress) tuple of arrays"
            )))
        }
        // (N, 2): one (stretch, stress) row per point
        [_, 2] => {
            let t = arr.getattr("T")?;
            (t.get_item(0)?.extract()?, t.get_item(1)?.extract()?)
        }
        [2, _] => (arr.get_item(0)?.extract()?, arr.get_item(1)?.extract()?),
        _ => return Err(bad()),
    };
    Ok((
        TestData {
            mode,
            stretch,
            stress,
        },
        false,
    ))
}

/// Fit a law's parameters to test data: `law` a model name (starting values estimated from
/// the data), a material dict with starting values, or a `Material`; `uniaxial`,
/// `equibiaxial`, `pure_shear` each a CSV path, an (N, 2) array or a (stretch, stress) pair.
/// `fix` holds parameters at values (`{"c30": 0.0}`), `bounds` bounds them (`{"c20": (-1.0,
/// 1.0)}`), `starts` is the number of starts tried besides the law's own. Returns a dict:
/// `material` (the fitted `Material`), `converged` (False: the best iterate, not a fitted law;
/// `stop_reason` says why), `parameters` (name, value, std_error — None where fixed or not
/// determined —, determined, fixed, at_bound), `correlation`, `rank`, `residual_std`,
/// `max_relative_residual`, `points`, `starts`, `starts_agreeing`, `termination`,
/// `evaluations`, `warnings` and `stress_unit` ("Pa" where the files' headers named a unit and
/// the moduli are in Pa; None where the data's numbers were taken as they are).
#[pyfunction]
#[pyo3(signature = (law, uniaxial=None, equibiaxial=None, pure_shear=None, fix=None, bounds=None, starts=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit<'py>(
    py: Python<'py>,
    law: &Bound<'py, PyAny>,
    uniaxial: Option<&Bound<'py, PyAny>>,
    equibiaxial: Option<&Bound<'py, PyAny>>,
    pure_shear: Option<&Bound<'py, PyAny>>,
    fix: Option<std::collections::BTreeMap<String, f64>>,
    bounds: Option<std::collections::BTreeMap<String, (f64, f64)>>,
    starts: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let starts = match starts {
        None => tubemem_material::fit::DEFAULT_STARTS,
        Some(s) => crate::convert::int_arg(
            s,
            "starts",
            0,
            10_000,
            "the number of starts besides the law's own, from 0 to 10,000",
        )?,
    };
    let mut data = vec![];
    let mut named = vec![];
    for (arg, mode, what) in [
        (uniaxial, Mode::Uniaxial, "uniaxial"),
        (equibiaxial, Mode::Equibiaxial, "equibiaxial"),
        (pure_shear, Mode::PureShear, "pure_shear"),
    ] {
        if let Some(a) = arg.filter(|a| !a.is_none()) {
            let (d, unit) = test_data(py, mode, a, what)?;
            data.push(d);
            named.push((what, unit));
        }
    }
    // one unit per fit: files whose headers name a unit are read in Pa; arrays and files that
    // name none keep their numbers
    if named.iter().any(|n| n.1) && !named.iter().all(|n| n.1) {
        let list = |u: bool| {
            named
                .iter()
                .filter(|n| n.1 == u)
                .map(|n| n.0)
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(PyValueError::new_err(format!(
            "fit: one unit per fit: {} name their stress unit (read in Pa) and {} do not; give all as files whose headers name it, or all as numbers in one unit",
            list(true),
            list(false)
        )));
    }
    let in_pa = named.iter().all(|n| n.1);
    if data.is_empty() {
        return Err(PyValueError::new_err(
            "fit: give test data as uniaxial=, equibiaxial= and/or pure_shear=",
        ));
    }
    let start = match law.extract::<String>() {
        Ok(model) => tubemem_app::fit::default_start(&model, &data)
            .map_err(|e| PyValueError::new_err(format!("law: {}", tubemem_app::error_chain(&e))))?,
        Err(_) => spec_of(law)?,
    };
    let result = py
        .detach(|| {
            let opts = tubemem_material::fit::FitOptions {
                fixed: fix.unwrap_or_default(),
                bounds: bounds.unwrap_or_default(),
                starts,
            };
            tubemem_app::fit::run_fit_with(&start, &data, &opts)
        })
        .map_err(|e| {
            let msg = format!("fit: {}", tubemem_app::error_chain(&e));
            match e {
                tubemem_app::fit::FitError::Fit(tubemem_material::fit::FitError::Data(_))
                | tubemem_app::fit::FitError::Start(_) => PyValueError::new_err(msg),
                _ => TubememError::new_err(msg),
            }
        })?;
    let d = to_py(py, &result)?;
    d.set_item("stress_unit", if in_pa { Some("Pa") } else { None })?;
    d.set_item(
        "material",
        Bound::new(py, PyMaterial::of(result.spec.clone())?)?,
    )?;
    Ok(d)
}
