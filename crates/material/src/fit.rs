//! Fitting a law's parameters to test data: uniaxial, equibiaxial and pure-shear nominal
//! stress against stretch (the tests a silicone or rubber is characterized with), by
//! Levenberg–Marquardt (the `levenberg-marquardt` crate, a port of MINPACK's lmder).
//!
//! **The model.** For a membrane law W(λ1, λ2) (the 3D incompressible energy with λ3 =
//! 1/(λ1λ2), or the plane-stress sheet's), the nominal stress of each test is
//!
//! ```text
//! P = μ ∂W̄/∂λ1 (λ, λ2),   λ2 = the natural width (N2 = 0)   uniaxial   (λ^−½ when incompressible)
//!                          λ2 = λ                           equibiaxial
//!                          λ2 = 1                           pure shear (planar tension)
//! ```
//! (for an incompressible law P = dŴ/dλ, ½ dŴ/dλ and dŴ/dλ of the energy along each path).
//!
//! **Parameters.** Every number of the starting [`MaterialSpec`] is fitted (a modulus, Jm, N,
//! Ogden's μp and αp, E and ν, an energy's named parameters), by name; the energy text and the
//! model stay. Residuals are P_model − P_data (the data's units are the moduli's units).
//! A trial the law refuses (a parameter out of its range) gets a large finite residual, which
//! the trust region then steps back from.
//!
//! **Uncertainty.** At the solution, the Jacobian J (central differences, steps of 1e-6 of each
//! parameter) gives the covariance s² (JᵀJ)⁻¹ with s² = Σr²/(m − n) (the standard
//! least-squares estimate for independent errors of equal variance), its diagonal the standard
//! errors. A parameter is **not determined** by the data when its standard error exceeds its
//! value, or when it takes part (|component| > 0.3) in a direction of the column-scaled J whose
//! singular value is below 1e-6 of the largest (the data cannot tell it from the others).

use crate::{MaterialError, MaterialSpec, MembraneLaw};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra_lm::{storage::Owned, DMatrix, DVector, Dyn};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// A test's deformation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    Uniaxial,
    Equibiaxial,
    PureShear,
}

impl Mode {
    pub fn label(self) -> &'static str {
        match self {
            Mode::Uniaxial => "uniaxial",
            Mode::Equibiaxial => "equibiaxial",
            Mode::PureShear => "pure shear",
        }
    }
}

/// One test: stretches and nominal stresses (force over reference area).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestData {
    pub mode: Mode,
    pub stretch: Vec<f64>,
    pub stress: Vec<f64>,
}

/// Why a fit could not be made (a fit that converges poorly is a result, with warnings).
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// the data are not usable (with the test and the row)
    #[error("{0}")]
    Data(String),
    /// the starting law is not a law
    #[error("the starting law")]
    Start(#[source] MaterialError),
    /// the law has no number to fit
    #[error("the law has no parameter to fit")]
    NoParameters,
}

/// A fitted parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FittedParameter {
    /// as the material table names it: `c10`, `mu[1]`, `parameters.jm`
    pub name: String,
    pub value: f64,
    /// one standard error (NaN where the covariance does not exist)
    pub std_error: f64,
    /// false: the data do not determine it (see the module docs)
    pub determined: bool,
}

/// A fit's outcome.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitResult {
    /// the law with the fitted parameters
    pub spec: MaterialSpec,
    pub parameters: Vec<FittedParameter>,
    /// the correlation matrix of the parameters, in their order
    pub correlation: Vec<Vec<f64>>,
    /// √(Σr²/(m − n)), in the stress's units
    pub residual_std: f64,
    /// the largest |P_model − P_data| / max |P_data| of the fit
    pub max_relative_residual: f64,
    pub points: usize,
    /// how Levenberg–Marquardt stopped, and after how many evaluations
    pub termination: String,
    pub evaluations: usize,
    /// what the user should know: undetermined parameters, a fit that did not converge
    pub warnings: Vec<String>,
}

/// The nominal stress of `law` (its units: the law's modulus) in test `mode` at stretch `l`.
pub fn nominal_stress(law: &dyn MembraneLaw, mode: Mode, l: f64) -> Result<f64, MaterialError> {
    let l2 = match mode {
        Mode::Equibiaxial => l,
        Mode::PureShear => 1.0,
        Mode::Uniaxial => natural_width(law, l)?,
    };
    Ok(law.shear_modulus() * law.principal(l, l2)?.grad[0])
}

/// λ2 with N2(λ, λ2) = 0, by Newton from λ^−½ (safeguarded: halved where a step leaves λ2 > 0).
fn natural_width(law: &dyn MembraneLaw, l: f64) -> Result<f64, MaterialError> {
    let mut x = l.powf(-0.5);
    for _ in 0..60 {
        let p = law.principal(l, x)?;
        let mut next = x - p.grad[1] / p.hess[1][1];
        if !(next.is_finite() && next > 0.0) {
            next = 0.5 * x;
        }
        let done = (next - x).abs() <= 1e-14 * x;
        x = next;
        if done {
            break;
        }
    }
    Ok(x)
}

/// The fitted numbers of a spec: (name, JSON path) in a stable order.
fn parameter_paths(v: &Value) -> Vec<(String, Vec<PathStep>)> {
    let mut out = vec![];
    if let Value::Object(m) = v {
        for (k, x) in m {
            match x {
                Value::Number(_) => out.push((k.clone(), vec![PathStep::Key(k.clone())])),
                Value::Array(a) => {
                    for (i, y) in a.iter().enumerate() {
                        if y.is_number() {
                            out.push((
                                format!("{k}[{i}]"),
                                vec![PathStep::Key(k.clone()), PathStep::Index(i)],
                            ));
                        }
                    }
                }
                Value::Object(p) => {
                    for (j, y) in p {
                        if y.is_number() {
                            out.push((
                                format!("{k}.{j}"),
                                vec![PathStep::Key(k.clone()), PathStep::Key(j.clone())],
                            ));
                        }
                    }
                }
                _ => {}
            }
        }
    }
    out
}

#[derive(Clone, Debug)]
enum PathStep {
    Key(String),
    Index(usize),
}

fn slot<'a>(v: &'a mut Value, path: &[PathStep]) -> Option<&'a mut Value> {
    let mut cur = v;
    for s in path {
        cur = match s {
            PathStep::Key(k) => cur.get_mut(k.as_str())?,
            PathStep::Index(i) => cur.get_mut(*i)?,
        };
    }
    Some(cur)
}

/// The least-squares problem: the spec as JSON, its fitted slots, the data.
struct Problem<'a> {
    template: Value,
    paths: Vec<Vec<PathStep>>,
    data: &'a [TestData],
    x: DVector<f64>,
    /// the residual of a refused trial: large and finite
    penalty: f64,
}

impl Problem<'_> {
    fn spec_at(&self, x: &[f64]) -> Option<MaterialSpec> {
        let mut v = self.template.clone();
        for (p, &val) in self.paths.iter().zip(x) {
            *slot(&mut v, p)? = serde_json::Number::from_f64(val).map(Value::Number)?;
        }
        serde_json::from_value(v).ok()
    }
    fn residuals_at(&self, x: &[f64]) -> Option<Vec<f64>> {
        let law = self.spec_at(x)?.build().ok()?;
        let mut r = vec![];
        for t in self.data {
            for (&l, &p) in t.stretch.iter().zip(&t.stress) {
                let m = nominal_stress(law.as_ref(), t.mode, l).ok()?;
                if !m.is_finite() {
                    return None;
                }
                r.push(m - p);
            }
        }
        Some(r)
    }
    fn count(&self) -> usize {
        self.data.iter().map(|t| t.stretch.len()).sum()
    }
    /// Differences of the residuals in each parameter: central, with steps of 1e-6 of the
    /// parameter (of the largest parameter where it is 0); one-sided where the law refuses one
    /// side (a parameter at the edge of its range: Yeoh's C20 = 0 with C30 = 0).
    fn jacobian_at(&self, x: &[f64]) -> Option<DMatrix<f64>> {
        let m = self.count();
        let r0 = self.residuals_at(x)?;
        let size = x.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
        let mut j = DMatrix::zeros(m, x.len());
        for k in 0..x.len() {
            let h = 1e-6 * if x[k] != 0.0 { x[k].abs() } else { size };
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[k] += h;
            xm[k] -= h;
            let (rp, rm) = (self.residuals_at(&xp), self.residuals_at(&xm));
            for i in 0..m {
                j[(i, k)] = match (&rp, &rm) {
                    (Some(p), Some(q)) => (p[i] - q[i]) / (2.0 * h),
                    (Some(p), None) => (p[i] - r0[i]) / h,
                    (None, Some(q)) => (r0[i] - q[i]) / h,
                    (None, None) => return None,
                };
            }
        }
        Some(j)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }
    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self
            .residuals_at(self.x.as_slice())
            .unwrap_or_else(|| vec![self.penalty; self.count()]);
        Some(DVector::from_vec(r))
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        self.jacobian_at(self.x.as_slice())
    }
}

/// Check the data: finite, stretches > 0, at least one point per test, more points than
/// parameters overall.
fn check_data(data: &[TestData], n: usize) -> Result<(), FitError> {
    if data.is_empty() {
        return Err(FitError::Data(
            "no test data: give uniaxial, equibiaxial or pure-shear data".into(),
        ));
    }
    let mut m = 0;
    for t in data {
        let what = t.mode.label();
        if t.stretch.len() != t.stress.len() {
            return Err(FitError::Data(format!(
                "{what}: {} stretches but {} stresses",
                t.stretch.len(),
                t.stress.len()
            )));
        }
        if t.stretch.is_empty() {
            return Err(FitError::Data(format!("{what}: no data points")));
        }
        for (i, (&l, &p)) in t.stretch.iter().zip(&t.stress).enumerate() {
            if !(l.is_finite() && l > 0.0) {
                return Err(FitError::Data(format!(
                    "{what}, point {}: the stretch {l} must be a finite number > 0",
                    i + 1
                )));
            }
            if !p.is_finite() {
                return Err(FitError::Data(format!(
                    "{what}, point {}: the stress {p} is not a finite number",
                    i + 1
                )));
            }
        }
        m += t.stretch.len();
    }
    if m <= n {
        return Err(FitError::Data(format!(
            "{m} data points for {n} parameters: a fit needs more points than parameters"
        )));
    }
    Ok(())
}

/// Fit `start`'s numbers to `data`.
pub fn fit(start: &MaterialSpec, data: &[TestData]) -> Result<FitResult, FitError> {
    start.build().map_err(FitError::Start)?;
    let template = serde_json::to_value(start).map_err(|e| {
        FitError::Data(format!(
            "the starting law cannot be written as a table: {e}"
        ))
    })?;
    let named = parameter_paths(&template);
    if named.is_empty() {
        return Err(FitError::NoParameters);
    }
    let n = named.len();
    check_data(data, n)?;
    let mut v = template.clone();
    let x0: Vec<f64> = named
        .iter()
        .map(|(_, p)| slot(&mut v, p).and_then(|x| x.as_f64()).unwrap_or(f64::NAN))
        .collect();
    let scale = data
        .iter()
        .flat_map(|t| t.stress.iter())
        .fold(0.0f64, |a, &p| a.max(p.abs()))
        .max(f64::MIN_POSITIVE);
    let problem = Problem {
        template,
        paths: named.iter().map(|(_, p)| p.clone()).collect(),
        data,
        x: DVector::from_vec(x0),
        penalty: 1e6 * scale,
    };
    let (problem, report) = LevenbergMarquardt::new()
        .with_patience(200)
        .minimize(problem);
    let x: Vec<f64> = problem.x.iter().copied().collect();
    let mut warnings = vec![];
    if !report.termination.was_successful() {
        warnings.push(format!(
            "Levenberg–Marquardt stopped without converging ({:?}): the parameters are its last iterate",
            report.termination
        ));
    }
    let spec = problem
        .spec_at(&x)
        .ok_or_else(|| FitError::Data("the fitted parameters do not make a law".into()))?;
    let r = problem.residuals_at(&x).ok_or_else(|| {
        FitError::Data("the fitted law cannot be evaluated at every data point".into())
    })?;
    let m = r.len();
    let ssr: f64 = r.iter().map(|v| v * v).sum();
    let s2 = ssr / (m - n) as f64;
    let max_rel = r.iter().fold(0.0f64, |a, v| a.max(v.abs())) / scale;
    // covariance and identifiability from the Jacobian at the solution
    let jac = problem.jacobian_at(&x);
    let (std, corr, undetermined) = match &jac {
        Some(j) => uncertainty(j, &x, s2),
        None => (vec![f64::NAN; n], vec![vec![f64::NAN; n]; n], vec![true; n]),
    };
    let parameters: Vec<FittedParameter> = named
        .iter()
        .zip(&x)
        .zip(&std)
        .zip(&undetermined)
        .map(
            |((((name, _), &value), &std_error), &flat)| FittedParameter {
                name: name.clone(),
                value,
                std_error,
                determined: !flat && std_error.is_finite() && std_error <= value.abs(),
            },
        )
        .collect();
    for p in parameters.iter().filter(|p| !p.determined) {
        warnings.push(format!(
            "the data do not determine `{}` (fitted {:.4e} ± {:.2e}): add data that exercise it (larger stretches, another test mode) or fix it",
            p.name, p.value, p.std_error
        ));
    }
    Ok(FitResult {
        spec,
        parameters,
        correlation: corr,
        residual_std: s2.sqrt(),
        max_relative_residual: max_rel,
        points: m,
        termination: format!("{:?}", report.termination),
        evaluations: report.number_of_evaluations,
        warnings,
    })
}

/// (standard errors, correlation, in an unresolved direction) from the Jacobian `j` at `x`.
/// The columns are scaled to unit length first (D = diag(1/‖J_k‖)), so that the singular values
/// of J D measure how far the columns are from dependent, whatever the parameters' sizes; the
/// covariance is then s² D (Dᵀ JᵀJ D)⁻¹ D.
#[allow(clippy::type_complexity)]
fn uncertainty(j: &DMatrix<f64>, x: &[f64], s2: f64) -> (Vec<f64>, Vec<Vec<f64>>, Vec<bool>) {
    let n = x.len();
    let mut flat = vec![false; n];
    let mut d = vec![0.0; n];
    let mut js = j.clone();
    for k in 0..n {
        let norm = j.column(k).norm();
        if norm > 0.0 && norm.is_finite() {
            d[k] = 1.0 / norm;
        } else {
            flat[k] = true; // the residuals do not depend on it at all
        }
        for i in 0..js.nrows() {
            js[(i, k)] *= d[k];
        }
    }
    let svd = js.clone().svd(false, true);
    let sv = &svd.singular_values;
    let smax = sv.iter().fold(0.0f64, |a, &v| a.max(v));
    if let Some(vt) = &svd.v_t {
        for (r, &s) in sv.iter().enumerate() {
            if s <= 1e-6 * smax {
                for k in 0..n {
                    if vt[(r, k)].abs() > 0.3 {
                        flat[k] = true;
                    }
                }
            }
        }
    }
    let jtj = js.transpose() * &js;
    let mut std = vec![f64::NAN; n];
    let mut corr = vec![vec![f64::NAN; n]; n];
    match jtj.try_inverse() {
        Some(c) => {
            for a in 0..n {
                std[a] = (s2 * c[(a, a)]).max(0.0).sqrt() * d[a];
                for b in 0..n {
                    corr[a][b] = c[(a, b)] / (c[(a, a)] * c[(b, b)]).sqrt();
                }
            }
        }
        None => flat.iter_mut().for_each(|f| *f = true),
    }
    (std, corr, flat)
}
