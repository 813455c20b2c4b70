//! `tubemem fit`: a law's parameters from test data files, with a starting law (a material
//! table, or a model name and starting values estimated from the data), the fit
//! ([`tubemem_material::fit`]), its figure and its report.
//!
//! A data file is CSV: a header naming its columns, then one row per point; lines starting
//! with `#` are comments. The columns are found by name: `stretch` (or `lambda`), and the
//! nominal stress, `nominal_stress` or `stress`, whose unit the name gives as a suffix
//! (`nominal_stress_mpa`, `stress_kpa`, `stress_pa`) or in brackets (`stress (MPa)`). Stresses
//! in a known unit are read in pascals, so the fitted moduli come out in Pa, ready for a case
//! with `[units] system = "SI"`; a header that names no unit keeps the data's numbers, and the
//! report says so. Every file of one fit must agree.

use crate::figures::{save, Figure, FigureOptions, Markers, Series, Stroke};
use plotters::style::RGBColor;
use std::path::{Path, PathBuf};
use tubemem_material::fit::{fit_with, nominal_stress, FitOptions, FitResult, Mode, TestData};
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
    /// the files of one fit give their stresses in different units, or some name none
    #[error("{0}")]
    Units(String),
}

/// A stress unit a data file's header names, with its factor to pascals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StressUnit {
    pub name: &'static str,
    pub pascals: f64,
}

/// The stress units a header may name (case-insensitive).
pub const STRESS_UNITS: [StressUnit; 5] = [
    StressUnit {
        name: "Pa",
        pascals: 1.0,
    },
    StressUnit {
        name: "kPa",
        pascals: 1e3,
    },
    StressUnit {
        name: "MPa",
        pascals: 1e6,
    },
    StressUnit {
        name: "GPa",
        pascals: 1e9,
    },
    StressUnit {
        name: "psi",
        pascals: 6_894.757_293_168,
    },
];

/// The unit a stress column's name gives (`nominal_stress_mpa`, `stress (kPa)`), if any.
pub fn unit_of_column(name: &str) -> Option<StressUnit> {
    let n = name.trim().to_ascii_lowercase();
    let tail = n
        .rsplit(['_', '(', '[', ' '])
        .next()
        .unwrap_or("")
        .trim_end_matches([')', ']']);
    STRESS_UNITS
        .iter()
        .copied()
        .find(|u| u.name.to_ascii_lowercase() == tail)
}

/// One test's data as read: the points (stresses in Pa where the unit is known) and the unit.
#[derive(Clone, Debug)]
pub struct TestFile {
    pub data: TestData,
    pub unit: Option<StressUnit>,
}

/// The longest excerpt of a data line a message quotes.
const EXCERPT: usize = 60;

fn excerpt(line: &str) -> String {
    if line.chars().count() <= EXCERPT {
        line.to_string()
    } else {
        format!("{}…", line.chars().take(EXCERPT).collect::<String>())
    }
}

/// A data file's lines as the fits read them: the header (its index from 0, its text and its
/// lower-case column names) and the data rows (index, text); blank and `#` lines skipped.
pub(crate) struct CsvLines {
    pub path: PathBuf,
    pub header_line: usize,
    pub header: String,
    pub names: Vec<String>,
    pub rows: Vec<(usize, String)>,
}

impl CsvLines {
    /// The file's content refused at `line` (counted from 1).
    pub fn err(&self, line: usize, message: String) -> FitError {
        FitError::Data {
            path: self.path.clone(),
            line,
            message,
        }
    }
}

/// Read `path` (at most [`tubemem_mesh::io::MAX_TEXT_INPUT_BYTES`]) into [`CsvLines`].
pub(crate) fn csv_lines(path: &Path) -> Result<CsvLines, FitError> {
    let text = tubemem_mesh::io::read_text_limited(path, tubemem_mesh::io::MAX_TEXT_INPUT_BYTES)
        .map_err(|source| FitError::Read {
            path: path.to_path_buf(),
            source,
        })?;
    let mut rows = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|(k, l)| (k, l.to_string()));
    let Some((h, header)) = rows.next() else {
        return Err(FitError::Data {
            path: path.to_path_buf(),
            line: 1,
            message: "the file has no header and no data".into(),
        });
    };
    let names = header
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    Ok(CsvLines {
        path: path.to_path_buf(),
        header_line: h,
        header,
        names,
        rows: rows.collect(),
    })
}

/// Read a test's CSV file: a header naming a `stretch` and a stress column (with its unit),
/// then rows. `unit` states the stress unit where the header names none (`--stress-unit`).
pub fn read_test_file(
    path: &Path,
    mode: Mode,
    unit: Option<StressUnit>,
) -> Result<TestFile, FitError> {
    let lines = csv_lines(path)?;
    let err = |line: usize, message: String| lines.err(line, message);
    let (h, header, names) = (lines.header_line, &lines.header, &lines.names);
    let stretch_col = names
        .iter()
        .position(|c| c.starts_with("stretch") || c.starts_with("lambda"));
    let stress_col = names
        .iter()
        .position(|c| c.starts_with("nominal_stress") || c.starts_with("stress"));
    let (Some(sc), Some(pc)) = (stretch_col, stress_col) else {
        return Err(err(
            h + 1,
            format!(
                "the header `{}` must name a `stretch` column and a `nominal_stress` (or `stress`) column, with the stress's unit as a suffix, e.g. `stretch,nominal_stress_mpa` (a file without a header is refused: its first row would be taken for one)",
                excerpt(header)
            ),
        ));
    };
    let named = unit_of_column(&names[pc]);
    let unit = match (named, unit) {
        (Some(n), Some(u)) if n != u => {
            return Err(err(
                h + 1,
                format!(
                    "the header names the stress in {} and --stress-unit says {}: give one",
                    n.name, u.name
                ),
            ))
        }
        (n, u) => n.or(u),
    };
    let factor = unit.map_or(1.0, |u| u.pascals);
    let (mut stretch, mut stress) = (vec![], vec![]);
    for (k, line) in &lines.rows {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != names.len() {
            return Err(err(
                k + 1,
                format!(
                    "`{}` has {} fields and the header {}{}",
                    excerpt(line),
                    f.len(),
                    names.len(),
                    if f.len() > names.len() {
                        " (a decimal comma? write 1.5, not 1,5)"
                    } else {
                        ""
                    }
                ),
            ));
        }
        let num = |s: &str, what: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(
                        k + 1,
                        format!("{what} `{}` is not a finite number", excerpt(s)),
                    )
                })
        };
        stretch.push(num(f[sc], "the stretch")?);
        let p = num(f[pc], "the stress")? * factor;
        if !p.is_finite() {
            return Err(err(k + 1, "the stress overflows in pascals".into()));
        }
        stress.push(p);
    }
    if stretch.is_empty() {
        return Err(err(h + 1, "the file has no data rows".into()));
    }
    Ok(TestFile {
        data: TestData {
            mode,
            stretch,
            stress,
        },
        unit,
    })
}

/// The one stress unit of a fit's files: all name the same one (the data are then in Pa), or
/// none does (the data's own numbers); a mix is refused.
pub fn common_unit(files: &[(PathBuf, TestFile)]) -> Result<Option<StressUnit>, FitError> {
    let named: Vec<_> = files.iter().filter(|(_, f)| f.unit.is_some()).collect();
    if named.is_empty() {
        return Ok(None);
    }
    if named.len() < files.len() {
        let bare: Vec<String> = files
            .iter()
            .filter(|(_, f)| f.unit.is_none())
            .map(|(p, _)| p.display().to_string())
            .collect();
        return Err(FitError::Units(format!(
            "one unit per fit: {} names no stress unit while {} does ({}); name it in the header (e.g. nominal_stress_mpa) or with --stress-unit",
            bare.join(", "),
            named[0].0.display(),
            named[0].1.unit.map_or("", |u| u.name)
        )));
    }
    // named units may differ (MPa and kPa): each file was read in Pa
    Ok(Some(StressUnit {
        name: "Pa",
        pascals: 1.0,
    }))
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

/// Fit `start` to `data` (every parameter free, the default starts).
pub fn run_fit(start: &MaterialSpec, data: &[TestData]) -> Result<FitResult, FitError> {
    run_fit_with(start, data, &FitOptions::default())
}

/// Fit `start` to `data` with fixed and bounded parameters and the starts of `opts`.
pub fn run_fit_with(
    start: &MaterialSpec,
    data: &[TestData],
    opts: &FitOptions,
) -> Result<FitResult, FitError> {
    fit_with(start, data, opts).map_err(|e| match e {
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
pub fn fit_figure(result: &FitResult, data: &[TestData], unit: Option<StressUnit>) -> Figure {
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
        &match unit {
            Some(u) => format!("nominal stress P ({})", u.name),
            None => "nominal stress P (the data's unit: the headers name none)".to_string(),
        },
        series,
    );
    fig.markers = markers;
    fig.notes = parameter_notes(result);
    fig
}

/// A figure's note per fitted parameter: its value, standard error, and whether it is fixed,
/// at a bound or not determined.
pub(crate) fn parameter_notes(result: &FitResult) -> Vec<String> {
    result
        .parameters
        .iter()
        .map(|p| {
            format!(
                "{} = {:.5e}{}{}",
                p.name,
                p.value,
                p.std_error.map_or(String::new(), |e| format!(" ± {e:.2e}")),
                if p.fixed {
                    " (fixed)"
                } else if p.at_bound.is_some() {
                    " (at its bound)"
                } else if p.determined {
                    ""
                } else {
                    " (not determined)"
                }
            )
        })
        .collect()
}

/// Write the fit's figure as `stem`.svg and/or .png.
pub fn save_figure(
    result: &FitResult,
    data: &[TestData],
    unit: Option<StressUnit>,
    stem: &Path,
    opts: &FigureOptions,
) -> Result<Vec<PathBuf>, FitError> {
    save(&fit_figure(result, data, unit), stem, opts).map_err(|e| FitError::Figure(Box::new(e)))
}

/// The fitted law as a case file's `[material]` table, with a comment saying which unit its
/// moduli are in: Pa where the data named their unit (ready for `[units] system = "SI"`),
/// else the data's own.
pub fn material_table(spec: &MaterialSpec, unit: Option<StressUnit>) -> String {
    // numbers in their shortest round-trip form (1e300, not 301 digits)
    fn value(v: &toml::Value) -> String {
        match v {
            toml::Value::Float(f) => format!("{f:?}"),
            toml::Value::Array(a) => {
                format!("[{}]", a.iter().map(value).collect::<Vec<_>>().join(", "))
            }
            toml::Value::Table(t) => format!(
                "{{ {} }}",
                t.iter()
                    .map(|(k, v)| format!("{k} = {}", value(v)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            other => other.to_string(),
        }
    }
    let body: String = match toml::Value::try_from(spec) {
        Ok(toml::Value::Table(t)) => t
            .iter()
            .map(|(k, v)| format!("{k} = {}\n", value(v)))
            .collect(),
        _ => String::new(),
    };
    let note = match unit {
        Some(u) => format!(
            "# moduli in {} (SI): for a case with [units] system = \"SI\" (a dimensionless case takes them as they are: only their ratios matter)",
            u.name
        ),
        None => "# moduli in the data's stress unit (its headers name none): for a case with [units] system = \"SI\", convert them to Pa".to_string(),
    };
    format!("{note}\n[material]\n{body}")
}
