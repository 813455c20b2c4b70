//! The arithmetic of the verification checks and the atlas: grid convergence (Roache's GCI in
//! the form of Celik et al. 2008, ASME J. Fluids Eng. 130, 078001, "Procedure for estimation
//! and reporting of uncertainty due to discretization in CFD applications") and the end-effect
//! laws fitted to the mid-span error against the tube length.

/// The three-grid study of one quantity (grid 1 the finest).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Gci {
    /// apparent (observed) order p
    pub order: f64,
    /// Richardson-extrapolated value φ_ext^21
    pub extrapolated: f64,
    /// approximate relative error |(φ1 − φ2)/φ1|
    pub relative_error: f64,
    /// GCI of the fine grid, relative: Fs e_a^21 / (r21^p − 1)
    pub gci_fine: f64,
}

/// Why a three-grid study has no order.
#[derive(Clone, Debug, PartialEq)]
pub enum GciError {
    /// the differences change sign: oscillatory convergence (or none)
    Oscillatory { e21: f64, e32: f64 },
    /// the coarse difference is not larger than the fine one: the family does not converge
    Diverging { e21: f64, e32: f64 },
    /// the fine and medium values are equal: nothing to extrapolate (converged, or insensitive)
    NoChange,
    /// the refinement ratios are not above 1
    BadRatio,
}

impl std::fmt::Display for GciError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GciError::Oscillatory { e21, e32 } => write!(
                f,
                "the mesh family does not converge monotonically (φ2 − φ1 = {e21:.3e} and φ3 − φ2 = {e32:.3e} differ in sign)"
            ),
            GciError::Diverging { e21, e32 } => write!(
                f,
                "the mesh family does not converge (the fine-grid change |φ2 − φ1| = {:.3e} is not smaller than the coarse one |φ3 − φ2| = {:.3e})",
                e21.abs(),
                e32.abs()
            ),
            GciError::NoChange => write!(f, "the two finest meshes give the same value: no order can be observed"),
            GciError::BadRatio => write!(f, "the refinement ratios must be above 1"),
        }
    }
}

/// Safety factor of the GCI for three or more grids (Roache; Celik et al. 2008).
pub const SAFETY_FACTOR: f64 = 1.25;

/// Three grids: values `phi` = [φ1, φ2, φ3] from fine to coarse, with refinement ratios
/// r21 = h2/h1 and r32 = h3/h2. The apparent order solves (Celik et al. eqs. 4–6)
/// p = |ln|ε32/ε21| + q(p)| / ln r21,  q(p) = ln((r21^p − s)/(r32^p − s)),  s = sign(ε32/ε21),
/// by fixed-point iteration (q = 0 for a constant ratio).
pub fn gci(phi: [f64; 3], r21: f64, r32: f64) -> Result<Gci, GciError> {
    if !(r21 > 1.0 && r32 > 1.0) {
        return Err(GciError::BadRatio);
    }
    let (e21, e32) = (phi[1] - phi[0], phi[2] - phi[1]);
    if e21 == 0.0 {
        return Err(GciError::NoChange);
    }
    let ratio = e32 / e21;
    if ratio < 0.0 {
        return Err(GciError::Oscillatory { e21, e32 });
    }
    if ratio <= 1.0 {
        return Err(GciError::Diverging { e21, e32 });
    }
    let s = 1.0;
    let mut p = ratio.ln() / r21.ln();
    for _ in 0..200 {
        let q = ((r21.powf(p) - s) / (r32.powf(p) - s)).ln();
        let next = (ratio.ln() + q).abs() / r21.ln();
        if (next - p).abs() <= 1e-14 * p.abs().max(1.0) {
            p = next;
            break;
        }
        p = next;
    }
    let rp = r21.powf(p);
    let extrapolated = (rp * phi[0] - phi[1]) / (rp - 1.0);
    let relative_error = ((phi[0] - phi[1]) / phi[0]).abs();
    Ok(Gci {
        order: p,
        extrapolated,
        relative_error,
        gci_fine: SAFETY_FACTOR * relative_error / (rp - 1.0),
    })
}

/// The law of the mid-span error against the tube length L/R.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EndLaw {
    /// e = c + A exp(−k L/R): an open inflation (the cap's disturbance decays along the tube)
    Exponential,
    /// e = c + A/(L/R): the gas-closed squeeze (the gas the ends keep)
    Inverse,
}

/// A fitted end-effect law. `c` is the part that does not depend on the length (the
/// discretization's), `a` and `k` the law's amplitude and rate (k = 1 for the inverse law).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EndFit {
    pub law: EndLaw,
    pub c: f64,
    pub a: f64,
    pub k: f64,
    /// root-mean-square residual over max |e − c|: how well the law describes the family
    pub relative_residual: f64,
    /// the inverse law's truncation: |c' − c|, c' the constant of the law with its next term,
    /// c + A/(L/R) + B/(L/R)², fitted to the same family (the cap's gas keeps a share that
    /// falls as 1/(L + L₀), whose expansion has that term). It bounds how far the fitted c,
    /// the family's limit at infinite length, moves with the law; `None` for the exponential
    /// law, or with fewer than three lengths
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truncation: Option<f64>,
}

impl EndFit {
    /// The end effect A f(L/R) at length `l`.
    pub fn end_effect(&self, l: f64) -> f64 {
        match self.law {
            EndLaw::Exponential => self.a * (-self.k * l).exp(),
            EndLaw::Inverse => self.a / l,
        }
    }

    /// The shortest L/R at which |A f(L/R)| ≤ ε.
    pub fn length_for(&self, eps: f64) -> f64 {
        match self.law {
            EndLaw::Exponential => ((self.a.abs() / eps).ln() / self.k).max(0.0),
            EndLaw::Inverse => self.a.abs() / eps,
        }
    }
}

/// Linear least squares of e ≈ c + a g(L): (c, a, sum of squared residuals).
fn linear_fit(l: &[f64], e: &[f64], g: impl Fn(f64) -> f64) -> (f64, f64, f64) {
    let n = l.len() as f64;
    let gs: Vec<f64> = l.iter().map(|&x| g(x)).collect();
    let (sg, se) = (gs.iter().sum::<f64>(), e.iter().sum::<f64>());
    let sgg: f64 = gs.iter().map(|v| v * v).sum();
    let sge: f64 = gs.iter().zip(e).map(|(a, b)| a * b).sum();
    let det = n * sgg - sg * sg;
    let a = if det.abs() > 0.0 {
        (n * sge - sg * se) / det
    } else {
        0.0
    };
    let c = (se - a * sg) / n;
    let ss = gs
        .iter()
        .zip(e)
        .map(|(gv, ev)| (ev - c - a * gv).powi(2))
        .sum();
    (c, a, ss)
}

/// Fit `law` to errors `e` at lengths `l` (at least three). For the exponential law, k is found
/// by golden-section search on ln k in [1e-3, 1e2] with (c, A) by linear least squares at each k
/// (variable projection).
pub fn fit_end_law(law: EndLaw, l: &[f64], e: &[f64]) -> Option<EndFit> {
    if l.len() < 3 || l.len() != e.len() {
        return None;
    }
    let (c, a, k, ss) = match law {
        EndLaw::Inverse => {
            let (c, a, ss) = linear_fit(l, e, |x| 1.0 / x);
            (c, a, 1.0, ss)
        }
        EndLaw::Exponential => {
            let cost = |lk: f64| linear_fit(l, e, |x| (-lk.exp() * x).exp()).2;
            // a coarse scan first (the cost can have several dips), then golden section
            let (lo, hi) = (1e-3f64.ln(), 1e2f64.ln());
            let n = 200;
            let mut best = (f64::INFINITY, lo);
            for j in 0..=n {
                let t = lo + (hi - lo) * j as f64 / n as f64;
                let v = cost(t);
                if v < best.0 {
                    best = (v, t);
                }
            }
            let step = (hi - lo) / n as f64;
            let (mut a_, mut b_) = (best.1 - step, best.1 + step);
            let g = 0.5 * (5f64.sqrt() - 1.0);
            for _ in 0..200 {
                let (x1, x2) = (b_ - g * (b_ - a_), a_ + g * (b_ - a_));
                if cost(x1) < cost(x2) {
                    b_ = x2;
                } else {
                    a_ = x1;
                }
            }
            let lk = 0.5 * (a_ + b_);
            let k = lk.exp();
            let (c, a, ss) = linear_fit(l, e, |x| (-k * x).exp());
            (c, a, k, ss)
        }
    };
    let scale = e.iter().map(|v| (v - c).abs()).fold(0.0, f64::max);
    let rms = (ss / l.len() as f64).sqrt();
    let truncation = match law {
        EndLaw::Inverse => quadratic_constant(l, e).map(|c3| (c3 - c).abs()),
        EndLaw::Exponential => None,
    };
    Some(EndFit {
        law,
        c,
        a,
        k,
        relative_residual: if scale > 0.0 { rms / scale } else { 0.0 },
        truncation,
    })
}

/// The constant c of the least-squares fit e ≈ c + A/L + B/L² (three or more lengths; `None`
/// where the normal equations are singular: fewer than three distinct lengths).
fn quadratic_constant(l: &[f64], e: &[f64]) -> Option<f64> {
    let mut m = [[0.0f64; 3]; 3];
    let mut b = [0.0f64; 3];
    for (&x, &y) in l.iter().zip(e) {
        let g = [1.0, 1.0 / x, 1.0 / (x * x)];
        for i in 0..3 {
            b[i] += g[i] * y;
            for j in 0..3 {
                m[i][j] += g[i] * g[j];
            }
        }
    }
    // Gaussian elimination with partial pivoting on the 3 × 3 normal equations
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[piv][col].abs() <= 1e-300 {
            return None;
        }
        m.swap(col, piv);
        b.swap(col, piv);
        let (pivot, pb) = (m[col], b[col]);
        for row in col + 1..3 {
            let f = m[row][col] / pivot[col];
            for (x, p) in m[row][col..].iter_mut().zip(&pivot[col..]) {
                *x -= f * p;
            }
            b[row] -= f * pb;
        }
    }
    let mut x = [0.0f64; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| m[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / m[row][row];
    }
    x[0].is_finite().then_some(x[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worked example of Celik et al. (2008), Table 1, first column: N = 18 000, 8 000,
    /// 4 500 cells (r21 = 1.5, r32 = 1.333), φ = 6.063, 5.972, 5.863 → p = 1.53,
    /// φ_ext^21 = 6.1685, e_a^21 = 1.5 %, GCI_fine^21 = 2.2 %. The published values are rounded
    /// to the digits shown, so they are compared to half a unit of their last digit.
    #[test]
    fn gci_reproduces_the_published_three_grid_example() {
        let r21 = (18_000f64 / 8_000.0).sqrt();
        let r32 = (8_000f64 / 4_500.0).sqrt();
        assert!((r21 - 1.5).abs() < 1e-12 && (r32 - 1.333).abs() < 5e-4);
        let g = gci([6.063, 5.972, 5.863], r21, r32).unwrap();
        assert!((g.order - 1.53).abs() <= 0.005, "{g:?}");
        assert!((g.extrapolated - 6.1685).abs() <= 0.00005 + 0.0005, "{g:?}");
        assert!((g.relative_error - 0.015).abs() <= 0.0005, "{g:?}");
        assert!((g.gci_fine - 0.022).abs() <= 0.0005, "{g:?}");
    }

    /// A constant ratio and an exact power law: the order and the limit come back exactly.
    #[test]
    fn gci_of_an_exact_power_law() {
        let f = |h: f64| 2.0 + 0.3 * h * h;
        let g = gci([f(0.25), f(0.5), f(1.0)], 2.0, 2.0).unwrap();
        assert!((g.order - 2.0).abs() < 1e-10 && (g.extrapolated - 2.0).abs() < 1e-12);
    }

    #[test]
    fn families_that_do_not_converge_are_named() {
        assert!(matches!(
            gci([1.0, 1.1, 1.0], 2.0, 2.0),
            Err(GciError::Oscillatory { .. })
        ));
        let e = gci([1.0, 1.2, 1.3], 2.0, 2.0).unwrap_err();
        assert!(matches!(e, GciError::Diverging { .. }));
        assert!(e.to_string().contains("does not converge"));
        assert_eq!(gci([1.0, 1.0, 1.1], 2.0, 2.0), Err(GciError::NoChange));
    }

    #[test]
    fn end_laws_are_recovered_from_exact_data() {
        let l = [4.0, 6.0, 8.0, 10.0];
        let e: Vec<f64> = l
            .iter()
            .map(|x| 1.2e-3 + 0.5 * (-0.78f64 * x).exp())
            .collect();
        let f = fit_end_law(EndLaw::Exponential, &l, &e).unwrap();
        assert!(
            (f.k - 0.78).abs() < 1e-6 && (f.c - 1.2e-3).abs() < 1e-9,
            "{f:?}"
        );
        assert!((f.length_for(1e-3) - (0.5f64 / 1e-3).ln() / 0.78).abs() < 1e-4);
        let e: Vec<f64> = l.iter().map(|x| -1e-3 - 0.26 / x).collect();
        let f = fit_end_law(EndLaw::Inverse, &l, &e).unwrap();
        assert!((f.a + 0.26).abs() < 1e-12 && f.relative_residual < 1e-12);
        assert!((f.length_for(1e-3) - 260.0).abs() < 1e-9);
        // an exact inverse law has no truncation
        assert!(f.truncation.unwrap() < 1e-12, "{f:?}");
    }

    /// The gas the caps keep falls as A/(L + L₀) = A/L − A L₀/L² + …: fitted with c + A/L
    /// alone over L, 1.5L, 2L, its constant c is off by the second term, and the truncation
    /// (the change of c when B/L² is added) measures that shift: within 5 % of the true offset
    /// of the 2-term c from the limit c₀ (the rest is the third term, A L₀²/L³).
    #[test]
    fn the_inverse_laws_truncation_measures_the_next_term() {
        let (c0, a, l0) = (5e-5, -0.23, 1.5);
        let l = [18.18, 27.27, 36.36];
        let e: Vec<f64> = l.iter().map(|x| c0 + a / (x + l0)).collect();
        let f = fit_end_law(EndLaw::Inverse, &l, &e).unwrap();
        let offset = (f.c - c0).abs();
        let t = f.truncation.unwrap();
        assert!(
            offset > 1e-4,
            "the 2-term c must be visibly off here: {offset}"
        );
        assert!(
            (t / offset - 1.0).abs() < 0.05,
            "truncation {t} against offset {offset}"
        );
    }
}
