//! The paper's figures for one law: Figs. 5-7 and λz against λs, with their CSVs, and the FE
//! points of overlaid runs.

use super::overlay::{points_file, same_start, start_tag, PointSupply};
use super::{
    law_label, render_files, same_law, Figure, FigureOptions, Markers, Overlay, Panel, Series,
    SqueezePoint, Stroke, FE_COLORS, GPS_COLOR, GREY, PAPER_LAW, PS_COLOR,
};
use crate::curves::{
    csv_text, flattening_values, inflation_values, FLATTENING_HEADER, INFLATION_HEADER,
};
use crate::{AppError, Result};
use plotters::style::{RGBColor, BLACK};
use std::path::{Path, PathBuf};
use tubemem_gps::limits::limit_points;
use tubemem_gps::regulated::regulated_curve_until;
use tubemem_gps::{flattening_curve, inflation_curve, FlatteningState, Hypothesis};
use tubemem_material::MaterialSpec;

/// The closed-form curves of one law: GPS and PS inflation, the flattening from each start
/// λs*, and the GPS limit points.
struct Curves {
    /// the paper's two starts (Figs. 6 and 7), then each overlaid squeeze's own λs* (Figs.
    /// 8, …), each with its line style: a run is drawn against the curves from where it starts,
    /// never against another start's
    starts: Vec<(f64, Stroke)>,
    /// inflation[hyp]
    inflation: Vec<Vec<tubemem_gps::InflationState>>,
    /// flattening[start][hyp]
    flattening: Vec<Vec<Vec<FlatteningState>>>,
    /// regulated[start][hyp]: the squeeze with the pressure held at ϖ(λs*), up to where the
    /// path stops (a pressure-controlled section that snaps), and why it stopped
    regulated: Vec<Vec<(Vec<FlatteningState>, Option<String>)>>,
    limits: tubemem_gps::limits::Limits,
}

/// The two hypotheses and their colours.
const HYPS: [(Hypothesis, RGBColor); 2] =
    [(Hypothesis::Gps, GPS_COLOR), (Hypothesis::Ps, PS_COLOR)];

impl Curves {
    /// The curves of `law`, and their CSV files in `dir` appended to `files`.
    fn compute(
        law: &dyn tubemem_material::MembraneLaw,
        overlays: &[Overlay],
        dir: &Path,
        files: &mut Vec<(PathBuf, Vec<u8>)>,
    ) -> Result<Self> {
        let mut starts = vec![(1.3, Stroke::Dashed), (6.0, Stroke::Dotted)];
        for o in overlays {
            for p in &o.squeeze {
                let l = p.start();
                if l.is_finite() && !starts.iter().any(|(x, _)| same_start(l, *x)) {
                    starts.push((l, Stroke::Dashed));
                }
            }
        }
        let mut inflation = vec![];
        for (h, _) in HYPS {
            let c = inflation_curve(law, h, 1.0, 7.5, 651)
                .map_err(|e| AppError::gps("the inflation curve", e))?;
            let p = dir.join(format!("inflation_{}.csv", h.label().to_lowercase()));
            let text = csv_text(&p, INFLATION_HEADER, c.iter().map(inflation_values))?;
            files.push((p, text.into_bytes()));
            inflation.push(c);
        }
        let mut flattening = vec![];
        for &(ls0, _) in &starts {
            let mut per = vec![];
            for (h, _) in HYPS {
                let c = flattening_curve(law, h, ls0, 0.5 * ls0, 201).map_err(|e| {
                    AppError::gps(format!("the flattening curve from λs* = {ls0}"), e)
                })?;
                flattening_csv(dir, ls0, h, "", &c, files)?;
                per.push(c);
            }
            flattening.push(per);
        }
        let mut regulated = vec![];
        for &(ls0, _) in &starts {
            let mut per = vec![];
            for (h, _) in HYPS {
                let (c, stop) =
                    regulated_curve_until(law, h, ls0, 0.5 * ls0, 201, None).map_err(|e| {
                        AppError::gps(format!("the pressure-held squeeze from λs* = {ls0}"), e)
                    })?;
                let c: Vec<FlatteningState> = c.iter().map(|s| s.as_flattening(ls0)).collect();
                flattening_csv(dir, ls0, h, "_pressure_held", &c, files)?;
                let stop = stop.map(|_| {
                    let last = c.last().map_or(ls0, |s| s.rho);
                    format!(
                        "{}: the pressure-held section snaps after ρ = {} (its pressure slope changes sign: tubemem gps flatten --control pressure says where)",
                        h.label(),
                        tubemem_material::Num(crate::units::round_sig(last))
                    )
                });
                per.push((c, stop));
            }
            regulated.push(per);
        }
        let limits =
            limit_points(law, Hypothesis::Gps).map_err(|e| AppError::gps("the limit points", e))?;
        Ok(Curves {
            starts,
            inflation,
            flattening,
            regulated,
            limits,
        })
    }
}

/// The CSV of a flattening curve from λs* = `ls0` under `h`, as
/// `flattening_ls<λs*>_<hyp><suffix>.csv` in `dir`, appended to `files`.
fn flattening_csv(
    dir: &Path,
    ls0: f64,
    h: Hypothesis,
    suffix: &str,
    curve: &[FlatteningState],
    files: &mut Vec<(PathBuf, Vec<u8>)>,
) -> Result<()> {
    let p = dir.join(format!(
        "flattening_ls{}_{}{suffix}.csv",
        start_tag(ls0),
        h.label().to_lowercase()
    ));
    let text = csv_text(&p, FLATTENING_HEADER, curve.iter().map(flattening_values))?;
    files.push((p, text.into_bytes()));
    Ok(())
}

/// How the figures' axes are drawn: dimensionless, or in the overlays' `[units]` when they
/// all have the same (pressures in kPa, forces per length in N/m and plate approaches in mm on
/// Figs. 5–8; the CSVs stay dimensionless).
#[derive(Clone, Copy)]
struct Axes(Option<tubemem_gps::Scales>);

impl Axes {
    fn of(overlays: &[Overlay]) -> Self {
        Axes(
            overlays
                .first()
                .and_then(|o| o.scales)
                .filter(|s| overlays.iter().all(|o| o.scales == Some(*s))),
        )
    }
    fn pressure(self, f: Figure) -> Figure {
        match self.0 {
            Some(s) => scaled(
                f,
                1.0,
                s.pressure(1.0) / 1e3,
                None,
                "pressure p = ϖμH/R (kPa)",
            ),
            None => f,
        }
    }
    fn force(self, f: Figure) -> Figure {
        match self.0 {
            Some(s) => scaled(
                f,
                2.0 * s.radius * 1e3,
                s.force_per_length(1.0),
                Some("plate approach 2R(λs* − ρ) (mm)"),
                "plate force per length (N/m)",
            ),
            None => f,
        }
    }
}

/// Compute the curves of `law` (or, when `None`, of the overlays' law, else the paper's) and
/// write every CSV and figure into `dir`, with the FE points of `overlays` on Figs. 5–7; returns
/// the files written. An overlay of another law is refused.
pub fn write_all(
    dir: &Path,
    law: Option<MaterialSpec>,
    overlays: &[Overlay],
    opts: &FigureOptions,
) -> Result<Vec<PathBuf>> {
    opts.check()?;
    let spec = law
        .or_else(|| overlays.first().map(|o| o.material.clone()))
        .unwrap_or(PAPER_LAW);
    for o in overlays {
        if !same_law(&o.material, &spec) {
            return Err(AppError::Overlay {
                path: o.source.clone(),
                message: format!(
                    "the run is {}, the curves are {}: its points do not belong on them (leave the material out to take it from the run)",
                    law_label(&o.material),
                    law_label(&spec)
                ),
            });
        }
    }
    let built = spec.build()?;
    let name = law_label(&spec);
    let axes = Axes::of(overlays);
    // every file rendered first; the folder is checked and written only once all are
    let mut files: Vec<(PathBuf, Vec<u8>)> = vec![];
    let curves = Curves::compute(built.as_ref(), overlays, dir, &mut files)?;
    for (k, o) in overlays.iter().enumerate() {
        files.push(points_file(dir, k, o));
    }
    let (fig5, zoom) = pressure_figures(&curves, overlays, &name);
    files.extend(render_files(
        &axes.pressure(fig5),
        &dir.join("fig5_pressure_stretch"),
        opts,
    )?);
    files.extend(render_files(
        &axes.pressure(zoom),
        &dir.join("fig5_zoom_ls1.3"),
        opts,
    )?);
    for (k, ((ls0, _), per)) in curves.starts.iter().zip(&curves.flattening).enumerate() {
        let num = 6 + k;
        let fig = force_figure(*ls0, per, num, overlays, &name);
        files.extend(render_files(
            &axes.force(fig),
            &dir.join(format!("fig{num}_force_displacement_ls{}", start_tag(*ls0))),
            opts,
        )?);
        let held = held_force_figure(*ls0, &curves.regulated[k], per, num, overlays, &name);
        files.extend(render_files(
            &axes.force(held),
            &dir.join(format!(
                "fig{num}_force_displacement_ls{}_pressure_held",
                start_tag(*ls0)
            )),
            opts,
        )?);
    }
    files.extend(render_files(
        &lambda_z_figure(&curves, &name),
        &dir.join("fig_lambda_z"),
        opts,
    )?);
    crate::output_file::create_folder(dir)?;
    crate::output_file::write_owned(dir, FIGURES_MANIFEST, "tubemem figures", &files)
}

/// Fig. 5 (ϖ against λs: inflation, every flattening branch, the limit points, the Maxwell
/// pressure and the overlays' points) and its zoom on the branches from λs* = 1.3.
fn pressure_figures(c: &Curves, overlays: &[Overlay], name: &str) -> (Figure, Figure) {
    let mut series = vec![];
    for ((h, color), curve) in HYPS.iter().zip(&c.inflation) {
        series.push(Series {
            label: format!("{} inflation", h.label()),
            points: curve.iter().map(|s| (s.lambda_s, s.w)).collect(),
            color: *color,
            stroke: Stroke::Solid,
            width: 3,
        });
    }
    for ((ls0, stroke), per) in c.starts.iter().zip(&c.flattening) {
        for ((h, color), curve) in HYPS.iter().zip(per) {
            series.push(Series {
                label: format!("{} flattening from λs* = {}", h.label(), start_tag(*ls0)),
                points: curve.iter().map(|s| (s.lambda_s, s.w)).collect(),
                color: *color,
                stroke: *stroke,
                width: 3,
            });
        }
    }
    let mut markers = vec![];
    let lp: Vec<(f64, f64)> = [c.limits.max, c.limits.min]
        .into_iter()
        .flatten()
        .map(|p| (p.lambda_s, p.w))
        .collect();
    if !lp.is_empty() {
        markers.push(Markers {
            label: "GPS limit points".into(),
            points: lp,
            color: BLACK,
            hollow: false,
        });
    }
    if let Some(m) = c.limits.maxwell {
        series.push(Series {
            label: format!("GPS Maxwell pressure ϖ = {:.4}", m.w),
            points: vec![(m.lambda_s_lower, m.w), (m.lambda_s_upper, m.w)],
            color: GREY,
            stroke: Stroke::Dashed,
            width: 2,
        });
    }
    for (run, color) in overlays.iter().zip(FE_COLORS.iter().cycle()) {
        let mut pts = run.inflation.clone();
        pts.extend(run.squeeze.iter().map(|s| (s.lambda_s, s.w)));
        if !pts.is_empty() {
            markers.push(Markers {
                label: format!("FE: {}", run.label),
                points: pts,
                color: *color,
                hollow: true,
            });
        }
    }
    // the λs* = 1.3 branches are short on the whole curve: a zoom on them (every series and
    // marker clipped to the window around the branches)
    let (zx0, zx1, zy0, zy1) = {
        let pts = c.flattening[0].iter().flatten();
        let (mut x0, mut x1, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in pts {
            x0 = x0.min(p.lambda_s);
            x1 = x1.max(p.lambda_s);
            y1 = y1.max(p.w);
        }
        let pad = 0.15 * (x1 - x0).max(1e-3);
        (x0 - pad, x1 + pad, 0.0, y1 * 1.05)
    };
    let inside = |p: &(f64, f64)| p.0 >= zx0 && p.0 <= zx1 && p.1 >= zy0 && p.1 <= zy1;
    let zoom_series: Vec<Series> = series
        .iter()
        .map(|s| Series {
            points: s.points.iter().copied().filter(inside).collect(),
            ..s.clone()
        })
        .filter(|s| s.points.len() >= 2)
        .collect();
    let zoom_markers: Vec<Markers> = markers
        .iter()
        .map(|m| Markers {
            points: m.points.iter().copied().filter(inside).collect(),
            ..m.clone()
        })
        .filter(|m| !m.points.is_empty())
        .collect();
    let fig5 = Figure {
        markers,
        ..Figure::new(
            format!("Fig. 5 — pressure vs hoop stretch ({name})"),
            "hoop stretch λs",
            "reduced pressure ϖ = pR/(μH)",
            series,
        )
    };
    let zoom = Figure {
        markers: zoom_markers,
        y_from_zero: false,
        ..Figure::new(
            format!("Fig. 5, zoom on the flattening from λs* = 1.3 ({name})"),
            "hoop stretch λs",
            "reduced pressure ϖ = pR/(μH)",
            zoom_series,
        )
    };
    (fig5, zoom)
}

/// Fig. `num`: the reduced force against the reduced displacement from λs* = `ls0` (GPS and
/// PS curves `per`), with the overlays' squeeze steps from that start and, under it, their
/// error against GPS at the same ρ.
fn force_figure(
    ls0: f64,
    per: &[Vec<FlatteningState>],
    num: usize,
    overlays: &[Overlay],
    name: &str,
) -> Figure {
    let tag = start_tag(ls0);
    let series: Vec<Series> = HYPS
        .iter()
        .zip(per)
        .map(|((h, color), c)| Series {
            label: h.label().to_string(),
            points: c.iter().map(|s| (s.displacement, s.force)).collect(),
            color: *color,
            stroke: Stroke::Solid,
            width: 3,
        })
        .collect();
    let (markers, panel) = squeeze_markers(overlays, ls0, PointSupply::Closed, "FE − GPS, same ρ");
    Figure {
        markers,
        panel,
        notes: vec![],
        ..Figure::new(
            format!("Fig. {num} — flattening from λs* = {tag} ({name})"),
            "reduced displacement λs* − ρ",
            "reduced force ϖχ = pc/(πμH)",
            series,
        )
    }
}

/// The overlays' squeeze steps from λs* = `ls0` supplied as `supply`, as markers, and their
/// error against GPS at the same ρ as a panel under the curves (`y_label`; none without GPS).
fn squeeze_markers(
    overlays: &[Overlay],
    ls0: f64,
    supply: PointSupply,
    y_label: &str,
) -> (Vec<Markers>, Option<Panel>) {
    let mut markers = vec![];
    let mut errors = vec![];
    for (run, color) in overlays.iter().zip(FE_COLORS.iter().cycle()) {
        let pts: Vec<&SqueezePoint> = run
            .squeeze
            .iter()
            .filter(|s| same_start(s.start(), ls0) && s.supply == supply)
            .collect();
        if pts.is_empty() {
            continue;
        }
        let label = format!("FE: {}", run.label);
        markers.push(Markers {
            label: label.clone(),
            points: pts.iter().map(|s| (s.displacement, s.force)).collect(),
            color: *color,
            hollow: true,
        });
        let e: Vec<(f64, f64)> = pts
            .iter()
            .filter_map(|s| s.gps_force.map(|g| (s.displacement, s.force - g)))
            .collect();
        if !e.is_empty() {
            errors.push(Markers {
                label,
                points: e,
                color: *color,
                hollow: false,
            });
        }
    }
    let panel = (!errors.is_empty()).then(|| Panel {
        y_label: y_label.into(),
        series: vec![],
        markers: errors,
    });
    (markers, panel)
}

/// The pressure-held companion of Fig. `num`: the force against the displacement from λs* =
/// `ls0` with the pressure held at ϖ(λs*) (a regulated supply; GPS and PS, `held`, each up to
/// where it snaps), the closed gas's curves (`closed`) thin and dashed beside them, and the
/// overlays' regulated squeeze steps from that start with their error against GPS at the same
/// ρ and pressure.
fn held_force_figure(
    ls0: f64,
    held: &[(Vec<FlatteningState>, Option<String>)],
    closed: &[Vec<FlatteningState>],
    num: usize,
    overlays: &[Overlay],
    name: &str,
) -> Figure {
    let tag = start_tag(ls0);
    let mut series: Vec<Series> = HYPS
        .iter()
        .zip(held)
        .map(|((h, color), (c, _))| Series {
            label: format!("{}, pressure held", h.label()),
            points: c.iter().map(|s| (s.displacement, s.force)).collect(),
            color: *color,
            stroke: Stroke::Solid,
            width: 3,
        })
        .collect();
    series.extend(HYPS.iter().zip(closed).map(|((h, color), c)| Series {
        label: format!("{}, gas closed (Fig. {num})", h.label()),
        points: c.iter().map(|s| (s.displacement, s.force)).collect(),
        color: *color,
        stroke: Stroke::Dashed,
        width: 1,
    }));
    let (markers, panel) = squeeze_markers(
        overlays,
        ls0,
        PointSupply::Regulated,
        "FE − GPS, same ρ and ϖ",
    );
    Figure {
        markers,
        panel,
        notes: held.iter().filter_map(|(_, stop)| stop.clone()).collect(),
        ..Figure::new(
            format!("Fig. {num}, pressure held — flattening from λs* = {tag} with a regulated supply ({name})"),
            "reduced displacement λs* − ρ",
            "reduced force ϖχ = pc/(πμH)",
            series,
        )
    }
}

/// λz against λs: GPS inflation, the GPS flattening from each start, and PS's λz = 1.
fn lambda_z_figure(c: &Curves, name: &str) -> Figure {
    let mut series = vec![Series {
        label: "GPS inflation".into(),
        points: c.inflation[0]
            .iter()
            .map(|s| (s.lambda_s, s.lambda_z))
            .collect(),
        color: GPS_COLOR,
        stroke: Stroke::Solid,
        width: 3,
    }];
    for ((ls0, stroke), per) in c.starts.iter().zip(&c.flattening) {
        series.push(Series {
            label: format!("GPS flattening from λs* = {}", start_tag(*ls0)),
            points: per[0].iter().map(|s| (s.lambda_s, s.lambda_z)).collect(),
            color: RGBColor(20, 150, 90),
            stroke: *stroke,
            width: 3,
        });
    }
    series.push(Series {
        label: "PS (λz = 1)".into(),
        points: vec![(1.0, 1.0), (7.5, 1.0)],
        color: PS_COLOR,
        stroke: Stroke::Solid,
        width: 3,
    });
    Figure::new(
        format!("Axial stretch vs hoop stretch ({name})"),
        "hoop stretch λs",
        "axial stretch λz",
        series,
    )
}

/// `fig` with x and y (and its panel's y) multiplied by `sx`, `sy`, and its axes renamed: the
/// dimensional figures of runs with `[units]`.
pub(super) fn scaled(
    mut fig: Figure,
    sx: f64,
    sy: f64,
    x_label: Option<&str>,
    y_label: &str,
) -> Figure {
    let scale = |pts: &mut Vec<(f64, f64)>| {
        for p in pts.iter_mut() {
            *p = (p.0 * sx, p.1 * sy);
        }
    };
    for s in &mut fig.series {
        scale(&mut s.points);
    }
    for m in &mut fig.markers {
        scale(&mut m.points);
    }
    if let Some(panel) = &mut fig.panel {
        for s in &mut panel.series {
            scale(&mut s.points);
        }
        for m in &mut panel.markers {
            scale(&mut m.points);
        }
        panel.y_label = format!("{} (N/m)", panel.y_label);
    }
    if let Some(x) = x_label {
        fig.x_label = x.to_string();
    }
    fig.y_label = y_label.to_string();
    fig
}

/// The list of the files `tubemem figures` wrote into its folder, so that a later call replaces
/// those and refuses any other file of the same name.
pub(super) const FIGURES_MANIFEST: &str = ".tubemem-figures";
