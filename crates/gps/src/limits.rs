//! Limit points of the free-inflation curve and the Maxwell (equal-area) pressure.
//!
//! Along the equilibrium path λs ↦ (ϖ, λz), implicit differentiation of N_s = 2N_z (GPS) gives
//!
//! ```text
//! λz' = −(∂Ns/∂λs − 2∂Nz/∂λs)/(∂Ns/∂λz − 2∂Nz/∂λz)        (λz' = 0 under PS)
//! dϖ/dλs = (∂Ns/∂λs + ∂Ns/∂λz λz')/λs − Ns/λs²
//! ```
//! The curve is scanned in λs from 1 with step 0.005 up to the locking limit of the law (where
//! the inflation problem stops having a solution) or λs = 50, whichever comes first; each sign
//! change of dϖ/dλs is refined by bisection to |Δλs| < 1e-13. The first change from + to − is
//! the pressure maximum, the first change from − to + after it the minimum.
//!
//! The Maxwell pressure ϖ_M is the pressure at which a bulge propagates in a long tube
//! (Kyriakides & Chang 1990; Lestringant & Audoly 2018): on the (v, ϖ) curve with
//! v = πλs²λz, the outer roots v1 < v3 of ϖ(v) = ϖ_M enclose equal areas,
//! A(ϖ_M) = ∫_{v1}^{v3} (ϖ − ϖ_M) dv = 0. A is computed by composite 8-point Gauss–Legendre
//! quadrature in λs (split at the two limit points), and A(ϖ_M) = 0 is solved by Newton with
//! dA/dϖ_M = −(v3 − v1), kept inside the bracket (ϖ_min, ϖ_max).

use crate::error::GpsError;
use crate::{inflation_solve, resultants, Hypothesis, InflationState};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use tubemem_material::MembraneLaw;

/// A limit point of the inflation curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LimitPoint {
    pub lambda_s: f64,
    pub lambda_z: f64,
    pub w: f64,
}

/// The Maxwell pressure and the two hoop stretches that coexist at it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Maxwell {
    pub w: f64,
    pub lambda_s_lower: f64,
    pub lambda_s_upper: f64,
}

/// What [`limit_points`] found; `None` where the law has no such point in the scanned range.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    pub max: Option<LimitPoint>,
    pub min: Option<LimitPoint>,
    pub maxwell: Option<Maxwell>,
    /// The largest λs scanned (the locking limit of the path, or the scan cap).
    pub scanned_to: f64,
}

/// The scan cap for laws without a locking limit.
pub const SCAN_MAX_STRETCH: f64 = 50.0;
const SCAN_STEP: f64 = 0.005;

/// The free-inflation equilibrium path of one law under one hypothesis.
pub struct InflationPath<'a> {
    law: &'a dyn MembraneLaw,
    hyp: Hypothesis,
    /// (λs, λz) samples used as initial guesses.
    table: Vec<(f64, f64)>,
}

impl<'a> InflationPath<'a> {
    pub fn new(law: &'a dyn MembraneLaw, hyp: Hypothesis) -> Self {
        Self {
            law,
            hyp,
            table: Vec::new(),
        }
    }

    fn guess(&self, ls: f64) -> f64 {
        let t = &self.table;
        if t.is_empty() {
            return crate::eq68_lambda_z(ls);
        }
        let i = t.partition_point(|p| p.0 < ls);
        if i == 0 {
            t[0].1
        } else if i >= t.len() {
            t[t.len() - 1].1
        } else {
            let (a, b) = (t[i - 1], t[i]);
            a.1 + (b.1 - a.1) * (ls - a.0) / (b.0 - a.0)
        }
    }

    /// The state at λs, and (dϖ/dλs, dλz/dλs).
    pub fn at(&self, ls: f64) -> Result<(InflationState, f64, f64), GpsError> {
        let s = inflation_solve(self.law, self.hyp, ls, self.guess(ls))?;
        let r = resultants::resultants(self.law, ls, s.lambda_z).map_err(|source| {
            GpsError::Material {
                stage: "inflation path slope",
                at: format!("λs = {}", tubemem_material::Num(ls)),
                source,
            }
        })?;
        let dlz = match self.hyp {
            Hypothesis::Ps => 0.0,
            Hypothesis::Gps => {
                -(r.jac[0][0] - 2.0 * r.jac[1][0]) / (r.jac[0][1] - 2.0 * r.jac[1][1])
            }
        };
        let dw = (r.jac[0][0] + r.jac[0][1] * dlz) / ls - r.ns / (ls * ls);
        Ok((s, dw, dlz))
    }

    /// v = πλs²λz, the volume per unit reference length (R = 1).
    fn volume(s: &InflationState) -> f64 {
        PI * s.lambda_s * s.lambda_s * s.lambda_z
    }
}

/// Bisection on the sign of dϖ/dλs in [a, b] (opposite signs at the ends).
fn refine(path: &InflationPath, mut a: f64, mut b: f64) -> Result<LimitPoint, GpsError> {
    let sa = path.at(a)?.1.signum();
    while b - a > 1e-13 {
        let m = 0.5 * (a + b);
        if path.at(m)?.1.signum() == sa {
            a = m;
        } else {
            b = m;
        }
    }
    let s = path.at(0.5 * (a + b))?.0;
    Ok(LimitPoint {
        lambda_s: s.lambda_s,
        lambda_z: s.lambda_z,
        w: s.w,
    })
}

/// λs on a branch [lo, hi] where ϖ increases, such that ϖ(λs) = p.
fn invert_branch(path: &InflationPath, mut lo: f64, mut hi: f64, p: f64) -> Result<f64, GpsError> {
    for _ in 0..200 {
        if hi - lo <= 1e-14 * hi {
            break;
        }
        let m = 0.5 * (lo + hi);
        if path.at(m)?.0.w < p {
            lo = m;
        } else {
            hi = m;
        }
    }
    Ok(0.5 * (lo + hi))
}

const GL8: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// ∫_{a}^{b} (ϖ − p) dv, by composite Gauss–Legendre in λs.
fn area(path: &InflationPath, a: f64, b: f64, p: f64, panels: usize) -> Result<f64, GpsError> {
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let c = a + (k as f64 + 0.5) * h;
        for &(x, wgt) in &GL8 {
            for ls in [c - 0.5 * h * x, c + 0.5 * h * x] {
                let (s, _, dlz) = path.at(ls)?;
                let dv = PI * (2.0 * ls * s.lambda_z + ls * ls * dlz);
                sum += wgt * 0.5 * h * (s.w - p) * dv;
            }
        }
    }
    Ok(sum)
}

/// Limit points and Maxwell pressure of the free-inflation curve.
pub fn limit_points(law: &dyn MembraneLaw, hyp: Hypothesis) -> Result<Limits, GpsError> {
    limit_points_until(law, hyp, &|| false)
}

/// [`limit_points`], stopped with [`GpsError::Interrupted`] as soon as `stop` says so (checked
/// at every state of the scan: for an energy of thousands of terms the scan takes minutes, and
/// a run's Ctrl-C must not wait for it).
pub fn limit_points_until(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    stop: &dyn Fn() -> bool,
) -> Result<Limits, GpsError> {
    let mut path = InflationPath::new(law, hyp);
    // Scan.
    let mut samples: Vec<(f64, f64)> = Vec::new(); // (λs, dϖ/dλs)
    let mut ls = 1.0;
    loop {
        if stop() {
            return Err(GpsError::Interrupted);
        }
        match path.at(ls) {
            Ok((s, dw, _)) => {
                path.table.push((ls, s.lambda_z));
                samples.push((ls, dw));
            }
            Err(GpsError::Material { .. }) if !samples.is_empty() => break, // locking ends the path
            Err(e) => return Err(e),
        }
        if ls >= SCAN_MAX_STRETCH {
            break;
        }
        ls = (ls + SCAN_STEP).min(SCAN_MAX_STRETCH);
    }
    let scanned_to = samples.last().map_or(1.0, |s| s.0);
    let (mut max, mut min) = (None, None);
    for w in samples.windows(2) {
        let ((a, da), (b, db)) = (w[0], w[1]);
        if max.is_none() && da > 0.0 && db <= 0.0 {
            max = Some(refine(&path, a, b)?);
        } else if max.is_some() && min.is_none() && da < 0.0 && db >= 0.0 {
            min = Some(refine(&path, a, b)?);
        }
    }
    let maxwell = match (max, min) {
        (Some(mx), Some(mn)) => maxwell(&path, mx, mn, scanned_to)?,
        _ => None,
    };
    Ok(Limits {
        max,
        min,
        maxwell,
        scanned_to,
    })
}

fn maxwell(
    path: &InflationPath,
    mx: LimitPoint,
    mn: LimitPoint,
    end: f64,
) -> Result<Option<Maxwell>, GpsError> {
    let w_end = path.at(end)?.0.w;
    let (mut lo, mut hi) = (mn.w, mx.w.min(w_end));
    let panels = 24;
    let eval = |p: f64| -> Result<(f64, f64, f64), GpsError> {
        let l1 = invert_branch(path, 1.0, mx.lambda_s, p)?;
        let l3 = invert_branch(path, mn.lambda_s, end, p)?;
        let a = area(path, l1, mx.lambda_s, p, panels)?
            + area(path, mx.lambda_s, mn.lambda_s, p, panels)?
            + area(path, mn.lambda_s, l3, p, panels)?;
        Ok((a, l1, l3))
    };
    // A decreases with p; a root exists in (ϖ_min, min(ϖ_max, ϖ_end)) iff A(hi) ≤ 0.
    if eval(hi)?.0 > 0.0 {
        return Ok(None);
    }
    let mut p = 0.5 * (lo + hi);
    for _ in 0..100 {
        let (a, l1, l3) = eval(p)?;
        if a > 0.0 {
            lo = p;
        } else {
            hi = p;
        }
        let v1 = InflationPath::volume(&path.at(l1)?.0);
        let v3 = InflationPath::volume(&path.at(l3)?.0);
        let mut next = p + a / (v3 - v1);
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - p).abs() <= 1e-14 * p.abs() || hi - lo <= 1e-14 * p.abs() {
            let (_, l1, l3) = eval(next)?;
            return Ok(Some(Maxwell {
                w: next,
                lambda_s_lower: l1,
                lambda_s_upper: l3,
            }));
        }
        p = next;
    }
    Err(GpsError::NoConvergence {
        stage: "Maxwell equal-area pressure",
        at: format!("ϖ = {}", tubemem_material::Num(p)),
        residual: hi - lo,
        iterations: 100,
    })
}
