//! Small Newton solvers with backtracking. A trial point the law rejects (e.g. beyond locking)
//! is treated like a step that increased the residual: the step is halved.

use tubemem_material::MaterialError;

pub(crate) struct Failure {
    pub residual: f64,
    pub iterations: usize,
    /// The last material error met, if that is what stopped the iteration.
    pub material: Option<MaterialError>,
}

impl Failure {
    /// The solve could not even evaluate its starting point.
    fn at_start(e: MaterialError) -> Self {
        Failure {
            residual: f64::NAN,
            iterations: 0,
            material: Some(e),
        }
    }

    /// The typed error of a failed solve in `stage` at `at`: the material's, if that is what
    /// stopped it, otherwise no convergence with the residual and iteration count.
    pub(crate) fn into_error(self, stage: &'static str, at: &str) -> crate::GpsError {
        match self.material {
            Some(source) => crate::GpsError::Material {
                stage,
                at: at.to_string(),
                source,
            },
            None => crate::GpsError::NoConvergence {
                stage,
                at: at.to_string(),
                residual: self.residual,
                iterations: self.iterations,
            },
        }
    }
}

const MAX_IT: usize = 60;
const MAX_HALVINGS: usize = 40;

/// The backtracking line search both solvers share: from t = 1, halved up to [`MAX_HALVINGS`]
/// times, the first trial x + t·step with every unknown positive, accepted by the law, with a
/// finite merit below `merit0` (or a negligible step, `small(t)`). Returns t, the trial and its
/// evaluation, or `None`; a law's rejection is kept in `last_err`.
fn line_search<const N: usize, J>(
    f: impl Fn([f64; N]) -> Result<([f64; N], J), MaterialError>,
    x: [f64; N],
    step: [f64; N],
    merit0: f64,
    merit: impl Fn(&[f64; N]) -> f64,
    small: impl Fn(f64) -> bool,
    last_err: &mut Option<MaterialError>,
) -> Option<(f64, [f64; N], [f64; N], J)> {
    let mut t = 1.0;
    for _ in 0..MAX_HALVINGS {
        let xt: [f64; N] = std::array::from_fn(|k| x[k] + t * step[k]);
        if xt.iter().all(|v| *v > 0.0) {
            match f(xt) {
                Ok((ft, jt)) if merit(&ft).is_finite() && (merit(&ft) < merit0 || small(t)) => {
                    return Some((t, xt, ft, jt));
                }
                Ok(_) => {}
                Err(e) => *last_err = Some(e),
            }
        }
        t *= 0.5;
    }
    None
}

/// Solve f(x) = 0 (f returns value and derivative), x > 0, from `x0`.
/// Converged when the Newton step is below 1e-14 (1 + |x|) and |f| ≤ `ftol`.
pub(crate) fn scalar(
    f: impl Fn(f64) -> Result<(f64, f64), MaterialError>,
    x0: f64,
    ftol: f64,
) -> Result<f64, Failure> {
    let mut x = x0;
    let (mut fx, mut dfx) = f(x).map_err(Failure::at_start)?;
    let mut last_err = None;
    for it in 1..=MAX_IT {
        if fx == 0.0 {
            return Ok(x);
        }
        if !dfx.is_finite() {
            break;
        }
        let step = if dfx != 0.0 && dfx.is_finite() {
            -fx / dfx
        } else {
            0.0
        };
        if step == 0.0 || !step.is_finite() {
            break;
        }
        let small = |t: f64| t * step.abs() < 1e-12 * (1.0 + x.abs());
        let Some((t, [xt], [ft], dft)) = line_search(
            |[v]| f(v).map(|(fv, dv)| ([fv], dv)),
            [x],
            [step],
            fx.abs(),
            |[v]: &[f64; 1]| v.abs(),
            small,
            &mut last_err,
        ) else {
            return Err(Failure {
                residual: fx.abs(),
                iterations: it,
                material: last_err,
            });
        };
        (x, fx, dfx) = (xt, ft, dft);
        if (t * step).abs() <= 1e-14 * (1.0 + x.abs()) && fx.abs() <= ftol {
            return Ok(x);
        }
    }
    if fx.abs() <= ftol {
        return Ok(x);
    }
    Err(Failure {
        residual: fx.abs(),
        iterations: MAX_IT,
        material: last_err,
    })
}

/// Solve F(x) = 0 in two unknowns (F returns value and Jacobian), both unknowns > 0.
/// Merit |F|₂; converged when |F|₂ ≤ `ftol` and the step is below 1e-13 (1 + |x|).
pub(crate) fn system2(
    f: impl Fn([f64; 2]) -> Result<([f64; 2], [[f64; 2]; 2]), MaterialError>,
    x0: [f64; 2],
    ftol: f64,
) -> Result<[f64; 2], Failure> {
    let norm = |v: [f64; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
    let mut x = x0;
    let (mut fx, mut jx) = f(x).map_err(Failure::at_start)?;
    let mut last_err = None;
    for it in 1..=MAX_IT {
        let det = jx[0][0] * jx[1][1] - jx[0][1] * jx[1][0];
        if !(det.is_finite() && det != 0.0) {
            return Err(Failure {
                residual: norm(fx),
                iterations: it,
                material: last_err,
            });
        }
        let step = [
            -(jx[1][1] * fx[0] - jx[0][1] * fx[1]) / det,
            -(-jx[1][0] * fx[0] + jx[0][0] * fx[1]) / det,
        ];
        let x_start = x;
        let small = |t: f64| {
            (t * step[0]).abs() <= 1e-13 * (1.0 + x_start[0].abs())
                && (t * step[1]).abs() <= 1e-13 * (1.0 + x_start[1].abs())
        };
        let Some((t, xt, ft, jt)) =
            line_search(&f, x, step, norm(fx), |v| norm(*v), small, &mut last_err)
        else {
            return Err(Failure {
                residual: norm(fx),
                iterations: it,
                material: last_err,
            });
        };
        (x, fx, jx) = (xt, ft, jt);
        if small(t) && norm(fx) <= ftol {
            return Ok(x);
        }
    }
    if norm(fx) <= ftol {
        return Ok(x);
    }
    Err(Failure {
        residual: norm(fx),
        iterations: MAX_IT,
        material: last_err,
    })
}
