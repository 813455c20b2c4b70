//! The atlas's files: atlas.csv (one row per λs*, ρ, quantity, ε), runs.csv (the raw per-run
//! errors), atlas.json (the atlas, its points and its members' results: what `tubemem atlas
//! predict` and Python read), and the contour maps of the minimum L/R.

use super::fit::{law_name, Point};
use super::member::MemberResult;
use super::spec::{Atlas, QUANTITIES};
use super::AtlasError;
use crate::figures::{series_color, Figure, FigureOptions, Markers, Series, Stroke};
use plotters::style::RGBColor;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// atlas.json.
#[derive(Serialize, Deserialize)]
pub struct AtlasJson {
    pub tubemem: String,
    pub spec: super::AtlasSpec,
    pub points: Vec<Point>,
    pub members: Vec<MemberResult>,
}

/// A CSV field: quoted when it holds a comma, a quote or a line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn num(v: Option<f64>) -> String {
    v.filter(|v| v.is_finite())
        .map_or(String::new(), |v| v.to_string())
}

/// atlas.csv's text.
pub fn atlas_csv(atlas: &Atlas, points: &[Point]) -> String {
    let mut s = String::from(
        "lambda_s_star,rho,quantity,epsilon,min_length_ratio,min_length_extent,law,c,a,k,fit_residual,flag,reason\n",
    );
    for p in points {
        for (e, m) in atlas.spec.epsilon.iter().zip(&p.min_length) {
            let f = p.fit.as_ref();
            s.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                p.stretch,
                p.rho,
                p.quantity,
                e,
                num(*m),
                m.map_or("", |m| super::fit::extent(m, &atlas.spec.lengths).name()),
                field(law_name(atlas.spec.law)),
                num(f.map(|f| f.c)),
                num(f.map(|f| f.a)),
                num(f.map(|f| f.k)),
                num(f.map(|f| f.relative_residual)),
                p.flag.as_ref().map_or("", |f| f.flag.as_str()),
                field(p.flag.as_ref().map_or("", |f| f.reason.as_str())),
            ));
        }
    }
    s
}

/// runs.csv's text: every member, level and quantity.
pub fn runs_csv(atlas: &Atlas, results: &[MemberResult]) -> String {
    let mut s = String::from(
        "member,lambda_s_star,length_ratio,rho,quantity,fe,gps,error,contact,uniform,critical,run_error\n",
    );
    for r in results {
        let err = field(r.error.as_deref().unwrap_or(""));
        if r.levels.is_empty() {
            s.push_str(&format!(
                "{},{},{},,,,,,,,,{err}\n",
                r.name, r.stretch, r.length
            ));
        }
        for l in &r.levels {
            for q in &atlas.spec.quantities {
                let qi = QUANTITIES.iter().position(|x| x == q).expect("validated");
                let v = l.values[qi];
                s.push_str(&format!(
                    "{},{},{},{},{},{},{},{},{},{},{},{err}\n",
                    r.name,
                    r.stretch,
                    r.length,
                    l.rho,
                    q,
                    num(v.map(|v| v.fe)),
                    num(v.map(|v| v.gps)),
                    num(v.map(|v| v.error())),
                    l.contact,
                    l.uniform.map_or(String::new(), |u| u.to_string()),
                    l.critical,
                ));
            }
        }
    }
    s
}

/// The contour levels of a minimum L/R map: 1, 1.5, 2, 3, 5, 7 × 10^k across the finite values.
pub fn nice_levels(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return vec![];
    }
    let mut out = vec![];
    let mut e = lo.log10().floor() as i32;
    while 10f64.powi(e) <= hi {
        for m in [1.0, 1.5, 2.0, 3.0, 5.0, 7.0] {
            let v = m * 10f64.powi(e);
            if v > lo && v < hi {
                out.push(v);
            }
        }
        e += 1;
    }
    out
}

/// The map of the minimum L/R for quantity `q` and the `e`-th ε over (λs*, ρ): contours of
/// log L/R, the grid points valid (filled) or flagged (hollow).
pub fn min_length_figure(atlas: &Atlas, points: &[Point], q: &str, e: usize) -> Figure {
    let s = &atlas.spec;
    let mut xs = s.stretches.clone();
    xs.sort_by(f64::total_cmp);
    let mut ys = s.rho.clone();
    ys.sort_by(f64::total_cmp);
    let at = |x: f64, y: f64| {
        points
            .iter()
            .find(|p| p.stretch == x && p.rho == y && p.quantity == q)
    };
    let z: Vec<Vec<f64>> = xs
        .iter()
        .map(|&x| {
            ys.iter()
                .map(|&y| {
                    at(x, y)
                        .and_then(|p| p.min_length[e])
                        .filter(|v| *v > 0.0)
                        .map_or(f64::NAN, f64::ln)
                })
                .collect()
        })
        .collect();
    let levels = nice_levels(z.iter().flatten().map(|v| v.exp()));
    let series: Vec<Series> = levels
        .iter()
        .enumerate()
        .map(|(k, &lv)| Series {
            label: format!("L/R = {lv}"),
            points: super::contour::contour(&xs, &ys, &z, lv.ln()),
            color: series_color(k),
            stroke: Stroke::Solid,
            width: 2,
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let mut valid = vec![];
    let mut flagged = vec![];
    for &x in &xs {
        for &y in &ys {
            match at(x, y).map(|p| p.min_length[e]) {
                Some(Some(_)) => valid.push((x, y)),
                _ => flagged.push((x, y)),
            }
        }
    }
    let mut notes = vec![format!(
        "end-effect law {} fitted over L/R = {:?}; the minimum L/R for |A f(L/R)| ≤ ε",
        law_name(s.law),
        s.lengths
    )];
    let values: Vec<String> = xs
        .iter()
        .flat_map(|&x| ys.iter().map(move |&y| (x, y)))
        .filter_map(|(x, y)| {
            at(x, y)
                .and_then(|p| p.min_length[e])
                .map(|m| format!("({x}, {y}): {m:.3}"))
        })
        .collect();
    for chunk in values.chunks(4) {
        notes.push(chunk.join("   "));
    }
    Figure {
        markers: vec![
            Markers {
                label: "grid point with a law".into(),
                points: valid,
                color: RGBColor(0, 0, 0),
                hollow: false,
            },
            Markers {
                label: "flagged (no law: see atlas.csv)".into(),
                points: flagged,
                color: RGBColor(120, 120, 120),
                hollow: true,
            },
        ],
        notes,
        y_from_zero: false,
        ..Figure::new(
            format!(
                "minimum L/R for {q} within ε = {:e} of GPS (end effect)",
                s.epsilon[e]
            ),
            "inflated mid-span stretch λs*",
            "half-gap ρ = r/R",
            series,
        )
    }
}

/// Write every file of the atlas into `out`; returns the paths.
pub fn write_all(
    atlas: &Atlas,
    results: &[MemberResult],
    points: &[Point],
    out: &Path,
) -> Result<Vec<PathBuf>, AtlasError> {
    let mut written = vec![];
    let mut put = |name: &str, bytes: &[u8]| -> Result<(), AtlasError> {
        let p = out.join(name);
        crate::output_file::write_whole(&p, bytes)?;
        written.push(p);
        Ok(())
    };
    put("atlas.csv", atlas_csv(atlas, points).as_bytes())?;
    put("runs.csv", runs_csv(atlas, results).as_bytes())?;
    let json = AtlasJson {
        tubemem: env!("CARGO_PKG_VERSION").into(),
        spec: atlas.spec.clone(),
        points: points.to_vec(),
        members: results
            .iter()
            .map(|r| MemberResult {
                // the wall time differs from run to run: not part of the result files
                seconds: 0.0,
                ..r.clone()
            })
            .collect(),
    };
    put(
        "atlas.json",
        serde_json::to_string_pretty(&json)
            .expect("plain data serializes")
            .as_bytes(),
    )?;
    let s = &atlas.spec;
    let lo_s = s.stretches.iter().copied().fold(f64::INFINITY, f64::min);
    let hi_s = s.stretches.iter().copied().fold(0.0, f64::max);
    let lo_r = s.rho.iter().copied().fold(f64::INFINITY, f64::min);
    let stretch = s
        .ps_map
        .stretches
        .map_or((lo_s.min(1.05), hi_s), |[a, b]| (a, b));
    let rho = s
        .ps_map
        .rho
        .map_or((lo_r.min(stretch.0), stretch.1), |[a, b]| (a, b));
    let law = atlas.material.build().map_err(|e| AtlasError::Invalid {
        key: "material".into(),
        message: crate::error_chain(&e),
    })?;
    let supply = match s.squeeze.get("control").and_then(|v| v.as_str()) {
        Some("pressure") => super::ps_map::MapSupply::Regulated,
        _ => super::ps_map::MapSupply::Closed,
    };
    written.extend(super::ps_map::write(
        law.as_ref(),
        supply,
        &crate::figures::overlay::law_label(&atlas.material),
        stretch,
        rho,
        s.ps_map.points.unwrap_or(41),
        &s.epsilon,
        out,
    )?);
    let figures = out.join("figures");
    crate::output_file::create_folder(&figures)?;
    for q in &atlas.spec.quantities {
        for (e, eps) in atlas.spec.epsilon.iter().enumerate() {
            let fig = min_length_figure(atlas, points, q, e);
            let stem = figures.join(format!("min_length_{q}_eps{eps:e}"));
            written.extend(crate::figures::save(
                &fig,
                &stem,
                &FigureOptions::default(),
            )?);
        }
    }
    Ok(written)
}
