//! Rendering a [`Figure`]: plotters draws it once as SVG, resvg rasterizes that SVG into an
//! anti-aliased PNG at the requested DPI; text in the bundled DejaVu Sans.

use super::{
    axes, legend_corner, range, Figure, FigureOptions, Markers, Series, Stroke, BASE_DPI, CANVAS,
};
use crate::{AppError, Result};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Once};

pub(super) static FONT: Once = Once::new();
pub(super) const FONT_BYTES: &[u8] = include_bytes!("../../../../assets/fonts/DejaVuSans.ttf");
pub(super) const FONT_FAMILY: &str = "DejaVu Sans";

pub(super) fn register_font(path: &Path) -> Result<()> {
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

pub(super) fn stroke_pattern(s: Stroke) -> Option<(u32, u32)> {
    match s {
        Stroke::Solid => None,
        Stroke::Dashed => Some((12, 7)),
        Stroke::Dotted => Some((3, 5)),
    }
}

pub(super) type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

pub(super) fn draw_series<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    s: &Series,
    err: &dyn Fn(String) -> AppError,
) -> Result<()> {
    let style = s.color.stroke_width(s.width);
    // a non-finite point breaks the curve (a contour's separate pieces): each run of finite
    // points is drawn on its own, the legend entry once
    let mut runs: Vec<&[(f64, f64)]> = s
        .points
        .split(|p| !(p.0.is_finite() && p.1.is_finite()))
        .filter(|r| !r.is_empty())
        .collect();
    if runs.is_empty() {
        runs.push(&[]);
    }
    // the later pieces without a legend entry (plotters lists labelled series only)
    for r in &runs[1..] {
        match stroke_pattern(s.stroke) {
            Some((dash, gap)) => chart
                .draw_series(DashedLineSeries::new(r.iter().copied(), dash, gap, style))
                .map(|_| ()),
            None => chart
                .draw_series(LineSeries::new(r.iter().copied(), style))
                .map(|_| ()),
        }
        .map_err(|e| err(e.to_string()))?;
    }
    let anno = match stroke_pattern(s.stroke) {
        Some((dash, gap)) => chart
            .draw_series(DashedLineSeries::new(
                runs[0].iter().copied(),
                dash,
                gap,
                style,
            ))
            .map_err(|e| err(e.to_string()))?,
        None => chart
            .draw_series(LineSeries::new(runs[0].iter().copied(), style))
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

pub(super) fn draw_markers<'a, 'b: 'a>(
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
pub(crate) fn render_svg(fig: &Figure, path: &Path) -> Result<String> {
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

pub(super) fn font_database() -> Arc<resvg::usvg::fontdb::Database> {
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
pub(crate) fn rasterize(svg: &str, dpi: f64, path: &Path) -> Result<Vec<u8>> {
    let err = |message: String| AppError::Figure {
        path: path.to_path_buf(),
        message,
    };
    let opt = resvg::usvg::Options {
        fontdb: font_database(),
        font_family: FONT_FAMILY.to_string(),
        ..Default::default()
    };
    // the bundled DejaVu Sans has no mathematical script letters (the ABB law's 𝒩 drew as a
    // box): the PNG spells it N; the SVG keeps 𝒩 for viewers with a fuller font
    let svg = svg.replace('𝒩', "N");
    let tree = resvg::usvg::Tree::from_str(&svg, &opt).map_err(|e| err(e.to_string()))?;
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
pub(crate) fn render_files(
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
