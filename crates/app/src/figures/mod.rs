//! Reproductions of the paper's Figs. 5–7, plus λz versus λs, for any membrane law, as SVG and
//! anti-aliased PNG, with their data as CSV.
//!
//! Fig. 5: ϖ versus λs, GPS and PS inflation (solid) and the flattening branches from
//! λs* = 1.3 (dashed) and 6.0 (dotted), with the GPS limit points and Maxwell pressure marked.
//! Figs. 6 and 7: reduced force ϖχ versus reduced displacement λs* − ρ (eqs. 80–81) for
//! λs* = 1.3 and 6.0; with FE runs overlaid, an error panel (FE − GPS at the same ρ, from the
//! run's own λs*) sits under the curves. The flattening runs to ρ = λs*/2.
//!
//! Rendering: plotters draws each figure once as SVG (its SVG backend); resvg rasterizes that
//! SVG into the PNG, anti-aliased, at the requested DPI (plotters' own bitmap backend draws
//! aliased lines). Text uses the bundled DejaVu Sans in both, so no system font is needed.
//!
//! FE points come from [`Overlay`]s: a run's typed report ([`Overlay::from_report`], the main
//! job) or a `tubemem run` folder ([`Overlay::read`], `tubemem figures --overlay`). An overlay of
//! another law than the curves' is refused.

//!
//! | module | what |
//! |---|---|
//! | this one | the figure model: [`Figure`], its series, markers, panel and legend |
//! | [`render`] | SVG and PNG |
//! | [`overlay`] | the FE points of runs |
//! | [`paper`] | Figs. 5-7 and λz against λs ([`write_all`]) |
//! | [`mode`] | a critical mode along the tube |
//! | [`loops`] | the force–gap loops of a viscoelastic tube at several plate speeds |

pub mod loops;
pub mod mode;
pub mod overlay;
pub mod paper;
pub mod render;

pub use loops::{loops_figure, Loop, LOOPS_TITLE};
pub use mode::mode_figure;
pub use overlay::{law_label, same_law, Overlay, SqueezePoint, PAPER_LAW};
pub use paper::write_all;
pub use render::save;
pub(crate) use render::{rasterize, render_files, render_svg};

use crate::{AppError, Result};
use plotters::prelude::*;
use std::path::PathBuf;

const GPS_COLOR: RGBColor = RGBColor(31, 90, 180);
const PS_COLOR: RGBColor = RGBColor(200, 50, 40);
const GREY: RGBColor = RGBColor(90, 90, 90);
const FE_COLORS: [RGBColor; 3] = [
    RGBColor(20, 140, 60),
    RGBColor(150, 60, 170),
    RGBColor(230, 130, 0),
];

/// The colours of a figure's numbered series (the verify kinds' and the atlas's curves).
const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 90, 180),
    RGBColor(200, 50, 40),
    RGBColor(20, 140, 60),
    RGBColor(150, 60, 170),
    RGBColor(230, 130, 0),
    RGBColor(90, 90, 90),
    RGBColor(0, 150, 160),
    RGBColor(160, 110, 40),
];

/// The colour of a figure's `k`-th series: the eight-colour palette, cycled.
pub fn series_color(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

/// The figure canvas in pixels at [`BASE_DPI`].
pub const CANVAS: (u32, u32) = (1100, 760);
/// The DPI at which the PNG is [`CANVAS`] pixels.
pub const BASE_DPI: f64 = 100.0;

/// Which files a figure is written as.
#[derive(Clone, Debug)]
pub struct FigureOptions {
    pub png: bool,
    pub svg: bool,
    /// PNG resolution; the canvas is 11 × 7.6 in
    pub dpi: f64,
}

impl Default for FigureOptions {
    fn default() -> Self {
        Self {
            png: true,
            svg: true,
            dpi: BASE_DPI,
        }
    }
}

impl FigureOptions {
    fn check(&self) -> Result<()> {
        if !(self.png || self.svg) {
            return Err(AppError::Figure {
                path: PathBuf::new(),
                message: "no figure format chosen (PNG, SVG or both)".into(),
            });
        }
        // 25 dpi is a 275-pixel-wide thumbnail; 1200 dpi is 13200 × 9120 pixels (480 MB RGBA)
        if !(25.0..=1200.0).contains(&self.dpi) {
            return Err(AppError::Figure {
                path: PathBuf::new(),
                message: format!("dpi = {} is outside 25–1200", self.dpi),
            });
        }
        Ok(())
    }
}

/// How a curve is stroked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stroke {
    Solid,
    Dashed,
    Dotted,
}

/// One curve of a figure.
#[derive(Clone)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub color: RGBColor,
    pub stroke: Stroke,
    pub width: u32,
}

/// Isolated markers with a legend entry; hollow markers leave the curves under them visible.
#[derive(Clone)]
pub struct Markers {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub color: RGBColor,
    pub hollow: bool,
}

/// A panel under the main plot (shared x axis), e.g. FE − GPS.
pub struct Panel {
    pub y_label: String,
    pub series: Vec<Series>,
    pub markers: Vec<Markers>,
}

pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub markers: Vec<Markers>,
    pub panel: Option<Panel>,
    /// lines of text printed under the title
    pub notes: Vec<String>,
    /// one unit of x as long as one unit of y (a cross-section), without a panel
    pub equal_aspect: bool,
    /// the y axis starts at 0 (or below)
    pub y_from_zero: bool,
}

impl Figure {
    /// A plain figure of curves: no markers, panel or notes, the y axis from zero.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
        series: Vec<Series>,
    ) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series,
            markers: vec![],
            panel: None,
            notes: vec![],
            equal_aspect: false,
            y_from_zero: true,
        }
    }
}

fn range(values: impl Iterator<Item = f64>, from_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    if from_zero {
        lo = lo.min(0.0);
    }
    let pad = 0.04 * (hi - lo).max(1e-12);
    (if from_zero && lo >= 0.0 { lo } else { lo - pad }, hi + pad)
}

/// The share of the plot's width and, per legend line, of its height that a legend covers:
/// estimates on the safe side, not measured (on the 1100 × 760 canvas a 16-pixel legend line
/// takes roughly 20 of the plot's ~630 pixels, 0.03; a swatch and a label of 40 characters
/// about a third of its width), so a point near the legend counts as under it.
const LEGEND_WIDTH: f64 = 0.5;
const LEGEND_LINE: f64 = 0.045;

/// The axes' ranges of the figure's top panel: every point of its curves and markers inside,
/// with a margin.
pub fn axes(fig: &Figure) -> ((f64, f64), (f64, f64)) {
    let all = || {
        fig.series
            .iter()
            .flat_map(|s| s.points.iter())
            .chain(fig.markers.iter().flat_map(|m| m.points.iter()))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
    };
    let x = range(all().map(|p| p.0), false);
    let mut y = range(all().map(|p| p.1), fig.y_from_zero);
    // where every corner holds a marker (an atlas's grid spans the whole plot), room above the
    // data for the legend: the y range grows by the legend's height, so the upper corners are
    // free of markers and the legend hides none
    let size = legend_size(fig);
    let unit = |p: &(f64, f64)| ((p.0 - x.0) / (x.1 - x.0), (p.1 - y.0) / (y.1 - y.0));
    let marks: Vec<(f64, f64)> = fig
        .markers
        .iter()
        .flat_map(|m| m.points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .map(unit)
        .collect();
    let blocked = [(true, true), (false, true), (true, false), (false, false)]
        .iter()
        .all(|&(l, u)| marks.iter().any(|m| under_legend(m.0, m.1, l, u, size)));
    if blocked && y.1 > y.0 {
        y.1 = y.0 + (y.1 - y.0) / (1.0 - (size.1 + 0.02)).max(0.1);
    }
    (x, y)
}

/// What a figure shows, for tests of the plots: its points (curve and marker points), those not
/// drawn inside its axes (not finite), and the marker points under its legend.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FigureAudit {
    pub points: usize,
    pub outside: usize,
    pub under_legend: usize,
    /// curves of a single point, which draw nothing
    pub lone_points: usize,
}

/// The share of the plot's width and height that the legend of `fig` covers.
fn legend_size(fig: &Figure) -> (f64, f64) {
    let lines = fig.series.len() + fig.markers.len();
    (LEGEND_WIDTH, (LEGEND_LINE * lines as f64 + 0.03).min(0.9))
}

/// Whether the point (u, v) of the unit plot square lies under a legend of `size` in the
/// corner (`left`, `upper`).
fn under_legend(u: f64, v: f64, left: bool, upper: bool, size: (f64, f64)) -> bool {
    let (w, h) = size;
    (if left { u <= w } else { u >= 1.0 - w }) && (if upper { v >= 1.0 - h } else { v <= h })
}

/// The [`FigureAudit`] of the top panel of `fig` as [`render_svg`] draws it.
pub(crate) fn audit(fig: &Figure) -> FigureAudit {
    let (x, y) = axes(fig);
    let all: Vec<(f64, f64)> = fig
        .series
        .iter()
        .flat_map(|s| s.points.iter())
        .chain(fig.markers.iter().flat_map(|m| m.points.iter()))
        .copied()
        .collect();
    let inside = |p: &(f64, f64)| (x.0..=x.1).contains(&p.0) && (y.0..=y.1).contains(&p.1);
    let size = legend_size(fig);
    let (left, upper) = match legend_corner(fig, x, y) {
        SeriesLabelPosition::UpperRight => (false, true),
        SeriesLabelPosition::LowerLeft => (true, false),
        SeriesLabelPosition::LowerRight => (false, false),
        _ => (true, true),
    };
    let under = |p: &&(f64, f64)| {
        let (u, v) = ((p.0 - x.0) / (x.1 - x.0), (p.1 - y.0) / (y.1 - y.0));
        under_legend(u, v, left, upper, size)
    };
    FigureAudit {
        points: all
            .iter()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .count(),
        outside: all.iter().filter(|p| !inside(p)).count(),
        under_legend: fig
            .markers
            .iter()
            .flat_map(|m| m.points.iter())
            .filter(under)
            .count(),
        lone_points: fig.series.iter().filter(|s| s.points.len() == 1).count(),
    }
}

/// The weight of a marker against a curve's sample in [`legend_corner`]: a marker hidden is a
/// datum (an FE point, an atlas grid point) lost, a curve's sample a short stretch of a line
/// whose course the rest shows, so one marker outweighs any curve's samples in a corner.
const MARKER_WEIGHT: usize = 100_000;

/// The corner of the plot where the legend covers the least: markers first (each outweighs any
/// number of curve samples, [`MARKER_WEIGHT`]), then curve points (a curve's segments sampled
/// between its points); the upper left on a tie.
pub(crate) fn legend_corner(fig: &Figure, x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    let size = legend_size(fig);
    let unit = |p: (f64, f64)| ((p.0 - x.0) / (x.1 - x.0), (p.1 - y.0) / (y.1 - y.0));
    let marks: Vec<(f64, f64)> = fig
        .markers
        .iter()
        .flat_map(|m| m.points.iter().map(|&p| unit(p)))
        .collect();
    let mut pts: Vec<(f64, f64)> = vec![];
    for s in &fig.series {
        for seg in s.points.windows(2) {
            let (a, b) = (unit(seg[0]), unit(seg[1]));
            pts.extend((0..8).map(|k| {
                let t = k as f64 / 8.0;
                (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
            }));
        }
        if let Some(&p) = s.points.last() {
            pts.push(unit(p));
        }
    }
    let covered = |left: bool, upper: bool| {
        let hidden = |v: &[(f64, f64)]| {
            v.iter()
                .filter(|(u, w)| under_legend(*u, *w, left, upper, size))
                .count()
        };
        MARKER_WEIGHT * hidden(&marks) + hidden(&pts)
    };
    [
        (SeriesLabelPosition::UpperLeft, true, true),
        (SeriesLabelPosition::UpperRight, false, true),
        (SeriesLabelPosition::LowerLeft, true, false),
        (SeriesLabelPosition::LowerRight, false, false),
    ]
    .into_iter()
    .min_by_key(|(_, left, upper)| covered(*left, *upper))
    .map_or(SeriesLabelPosition::UpperLeft, |c| c.0)
}

#[cfg(test)]
mod legend_tests {
    use super::*;

    /// Issue #60 item 9: an atlas map's grid fills the plot to its corners, so the legend hid
    /// the grid point in whichever corner it took ((1.3, 0.8) on the CI atlas). The y range
    /// now grows by the legend's height there, and no marker lies under it.
    #[test]
    fn a_legend_hides_no_marker_when_markers_fill_every_corner() {
        let grid: Vec<(f64, f64)> = [1.2, 1.3]
            .iter()
            .flat_map(|&x| [0.8, 0.9, 1.0, 1.1].map(|y| (x, y)))
            .collect();
        let mut fig = Figure::new(
            "minimum L/R",
            "λs*",
            "ρ",
            vec![Series {
                label: "L/R = 200".into(),
                points: vec![(1.2, 0.93), (1.22, 1.1)],
                color: series_color(0),
                stroke: Stroke::Solid,
                width: 2,
            }],
        );
        // an atlas map's axes start at the grid's range, not at zero
        fig.y_from_zero = false;
        fig.markers = vec![Markers {
            label: "grid point".into(),
            points: grid,
            color: plotters::style::RGBColor(0, 0, 0),
            hollow: false,
        }];
        let a = audit(&fig);
        assert_eq!((a.under_legend, a.outside), (0, 0), "{a:?}");
        let (_, grown) = axes(&fig);
        // a plot with a free corner keeps its range (the legend goes there)
        fig.markers[0].points.retain(|p| *p != (1.3, 1.1));
        let (_, kept) = axes(&fig);
        assert!(grown.1 > kept.1, "{grown:?} against {kept:?}");
        assert_eq!(audit(&fig).under_legend, 0);
    }
}
