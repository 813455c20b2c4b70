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
//! value (unless the data are reproduced exactly, [`EXACT_FIT`], where every standard error is
//! round-off), or when it takes part (|component| > 0.3) in a direction of the column-scaled J whose
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

/// One test history (issue #63): times, stretches and nominal stresses of a uniaxial or
/// equibiaxial test under any loading (a relaxation, a loading–unloading at a rate), fitted by
/// a QLV Prony law ([`crate::viscoelastic::nominal_history`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HistoryData {
    /// what the test is called in messages and the per-test residuals (its file)
    pub name: String,
    pub mode: Mode,
    pub time: Vec<f64>,
    pub stretch: Vec<f64>,
    pub stress: Vec<f64>,
}

/// How well the fitted law reproduces one test.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestResidual {
    pub name: String,
    pub points: usize,
    /// √(Σr²/m) over the test's points, in the stress's units
    pub rms: f64,
    /// the largest |P_model − P_data| over the test's largest |P_data|
    pub max_relative: f64,
}

/// The data a fit reproduces: stress–stretch points of elastic tests, or histories.
#[derive(Clone, Copy)]
enum Data<'a> {
    Points(&'a [TestData]),
    Histories(&'a [HistoryData]),
}

impl Data<'_> {
    fn count(&self) -> usize {
        match self {
            Data::Points(d) => d.iter().map(|t| t.stretch.len()).sum(),
            Data::Histories(d) => d.iter().map(|t| t.stretch.len()).sum(),
        }
    }
    fn stresses(&self) -> Vec<f64> {
        match self {
            Data::Points(d) => d.iter().flat_map(|t| t.stress.iter().copied()).collect(),
            Data::Histories(d) => d.iter().flat_map(|t| t.stress.iter().copied()).collect(),
        }
    }
    /// (name, points) of each test, in the residuals' order
    fn tests(&self) -> Vec<(String, usize, f64)> {
        let top = |s: &[f64]| s.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        match self {
            Data::Points(d) => d
                .iter()
                .map(|t| (t.mode.label().to_string(), t.stretch.len(), top(&t.stress)))
                .collect(),
            Data::Histories(d) => d
                .iter()
                .map(|t| (t.name.clone(), t.stretch.len(), top(&t.stress)))
                .collect(),
        }
    }
    /// P_model − P_data at every point, or the first point the law cannot take (its test, its
    /// stretch and the law's reason).
    fn residuals(
        &self,
        law: &dyn MembraneLaw,
        prony: Option<&crate::viscoelastic::Prony>,
    ) -> Result<Vec<f64>, String> {
        let mut r = vec![];
        match (self, prony) {
            (Data::Points(d), _) => {
                for t in d.iter() {
                    for (&l, &p) in t.stretch.iter().zip(&t.stress) {
                        let at = |what: String| {
                            format!(
                                "the {} point at stretch {}: {what}",
                                t.mode.label(),
                                crate::Num(l)
                            )
                        };
                        let m = nominal_stress(law, t.mode, l).map_err(|e| at(e.to_string()))?;
                        if !m.is_finite() {
                            return Err(at(format!("the law's stress is {m}")));
                        }
                        r.push(m - p);
                    }
                }
            }
            (Data::Histories(d), Some(prony)) => {
                for t in d.iter() {
                    let eq = t.mode == Mode::Equibiaxial;
                    let m =
                        crate::viscoelastic::nominal_history(law, prony, eq, &t.time, &t.stretch)
                            .map_err(|e| format!("the history {}: {e}", t.name))?;
                    for (m, p) in m.iter().zip(&t.stress) {
                        if !m.is_finite() {
                            return Err(format!("the history {}: the law's stress is {m}", t.name));
                        }
                        r.push(m - p);
                    }
                }
            }
            (Data::Histories(_), None) => return Err("histories need a Prony series".into()),
        }
        Ok(r)
    }
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
    /// one standard error (`None`: a fixed parameter, or one the data do not determine: the
    /// Jacobian's rank is short along it)
    pub std_error: Option<f64>,
    /// false: the data do not determine it (see the module docs)
    pub determined: bool,
    /// held at its value (`FitOptions::fixed`), not fitted
    #[serde(default)]
    pub fixed: bool,
    /// "lower" or "upper": the fit ended on this bound of the parameter
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_bound: Option<String>,
}

/// A fit's outcome.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitResult {
    /// the law with the fitted parameters
    pub spec: MaterialSpec,
    pub parameters: Vec<FittedParameter>,
    /// the correlation matrix of the fitted (free) parameters, in their order (`None` where a
    /// parameter has no standard error)
    pub correlation: Vec<Vec<Option<f64>>>,
    /// √(Σr²/(m − n)), in the stress's units
    pub residual_std: f64,
    /// the largest |P_model − P_data| / max |P_data| of the fit
    pub max_relative_residual: f64,
    pub points: usize,
    /// whether the fit converged: Levenberg–Marquardt stopped on a convergence test at the
    /// best start, and the result is stationary there (every free parameter's Jacobian column
    /// at most [`STATIONARITY`] from orthogonal to the residual, in cosine; at a bound, the
    /// gradient may point outward)
    pub converged: bool,
    /// why the best start's Levenberg–Marquardt stopped, and the stationarity measured
    pub stop_reason: String,
    /// how Levenberg–Marquardt stopped (its own words), and after how many evaluations, at
    /// the best start
    pub termination: String,
    pub evaluations: usize,
    /// the largest |Jₖᵀr| / (‖Jₖ‖ ‖r‖) over the free parameters not held at a bound
    pub gradient_cosine: f64,
    /// the starts tried, and how many of them reached the best sum of squares (to 1e-6)
    pub starts: usize,
    pub starts_agreeing: usize,
    /// the rank of the column-scaled Jacobian of the free parameters (singular values above
    /// 1e-6 of the largest), and their number
    pub rank: usize,
    pub free_parameters: usize,
    /// what the user should know: undetermined parameters, a fit that did not converge
    pub warnings: Vec<String>,
    /// the fitted Prony series of a fit to histories
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prony: Option<Vec<crate::viscoelastic::PronyTerm>>,
    /// how well each test is reproduced
    #[serde(default)]
    pub tests: Vec<TestResidual>,
}

/// A fit whose largest residual is at most this fraction of the data's largest stress
/// reproduces the data exactly: the law's stress in floating point is good to about 1e-15 of
/// its value, so a residual of 1e-10 is round-off with a margin of 1e5, and measured data
/// (CSV values of 6 to 8 digits) leave residuals of 1e-8 or more. Exact fits of synthetic
/// data give 1e-16.
pub const EXACT_FIT: f64 = 1e-10;

/// A fit is stationary where every free parameter's Jacobian column is within this cosine of
/// orthogonal to the residual: 1e-5. At a least-squares minimum the residual is orthogonal to
/// the columns (the normal equations); the converged fits of the tests reach 1e-9 or less,
/// and a fit handed back at a start that is not a minimum has cosines of order 0.1 to 1.
pub const STATIONARITY: f64 = 1e-5;

/// The starts [`fit`] tries besides the one given: 8 (the given start, one with its moduli
/// scaled to the data, and log-uniform draws within a decade of it, deterministic).
pub const DEFAULT_STARTS: usize = 8;

/// What a fit may hold or bound.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// parameters held at a value, by name (`c30` → 0)
    pub fixed: std::collections::BTreeMap<String, f64>,
    /// bounds (low, high) by name; ±∞ for an open side
    pub bounds: std::collections::BTreeMap<String, (f64, f64)>,
    /// starts tried besides the given one
    pub starts: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            fixed: Default::default(),
            bounds: Default::default(),
            starts: DEFAULT_STARTS,
        }
    }
}

/// The parameters in stress units, by their table name (`mu[1]` as `mu`): scaling all of them
/// by s scales every nominal stress by s.
const MODULI: [&str; 7] = [
    "shear_modulus",
    "c10",
    "c20",
    "c30",
    "c2",
    "mu",
    "young_modulus",
];

/// Whether a fitted parameter (`mu[1]`, `c10`) is in stress units (the others are ratios).
pub fn is_modulus(name: &str) -> bool {
    let base = name.split('[').next().unwrap_or(name);
    MODULI.contains(&base)
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
                        // a table in the array (a Prony term): `prony[0].g`
                        if let Value::Object(o) = y {
                            for (j, z) in o {
                                if z.is_number() {
                                    out.push((
                                        format!("{k}[{i}].{j}"),
                                        vec![
                                            PathStep::Key(k.clone()),
                                            PathStep::Index(i),
                                            PathStep::Key(j.clone()),
                                        ],
                                    ));
                                }
                            }
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

/// A parameter's bounds, and the map from the unbounded coordinate u the optimizer moves to the
/// parameter x (lmfit's transforms, after MINPACK-1's users): both sides x = lo + (hi − lo)(1 +
/// sin u)/2; a lower side x = lo − 1 + √(u² + 1); an upper side x = hi + 1 − √(u² + 1).
#[derive(Clone, Copy, Debug)]
struct Bound {
    lo: f64,
    hi: f64,
}

impl Bound {
    fn x(&self, u: f64) -> f64 {
        match (self.lo.is_finite(), self.hi.is_finite()) {
            (true, true) => self.lo + (self.hi - self.lo) * 0.5 * (1.0 + u.sin()),
            (true, false) => self.lo - 1.0 + (u * u + 1.0).sqrt(),
            (false, true) => self.hi + 1.0 - (u * u + 1.0).sqrt(),
            (false, false) => u,
        }
    }
    fn u(&self, x: f64) -> f64 {
        match (self.lo.is_finite(), self.hi.is_finite()) {
            (true, true) => (2.0 * (x - self.lo) / (self.hi - self.lo) - 1.0)
                .clamp(-1.0, 1.0)
                .asin(),
            (true, false) => ((x - self.lo + 1.0).powi(2) - 1.0).max(0.0).sqrt(),
            (false, true) => ((self.hi - x + 1.0).powi(2) - 1.0).max(0.0).sqrt(),
            (false, false) => x,
        }
    }
    /// dx/du at u
    fn slope(&self, u: f64) -> f64 {
        match (self.lo.is_finite(), self.hi.is_finite()) {
            (true, true) => (self.hi - self.lo) * 0.5 * u.cos(),
            (true, false) => u / (u * u + 1.0).sqrt(),
            (false, true) => -u / (u * u + 1.0).sqrt(),
            (false, false) => 1.0,
        }
    }
    /// "lower" or "upper" where `x` sits on a finite bound (to 1e-9 relative)
    fn at(&self, x: f64) -> Option<&'static str> {
        let near =
            |b: f64| b.is_finite() && (x - b).abs() <= 1e-9 * b.abs().max(1e-300).max(x.abs());
        if near(self.lo) {
            Some("lower")
        } else if near(self.hi) {
            Some("upper")
        } else {
            None
        }
    }
}

/// The least-squares problem: the spec as JSON, its fitted slots, the data; the optimizer moves
/// the unbounded coordinates `u` of the free parameters ([`Bound`]).
struct Problem<'a> {
    template: Value,
    paths: Vec<Vec<PathStep>>,
    data: Data<'a>,
    bounds: Vec<Bound>,
    x: DVector<f64>,
    /// the residual of a refused trial: large and finite
    penalty: f64,
}

impl Problem<'_> {
    /// The law's table and, for histories, its Prony series at `x`.
    fn model_at(&self, x: &[f64]) -> Option<(MaterialSpec, Option<crate::viscoelastic::Prony>)> {
        let mut v = self.template.clone();
        for (p, &val) in self.paths.iter().zip(x) {
            *slot(&mut v, p)? = serde_json::Number::from_f64(val).map(Value::Number)?;
        }
        split_prony(v).ok()
    }
    fn spec_at(&self, x: &[f64]) -> Option<MaterialSpec> {
        self.model_at(x).map(|m| m.0)
    }
    fn evaluate(&self, x: &[f64]) -> Result<Vec<f64>, String> {
        let (spec, prony) = self
            .model_at(x)
            .ok_or_else(|| "the parameters are not numbers a law takes".to_string())?;
        let law = spec
            .build()
            .map_err(|e| format!("the parameters make no law: {e}"))?;
        self.data.residuals(law.as_ref(), prony.as_ref())
    }
    fn residuals_at(&self, x: &[f64]) -> Option<Vec<f64>> {
        self.evaluate(x).ok()
    }
    /// Why [`Self::residuals_at`] has no value at `x`: the parameters, and the first data
    /// point the law cannot take, with the law's own reason.
    fn evaluation_failure(&self, x: &[f64], names: &[&str]) -> String {
        let params: Vec<String> = names
            .iter()
            .zip(x)
            .map(|(n, v)| format!("{n} = {}", crate::Num(*v)))
            .collect();
        let at = params.join(", ");
        match self.evaluate(x) {
            Err(e) => format!("with {at}, {e}"),
            Ok(_) => format!("with {at}: no point fails (please report this input)"),
        }
    }
    fn count(&self) -> usize {
        self.data.count()
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
            // a step of 1e-6 of the parameter, at least 1e-12 of the largest one: a parameter
            // the fit drove to round-off (Yeoh's C20 = 4e-13 on neo-Hookean data) had a step
            // of 4e-19, whose difference quotient is round-off, and was reported flat
            let h = 1e-6 * x[k].abs().max(1e-6 * size);
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

impl Problem<'_> {
    /// The parameters x of the unbounded coordinates u.
    fn x_of(&self, u: &[f64]) -> Vec<f64> {
        u.iter().zip(&self.bounds).map(|(u, b)| b.x(*u)).collect()
    }
}

/// The optimizer's view: `x` holds the unbounded coordinates u.
impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.x.copy_from(u);
    }
    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self
            .residuals_at(&self.x_of(self.x.as_slice()))
            .unwrap_or_else(|| vec![self.penalty; self.count()]);
        Some(DVector::from_vec(r))
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let u = self.x.as_slice();
        let mut j = self.jacobian_at(&self.x_of(u))?;
        for (k, (uk, b)) in u.iter().zip(&self.bounds).enumerate() {
            let d = b.slope(*uk);
            j.column_mut(k).iter_mut().for_each(|v| *v *= d);
        }
        Some(j)
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

/// Check histories: each with points, equal lengths, finite values, stretches > 0, times not
/// decreasing; uniaxial or equibiaxial; more points than parameters overall.
fn check_histories(data: &[HistoryData], n: usize) -> Result<(), FitError> {
    if data.is_empty() {
        return Err(FitError::Data("no test histories".into()));
    }
    let mut m = 0;
    for t in data {
        let what = &t.name;
        if t.mode == Mode::PureShear {
            return Err(FitError::Data(format!(
                "{what}: a history must be uniaxial or equibiaxial"
            )));
        }
        if t.stretch.len() != t.stress.len() || t.time.len() != t.stress.len() {
            return Err(FitError::Data(format!(
                "{what}: {} times, {} stretches and {} stresses",
                t.time.len(),
                t.stretch.len(),
                t.stress.len()
            )));
        }
        if t.stretch.is_empty() {
            return Err(FitError::Data(format!("{what}: no data points")));
        }
        for i in 0..t.time.len() {
            let (tt, l, p) = (t.time[i], t.stretch[i], t.stress[i]);
            let row = i + 1;
            if !(tt.is_finite() && l.is_finite() && l > 0.0 && p.is_finite()) {
                return Err(FitError::Data(format!(
                    "{what}, point {row}: time {tt}, stretch {l}, stress {p}: each must be a finite number, the stretch > 0"
                )));
            }
            if i > 0 && tt < t.time[i - 1] {
                return Err(FitError::Data(format!(
                    "{what}, point {row}: the time {tt} is before the previous point's {}",
                    t.time[i - 1]
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

/// Fit `start`'s numbers to `data` ([`FitOptions::default`]: every number free, unbounded
/// but by the law's own ranges, [`DEFAULT_STARTS`] starts).
pub fn fit(start: &MaterialSpec, data: &[TestData]) -> Result<FitResult, FitError> {
    fit_with(start, data, &FitOptions::default())
}

/// A deterministic stream of numbers in [0, 1) (a linear congruential generator, Knuth's
/// MMIX constants): the starts are the same on every machine and run.
struct Draws(u64);

impl Draws {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// One start's outcome: the parameters, the sum of squares, LM's report.
struct Run {
    x: Vec<f64>,
    ssr: f64,
    successful: bool,
    termination: String,
    evaluations: usize,
}

/// Fit `start`'s numbers to `data`, holding `opts.fixed`, within `opts.bounds`, from the given
/// start and `opts.starts` more, keeping the best sum of squares.
pub fn fit_with(
    start: &MaterialSpec,
    data: &[TestData],
    opts: &FitOptions,
) -> Result<FitResult, FitError> {
    let template = serde_json::to_value(start).map_err(|e| {
        FitError::Data(format!(
            "the starting law cannot be written as a table: {e}"
        ))
    })?;
    fit_data(template, Data::Points(data), opts)
}

/// Fit `start`'s numbers and the Prony series `prony` (each term's `g` and `tau`, named
/// `prony[i].g`, `prony[i].tau`; bounded to (0, 1) and (0, ∞) unless `opts` bounds them) to
/// test histories, holding `opts.fixed`, as [`fit_with`] (issue #63).
pub fn fit_histories_with(
    start: &MaterialSpec,
    prony: &[crate::viscoelastic::PronyTerm],
    data: &[HistoryData],
    opts: &FitOptions,
) -> Result<FitResult, FitError> {
    let mut template = serde_json::to_value(start).map_err(|e| {
        FitError::Data(format!(
            "the starting law cannot be written as a table: {e}"
        ))
    })?;
    if let Value::Object(m) = &mut template {
        m.insert(
            "prony".into(),
            serde_json::to_value(prony).map_err(|e| FitError::Data(e.to_string()))?,
        );
    }
    let mut opts = opts.clone();
    for i in 0..prony.len() {
        for (key, range) in [("g", (0.0, 1.0)), ("tau", (0.0, f64::INFINITY))] {
            let name = format!("prony[{i}].{key}");
            if !opts.fixed.contains_key(&name) {
                opts.bounds.entry(name).or_insert(range);
            }
        }
    }
    fit_data(template, Data::Histories(data), &opts)
}

/// The law's table and the Prony series of a template: its `prony` key, if any, taken out.
fn split_prony(mut v: Value) -> Result<(MaterialSpec, Option<crate::viscoelastic::Prony>), String> {
    let prony = v.as_object_mut().and_then(|m| m.remove("prony"));
    let spec: MaterialSpec = serde_json::from_value(v).map_err(|e| e.to_string())?;
    let prony = match prony {
        None => None,
        Some(p) => {
            let terms: Vec<crate::viscoelastic::PronyTerm> =
                serde_json::from_value(p).map_err(|e| e.to_string())?;
            Some(crate::viscoelastic::Prony::new(terms).map_err(|e| e.to_string())?)
        }
    };
    Ok((spec, prony))
}

fn fit_data(mut template: Value, data: Data<'_>, opts: &FitOptions) -> Result<FitResult, FitError> {
    let model = template
        .get("model")
        .and_then(|m| m.as_str())
        .unwrap_or("?")
        .to_string();
    let named = parameter_paths(&template);
    if named.is_empty() {
        return Err(FitError::NoParameters);
    }
    let names: Vec<&str> = named.iter().map(|(n, _)| n.as_str()).collect();
    let unknown = |what: &str, n: &str| {
        FitError::Data(format!(
            "{what} `{n}`: the {} law has no parameter `{n}`; its parameters are {}",
            model,
            names.join(", ")
        ))
    };
    for (n, v) in &opts.fixed {
        let (_, path) = named
            .iter()
            .find(|(m, _)| m == n)
            .ok_or_else(|| unknown("fixed", n))?;
        if !v.is_finite() {
            return Err(FitError::Data(format!(
                "fixed `{n}` = {v}: a fixed value must be a finite number"
            )));
        }
        if let Some(slot) = slot(&mut template, path) {
            *slot = serde_json::Number::from_f64(*v)
                .map(Value::Number)
                .unwrap_or(Value::Null);
        }
    }
    for (n, (lo, hi)) in &opts.bounds {
        if !names.contains(&n.as_str()) {
            return Err(unknown("bound", n));
        }
        if opts.fixed.contains_key(n) {
            return Err(FitError::Data(format!(
                "`{n}` is both fixed and bounded: give one"
            )));
        }
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(FitError::Data(format!(
                "bound `{n}` = [{lo}, {hi}]: the low end must be below the high end"
            )));
        }
    }
    let (spec0, _) = split_prony(template.clone())
        .map_err(|e| FitError::Data(format!("the fixed values do not make a law: {e}")))?;
    spec0.build().map_err(FitError::Start)?;
    let free: Vec<usize> = (0..named.len())
        .filter(|&k| !opts.fixed.contains_key(&named[k].0))
        .collect();
    if free.is_empty() {
        return Err(FitError::Data(
            "every parameter is fixed: nothing is left to fit".into(),
        ));
    }
    let n = free.len();
    match data {
        Data::Points(d) => check_data(d, n)?,
        Data::Histories(d) => check_histories(d, n)?,
    }
    let mut v = template.clone();
    let x_all: Vec<f64> = named
        .iter()
        .map(|(_, p)| slot(&mut v, p).and_then(|x| x.as_f64()).unwrap_or(f64::NAN))
        .collect();
    let bounds: Vec<Bound> = free
        .iter()
        .map(|&k| {
            let (lo, hi) = opts
                .bounds
                .get(&named[k].0)
                .copied()
                .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            Bound { lo, hi }
        })
        .collect();
    // a start outside its bounds starts on the nearer bound
    let x0: Vec<f64> = free
        .iter()
        .zip(&bounds)
        .map(|(&k, b)| x_all[k].clamp(b.lo, b.hi))
        .collect();
    let scale = data
        .stresses()
        .iter()
        .fold(0.0f64, |a, &p| a.max(p.abs()))
        .max(f64::MIN_POSITIVE);
    let mut problem = Problem {
        template,
        paths: free.iter().map(|&k| named[k].1.clone()).collect(),
        data,
        bounds: bounds.clone(),
        x: DVector::from_vec(vec![0.0; n]),
        penalty: 1e6 * scale,
    };
    let free_names: Vec<&str> = free.iter().map(|&k| named[k].0.as_str()).collect();
    let starts = starts_of(&problem, &x0, &free_names, opts.starts);
    let mut runs: Vec<Run> = vec![];
    for s in &starts {
        let u: Vec<f64> = s.iter().zip(&bounds).map(|(x, b)| b.u(*x)).collect();
        problem.x = DVector::from_vec(u);
        let (solved, report) = LevenbergMarquardt::new()
            .with_patience(200)
            .minimize(problem);
        problem = solved;
        let x = problem.x_of(problem.x.as_slice());
        let ssr = problem
            .residuals_at(&x)
            .map_or(f64::INFINITY, |r| r.iter().map(|v| v * v).sum());
        runs.push(Run {
            x,
            ssr,
            successful: report.termination.was_successful(),
            termination: format!("{:?}", report.termination),
            evaluations: report.number_of_evaluations,
        });
    }
    let best = runs
        .iter()
        .filter(|r| r.ssr.is_finite())
        .min_by(|a, b| a.ssr.total_cmp(&b.ssr))
        .ok_or_else(|| {
            FitError::Data(format!(
                "no start reached a law that can be evaluated at every data point ({} starts tried); where the first ended, {}",
                runs.len(),
                runs.first()
                    .map_or_else(|| "no start".to_string(), |r| problem.evaluation_failure(&r.x, &free_names))
            ))
        })?;
    let agreeing = runs
        .iter()
        .filter(|r| (r.ssr - best.ssr).abs() <= 1e-6 * best.ssr.max(f64::MIN_POSITIVE))
        .count();
    let x = best.x.clone();
    let spec = problem
        .spec_at(&x)
        .ok_or_else(|| FitError::Data("the fitted parameters do not make a law".into()))?;
    let r = problem.residuals_at(&x).ok_or_else(|| {
        FitError::Data(format!(
            "the fitted law cannot be evaluated at every data point: {}",
            problem.evaluation_failure(&x, &free_names)
        ))
    })?;
    let m = r.len();
    let ssr: f64 = r.iter().map(|v| v * v).sum();
    let s2 = ssr / (m - n) as f64;
    let max_rel = r.iter().fold(0.0f64, |a, v| a.max(v.abs())) / scale;
    let at_bound: Vec<Option<&'static str>> =
        x.iter().zip(&bounds).map(|(x, b)| b.at(*x)).collect();
    let jac = problem.jacobian_at(&x);
    // stationarity: each free column's cosine with the residual (a column at a bound may
    // have the residual's gradient pointing outward)
    let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let gradient_cosine = match &jac {
        Some(j) if rn > 0.0 => (0..n)
            .filter(|&k| at_bound[k].is_none())
            .map(|k| {
                let col = j.column(k);
                let norm = col.norm();
                if norm > 0.0 {
                    (col.iter().zip(&r).map(|(a, b)| a * b).sum::<f64>() / (norm * rn)).abs()
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max),
        Some(_) => 0.0,
        None => f64::INFINITY,
    };
    // data the law reproduces exactly (to EXACT_FIT of their scale): the residual is round-off
    // and its direction noise, so the cosine says nothing; such a fit is a minimum
    let exact = max_rel <= EXACT_FIT;
    let stationary = exact || gradient_cosine <= STATIONARITY;
    let converged = best.successful && stationary;
    let stop_reason = format!(
        "{} at the best of {} starts ({} of them reached its sum of squares to 1e-6), after {} evaluations; the largest cosine between a parameter's Jacobian column and the residual is {:.1e} ({} {:.0e})",
        if best.successful {
            "Levenberg–Marquardt converged"
        } else {
            "Levenberg–Marquardt stopped without converging"
        },
        runs.len(),
        agreeing,
        best.evaluations,
        gradient_cosine,
        if stationary { "≤" } else { ">" },
        STATIONARITY
    );
    let mut warnings = vec![];
    if !converged {
        warnings.push(format!(
            "the fit did not converge ({}): the parameters are the best iterate found, not a minimum; try other starts, fix or bound parameters, or add data",
            if best.successful {
                "the result is not stationary: the residual still has a component along a parameter"
            } else {
                best.termination.as_str()
            }
        ));
    }
    let (std, corr, flat, rank) = match &jac {
        Some(j) => uncertainty(j, &x, s2, &at_bound),
        None => (vec![None; n], vec![vec![None; n]; n], vec![true; n], 0),
    };
    let mut parameters = vec![];
    let mut fi = 0;
    for (name, _) in named.iter() {
        if let Some(&v) = opts.fixed.get(name) {
            parameters.push(FittedParameter {
                name: name.clone(),
                value: v,
                std_error: None,
                determined: true,
                fixed: true,
                at_bound: None,
            });
            continue;
        }
        let value = x[fi];
        let se = std[fi];
        parameters.push(FittedParameter {
            name: name.clone(),
            value,
            std_error: se,
            // (of an exact fit every standard error is round-off: a parameter the data fix at
            // 0 is determined, as long as the Jacobian does not say otherwise)
            determined: !flat[fi] && se.is_some_and(|e| exact || e <= value.abs()),
            fixed: false,
            at_bound: at_bound[fi].map(String::from),
        });
        fi += 1;
    }
    for p in parameters.iter().filter(|p| p.at_bound.is_some()) {
        warnings.push(format!(
            "`{}` ended on its {} bound ({:.4e}): the data push it there; its standard error is not given",
            p.name,
            p.at_bound.as_deref().unwrap_or(""),
            p.value
        ));
    }
    for p in parameters
        .iter()
        .filter(|p| !p.determined && !p.fixed && p.at_bound.is_none())
    {
        warnings.push(format!(
            "the data do not determine `{}` (fitted {:.4e}{}; the Jacobian's rank is {rank} of {n}): add data that exercise it (larger stretches, another test mode) or fix it (--fix {}=VALUE)",
            p.name,
            p.value,
            p.std_error.map_or(String::new(), |e| format!(" ± {e:.2e}")),
            p.name
        ));
    }
    let prony = problem
        .model_at(&x)
        .and_then(|m| m.1)
        .map(|p| p.terms().to_vec());
    let mut tests = vec![];
    let mut at = 0;
    for (name, count, top) in data.tests() {
        let rt = &r[at..at + count];
        at += count;
        tests.push(TestResidual {
            name,
            points: count,
            rms: (rt.iter().map(|v| v * v).sum::<f64>() / count as f64).sqrt(),
            max_relative: rt.iter().fold(0.0f64, |a, v| a.max(v.abs()))
                / top.max(f64::MIN_POSITIVE),
        });
    }
    Ok(FitResult {
        prony,
        tests,
        spec,
        parameters,
        correlation: corr,
        residual_std: s2.sqrt(),
        max_relative_residual: max_rel,
        points: m,
        converged,
        stop_reason,
        termination: best.termination.clone(),
        evaluations: best.evaluations,
        gradient_cosine,
        starts: runs.len(),
        starts_agreeing: agreeing,
        rank,
        free_parameters: n,
        warnings,
    })
}

/// The starts: the given one; the same with its moduli scaled to the data (the least-squares
/// factor s of P_data ≈ s P_model: a start in MPa for data in Pa); then `more` − 1 draws,
/// each parameter log-uniform within a decade of its start (a zero one uniform within ±0.1 of
/// the largest modulus), moduli scaled by s; each inside its bounds and a law.
fn starts_of(problem: &Problem, x0: &[f64], names: &[&str], more: usize) -> Vec<Vec<f64>> {
    let mut out = vec![x0.to_vec()];
    let valid = |x: &[f64]| problem.residuals_at(x).is_some();
    let inside = |x: &[f64]| {
        x.iter()
            .zip(&problem.bounds)
            .all(|(v, b)| *v >= b.lo && *v <= b.hi)
    };
    // the data-scaled start
    let s = problem.residuals_at(x0).and_then(|r| {
        // r = P_model − P_data, so P_model = r + P_data
        let p: Vec<f64> = problem.data.stresses();
        let (pm_pd, pm_pm) = r.iter().zip(&p).fold((0.0, 0.0), |(a, b), (r, pd)| {
            let pm = r + pd;
            (a + pm * pd, b + pm * pm)
        });
        let s = pm_pd / pm_pm;
        (s.is_finite() && s > 0.0).then_some(s)
    });
    let scaled = |x: &[f64], s: f64| -> Vec<f64> {
        x.iter()
            .zip(names)
            .map(|(v, n)| if is_modulus(n) { v * s } else { *v })
            .collect()
    };
    if let Some(s) = s {
        let x = scaled(x0, s);
        if valid(&x) && inside(&x) {
            out.push(x);
        }
    }
    let largest = x0
        .iter()
        .zip(names)
        .filter(|(_, n)| is_modulus(n))
        .fold(0.0f64, |a, (v, _)| a.max(v.abs()));
    let mut draws = Draws(0x7475_6265_6d65_6d21);
    let mut tries = 0;
    while out.len() < more + 1 && tries < 50 * (more + 1) {
        tries += 1;
        let x: Vec<f64> = x0
            .iter()
            .zip(names)
            .map(|(v, n)| {
                if *v != 0.0 {
                    v * 10f64.powf(2.0 * draws.next() - 1.0)
                } else if is_modulus(n) {
                    0.1 * largest * (2.0 * draws.next() - 1.0)
                } else {
                    2.0 * draws.next() - 1.0
                }
            })
            .collect();
        let x = scaled(&x, s.unwrap_or(1.0));
        if valid(&x) && inside(&x) {
            out.push(x);
        }
    }
    out
}

/// (standard errors, correlation, in an unresolved direction, the rank) from the Jacobian `j`
/// at `x`. The columns are scaled to unit length first (D = diag(1/‖J_k‖)), so that the
/// singular values of J D measure how far the columns are from dependent, whatever the
/// parameters' sizes. The covariance is s² D (Dᵀ JᵀJ D)⁺ D with the pseudo-inverse over the
/// singular values above 1e-6 of the largest (the rank): a parameter in a direction below
/// that, or held at a bound, has no standard error (`None`), never NaN.
#[allow(clippy::type_complexity)]
fn uncertainty(
    j: &DMatrix<f64>,
    x: &[f64],
    s2: f64,
    at_bound: &[Option<&str>],
) -> (Vec<Option<f64>>, Vec<Vec<Option<f64>>>, Vec<bool>, usize) {
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
    let mut rank = 0;
    let mut cov = DMatrix::<f64>::zeros(n, n);
    if let Some(vt) = &svd.v_t {
        for (r, &s) in sv.iter().enumerate() {
            if s > 1e-6 * smax && s.is_finite() {
                rank += 1;
                for a in 0..n {
                    for b in 0..n {
                        cov[(a, b)] += vt[(r, a)] * vt[(r, b)] / (s * s);
                    }
                }
            } else {
                for k in 0..n {
                    if vt[(r, k)].abs() > 0.3 {
                        flat[k] = true;
                    }
                }
            }
        }
    } else {
        flat.iter_mut().for_each(|f| *f = true);
    }
    let has = |a: usize| !flat[a] && at_bound[a].is_none() && cov[(a, a)] > 0.0;
    let std: Vec<Option<f64>> = (0..n)
        .map(|a| has(a).then(|| (s2 * cov[(a, a)]).max(0.0).sqrt() * d[a]))
        .collect();
    let corr = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| {
                    (has(a) && has(b))
                        .then(|| cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt())
                        .filter(|v| v.is_finite())
                })
                .collect()
        })
        .collect();
    (std, corr, flat, rank)
}
