//! Where plane strain fails: |PS/GPS − 1| of the closed forms over a fine (λs*, ρ) grid, for the
//! atlas's law (both hypotheses squeezed from the same λs*, as the atlas's squeezes are: the gas
//! closed in, eqs. 76–77, or the pressure held at its inflated value, eqs. 76; with λz free or
//! λz = 1). No FE: the map is the closed form itself.

use super::AtlasError;
use crate::figures::{Figure, Series, Stroke};
use plotters::style::RGBColor;
use tubemem_gps::regulated::flatten_at_pressure;
use tubemem_gps::{flatten, FlatteningState, Hypothesis};

/// How the map's squeezes are supplied with gas: as the atlas's squeeze stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapSupply {
    /// closed in the tube inflated to λs* (Boyle, eqs. 76–77)
    Closed,
    /// held at the inflated pressure ϖ(λs*) by a regulator (eqs. 76; `control = "pressure"`)
    Regulated,
}

impl MapSupply {
    /// The squeeze from λs* = `s` to ρ = `r` under hypothesis `h` (None where it has no
    /// solution).
    fn solve(
        self,
        law: &dyn MembraneLaw,
        h: Hypothesis,
        s: f64,
        r: f64,
    ) -> Option<FlatteningState> {
        match self {
            MapSupply::Closed => flatten(law, h, s, r).ok(),
            MapSupply::Regulated => flatten_at_pressure(law, h, s, r)
                .ok()
                .map(|x| x.as_flattening(s)),
        }
    }

    fn describe(self) -> &'static str {
        match self {
            MapSupply::Closed => "the gas closed, eqs. 76–77",
            MapSupply::Regulated => "the pressure held at its inflated value, eqs. 76",
        }
    }
}
use tubemem_material::MembraneLaw;

/// The quantities of the map.
pub const PS_QUANTITIES: [&str; 4] = ["w", "force", "chi", "lambda_s"];

/// One grid point: GPS and PS (None where ρ ≥ λs* or a closed form has no solution).
#[derive(Clone, Copy, Debug)]
pub struct PsPoint {
    pub stretch: f64,
    pub rho: f64,
    pub gps: Option<FlatteningState>,
    pub ps: Option<FlatteningState>,
}

fn value(s: &FlatteningState, q: &str) -> f64 {
    match q {
        "w" => s.w,
        "force" => s.force,
        "chi" => s.chi,
        _ => s.lambda_s,
    }
}

impl PsPoint {
    /// |PS/GPS − 1| of quantity `q`, NaN where either is missing.
    pub fn difference(&self, q: &str) -> f64 {
        match (&self.gps, &self.ps) {
            (Some(g), Some(p)) => (value(p, q) / value(g, q) - 1.0).abs(),
            _ => f64::NAN,
        }
    }
}

/// The grid: `n` λs* from `stretch.0` to `stretch.1` and `n` ρ from `rho.0` to `rho.1`, the
/// squeezes supplied as `supply` says.
pub fn grid(
    law: &dyn MembraneLaw,
    supply: MapSupply,
    stretch: (f64, f64),
    rho: (f64, f64),
    n: usize,
) -> Vec<Vec<PsPoint>> {
    let lin = |a: f64, b: f64, i: usize| a + (b - a) * i as f64 / (n - 1).max(1) as f64;
    (0..n)
        .map(|i| {
            let s = lin(stretch.0, stretch.1, i);
            (0..n)
                .map(|j| {
                    let r = lin(rho.0, rho.1, j);
                    let solve = |h| (r < s).then(|| supply.solve(law, h, s, r)).flatten();
                    PsPoint {
                        stretch: s,
                        rho: r,
                        gps: solve(Hypothesis::Gps),
                        ps: solve(Hypothesis::Ps),
                    }
                })
                .collect()
        })
        .collect()
}

/// ps_map.csv's text: every point and quantity.
pub fn csv(grid: &[Vec<PsPoint>]) -> String {
    let mut s = String::from("lambda_s_star,rho,quantity,gps,ps,abs_relative_difference\n");
    let num = |v: Option<f64>| {
        v.filter(|v| v.is_finite())
            .map_or(String::new(), |v| v.to_string())
    };
    for p in grid.iter().flatten() {
        for q in PS_QUANTITIES {
            s.push_str(&format!(
                "{},{},{q},{},{},{}\n",
                p.stretch,
                p.rho,
                num(p.gps.map(|g| value(&g, q))),
                num(p.ps.map(|g| value(&g, q))),
                num(Some(p.difference(q))),
            ));
        }
    }
    s
}

/// The map of quantity `q`: the contours |PS/GPS − 1| = ε for each ε.
pub fn figure(
    grid: &[Vec<PsPoint>],
    supply: MapSupply,
    q: &str,
    epsilon: &[f64],
    law: &str,
) -> Figure {
    let xs: Vec<f64> = grid.iter().map(|c| c[0].stretch).collect();
    let ys: Vec<f64> = grid[0].iter().map(|p| p.rho).collect();
    let z: Vec<Vec<f64>> = grid
        .iter()
        .map(|c| {
            c.iter()
                // a missing point stays NaN (f64::max would turn it into the floor: a false
                // contour along the edge of the squeezed states)
                .map(|p| match p.difference(q) {
                    d if d.is_finite() => d.max(1e-300).log10(),
                    _ => f64::NAN,
                })
                .collect()
        })
        .collect();
    const C: [RGBColor; 4] = [
        RGBColor(31, 90, 180),
        RGBColor(200, 50, 40),
        RGBColor(20, 140, 60),
        RGBColor(150, 60, 170),
    ];
    let mut series: Vec<Series> = epsilon
        .iter()
        .enumerate()
        .map(|(k, &e)| Series {
            label: format!("|PS/GPS − 1| = {e:e}"),
            points: super::contour::contour(&xs, &ys, &z, e.log10()),
            color: C[k % C.len()],
            stroke: Stroke::Solid,
            width: 2,
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    // the edge of the squeezed states: ρ = λs*
    let (lo, hi) = (xs[0], xs[xs.len() - 1]);
    series.push(Series {
        label: "ρ = λs* (first contact)".into(),
        points: vec![(lo, lo), (hi, hi)],
        color: RGBColor(90, 90, 90),
        stroke: Stroke::Dashed,
        width: 1,
    });
    Figure {
        notes: vec![format!(
            "{law}: the closed forms only ({}, λz free against λz = 1), {} × {} grid",
            supply.describe(),
            xs.len(),
            ys.len()
        )],
        y_from_zero: false,
        ..Figure::new(
            format!("plane strain against GPS: |PS/GPS − 1| of {q}"),
            "inflated mid-span stretch λs*",
            "half-gap ρ = r/R",
            series,
        )
    }
}

/// Compute and write ps_map.csv and its figures into `out`.
#[allow(clippy::too_many_arguments)]
pub fn write(
    law: &dyn MembraneLaw,
    supply: MapSupply,
    law_label: &str,
    stretch: (f64, f64),
    rho: (f64, f64),
    n: usize,
    epsilon: &[f64],
    out: &std::path::Path,
) -> Result<Vec<std::path::PathBuf>, AtlasError> {
    let g = grid(law, supply, stretch, rho, n);
    let mut written = vec![];
    let p = out.join("ps_map.csv");
    crate::output_file::write_whole(&p, csv(&g).as_bytes())?;
    written.push(p);
    let figures = out.join("figures");
    crate::output_file::create_folder(&figures)?;
    for q in PS_QUANTITIES {
        let fig = figure(&g, supply, q, epsilon, law_label);
        written.extend(crate::figures::save(
            &fig,
            &figures.join(format!("ps_map_{q}")),
            &Default::default(),
        )?);
    }
    Ok(written)
}
