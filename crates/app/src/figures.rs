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

use crate::curves::{
    csv_text, flattening_values, inflation_values, FLATTENING_HEADER, INFLATION_HEADER,
};
use crate::report::RunReport;
use crate::{AppError, Result};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Once};
use tubemem_gps::limits::limit_points;
use tubemem_gps::{flattening_curve, inflation_curve, FlatteningState, Hypothesis};
use tubemem_material::MaterialSpec;

static FONT: Once = Once::new();
const FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
const FONT_FAMILY: &str = "DejaVu Sans";

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
const GREY: RGBColor = RGBColor(90, 90, 90);
const FE_COLORS: [RGBColor; 3] = [
    RGBColor(20, 140, 60),
    RGBColor(150, 60, 170),
    RGBColor(230, 130, 0),
];

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
    (
        range(all().map(|p| p.0), false),
        range(all().map(|p| p.1), fig.y_from_zero),
    )
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
pub fn audit(fig: &Figure) -> FigureAudit {
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

/// The corner of the plot where the legend covers the fewest points (curve and marker points,
/// a curve's segments sampled between its points), the upper left on a tie.
pub fn legend_corner(fig: &Figure, x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    let size = legend_size(fig);
    let unit = |p: (f64, f64)| ((p.0 - x.0) / (x.1 - x.0), (p.1 - y.0) / (y.1 - y.0));
    let mut pts: Vec<(f64, f64)> = fig
        .markers
        .iter()
        .flat_map(|m| m.points.iter().map(|&p| unit(p)))
        .collect();
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
        pts.iter()
            .filter(|(u, v)| under_legend(*u, *v, left, upper, size))
            .count()
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

fn stroke_pattern(s: Stroke) -> Option<(u32, u32)> {
    match s {
        Stroke::Solid => None,
        Stroke::Dashed => Some((12, 7)),
        Stroke::Dotted => Some((3, 5)),
    }
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn draw_series<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    s: &Series,
    err: &dyn Fn(String) -> AppError,
) -> Result<()> {
    let style = s.color.stroke_width(s.width);
    let anno = match stroke_pattern(s.stroke) {
        Some((dash, gap)) => chart
            .draw_series(DashedLineSeries::new(
                s.points.iter().copied(),
                dash,
                gap,
                style,
            ))
            .map_err(|e| err(e.to_string()))?,
        None => chart
            .draw_series(LineSeries::new(s.points.iter().copied(), style))
            .map_err(|e| err(e.to_string()))?,
    };
    let pattern = stroke_pattern(s.stroke);
    anno.label(s.label.clone()).legend(move |(x, y)| {
        // the legend sample shows the stroke's own pattern over 30 pixels: four segments
        // (repeated where the pattern has fewer in that length)
        let (dash, gap) = pattern.unwrap_or((8, 0));
        let mut seg = vec![];
        let mut a = 0;
        while a < 30 && seg.len() < 4 {
            let b = (a + dash as i32).min(30);
            seg.push(vec![(x + a, y), (x + b, y)]);
            a = b + gap as i32;
        }
        while seg.len() < 4 {
            seg.push(seg[0].clone());
        }
        EmptyElement::at((0, 0))
            + PathElement::new(seg[0].clone(), style)
            + PathElement::new(seg[1].clone(), style)
            + PathElement::new(seg[2].clone(), style)
            + PathElement::new(seg[3].clone(), style)
    });
    Ok(())
}

fn draw_markers<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    m: &Markers,
    err: &dyn Fn(String) -> AppError,
) -> Result<()> {
    let c = m.color;
    let style = if m.hollow {
        c.stroke_width(2)
    } else {
        c.filled()
    };
    chart
        .draw_series(m.points.iter().map(|&p| Circle::new(p, 5, style)))
        .map_err(|e| err(e.to_string()))?
        .label(m.label.clone())
        .legend(move |(x, y)| Circle::new((x + 15, y), 5, style));
    Ok(())
}

/// The figure as an SVG document.
pub fn render_svg(fig: &Figure, path: &Path) -> Result<String> {
    register_font(path)?;
    let err = |message: String| AppError::Figure {
        path: path.to_path_buf(),
        message,
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, CANVAS).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        let root = root
            .titled(&fig.title, ("sans-serif", 26))
            .map_err(|e| err(e.to_string()))?;
        let (top, bottom) = match fig.panel {
            Some(_) => {
                let (t, b) = root.split_vertically(CANVAS.1 * 64 / 100);
                (t, Some(b))
            }
            None => (root, None),
        };
        let ((mut x0, mut x1), (mut y0, mut y1)) = axes(fig);
        if fig.equal_aspect {
            // the plot area's shape: the canvas less the label areas and margins
            let (w, h) = top.dim_in_pixel();
            let ratio =
                (w as f64 - 86.0 - 28.0) / (h as f64 - 58.0 - 28.0 - 20.0 * fig.notes.len() as f64);
            let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            let (mut hx, mut hy) = (0.5 * (x1 - x0), 0.5 * (y1 - y0));
            if hx / hy < ratio {
                hx = hy * ratio;
            } else {
                hy = hx / ratio;
            }
            (x0, x1, y0, y1) = (cx - hx, cx + hx, cy - hy, cy + hy);
        }
        // the notes go under the title, above the plot, where no curve can be under them
        let (w, _) = top.dim_in_pixel();
        for (k, note) in fig.notes.iter().enumerate() {
            top.draw(&Text::new(
                note.clone(),
                (w as i32 / 2, 2 + 20 * k as i32),
                ("sans-serif", 15)
                    .into_font()
                    .color(&RGBColor(60, 60, 60))
                    .pos(plotters::style::text_anchor::Pos::new(
                        plotters::style::text_anchor::HPos::Center,
                        plotters::style::text_anchor::VPos::Top,
                    )),
            ))
            .map_err(|e| err(e.to_string()))?;
        }
        let mut chart = ChartBuilder::on(&top)
            .margin(14)
            .margin_top(14 + 20 * fig.notes.len() as u32)
            .x_label_area_size(if bottom.is_some() { 30 } else { 58 })
            .y_label_area_size(86)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(e.to_string()))?;
        let mut mesh = chart.configure_mesh();
        mesh.y_desc(fig.y_label.as_str())
            .axis_desc_style(("sans-serif", 21))
            .label_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235));
        if bottom.is_none() {
            mesh.x_desc(fig.x_label.as_str());
        }
        mesh.draw().map_err(|e| err(e.to_string()))?;
        for m in &fig.markers {
            draw_markers(&mut chart, m, &err)?;
        }
        // curves over the markers: hollow FE markers never hide a branch
        for s in &fig.series {
            draw_series(&mut chart, s, &err)?;
        }
        chart
            .configure_series_labels()
            .position(legend_corner(fig, (x0, x1), (y0, y1)))
            .label_font(("sans-serif", 16))
            .background_style(WHITE.mix(0.92))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(e.to_string()))?;
        if let (Some(panel), Some(bottom)) = (&fig.panel, bottom) {
            let pts = || {
                panel
                    .series
                    .iter()
                    .flat_map(|s| s.points.iter())
                    .chain(panel.markers.iter().flat_map(|m| m.points.iter()))
            };
            let (py0, py1) = range(pts().map(|p| p.1), true);
            let (py0, py1) = (py0.min(-0.02 * py1.abs()), py1.max(0.02 * py0.abs()));
            let mut chart = ChartBuilder::on(&bottom)
                .margin(14)
                .x_label_area_size(58)
                .y_label_area_size(86)
                .build_cartesian_2d(x0..x1, py0..py1)
                .map_err(|e| err(e.to_string()))?;
            chart
                .configure_mesh()
                .x_desc(fig.x_label.as_str())
                .y_desc(panel.y_label.as_str())
                .axis_desc_style(("sans-serif", 19))
                .label_style(("sans-serif", 15))
                .y_label_formatter(&|v| {
                    // a tick at rounding distance from zero is zero
                    if v.abs() <= 1e-9 * py0.abs().max(py1.abs()) {
                        "0".to_string()
                    } else if v.abs() >= 1e-2 {
                        format!("{v:.3}")
                    } else {
                        format!("{v:.1e}")
                    }
                })
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(|e| err(e.to_string()))?;
            chart
                .draw_series(LineSeries::new(
                    [(x0, 0.0), (x1, 0.0)],
                    BLACK.stroke_width(1),
                ))
                .map_err(|e| err(e.to_string()))?;
            for m in &panel.markers {
                draw_markers(&mut chart, m, &err)?;
            }
            for s in &panel.series {
                draw_series(&mut chart, s, &err)?;
            }
        }
        top.present().map_err(|e| err(e.to_string()))?;
    }
    Ok(svg)
}

fn font_database() -> Arc<resvg::usvg::fontdb::Database> {
    static DB: std::sync::OnceLock<Arc<resvg::usvg::fontdb::Database>> = std::sync::OnceLock::new();
    DB.get_or_init(|| {
        let mut db = resvg::usvg::fontdb::Database::new();
        db.load_font_data(FONT_BYTES.to_vec());
        db.set_sans_serif_family(FONT_FAMILY);
        Arc::new(db)
    })
    .clone()
}

/// Rasterize an SVG document into PNG bytes at `dpi` (anti-aliased, resvg).
pub fn rasterize(svg: &str, dpi: f64, path: &Path) -> Result<Vec<u8>> {
    let err = |message: String| AppError::Figure {
        path: path.to_path_buf(),
        message,
    };
    let opt = resvg::usvg::Options {
        fontdb: font_database(),
        font_family: FONT_FAMILY.to_string(),
        ..Default::default()
    };
    let tree = resvg::usvg::Tree::from_str(svg, &opt).map_err(|e| err(e.to_string()))?;
    let scale = (dpi / BASE_DPI) as f32;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(scale)
        .ok_or_else(|| err(format!("dpi = {dpi} gives an empty image")))?;
    let mut pixmap =
        resvg::tiny_skia::Pixmap::new(size.width(), size.height()).ok_or_else(|| {
            err(format!(
                "cannot allocate a {}×{} image",
                size.width(),
                size.height()
            ))
        })?;
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    pixmap.encode_png().map_err(|e| err(e.to_string()))
}

/// Write `fig` as `<stem>.svg` and/or `<stem>.png`; returns the files written.
pub fn save(fig: &Figure, stem: &Path, opts: &FigureOptions) -> Result<Vec<PathBuf>> {
    let mut written = vec![];
    for (path, bytes) in render_files(fig, stem, opts)? {
        crate::output_file::write_whole(&path, &bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// The files [`save`] writes, rendered: (path, content).
pub fn render_files(
    fig: &Figure,
    stem: &Path,
    opts: &FigureOptions,
) -> Result<Vec<(PathBuf, Vec<u8>)>> {
    opts.check()?;
    // (not `with_extension`: a stem like `…_ls1.3` has a dot of its own)
    let with = |ext: &str| {
        let mut p = stem.as_os_str().to_owned();
        p.push(ext);
        PathBuf::from(p)
    };
    let (svg_path, png_path) = (with(".svg"), with(".png"));
    let svg = render_svg(fig, &svg_path)?;
    let png = if opts.png {
        Some(rasterize(&svg, opts.dpi, &png_path)?)
    } else {
        None
    };
    let mut files = vec![];
    if opts.svg {
        files.push((svg_path, svg.into_bytes()));
    }
    files.extend(png.map(|png| (png_path, png)));
    Ok(files)
}

/// One FE point of a squeeze step.
#[derive(Clone, Debug)]
pub struct SqueezePoint {
    pub lambda_s: f64,
    pub w: f64,
    pub rho: f64,
    pub displacement: f64,
    pub force: f64,
    /// the run's λs* (mid-span stretch when the squeeze started)
    pub initial_stretch: f64,
    /// GPS flattening from the run's λs* at the same ρ, when it has a solution
    pub gps_force: Option<f64>,
}

/// The FE points of one run to draw over the closed-form curves.
#[derive(Clone, Debug)]
pub struct Overlay {
    pub label: String,
    /// where it came from (the run folder), for messages
    pub source: PathBuf,
    pub material: MaterialSpec,
    /// the run's `[units]` scales (None: dimensionless)
    pub scales: Option<tubemem_gps::Scales>,
    /// (λs, ϖ) of the inflation steps
    pub inflation: Vec<(f64, f64)>,
    pub squeeze: Vec<SqueezePoint>,
}

impl Overlay {
    /// The points of a run's typed report.
    pub fn from_report(report: &RunReport, label: &str, source: &Path) -> Self {
        let mut o = Overlay {
            label: label.to_string(),
            source: source.to_path_buf(),
            material: report.material_spec,
            scales: report.scales,
            inflation: vec![],
            squeeze: vec![],
        };
        for s in report.steps() {
            match &s.contact {
                Some(c) => o.squeeze.push(SqueezePoint {
                    lambda_s: s.midspan.lambda_s,
                    w: s.midspan.w,
                    rho: c.values.rho,
                    displacement: c.displacement,
                    force: c.values.force,
                    initial_stretch: c.initial_stretch,
                    gps_force: s.closed_form.gps_flattening.as_ref().map(|g| g.force),
                }),
                None => o.inflation.push((s.midspan.lambda_s, s.midspan.w)),
            }
        }
        o
    }

    /// The points of a `tubemem run` folder: the law from summary.json, the steps from
    /// steps.csv.
    pub fn read(dir: &Path) -> Result<Self> {
        let summary_path = dir.join("summary.json");
        let overlay = |path: &Path, message: String| AppError::Overlay {
            path: path.to_path_buf(),
            message,
        };
        let text = std::fs::read_to_string(&summary_path).map_err(|e| {
            overlay(
                &summary_path,
                format!("cannot read it ({e}): is this a tubemem run folder?"),
            )
        })?;
        let summary: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| overlay(&summary_path, format!("not valid JSON: {e}")))?;
        let material: MaterialSpec =
            serde_json::from_value(summary.get("material_spec").cloned().unwrap_or_default())
                .map_err(|e| overlay(&summary_path, format!("no readable `material_spec`: {e}")))?;
        let path = dir.join("steps.csv");
        let text = std::fs::read_to_string(&path).map_err(|e| {
            overlay(
                &path,
                format!("cannot read it ({e}): is this a tubemem run folder?"),
            )
        })?;
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
        let col = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| overlay(&path, format!("no column `{name}`")))
        };
        let (cw, cls, crho, cdisp, cforce, cgps) = (
            col("w")?,
            col("lambda_s")?,
            col("rho")?,
            col("displacement")?,
            col("force")?,
            col("gps_force").ok(),
        );
        // summary.json's `units`: the scales of a run with `[units]`, else a text
        let units = summary.get("units").filter(|u| u.is_object());
        let scales = units.and_then(|u| {
            let f = |k: &str| u.get(k).and_then(|v| v.as_f64());
            tubemem_gps::Scales::new(f("radius_m")?, f("thickness_m")?, f("shear_modulus_pa")?).ok()
        });
        let mut o = Overlay {
            label: dir
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_else(|| dir.display().to_string()),
            source: dir.to_path_buf(),
            material,
            scales,
            inflation: vec![],
            squeeze: vec![],
        };
        for (k, line) in lines.enumerate() {
            let f: Vec<&str> = line.split(',').collect();
            let num = |i: usize| -> Result<f64> {
                f.get(i)
                    .and_then(|v| v.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        overlay(
                            &path,
                            format!("row {}: column {i} is not a finite number", k + 2),
                        )
                    })
            };
            if f.get(crho).is_some_and(|v| !v.is_empty()) {
                let (rho, d) = (num(crho)?, num(cdisp)?);
                o.squeeze.push(SqueezePoint {
                    lambda_s: num(cls)?,
                    w: num(cw)?,
                    rho,
                    displacement: d,
                    force: num(cforce)?,
                    initial_stretch: d + rho,
                    gps_force: match cgps {
                        Some(c) if f.get(c).is_some_and(|v| !v.is_empty()) => Some(num(c)?),
                        _ => None,
                    },
                });
            } else {
                o.inflation.push((num(cls)?, num(cw)?));
            }
        }
        Ok(o)
    }
}

/// The law in a few words, for titles and messages.
pub fn law_label(spec: &MaterialSpec) -> String {
    match *spec {
        MaterialSpec::Abb { kuhn, .. } => format!("ABB, Kuhn N = {kuhn}"),
        MaterialSpec::MooneyRivlin { alpha, .. } => format!("Mooney–Rivlin, α = {alpha}"),
        MaterialSpec::NeoHookean { .. } => "neo-Hookean".into(),
    }
}

/// Whether two specs are the same law (the shear modulus only scales, results are per μH).
pub fn same_law(a: &MaterialSpec, b: &MaterialSpec) -> bool {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * x.abs().max(y.abs());
    match (*a, *b) {
        (MaterialSpec::Abb { kuhn: x, .. }, MaterialSpec::Abb { kuhn: y, .. }) => close(x, y),
        (
            MaterialSpec::MooneyRivlin { alpha: x, .. },
            MaterialSpec::MooneyRivlin { alpha: y, .. },
        ) => close(x, y),
        (MaterialSpec::NeoHookean { .. }, MaterialSpec::NeoHookean { .. }) => true,
        (MaterialSpec::NeoHookean { .. }, MaterialSpec::MooneyRivlin { alpha, .. })
        | (MaterialSpec::MooneyRivlin { alpha, .. }, MaterialSpec::NeoHookean { .. }) => {
            alpha == 0.0
        }
        _ => false,
    }
}

/// The paper's law, the figures' default without overlays: ABB with 𝒩 = 30.
pub const PAPER_LAW: MaterialSpec = MaterialSpec::Abb {
    shear_modulus: 1.0,
    kuhn: 30.0,
};

/// A file-name-safe form of a label.
fn slug(s: &str) -> String {
    let t: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    t.trim_matches('_').to_string()
}

/// The overlays' points as CSV, one file each: every FE point drawn, with the GPS force at the
/// same ρ from the run's λs* and the difference shown in the error panels.
fn points_file(dir: &Path, k: usize, o: &Overlay) -> (PathBuf, Vec<u8>) {
    let p = dir.join(format!("fe_points_{}_{}.csv", k + 1, slug(&o.label)));
    let mut rows: Vec<Vec<f64>> = o
        .inflation
        .iter()
        .map(|&(ls, w)| {
            vec![
                0.0,
                ls,
                w,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
            ]
        })
        .collect();
    for s in &o.squeeze {
        let (g, d) = match s.gps_force {
            Some(g) => (g, s.force - g),
            None => (f64::NAN, f64::NAN),
        };
        rows.push(vec![
            1.0,
            s.lambda_s,
            s.w,
            s.rho,
            s.displacement,
            s.force,
            s.initial_stretch,
            g,
            d,
        ]);
    }
    // empty fields, not NaN, for what a point does not have
    let mut text = String::from(
        "squeeze,lambda_s,w,rho,displacement,force,initial_stretch,gps_force,force_minus_gps\n",
    );
    for r in rows {
        text.push_str(&crate::curves::csv_line(&r));
        text.push('\n');
    }
    (p, text.into_bytes())
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
        .or_else(|| overlays.first().map(|o| o.material))
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
    let law = built.as_ref();
    let name = law_label(&spec);
    // the overlays' `[units]`, when they all have the same: pressures in kPa, forces per length
    // in N/m and plate approaches in mm on Figs. 5–8 (the CSVs stay dimensionless)
    let units = overlays
        .first()
        .and_then(|o| o.scales)
        .filter(|s| overlays.iter().all(|o| o.scales == Some(*s)));
    let pressure_fig = |f: Figure| match units {
        Some(s) => scaled(
            f,
            1.0,
            s.pressure(1.0) / 1e3,
            None,
            "pressure p = ϖμH/R (kPa)",
        ),
        None => f,
    };
    let force_fig = |f: Figure| match units {
        Some(s) => scaled(
            f,
            2.0 * s.radius * 1e3,
            s.force_per_length(1.0),
            Some("plate approach 2R(λs* − ρ) (mm)"),
            "plate force per length (N/m)",
        ),
        None => f,
    };
    // every file rendered first; the folder is checked and written only once all are
    let mut files: Vec<(PathBuf, Vec<u8>)> = vec![];
    let hyps = [(Hypothesis::Gps, GPS_COLOR), (Hypothesis::Ps, PS_COLOR)];
    // the paper's two starts (Figs. 6 and 7), then each overlaid squeeze's own λs* (Figs. 8, …):
    // a run is drawn against the curves from where it starts, never against another start's
    let mut starts = vec![(1.3, Stroke::Dashed), (6.0, Stroke::Dotted)];
    for o in overlays {
        for p in &o.squeeze {
            let l = p.initial_stretch;
            if l.is_finite() && !starts.iter().any(|(x, _)| same_start(l, *x)) {
                starts.push((l, Stroke::Dashed));
            }
        }
    }

    let mut inflation = vec![];
    for (h, _) in hyps {
        let c = inflation_curve(law, h, 1.0, 7.5, 651)
            .map_err(|e| AppError::gps("the inflation curve", e))?;
        let p = dir.join(format!("inflation_{}.csv", h.label().to_lowercase()));
        let text = csv_text(&p, INFLATION_HEADER, c.iter().map(inflation_values))?;
        files.push((p, text.into_bytes()));
        inflation.push(c);
    }
    // flattening[start][hyp]
    let mut flattening: Vec<Vec<Vec<FlatteningState>>> = vec![];
    for &(ls0, _) in &starts {
        let mut per = vec![];
        for (h, _) in hyps {
            let c = flattening_curve(law, h, ls0, 0.5 * ls0, 201)
                .map_err(|e| AppError::gps(format!("the flattening curve from λs* = {ls0}"), e))?;
            let p = dir.join(format!(
                "flattening_ls{}_{}.csv",
                start_tag(ls0),
                h.label().to_lowercase()
            ));
            let text = csv_text(&p, FLATTENING_HEADER, c.iter().map(flattening_values))?;
            files.push((p, text.into_bytes()));
            per.push(c);
        }
        flattening.push(per);
    }
    let limits =
        limit_points(law, Hypothesis::Gps).map_err(|e| AppError::gps("the limit points", e))?;
    for (k, o) in overlays.iter().enumerate() {
        files.push(points_file(dir, k, o));
    }

    // Fig. 5
    let mut series = vec![];
    for ((h, color), c) in hyps.iter().zip(&inflation) {
        series.push(Series {
            label: format!("{} inflation", h.label()),
            points: c.iter().map(|s| (s.lambda_s, s.w)).collect(),
            color: *color,
            stroke: Stroke::Solid,
            width: 3,
        });
    }
    for ((ls0, stroke), per) in starts.iter().zip(&flattening) {
        for ((h, color), c) in hyps.iter().zip(per) {
            series.push(Series {
                label: format!("{} flattening from λs* = {}", h.label(), start_tag(*ls0)),
                points: c.iter().map(|s| (s.lambda_s, s.w)).collect(),
                color: *color,
                stroke: *stroke,
                width: 3,
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
            hollow: false,
        });
    }
    if let Some(m) = limits.maxwell {
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
        let pts = flattening[0].iter().flatten();
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
    files.extend(render_files(
        &pressure_fig(Figure {
            markers,
            ..Figure::new(
                format!("Fig. 5 — reduced pressure vs hoop stretch ({name})"),
                "hoop stretch λs",
                "reduced pressure ϖ = pR/(μH)",
                series,
            )
        }),
        &dir.join("fig5_pressure_stretch"),
        opts,
    )?);
    files.extend(render_files(
        &pressure_fig(Figure {
            markers: zoom_markers,
            y_from_zero: false,
            ..Figure::new(
                format!("Fig. 5, zoom on the flattening from λs* = 1.3 ({name})"),
                "hoop stretch λs",
                "reduced pressure ϖ = pR/(μH)",
                zoom_series,
            )
        }),
        &dir.join("fig5_zoom_ls1.3"),
        opts,
    )?);

    // Figs. 6 and 7
    for (((ls0, _), per), num) in starts.iter().zip(&flattening).zip(6..) {
        let tag = start_tag(*ls0);
        let series: Vec<Series> = hyps
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
        let mut markers = vec![];
        let mut errors = vec![];
        let notes = vec![];
        for (run, color) in overlays.iter().zip(FE_COLORS.iter().cycle()) {
            // the squeeze steps that start from this λs*
            let pts: Vec<&SqueezePoint> = run
                .squeeze
                .iter()
                .filter(|s| same_start(s.initial_stretch, *ls0))
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
                    label: label.clone(),
                    points: e,
                    color: *color,
                    hollow: false,
                });
            }
        }
        let panel = (!errors.is_empty()).then(|| Panel {
            y_label: "FE − GPS, same ρ".into(),
            series: vec![],
            markers: errors,
        });
        files.extend(render_files(
            &force_fig(Figure {
                markers,
                panel,
                notes,
                ..Figure::new(
                    format!("Fig. {num} — flattening from λs* = {tag} ({name})"),
                    "reduced displacement λs* − ρ",
                    "reduced force ϖχ = pc/(πμH)",
                    series,
                )
            }),
            &dir.join(format!("fig{num}_force_displacement_ls{tag}")),
            opts,
        )?);
    }

    // λz versus λs
    let mut series = vec![Series {
        label: "GPS inflation".into(),
        points: inflation[0]
            .iter()
            .map(|s| (s.lambda_s, s.lambda_z))
            .collect(),
        color: GPS_COLOR,
        stroke: Stroke::Solid,
        width: 3,
    }];
    for ((ls0, stroke), per) in starts.iter().zip(&flattening) {
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
    files.extend(render_files(
        &Figure::new(
            format!("Axial stretch vs hoop stretch ({name})"),
            "hoop stretch λs",
            "axial stretch λz",
            series,
        ),
        &dir.join("fig_lambda_z"),
        opts,
    )?);
    crate::output_file::create_folder(dir)?;
    crate::output_file::write_owned(dir, FIGURES_MANIFEST, "tubemem figures", &files)
}

/// `fig` with x and y (and its panel's y) multiplied by `sx`, `sy`, and its axes renamed: the
/// dimensional figures of runs with `[units]`.
fn scaled(mut fig: Figure, sx: f64, sy: f64, x_label: Option<&str>, y_label: &str) -> Figure {
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

/// Two squeezes start from the same λs* (one figure, one pair of curves) within this relative
/// difference: a stretch-controlled inflation ends at its target to Newton's tolerance.
const SAME_START: f64 = 1e-6;

fn same_start(a: f64, b: f64) -> bool {
    (a / b - 1.0).abs() <= SAME_START
}

/// A start λs* as the figures' file names and titles write it: one decimal where that is exact
/// (the paper's 1.3 and 6.0), else up to four, trailing zeros dropped (1.25, 1.4142).
fn start_tag(l: f64) -> String {
    if ((l * 10.0).round() - l * 10.0).abs() <= 1e-9 * l.abs().max(1.0) {
        format!("{l:.1}")
    } else {
        let t = format!("{l:.4}");
        t.trim_end_matches('0').to_string()
    }
}

/// The list of the files `tubemem figures` wrote into its folder, so that a later call replaces
/// those and refuses any other file of the same name.
const FIGURES_MANIFEST: &str = ".tubemem-figures";

/// A critical mode along the tube: the means over each ring of nodes at the reference radius
/// (the cylinder and the caps' equators) of the mode's radial and axial components, against
/// the reference Z, scaled so that the largest is 1 (a mode's size is arbitrary).
pub fn mode_figure(
    mesh: &tubemem_mesh::Mesh,
    mode: &[[f64; 3]],
    title: &str,
    notes: Vec<String>,
) -> Figure {
    let radius = mesh
        .nodes
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, f64::max);
    // (Z, mean u_r, mean u_z) per ring (a mode of another mesh's length draws nothing)
    let rings: Vec<(f64, f64, f64)> = mesh
        .rings()
        .iter()
        .filter(|ring| !ring.is_empty() && ring.iter().all(|&i| i < mode.len()))
        .map(|ring| {
            let (mut ur, mut uz) = (0.0, 0.0);
            for &i in ring {
                let p = mesh.nodes[i];
                ur += (mode[i][0] * p[0] + mode[i][1] * p[1]) / radius;
                uz += mode[i][2];
            }
            let n = ring.len() as f64;
            (mesh.nodes[ring[0]][2], ur / n, uz / n)
        })
        .collect();
    let scale = rings
        .iter()
        .map(|r| r.1.abs().max(r.2.abs()))
        .fold(0.0, f64::max)
        .max(1e-300);
    let series = |label: &str, pick: fn(&(f64, f64, f64)) -> f64, color, stroke| Series {
        label: label.into(),
        points: rings.iter().map(|r| (r.0, pick(r) / scale)).collect(),
        color,
        stroke,
        width: 2,
    };
    let mut fig = Figure::new(
        title,
        "reference axial position Z / R",
        "mode (ring mean, largest = 1)",
        vec![
            series(
                "radial component u_r",
                |r| r.1,
                RGBColor(200, 30, 30),
                Stroke::Solid,
            ),
            series(
                "axial component u_z",
                |r| r.2,
                RGBColor(30, 60, 200),
                Stroke::Dashed,
            ),
        ],
    );
    fig.y_from_zero = false;
    fig.notes = notes;
    fig
}
