//! `tubemem fit`: a law's parameters from test data files, with a starting law (a material
//! table, or a model name and starting values estimated from the data), the fit
//! ([`tubemem_material::fit`]), its figure and its report.
//!
//! A data file is CSV: a header line, then one `stretch,nominal_stress` pair per line; lines
//! starting with `#` are comments. Stresses are in any unit: the fitted moduli come out in it.

use crate::figures::{save, Figure, FigureOptions, Markers, Series, Stroke};
use plotters::style::RGBColor;
use std::path::{Path, PathBuf};
use tubemem_material::fit::{fit, nominal_stress, FitResult, Mode, TestData};
use tubemem_material::{MaterialError, MaterialSpec};

/// Why a fit could not be made.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    #[error("{}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// a data file's content, with its line
    #[error("{}, line {line}: {message}", path.display())]
    Data {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("the starting law")]
    Start(#[source] MaterialError),
    #[error("model `{0}`: give its starting values as a material table (a model without built-in starting values, or an unknown one; the models are {1})")]
    NoStart(String, String),
    #[error("the fit")]
    Fit(#[source] tubemem_material::fit::FitError),
    #[error("the fit's figure")]
    Figure(#[source] Box<crate::AppError>),
}

/// Read a test's CSV file: a header, then `stretch,nominal_stress` rows.
pub fn read_test(path: &Path, mode: Mode) -> Result<TestData, FitError> {
    let text = std::fs::read_to_string(path).map_err(|source| FitError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let err = |line: usize, message: String| FitError::Data {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut rows = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((h, header)) = rows.next() else {
        return Err(err(1, "the file has no header and no data".into()));
    };
    if header.split(',').count() < 2 {
        return Err(err(
            h + 1,
            format!("the header `{header}` must name two columns: stretch,nominal_stress"),
        ));
    }
    let (mut stretch, mut stress) = (vec![], vec![]);
    for (k, line) in rows {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() < 2 {
            return Err(err(
                k + 1,
                format!("`{line}`: two numbers, stretch and nominal stress, are needed"),
            ));
        }
        let num = |s: &str, what: &str| {
            s.parse::<f64>()
                .map_err(|_| err(k + 1, format!("{what} `{s}` is not a number")))
        };
        stretch.push(num(f[0], "the stretch")?);
        stress.push(num(f[1], "the stress")?);
    }
    if stretch.is_empty() {
        return Err(err(h + 1, "the file has no data rows".into()));
    }
    Ok(TestData {
        mode,
        stretch,
        stress,
    })
}

/// A starting law for `model` from the data: the small-strain modulus from the point nearest
/// λ = 1 (P ≈ 3μ(λ − 1) uniaxial, 6μ(λ − 1) equibiaxial, 4μ(λ − 1) pure shear, incompressible
/// linear theory) and the model's usual middle values.
pub fn default_start(model: &str, data: &[TestData]) -> Result<MaterialSpec, FitError> {
    let mu = data
        .iter()
        .flat_map(|t| {
            let k = match t.mode {
                Mode::Uniaxial => 3.0,
                Mode::Equibiaxial => 6.0,
                Mode::PureShear => 4.0,
            };
            t.stretch
                .iter()
                .zip(&t.stress)
                .filter(|(l, _)| (**l - 1.0).abs() > 1e-6)
                .map(move |(l, p)| ((l - 1.0).abs(), p / (k * (l - 1.0))))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, mu)| mu)
        .filter(|mu| mu.is_finite() && *mu > 0.0)
        .unwrap_or(1.0);
    let json = match model {
        "neo-hookean" => format!(r#"{{"model": "neo-hookean", "shear_modulus": {mu}}}"#),
        "mooney-rivlin" => {
            format!(r#"{{"model": "mooney-rivlin", "shear_modulus": {mu}, "alpha": 0.1}}"#)
        }
        "abb" => format!(r#"{{"model": "abb", "shear_modulus": {mu}, "kuhn": 10}}"#),
        "yeoh" => format!(
            r#"{{"model": "yeoh", "c10": {}, "c20": 0, "c30": 0}}"#,
            mu / 2.0
        ),
        "gent" => format!(r#"{{"model": "gent", "shear_modulus": {mu}, "jm": 50}}"#),
        "gent-gent" => format!(
            r#"{{"model": "gent-gent", "shear_modulus": {mu}, "jm": 50, "c2": {}}}"#,
            0.1 * mu
        ),
        "arruda-boyce" => {
            format!(r#"{{"model": "arruda-boyce", "shear_modulus": {mu}, "kuhn": 10}}"#)
        }
        "ogden" => format!(
            r#"{{"model": "ogden", "mu": [{}, {}], "alpha": [2.0, 5.0]}}"#,
            0.9 * mu,
            0.04 * mu
        ),
        "saint-venant-kirchhoff" | "svk" => format!(
            r#"{{"model": "saint-venant-kirchhoff", "young_modulus": {}, "poisson_ratio": 0.3}}"#,
            3.0 * mu
        ),
        _ => {
            let models: Vec<&str> = MaterialSpec::MODELS.iter().map(|(m, _)| *m).collect();
            return Err(FitError::NoStart(model.into(), models.join(", ")));
        }
    };
    serde_json::from_str(&json)
        .map_err(|e| FitError::NoStart(model.into(), format!("(internal: {e})")))
}

/// Fit `start` to `data`.
pub fn run_fit(start: &MaterialSpec, data: &[TestData]) -> Result<FitResult, FitError> {
    fit(start, data).map_err(|e| match e {
        tubemem_material::fit::FitError::Start(m) => FitError::Start(m),
        other => FitError::Fit(other),
    })
}

const MODE_COLORS: [RGBColor; 3] = [
    RGBColor(31, 90, 180),
    RGBColor(200, 50, 40),
    RGBColor(20, 140, 60),
];

/// The fit's figure: each test's data (markers) and the fitted law (a curve over the data's
/// range), nominal stress against stretch.
pub fn fit_figure(result: &FitResult, data: &[TestData]) -> Figure {
    let law = result.spec.build().ok();
    let mut series = vec![];
    let mut markers = vec![];
    for (t, color) in data.iter().zip(MODE_COLORS.iter().cycle()) {
        markers.push(Markers {
            label: format!("{} data", t.mode.label()),
            points: t
                .stretch
                .iter()
                .copied()
                .zip(t.stress.iter().copied())
                .collect(),
            color: *color,
            hollow: true,
        });
        if let Some(law) = &law {
            let (lo, hi) = t
                .stretch
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &l| {
                    (a.min(l), b.max(l))
                });
            let pts: Vec<(f64, f64)> = (0..=200)
                .map(|i| lo.min(1.0) + (hi - lo.min(1.0)) * i as f64 / 200.0)
                .filter_map(|l| nominal_stress(law.as_ref(), t.mode, l).ok().map(|p| (l, p)))
                .collect();
            series.push(Series {
                label: format!("{} fit", t.mode.label()),
                points: pts,
                color: *color,
                stroke: Stroke::Solid,
                width: 3,
            });
        }
    }
    let mut fig = Figure::new(
        format!(
            "Fit of the {} law to {} test point(s)",
            result.spec.model(),
            result.points
        ),
        "stretch λ",
        "nominal stress P",
        series,
    );
    fig.markers = markers;
    fig.notes = result
        .parameters
        .iter()
        .map(|p| {
            format!(
                "{} = {:.5e} ± {:.2e}{}",
                p.name,
                p.value,
                p.std_error,
                if p.determined {
                    ""
                } else {
                    " (not determined)"
                }
            )
        })
        .collect();
    fig
}

/// Write the fit's figure as `stem`.svg and/or .png.
pub fn save_figure(
    result: &FitResult,
    data: &[TestData],
    stem: &Path,
    opts: &FigureOptions,
) -> Result<Vec<PathBuf>, FitError> {
    save(&fit_figure(result, data), stem, opts).map_err(|e| FitError::Figure(Box::new(e)))
}

/// The fitted law as a case file's `[material]` table.
pub fn material_table(spec: &MaterialSpec) -> String {
    let v = toml::Value::try_from(spec).ok();
    let body = v.and_then(|v| toml::to_string(&v).ok()).unwrap_or_default();
    format!("[material]\n{body}")
}
