//! Fitting a viscoelastic (QLV Prony) law to test histories (issue #63): reading a history's
//! CSV, the fit, its figure and its case-file tables.
//!
//! A history file has a header naming a time column (`time` or `time_s`, in seconds: the
//! Prony times come out in seconds), a `stretch` column and either a `nominal_stress` column
//! (its unit as a suffix, as the elastic fit's files) or a `force` column: a force
//! proportional to the nominal stress whose unit and specimen section are not known (the
//! moduli then come out in the force's units, and only the law's shape and the Prony series
//! mean anything physical).

use crate::figures::{save, Figure, FigureOptions, Markers, Series, Stroke};
use crate::fit::{csv_lines, unit_of_column, FitError, StressUnit};
use plotters::style::RGBColor;
use std::path::{Path, PathBuf};
use tubemem_material::fit::{fit_histories_with, FitOptions, FitResult, HistoryData, Mode};
use tubemem_material::viscoelastic::{nominal_history, Prony, PronyTerm};
use tubemem_material::MaterialSpec;

/// A history as read, and what its stress column is.
#[derive(Clone, Debug)]
pub struct HistoryFile {
    pub data: HistoryData,
    /// the stress's unit where the header names one (the stresses are then in Pa)
    pub unit: Option<StressUnit>,
    /// the column is a force proportional to the stress (`force`), of unknown unit
    pub proportional: bool,
}

/// Read a history's CSV (see the module docs); its name is the file's stem.
pub fn read_history_file(path: &Path, mode: Mode) -> Result<HistoryFile, FitError> {
    let lines = csv_lines(path)?;
    let err = |line: usize, message: String| lines.err(line, message);
    let (h, header, names) = (lines.header_line, &lines.header, &lines.names);
    let find = |p: &dyn Fn(&str) -> bool| names.iter().position(|c| p(c));
    let time_col = find(&|c| c == "time" || c == "time_s");
    let stretch_col = find(&|c| c.starts_with("stretch") || c.starts_with("lambda"));
    let stress_col = find(&|c| c.starts_with("nominal_stress") || c.starts_with("stress"));
    let force_col = find(&|c| c == "force");
    let (Some(tc), Some(sc), Some(pc)) = (time_col, stretch_col, stress_col.or(force_col)) else {
        return Err(err(
            h + 1,
            format!(
                "the header `{header}` must name a `time` (or `time_s`, in seconds) column, a `stretch` column and a `nominal_stress` column with its unit as a suffix (or a `force` proportional to it), e.g. `time_s,stretch,force`"
            ),
        ));
    };
    let unit = stress_col.and_then(|c| unit_of_column(&names[c]));
    let factor = unit.map_or(1.0, |u| u.pascals);
    let (mut time, mut stretch, mut stress) = (vec![], vec![], vec![]);
    for (k, line) in &lines.rows {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != names.len() {
            return Err(err(
                k + 1,
                format!("{} fields where the header has {}", f.len(), names.len()),
            ));
        }
        let num = |s: &str, what: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| err(k + 1, format!("{what} `{s}` is not a finite number")))
        };
        let t = num(f[tc], "the time")?;
        if let Some(&last) = time.last() {
            if t < last {
                return Err(err(
                    k + 1,
                    format!("the time {t} s is before the previous row's {last} s"),
                ));
            }
        }
        time.push(t);
        stretch.push(num(f[sc], "the stretch")?);
        stress.push(num(f[pc], "the stress")? * factor);
    }
    if time.len() < 2 {
        return Err(err(h + 1, "a history needs at least two rows".into()));
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    Ok(HistoryFile {
        data: HistoryData {
            name,
            mode,
            time,
            stretch,
            stress,
        },
        unit,
        proportional: stress_col.is_none(),
    })
}

/// The default starting Prony series of `terms` terms for histories: τ spaced by decades
/// from ten times the shortest sampling interval up to the longest history's duration (at most
/// a decade apart, at least a factor 3), each g = 0.5/terms.
pub fn default_prony(data: &[HistoryData], terms: usize) -> Vec<PronyTerm> {
    let dt = data
        .iter()
        .flat_map(|h| h.time.windows(2).map(|w| w[1] - w[0]))
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let span = data
        .iter()
        .map(|h| h.time.last().unwrap_or(&0.0) - h.time.first().unwrap_or(&0.0))
        .fold(0.0, f64::max);
    let lo = if dt.is_finite() { 10.0 * dt } else { 1.0 };
    let hi = span.max(3.0 * lo);
    (0..terms)
        .map(|i| {
            let f = if terms == 1 {
                0.5
            } else {
                i as f64 / (terms - 1) as f64
            };
            PronyTerm {
                g: 0.5 / terms as f64,
                tau: lo * (hi / lo).powf(f),
            }
        })
        .collect()
}

/// Fit `start` and `prony` to the histories.
pub fn run_fit_histories(
    start: &MaterialSpec,
    prony: &[PronyTerm],
    data: &[HistoryData],
    opts: &FitOptions,
) -> Result<FitResult, FitError> {
    fit_histories_with(start, prony, data, opts).map_err(|e| match e {
        tubemem_material::fit::FitError::Start(m) => FitError::Start(m),
        other => FitError::Fit(other),
    })
}

/// The history fit's figure: every history's stress against time (markers, about 60 per
/// history) and the fitted law's along the same stretch history (lines), in two legend
/// entries (the histories overlap in time; each keeps its own line).
pub fn history_figure(result: &FitResult, data: &[HistoryData], y_label: &str) -> Figure {
    let law = result.spec.build().ok();
    let prony = result
        .prony
        .as_ref()
        .and_then(|t| Prony::new(t.clone()).ok());
    let mut data_points = vec![];
    let mut fit_points = vec![];
    for h in data {
        let every = (h.time.len() / 60).max(1);
        data_points.extend(
            h.time
                .iter()
                .zip(&h.stress)
                .step_by(every)
                .map(|(&t, &p)| (t, p)),
        );
        if let (Some(law), Some(prony)) = (&law, &prony) {
            let eq = h.mode == Mode::Equibiaxial;
            if let Ok(m) = nominal_history(law.as_ref(), prony, eq, &h.time, &h.stretch) {
                // a non-finite point starts a new line: one line per history
                if !fit_points.is_empty() {
                    fit_points.push((f64::NAN, f64::NAN));
                }
                fit_points.extend(h.time.iter().copied().zip(m));
            }
        }
    }
    let series = vec![Series {
        label: format!(
            "the fitted law along each history's stretches ({})",
            data.len()
        ),
        points: fit_points,
        color: RGBColor(200, 50, 40),
        stroke: Stroke::Solid,
        width: 2,
    }];
    let markers = vec![Markers {
        label: format!("data ({} histories)", data.len()),
        points: data_points,
        color: RGBColor(31, 90, 180),
        hollow: true,
    }];
    let mut fig = Figure::new(
        format!(
            "Fit of the {} law with {} Prony terms to {} histories",
            result.spec.model(),
            result.prony.as_ref().map_or(0, |p| p.len()),
            data.len()
        ),
        "time t (s)",
        y_label,
        series,
    );
    fig.markers = markers;
    fig.notes = crate::fit::parameter_notes(result);
    fig
}

/// Write the history fit's figure as `stem`.svg and/or .png.
pub fn save_history_figure(
    result: &FitResult,
    data: &[HistoryData],
    y_label: &str,
    stem: &Path,
    opts: &FigureOptions,
) -> Result<Vec<PathBuf>, FitError> {
    save(&history_figure(result, data, y_label), stem, opts)
        .map_err(|e| FitError::Figure(Box::new(e)))
}

/// The fitted Prony series as `tubemem gps history --prony` takes it (τ in seconds), and as
/// the `[material.viscoelastic]` table the FE's case files are to take (issue #63; `tubemem
/// run` does not read it yet, which the comment says).
pub fn prony_table(terms: &[PronyTerm]) -> String {
    let pairs: Vec<String> = terms
        .iter()
        .map(|t| format!("{:?}:{:?}", t.g, t.tau))
        .collect();
    let items: Vec<String> = terms
        .iter()
        .map(|t| format!("{{ g = {:?}, tau = {:?} }}", t.g, t.tau))
        .collect();
    format!(
        "# the Prony series (tau in seconds): `tubemem gps history --prony {}`\n# the FE in time (issue #63) is to read it as below; `tubemem run` does not yet\n# [material.viscoelastic]\n# prony = [{}]\n",
        pairs.join(","),
        items.join(", ")
    )
}
