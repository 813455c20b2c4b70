//! PNG and CSV reproductions of the paper's Figs. 5–7, plus λz versus λs.
//!
//! Fig. 5: ϖ versus λs, GPS and PS inflation (solid) and the flattening branches from
//! λs* = 1.3 and 6.0 (dashed), with the GPS limit points and Maxwell pressure marked.
//! Figs. 6 and 7: reduced force ϖχ versus reduced displacement λs* − ρ (eqs. 80–81) for
//! λs* = 1.3 and 6.0. The flattening runs to ρ = λs*/2.

use crate::curves::{
    flattening_values, inflation_values, write_csv, FLATTENING_HEADER, INFLATION_HEADER,
};
use crate::{AppError, Result};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::{Path, PathBuf};
use std::sync::Once;
use tubemem_gps::limits::limit_points;
use tubemem_gps::{flattening_curve, inflation_curve, Hypothesis};
use tubemem_material::laws::AnssariBenamBucchi;

static FONT: Once = Once::new();
const FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

fn register_font(path: &Path) -> Result<()> {
    let mut ok = true;
    FONT.call_once(|| {
        ok = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_BYTES).is_ok();
    });
    if ok {
        Ok(())
    } else {
        Err(AppError::Figure {
            path: path.to_path_buf(),
            message: "the bundled DejaVu Sans font could not be loaded".into(),
        })
    }
}

const GPS_COLOR: RGBColor = RGBColor(31, 90, 180);
const PS_COLOR: RGBColor = RGBColor(200, 50, 40);

/// One curve of a figure.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub color: RGBColor,
    pub dashed: bool,
}

/// Isolated markers with a legend entry.
pub struct Markers {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub color: RGBColor,
}

pub struct Figure<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub series: Vec<Series>,
    pub markers: Vec<Markers>,
}

fn range(values: impl Iterator<Item = f64>, from_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if from_zero {
        lo = lo.min(0.0);
    }
    let pad = 0.04 * (hi - lo).max(1e-12);
    (if from_zero && lo >= 0.0 { lo } else { lo - pad }, hi + pad)
}

/// Draw `fig` to a PNG at `path`.
pub fn draw(path: &Path, fig: &Figure) -> Result<()> {
    register_font(path)?;
    let all = || {
        fig.series
            .iter()
            .flat_map(|s| s.points.iter())
            .chain(fig.markers.iter().flat_map(|m| m.points.iter()))
    };
    let (x0, x1) = range(all().map(|p| p.0), false);
    let (y0, y1) = range(all().map(|p| p.1), true);
    let root = BitMapBackend::new(path, (1100, 760)).into_drawing_area();
    let err = |e: &dyn std::fmt::Display| AppError::Figure {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(fig.title, ("sans-serif", 26))
        .margin(18)
        .x_label_area_size(58)
        .y_label_area_size(78)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(fig.x_label)
        .y_desc(fig.y_label)
        .axis_desc_style(("sans-serif", 22))
        .label_style(("sans-serif", 17))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(|e| err(&e))?;
    for s in &fig.series {
        let style = s.color.stroke_width(3);
        let anno = if s.dashed {
            chart
                .draw_series(DashedLineSeries::new(
                    s.points.iter().copied(),
                    12,
                    7,
                    style,
                ))
                .map_err(|e| err(&e))?
        } else {
            chart
                .draw_series(LineSeries::new(s.points.iter().copied(), style))
                .map_err(|e| err(&e))?
        };
        let c = s.color;
        let dashed = s.dashed;
        anno.label(s.label.clone()).legend(move |(x, y)| {
            if dashed {
                PathElement::new(vec![(x, y), (x + 9, y)], c.stroke_width(3))
            } else {
                PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3))
            }
        });
    }
    for m in &fig.markers {
        let c = m.color;
        chart
            .draw_series(m.points.iter().map(|&p| Circle::new(p, 6, c.filled())))
            .map_err(|e| err(&e))?
            .label(m.label.clone())
            .legend(move |(x, y)| Circle::new((x + 12, y), 6, c.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(("sans-serif", 18))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// FE points read from a `tubemem run` folder.
#[derive(Default)]
struct RunPoints {
    label: String,
    /// (λs, ϖ) of inflation steps
    inflation: Vec<(f64, f64)>,
    /// (λs, ϖ, displacement, force, λs*) of squeeze steps
    squeeze: Vec<(f64, f64, f64, f64, f64)>,
}

fn read_run(dir: &Path) -> Result<RunPoints> {
    let path = dir.join("steps.csv");
    let overlay = |message: String| AppError::Overlay {
        path: path.clone(),
        message,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| {
        overlay(format!(
            "cannot read it ({e}): is this a tubemem run folder?"
        ))
    })?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| overlay(format!("no column `{name}`")))
    };
    let (cw, cls, crho, cdisp, cforce) = (
        col("w")?,
        col("lambda_s")?,
        col("rho")?,
        col("displacement")?,
        col("force")?,
    );
    let mut pts = RunPoints {
        label: dir
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default(),
        ..Default::default()
    };
    for (k, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| -> Result<f64> {
            f.get(i)
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| overlay(format!("row {}: column {i} is not a finite number", k + 2)))
        };
        if f.get(crho).is_some_and(|v| !v.is_empty()) {
            let (ls, w, rho, d, force) =
                (num(cls)?, num(cw)?, num(crho)?, num(cdisp)?, num(cforce)?);
            pts.squeeze.push((ls, w, d, force, d + rho));
        } else {
            pts.inflation.push((num(cls)?, num(cw)?));
        }
    }
    Ok(pts)
}

const FE_COLORS: [RGBColor; 3] = [
    RGBColor(20, 140, 60),
    RGBColor(150, 60, 170),
    RGBColor(230, 130, 0),
];

/// Compute the curves and write every CSV and PNG into `dir`, with the FE points of the run
/// folders in `overlays` on Figs. 5–7; returns the files written.
pub fn write_all(dir: &Path, kuhn: f64, overlays: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let runs: Vec<RunPoints> = overlays
        .iter()
        .map(|d| read_run(d))
        .collect::<Result<_>>()?;
    std::fs::create_dir_all(dir).map_err(|e| AppError::io(dir, e))?;
    let law = AnssariBenamBucchi::new(1.0, kuhn)?;
    let mut written = vec![];
    let hyps = [(Hypothesis::Gps, GPS_COLOR), (Hypothesis::Ps, PS_COLOR)];
    let starts = [1.3, 6.0];

    let mut inflation = vec![];
    for (h, _) in hyps {
        let c = inflation_curve(&law, h, 1.0, 7.5, 651)
            .map_err(|e| AppError::gps("the inflation curve", e))?;
        let p = dir.join(format!("inflation_{}.csv", h.label().to_lowercase()));
        write_csv(&p, INFLATION_HEADER, c.iter().map(inflation_values))?;
        written.push(p);
        inflation.push(c);
    }
    // flattening[start][hyp]
    let mut flattening = vec![];
    for ls0 in starts {
        let mut per = vec![];
        for (h, _) in hyps {
            let c = flattening_curve(&law, h, ls0, 0.5 * ls0, 201)
                .map_err(|e| AppError::gps("the flattening curve", e))?;
            let p = dir.join(format!(
                "flattening_ls{ls0:.1}_{}.csv",
                h.label().to_lowercase()
            ));
            write_csv(&p, FLATTENING_HEADER, c.iter().map(flattening_values))?;
            written.push(p);
            per.push(c);
        }
        flattening.push(per);
    }
    let limits =
        limit_points(&law, Hypothesis::Gps).map_err(|e| AppError::gps("the limit points", e))?;

    // Fig. 5
    let mut series = vec![];
    for ((h, color), c) in hyps.iter().zip(&inflation) {
        series.push(Series {
            label: format!("{} inflation", h.label()),
            points: c.iter().map(|s| (s.lambda_s, s.w)).collect(),
            color: *color,
            dashed: false,
        });
    }
    for (ls0, per) in starts.iter().zip(&flattening) {
        for ((h, color), c) in hyps.iter().zip(per) {
            series.push(Series {
                label: format!("{} flattening from λs* = {ls0}", h.label()),
                points: c.iter().map(|s| (s.lambda_s, s.w)).collect(),
                color: *color,
                dashed: true,
            });
        }
    }
    let mut markers = vec![];
    let lp: Vec<(f64, f64)> = [limits.max, limits.min]
        .into_iter()
        .flatten()
        .map(|p| (p.lambda_s, p.w))
        .collect();
    if !lp.is_empty() {
        markers.push(Markers {
            label: "GPS limit points".into(),
            points: lp,
            color: BLACK,
        });
    }
    if let Some(m) = limits.maxwell {
        series.push(Series {
            label: format!("GPS Maxwell pressure ϖ = {:.4}", m.w),
            points: vec![(m.lambda_s_lower, m.w), (m.lambda_s_upper, m.w)],
            color: RGBColor(90, 90, 90),
            dashed: true,
        });
    }
    for (run, color) in runs.iter().zip(FE_COLORS.iter().cycle()) {
        let mut pts = run.inflation.clone();
        pts.extend(run.squeeze.iter().map(|s| (s.0, s.1)));
        if !pts.is_empty() {
            markers.push(Markers {
                label: format!("FE run `{}`", run.label),
                points: pts,
                color: *color,
            });
        }
    }
    let title5 = format!("Fig. 5 — reduced pressure vs hoop stretch (ABB, Kuhn N = {kuhn})");
    let p = dir.join("fig5_pressure_stretch.png");
    draw(
        &p,
        &Figure {
            title: &title5,
            x_label: "hoop stretch λs",
            y_label: "reduced pressure ϖ = pR/(μH)",
            series,
            markers,
        },
    )?;
    written.push(p);

    // Figs. 6 and 7
    for ((ls0, per), num) in starts.iter().zip(&flattening).zip([6, 7]) {
        let series = hyps
            .iter()
            .zip(per)
            .map(|((h, color), c)| Series {
                label: h.label().to_string(),
                points: c.iter().map(|s| (s.displacement, s.force)).collect(),
                color: *color,
                dashed: false,
            })
            .collect();
        let mut markers = vec![];
        for (run, color) in runs.iter().zip(FE_COLORS.iter().cycle()) {
            // squeeze steps that start from (about) this λs*
            let pts: Vec<(f64, f64)> = run
                .squeeze
                .iter()
                .filter(|s| (s.4 - ls0).abs() < 0.05 * ls0)
                .map(|s| (s.2, s.3))
                .collect();
            if !pts.is_empty() {
                markers.push(Markers {
                    label: format!("FE run `{}`", run.label),
                    points: pts,
                    color: *color,
                });
            }
        }
        let title = format!("Fig. {num} — flattening from λs* = {ls0} (ABB, Kuhn N = {kuhn})");
        let p = dir.join(format!("fig{num}_force_displacement_ls{ls0:.1}.png"));
        draw(
            &p,
            &Figure {
                title: &title,
                x_label: "reduced displacement λs* − ρ",
                y_label: "reduced force ϖχ = pc/(πμH)",
                series,
                markers,
            },
        )?;
        written.push(p);
    }

    // λz versus λs
    let mut series = vec![Series {
        label: "GPS inflation".into(),
        points: inflation[0]
            .iter()
            .map(|s| (s.lambda_s, s.lambda_z))
            .collect(),
        color: GPS_COLOR,
        dashed: false,
    }];
    for (ls0, per) in starts.iter().zip(&flattening) {
        series.push(Series {
            label: format!("GPS flattening from λs* = {ls0}"),
            points: per[0].iter().map(|s| (s.lambda_s, s.lambda_z)).collect(),
            color: RGBColor(20, 150, 90),
            dashed: true,
        });
    }
    series.push(Series {
        label: "PS (λz = 1)".into(),
        points: vec![(1.0, 1.0), (7.5, 1.0)],
        color: PS_COLOR,
        dashed: false,
    });
    let title = format!("Axial stretch vs hoop stretch (ABB, Kuhn N = {kuhn})");
    let p = dir.join("fig_lambda_z.png");
    draw(
        &p,
        &Figure {
            title: &title,
            x_label: "hoop stretch λs",
            y_label: "axial stretch λz",
            series,
            markers: vec![],
        },
    )?;
    written.push(p);
    Ok(written)
}
