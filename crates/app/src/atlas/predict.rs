//! `tubemem atlas predict`: the fitted laws' FE/GPS − 1 at a (λs*, ρ, L/R), and the minimum
//! L/R per ε, from an atlas's atlas.json. Between grid points the coefficients c and A are
//! interpolated bilinearly over the four grid points around (all four must have a law).

use super::fit::Point;
use super::output::AtlasJson;
use super::AtlasError;
use serde::Serialize;
use std::path::Path;

/// The prediction for one quantity.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Prediction {
    pub quantity: String,
    /// c + A f(L/R): the FE/GPS − 1 the atlas's mesh would give
    pub error: f64,
    /// A f(L/R): the end effect alone
    pub end_effect: f64,
    /// c: the discretization's part
    pub c: f64,
    pub a: f64,
    /// per ε of the atlas: (ε, minimum L/R)
    pub min_length_ratio: Vec<(f64, f64)>,
    /// where the length predicted at lies against the lengths run (`beyond-runs`: the law's
    /// extrapolation)
    pub length_extent: super::fit::Extent,
}

/// Read an atlas's atlas.json.
pub fn read(dir: &Path) -> Result<AtlasJson, AtlasError> {
    let path = dir.join("atlas.json");
    let text = std::fs::read_to_string(&path).map_err(|e| AtlasError::NotAnAtlas {
        path: dir.to_path_buf(),
        source: Box::new(e),
    })?;
    serde_json::from_str(&text).map_err(|e| AtlasError::NotAnAtlas {
        path: dir.to_path_buf(),
        source: Box::new(e),
    })
}

/// The grid values around x in `grid` (sorted): (lower, upper, weight of upper).
fn bracket(grid: &[f64], x: f64, what: &str) -> Result<(f64, f64, f64), AtlasError> {
    let mut g = grid.to_vec();
    g.sort_by(f64::total_cmp);
    g.dedup();
    if let Some(&v) = g.iter().find(|&&v| v == x) {
        return Ok((v, v, 0.0));
    }
    for w in g.windows(2) {
        if w[0] < x && x < w[1] {
            return Ok((w[0], w[1], (x - w[0]) / (w[1] - w[0])));
        }
    }
    Err(AtlasError::Predict(format!(
        "{what} = {x} is outside the atlas's grid {g:?}: it predicts inside it only"
    )))
}

/// The prediction of every quantity of the atlas at (λs*, ρ, L/R).
pub fn predict(
    atlas: &AtlasJson,
    stretch: f64,
    rho: f64,
    length: f64,
) -> Result<Vec<Prediction>, AtlasError> {
    if !(length.is_finite() && length > 0.0) {
        return Err(AtlasError::Predict(format!(
            "--length-ratio {length} is not a positive number"
        )));
    }
    let s = &atlas.spec;
    // below the shortest run the law's asymptotic form has no support (A/(L/R) grows without
    // bound as L → 0): refused; beyond the longest it is the law's tail, flagged
    let runs = super::fit::extent(length, &s.lengths);
    if runs == super::fit::Extent::BelowRuns {
        return Err(AtlasError::Predict(format!(
            "--length-ratio {length} is below every length the atlas ran ({:?}): the end-effect law is fitted on those lengths and does not hold for shorter tubes",
            s.lengths
        )));
    }
    let (s0, s1, ws) = bracket(&s.stretches, stretch, "--lambda-s-star")?;
    let (r0, r1, wr) = bracket(&s.rho, rho, "--rho")?;
    let mut out = vec![];
    for q in &s.quantities {
        let at = |x: f64, y: f64| -> Result<&Point, AtlasError> {
            let p = atlas
                .points
                .iter()
                .find(|p| p.stretch == x && p.rho == y && &p.quantity == q)
                .ok_or_else(|| {
                    AtlasError::Predict(format!("atlas.json has no point ({x}, {y}, {q})"))
                })?;
            match (&p.flag, &p.fit) {
                (None, Some(_)) => Ok(p),
                (Some(f), _) => Err(AtlasError::Predict(format!(
                    "{q} at λs* = {x}, ρ = {y} has no law ({}: {})",
                    f.flag, f.reason
                ))),
                (None, None) => Err(AtlasError::Predict(format!(
                    "{q} at λs* = {x}, ρ = {y} has no law"
                ))),
            }
        };
        let corners = [
            (at(s0, r0)?, (1.0 - ws) * (1.0 - wr)),
            (at(s1, r0)?, ws * (1.0 - wr)),
            (at(s0, r1)?, (1.0 - ws) * wr),
            (at(s1, r1)?, ws * wr),
        ];
        let (mut c, mut a, mut k) = (0.0, 0.0, 0.0);
        let mut fit = corners[0].0.fit.expect("checked");
        for (p, w) in corners {
            let f = p.fit.expect("checked");
            c += w * f.c;
            a += w * f.a;
            k += w * f.k;
        }
        fit.c = c;
        fit.a = a;
        fit.k = k;
        let end = fit.end_effect(length);
        out.push(Prediction {
            quantity: q.clone(),
            error: c + end,
            end_effect: end,
            c,
            a,
            min_length_ratio: s.epsilon.iter().map(|&e| (e, fit.length_for(e))).collect(),
            length_extent: runs,
        });
    }
    Ok(out)
}
