//! `tubemem verify`: the verification suite as a product.
//!
//! A suite file ([`suite`]) lists checks; each runs its case (and its mesh or length family)
//! into its own folder and compares what the typed [`RunReport`] says with a reference:
//!
//! * `closed-form`: the mid-span against GPS at every step (and the section under the FE's own
//!   pressure for a squeeze), per-quantity relative tolerances; PS reported;
//! * `reference`: the FE against the scikit-fem references of `python_ref` (run as a separate
//!   Python process); skipped, with the reason, when they are not installed;
//! * `convergence`: a mesh family: observed order, Richardson extrapolation and GCI
//!   ([`stats::gci`]), the reference within the extrapolated value ± GCI;
//! * `end-effect`: a length family: the mid-span error against GPS fitted to
//!   c + A exp(−k L/R) (open inflation) or c + A/(L/R) (gas-closed squeeze) ([`stats`]);
//! * `invariance`: the middle region within which every profile quantity stays within ε of
//!   its mid-span value, at every step;
//! * `gold`: every step and the summary against stored gold files, like MOOSE's CSVDiff.
//!
//! Checks run in parallel (rayon, `jobs` threads). [`report`] writes results.json, report.md,
//! a self-contained report.html and junit.xml. [`study`] builds the checks for a user's own
//! case (`tubemem verify --case`).

pub mod report;
pub mod stats;
pub mod study;
pub mod suite;

use crate::case::Case;
use crate::figures::{rasterize, render_svg, Figure, Markers, Series, Stroke};
use crate::output::{FolderMode, RunWriter, STEPS_HEADER};
use crate::report::{RunReport, StepRecord};
use plotters::style::RGBColor;
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

/// Set (by a front end's signal handler) to stop a verification: the checks not started yet
/// are skipped, the FE runs in progress stop at their next Newton iteration (their checks end
/// in error, "interrupted"), and the report of what ran is written.
static INTERRUPT: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// Install the verification's interrupt flag (once per process).
pub fn set_interrupt(flag: Arc<AtomicBool>) {
    let _ = INTERRUPT.set(flag);
}

/// Whether the verification was interrupted.
pub fn interrupted() -> bool {
    INTERRUPT.get().is_some_and(|f| f.load(Ordering::Relaxed))
}
use suite::{Check, CheckKind, Tol};
use tubemem_gps::Hypothesis;

/// How a check ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    Pass,
    Fail,
    /// a member run failed or did not converge, or the check could not be evaluated
    Error,
    /// not applicable here (e.g. the Python references are not installed), with the reason
    Skipped,
}

impl Status {
    pub fn label(self) -> &'static str {
        match self {
            Status::Pass => "PASS",
            Status::Fail => "FAIL",
            Status::Error => "ERROR",
            Status::Skipped => "SKIPPED",
        }
    }
}

/// One measured quantity of a check against its tolerance.
#[derive(Clone, Debug, Serialize)]
pub struct Measure {
    pub quantity: String,
    pub measured: f64,
    /// the admissible value (None: reported only)
    pub tolerance: Option<f64>,
    pub source: Option<String>,
    pub pass: bool,
    /// where or how it was measured
    pub note: String,
    /// the tolerance is a lower bound (measured ≥ tolerance passes), e.g. a core fraction
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub at_least: bool,
}

impl Measure {
    fn held(quantity: &str, measured: f64, tol: &Tol, note: String) -> Self {
        Measure {
            quantity: quantity.into(),
            measured,
            tolerance: Some(tol.value),
            source: Some(tol.source.clone()),
            pass: measured.is_finite() && measured <= tol.value,
            note,
            at_least: false,
        }
    }
    /// A quantity that has a tolerance but nothing was measured for it: a failure that says why.
    fn missing(quantity: &str, tol: &Tol, why: &str) -> Self {
        Measure {
            quantity: quantity.into(),
            measured: f64::NAN,
            tolerance: Some(tol.value),
            source: Some(tol.source.clone()),
            pass: false,
            note: why.into(),
            at_least: false,
        }
    }
    /// A fitted or observed value against an expectation `value ± within`.
    fn expected(label: &str, symbol: &str, found: f64, e: &suite::Expect, note: &str) -> Self {
        let d = (found - e.value).abs();
        Measure {
            quantity: format!("{label}|{symbol} − {}|", e.value),
            measured: d,
            tolerance: Some(e.within),
            source: Some(e.source.clone()),
            pass: d <= e.within,
            note: format!("{note} {found:.4}, expected {} ± {}", e.value, e.within),
            at_least: false,
        }
    }
    fn reported(quantity: &str, measured: f64, note: String) -> Self {
        Measure {
            quantity: quantity.into(),
            measured,
            tolerance: None,
            source: None,
            pass: true,
            note,
            at_least: false,
        }
    }
}

/// The result of one check.
#[derive(Clone, Debug, Serialize)]
pub struct CheckResult {
    pub name: String,
    pub suite: String,
    pub kind: CheckKind,
    pub status: Status,
    /// one line: why it failed, what it found, or why it was skipped
    pub message: String,
    pub seconds: f64,
    /// the member run folders, relative to the output folder
    pub runs: Vec<String>,
    pub measures: Vec<Measure>,
    /// kind-specific numbers (fits, family tables, per-step cores)
    pub details: serde_json::Value,
    /// the plot's file, relative to the output folder
    pub plot: Option<String>,
    #[serde(skip)]
    pub png: Option<Vec<u8>>,
    /// what the plot shows (for the tests of the report's plots)
    #[serde(skip)]
    pub figure: Option<crate::figures::FigureAudit>,
}

/// What [`run_checks`] reports as it goes.
pub enum Event<'a> {
    Started {
        index: usize,
        total: usize,
        name: &'a str,
    },
    Finished {
        done: usize,
        total: usize,
        result: &'a CheckResult,
    },
}

/// Options of a verification run.
#[derive(Clone, Debug, Default)]
pub struct VerifyOptions {
    /// checks run at once (0: rayon's default, the number of cores)
    pub jobs: usize,
    /// run only the checks whose name contains this text
    pub filter: Option<String>,
    /// rewrite the gold files from this run (gold checks), on request only
    pub update_gold: bool,
    /// the Python interpreter of the references (default: $TUBEMEM_PYTHON, else the
    /// `.venv/bin/python` next to `python_ref/`, else `python3`)
    pub python: Option<PathBuf>,
    /// the `python_ref` folder (default: searched upwards from the suite and the working folder)
    pub python_ref: Option<PathBuf>,
}

/// Run `checks` into `out` (each into `out/<name>/`), in parallel; results in the checks' order.
pub fn run_checks(
    checks: &[Check],
    out: &Path,
    opts: &VerifyOptions,
    progress: &(dyn Fn(Event) + Sync),
) -> crate::Result<Vec<CheckResult>> {
    std::fs::create_dir_all(out).map_err(|e| crate::AppError::io(out, e))?;
    let selected: Vec<&Check> = checks
        .iter()
        .filter(|c| {
            opts.filter
                .as_deref()
                .is_none_or(|f| c.spec.name.contains(f))
        })
        .collect();
    let total = selected.len();
    let done = AtomicUsize::new(0);
    // more threads than checks or cores gain nothing, and the FE runs inside the checks share
    // the pool (`--jobs 1000` made a 0.1 s check take 10 s)
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs = match opts.jobs {
        0 => 0,
        j => j.min(total.max(1)).min(cores),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| crate::AppError::Output {
            what: "the check threads".into(),
            source: Box::new(e),
        })?;
    let results = pool.install(|| {
        selected
            .par_iter()
            .enumerate()
            .map(|(index, c)| {
                progress(Event::Started {
                    index,
                    total,
                    name: &c.spec.name,
                });
                let r = if interrupted() {
                    CheckResult {
                        status: Status::Skipped,
                        message: "not run: the verification was interrupted".into(),
                        ..CheckResult::empty(c)
                    }
                } else {
                    run_check(c, out, opts)
                };
                let d = done.fetch_add(1, Ordering::SeqCst) + 1;
                progress(Event::Finished {
                    done: d,
                    total,
                    result: &r,
                });
                r
            })
            .collect::<Vec<_>>()
    });
    Ok(results)
}

impl CheckResult {
    /// The result of check `c` before it ran: an error with no message, no runs, no measures.
    fn empty(c: &Check) -> Self {
        Self {
            name: c.spec.name.clone(),
            suite: c.suite.clone(),
            kind: c.spec.kind,
            status: Status::Error,
            message: String::new(),
            seconds: 0.0,
            runs: vec![],
            measures: vec![],
            details: serde_json::Value::Null,
            plot: None,
            png: None,
            figure: None,
        }
    }
}

/// Run one check; never panics on bad data, a failed member run is the check's error.
pub fn run_check(c: &Check, out: &Path, opts: &VerifyOptions) -> CheckResult {
    let t0 = std::time::Instant::now();
    let dir = out.join(&c.spec.name);
    let mut r = CheckResult::empty(c);
    let outcome = match std::fs::create_dir_all(&dir) {
        Err(e) => Err(format!("cannot create {}: {e}", dir.display())),
        Ok(()) => match c.spec.kind {
            CheckKind::ClosedForm => closed_form(c, &dir, &mut r),
            CheckKind::Reference => reference(c, &dir, opts, &mut r),
            CheckKind::Convergence => convergence(c, &dir, &mut r),
            CheckKind::EndEffect => end_effect(c, &dir, &mut r),
            CheckKind::Invariance => invariance(c, &dir, &mut r),
            CheckKind::Gold => gold(c, &dir, opts, &mut r),
        },
    };
    r.runs = r
        .runs
        .iter()
        .map(|p| {
            Path::new(p)
                .strip_prefix(out)
                .map(|q| q.display().to_string())
                .unwrap_or_else(|_| p.clone())
        })
        .collect();
    match outcome {
        Err(message) => {
            r.status = Status::Error;
            r.message = message;
        }
        Ok(Some(skip)) => {
            r.status = Status::Skipped;
            r.message = skip;
        }
        Ok(None) => {
            let failed: Vec<String> = r
                .measures
                .iter()
                .filter(|m| !m.pass)
                .map(|m| match m.tolerance {
                    Some(t) => format!(
                        "{}: {:.3e} {} {:.3e} ({}; tolerance: {})",
                        m.quantity,
                        m.measured,
                        if m.at_least { "<" } else { ">" },
                        t,
                        m.note,
                        m.source.as_deref().unwrap_or("")
                    ),
                    None => format!("{}: {}", m.quantity, m.note),
                })
                .collect();
            if failed.is_empty() {
                r.status = Status::Pass;
                if r.message.is_empty() {
                    r.message = r
                        .measures
                        .iter()
                        .filter(|m| m.tolerance.is_some())
                        .map(|m| {
                            format!(
                                "{} {:.2e} {} {:.2e}",
                                m.quantity,
                                m.measured,
                                if m.at_least { "≥" } else { "≤" },
                                m.tolerance.unwrap_or(0.0)
                            )
                        })
                        .collect::<Vec<_>>()
                        .join("; ");
                }
            } else {
                r.status = Status::Fail;
                r.message = failed.join("; ");
            }
        }
    }
    if let Some(png) = &r.png {
        let p = dir.join("plot.png");
        if tubemem_mesh::file::write_whole(&p, png).is_ok() {
            r.plot = Some(format!("{}/plot.png", c.spec.name));
        }
    }
    r.seconds = t0.elapsed().as_secs_f64();
    r
}

/// Why a study, a member run or a case variation could not be made. (A check that runs and
/// fails is not an error: it is a [`CheckResult`] with its status.)
#[derive(Debug, thiserror::Error)]
pub enum VerifyError {
    /// the case file could not be read
    #[error("{}", path.display())]
    Read {
        path: std::path::PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// the case (a file, or a member's varied text) is not a valid case
    #[error("{what}")]
    Case {
        what: String,
        #[source]
        source: crate::case::CaseError,
    },
    /// a case text to vary is not TOML
    #[error("the case text to vary is not TOML")]
    Toml(#[source] toml::de::Error),
    /// a varied case could not be written back as TOML
    #[error("the varied case could not be written as TOML")]
    TomlWrite(#[source] toml::ser::Error),
    /// a member run (or its folder) failed
    #[error("{label}")]
    Run {
        label: String,
        #[source]
        source: Box<crate::AppError>,
    },
    /// the checks could not be run (their output folder)
    #[error("the study's checks")]
    Checks(#[source] Box<crate::AppError>),
    /// a study the case cannot have
    #[error("{0}")]
    Study(&'static str),
}

/// A kind's error message: the whole chain.
impl From<VerifyError> for String {
    fn from(e: VerifyError) -> String {
        crate::error_chain(&e)
    }
}

/// Outcome of a kind's evaluation: `Ok(None)` judged by the measures, `Ok(Some(reason))`
/// skipped, `Err(message)` an error.
type KindResult = Result<Option<String>, String>;

/// A case text with edits applied to its TOML tables. Member runs write VTU at stage ends only
/// and no checkpoints, unless the case says otherwise.
pub fn vary(text: &str, edit: impl FnOnce(&mut toml::Table)) -> Result<String, VerifyError> {
    let mut t: toml::Table = toml::from_str(text).map_err(VerifyError::Toml)?;
    edit(&mut t);
    let output = t
        .entry("output")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let Some(o) = output.as_table_mut() {
        o.entry("vtu")
            .or_insert_with(|| toml::Value::String("stage-end".into()));
    }
    let solver = t
        .entry("solver")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let Some(s) = solver.as_table_mut() {
        s.entry("checkpoint_every")
            .or_insert(toml::Value::Integer(0));
    }
    toml::to_string(&t).map_err(VerifyError::TomlWrite)
}

/// Run a case text into `dir` (replacing what is there); the report, or the error's chain.
pub fn run_member(
    text: &str,
    base_dir: &Path,
    dir: &Path,
    label: &str,
) -> Result<RunReport, VerifyError> {
    let mut case = Case::parse(text).map_err(|source| VerifyError::Case {
        what: label.to_string(),
        source,
    })?;
    case.base_dir = base_dir.to_path_buf();
    let run_error = |source| VerifyError::Run {
        label: label.to_string(),
        source: Box::new(source),
    };
    let mut writer = RunWriter::create(dir, FolderMode::Overwrite, case.hash(), &[])
        .map_err(run_error)?
        .checkpoint_every(case.solver.checkpoint_every)
        .frames_of(case.output);
    let options = crate::run::RunOptions {
        interrupt: INTERRUPT.get().cloned(),
        ..Default::default()
    };
    crate::run::run_with(&case, label, &options, &mut [&mut writer])
        .into_result()
        .map_err(run_error)
}

fn member(c: &Check, text: &str, dir: &Path, r: &mut CheckResult) -> Result<RunReport, String> {
    r.runs.push(dir.display().to_string());
    let text = vary(text, |_| {})?;
    Ok(run_member(
        &text,
        &c.base_dir,
        dir,
        &format!("check {}", c.spec.name),
    )?)
}

/// (FE, closed form) of `q` at one step, if the step has both.
pub fn step_pair(s: &StepRecord, q: &str) -> Option<(f64, f64)> {
    let m = &s.midspan;
    let cf = &s.closed_form;
    if let Some(g) = &cf.gps_confine {
        // a confine step: the walls' forces compared wall by wall, the worst one kept
        let worst_wall = |c: &tubemem_gps::confine::ConfineState| {
            s.walls
                .iter()
                .zip(&c.walls)
                .filter(|(_, w)| w.force > 0.0)
                .map(|(fe, w)| (fe.force, w.force))
                .max_by(|a, b| (a.0 / a.1 - 1.0).abs().total_cmp(&(b.0 / b.1 - 1.0).abs()))
        };
        return match q {
            "w" => Some((m.w, g.w)),
            "lambda_s" => Some((m.lambda_s, g.lambda_s)),
            "lambda_z" => Some((m.lambda_z, g.lambda_z)),
            "n_s" => Some((m.n_s, g.n_s)),
            "n_z" => Some((m.n_z, g.n_z)),
            "wall_force" => worst_wall(g),
            "local_lambda_s" => cf.local_confine.as_ref().map(|l| (m.lambda_s, l.lambda_s)),
            "local_lambda_z" => cf.local_confine.as_ref().map(|l| (m.lambda_z, l.lambda_z)),
            "local_wall_force" => cf.local_confine.as_ref().and_then(worst_wall),
            "penetration" => Some((
                1.0 + s.walls.iter().map(|w| w.penetration).fold(0.0, f64::max),
                1.0,
            )),
            _ => None,
        };
    }
    if let Some(g) = &cf.gps_inflation {
        return match q {
            "w" => Some((m.w, g.w)),
            "lambda_s" => Some((m.lambda_s, g.lambda_s)),
            "lambda_z" => Some((m.lambda_z, g.lambda_z)),
            "n_s" => Some((m.n_s, g.n_s)),
            "n_z" => Some((m.n_z, g.n_z)),
            _ => None,
        };
    }
    let c = s.contact.as_ref()?;
    // deviations, compared as they are: (1 + d, 1) gives FE/GPS − 1 = d
    match q {
        "flat_pressure" => return c.values.flat_pressure_deviation.map(|d| (1.0 + d, 1.0)),
        "penetration" => return Some((1.0 + c.values.penetration, 1.0)),
        _ => {}
    }
    if let Some(local) = q.strip_prefix("local_") {
        let l = cf.local.as_ref()?.as_ref().ok()?;
        return match local {
            "lambda_s" => Some((m.lambda_s, l.lambda_s)),
            "lambda_z" => Some((m.lambda_z, l.lambda_z)),
            "chi" => Some((c.values.chi, l.chi)),
            "force" => Some((c.values.force, l.force)),
            _ => None,
        };
    }
    let g = cf.gps_flattening.as_ref()?;
    match q {
        "w" => Some((m.w, g.w)),
        "lambda_s" => Some((m.lambda_s, g.lambda_s)),
        "lambda_z" => Some((m.lambda_z, g.lambda_z)),
        "n_s" => Some((m.n_s, g.n_s)),
        "n_z" => Some((m.n_z, g.n_z)),
        "chi" => Some((c.values.chi, g.chi)),
        "force" => Some((c.values.force, g.force)),
        _ => None,
    }
}

/// The final mid-span value of `q` (the last step of the run).
pub fn final_value(report: &RunReport, q: &str) -> Option<f64> {
    let s = report.steps().last()?;
    let m = &s.midspan;
    match q {
        "w" => Some(m.w),
        "lambda_s" => Some(m.lambda_s),
        "lambda_z" => Some(m.lambda_z),
        "n_s" => Some(m.n_s),
        "n_z" => Some(m.n_z),
        "chi" => s.contact.map(|c| c.values.chi),
        "force" => s.contact.map(|c| c.values.force),
        _ => None,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    a / b - 1.0
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 90, 180),
    RGBColor(200, 50, 40),
    RGBColor(20, 140, 60),
    RGBColor(150, 60, 170),
    RGBColor(230, 130, 0),
    RGBColor(90, 90, 90),
];

/// Draw a small figure to PNG bytes (for the HTML report).
fn plot(fig: &Figure, r: &mut CheckResult) {
    r.figure = Some(crate::figures::audit(fig));
    let p = PathBuf::from(format!("{}.png", r.name));
    if let Ok(svg) = render_svg(fig, &p) {
        r.png = rasterize(&svg, 70.0, &p).ok();
    }
}

fn closed_form(c: &Check, dir: &Path, r: &mut CheckResult) -> KindResult {
    let report = member(c, &c.case_text, &dir.join("run"), r)?;
    let law = report.material_spec.build().map_err(|e| e.to_string())?;
    let steps: Vec<&StepRecord> = report.steps().collect();
    let mut series = vec![];
    // the Maxwell plateau: the steps whose mid-span sits in the propagating bulge
    let maxwell = if c.spec.tolerance.keys().any(|q| q.starts_with("maxwell_")) {
        let m = tubemem_gps::limits::limit_points(law.as_ref(), Hypothesis::Gps)
            .map_err(|e| e.to_string())?
            .maxwell
            .ok_or("the law has no Maxwell pressure (no pressure minimum)")?;
        let polygon = crate::case::Case::parse(&c.case_text)
            .map_err(|e| crate::error_chain(&e))?
            .mesh
            .polygon_factor()
            .ok_or(
                "maxwell_*: the case needs a generated mesh (`around`) for its polygon factor",
            )?;
        Some((m, polygon))
    } else {
        None
    };
    for (k, (q, tol)) in c.spec.tolerance.iter().enumerate() {
        let mut worst: Option<(f64, &StepRecord)> = None;
        let mut pts = vec![];
        let mut compared = 0;
        for (i, s) in steps.iter().enumerate() {
            let pair = match (q.as_str(), maxwell) {
                // the plateau's level: the step of least pressure among those whose mid-span
                // sits in the bulge (within 1 % of the upper coexisting stretch); a front near
                // a cap or near its mirror front only raises the pressure
                ("maxwell_w" | "maxwell_lambda_s", Some((m, polygon))) => {
                    let plateau = steps
                        .iter()
                        .filter(|t| {
                            t.contact.is_none()
                                && (t.midspan.lambda_s / m.lambda_s_upper - 1.0).abs() <= 0.01
                        })
                        .min_by(|a, b| a.midspan.w.total_cmp(&b.midspan.w));
                    match plateau {
                        Some(t) if std::ptr::eq(*t, *s) => Some(if q == "maxwell_w" {
                            (s.midspan.w, m.w * polygon)
                        } else {
                            (s.midspan.lambda_s, m.lambda_s_upper)
                        }),
                        _ => None,
                    }
                }
                ("maxwell_w" | "maxwell_lambda_s", None) => None,
                // the closed form is a uniform tube: not compared where the run found the tube
                // not uniform (a bulge), or a squeeze that started from such a tube
                _ if s.gps_applicable == Some(false) => None,
                _ => match q.strip_prefix("final_") {
                    Some(inner) if i + 1 == steps.len() => step_pair(s, inner),
                    Some(_) => None,
                    None => step_pair(s, q),
                },
            };
            // plotted as the share of the tolerance used, every quantity on one scale; a
            // `final_` quantity's curve shows every step, against the last step's tolerance
            let curve = match q.strip_prefix("final_") {
                Some(inner) if s.gps_applicable != Some(false) => step_pair(s, inner),
                _ => pair,
            };
            if let Some((fe, cf)) = curve.filter(|_| tol.value > 0.0) {
                pts.push(((i + 1) as f64, rel(fe, cf).abs() / tol.value));
            }
            if let Some((fe, cf)) = pair {
                let e = rel(fe, cf);
                compared += 1;
                if worst.is_none_or(|(w, _)| e.abs() > w.abs()) {
                    worst = Some((e, s));
                }
            }
        }
        match worst {
            None => r.measures.push(Measure::missing(
                q,
                tol,
                "no step of this run has this comparison",
            )),
            Some((e, s)) => r.measures.push(Measure::held(
                q,
                e.abs(),
                tol,
                format!(
                    "max |FE/GPS − 1| over {compared} steps, {e:+.3e} at stage {} step {}",
                    s.stage, s.step
                ),
            )),
        }
        series.push(Series {
            label: format!("{q}: |FE/GPS − 1| / tolerance"),
            points: pts,
            color: COLORS[k % COLORS.len()],
            stroke: Stroke::Solid,
            width: 2,
        });
    }
    // PS, reported: ϖ against PS at the same λs (inflation) or the same ρ from λs* (squeeze)
    let mut ps_worst = 0.0f64;
    let mut ps_pts = vec![];
    for (i, s) in steps.iter().enumerate() {
        let ps = match &s.contact {
            None => tubemem_gps::inflate(law.as_ref(), Hypothesis::Ps, s.midspan.lambda_s)
                .map(|p| p.w)
                .ok(),
            Some(ct) => tubemem_gps::flatten(
                law.as_ref(),
                Hypothesis::Ps,
                ct.initial_stretch,
                ct.values.rho,
            )
            .map(|p| p.w)
            .ok(),
        };
        if let Some(p) = ps {
            let e = rel(s.midspan.w, p);
            ps_pts.push(((i + 1) as f64, e));
            if e.abs() > ps_worst.abs() {
                ps_worst = e;
            }
        }
    }
    r.measures.push(Measure::reported(
        "w vs PS",
        ps_worst.abs(),
        format!("max |FE/PS − 1| = {ps_worst:+.3e} (reported: PS fixes λz = 1)"),
    ));
    r.details = serde_json::json!({
        "steps": steps.len(),
        "equations": report.mesh.equations,
        "material": report.material,
    });
    let n = steps.len().max(1) as f64;
    series.push(Series {
        label: "the tolerance".into(),
        points: vec![(1.0, 1.0), (n, 1.0)],
        color: RGBColor(0, 0, 0),
        stroke: Stroke::Dashed,
        width: 1,
    });
    // a `final_` quantity is judged at the last step only: its curve shows the others against
    // that step's tolerance, for the trend
    let notes = if c.spec.tolerance.keys().any(|q| q.starts_with("final_")) {
        vec!["final_*: judged at the last step only; the earlier steps are shown against its tolerance".to_string()]
    } else {
        vec![]
    };
    plot(
        &Figure {
            notes,
            ..Figure::new(
                format!("{}: FE against GPS at every step", c.spec.name),
                "step (all stages)",
                "share of the tolerance used",
                series,
            )
        },
        r,
    );
    Ok(None)
}

/// Where the `python_ref` folder is, when there is one to put on the module path: given
/// (`--python-ref`, `TUBEMEM_PYTHON_REF`), or the checkout's, searched upwards from `from` and
/// the working folder. None: the references are the `tubemem_ref` package installed in the
/// interpreter (`pip install ./python_ref`).
fn find_python_ref(opts: &VerifyOptions, from: &Path) -> Option<PathBuf> {
    if let Some(p) = &opts.python_ref {
        return Some(p.clone());
    }
    if let Some(p) = std::env::var_os("TUBEMEM_PYTHON_REF") {
        return Some(PathBuf::from(p));
    }
    let cwd = std::env::current_dir().ok();
    for start in [Some(from.to_path_buf()), cwd].into_iter().flatten() {
        let start = start.canonicalize().unwrap_or(start);
        for d in start.ancestors() {
            if d.join("python_ref")
                .join("tubemem_ref")
                .join("compare.py")
                .is_file()
            {
                return Some(d.join("python_ref"));
            }
        }
    }
    None
}

/// The interpreter that runs the references: `--python`, `TUBEMEM_PYTHON`, the `.venv` next to
/// the `python_ref` folder found, else `python3`.
fn python_for(opts: &VerifyOptions, python_ref: Option<&Path>) -> PathBuf {
    if let Some(p) = &opts.python {
        return p.clone();
    }
    if let Some(p) = std::env::var_os("TUBEMEM_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = python_ref
        .and_then(Path::parent)
        .map(|d| d.join(".venv").join("bin").join("python"));
    match venv {
        Some(v) if v.is_file() => v,
        _ => PathBuf::from("python3"),
    }
}

/// How to point `tubemem verify` at the references, for the messages of a skipped check.
pub const REFERENCES_HOWTO: &str = "install them in the interpreter (pip install ./python_ref) and pass it with --python or TUBEMEM_PYTHON, or name the python_ref folder with --python-ref or TUBEMEM_PYTHON_REF; the README's test command creates .venv with them";

fn reference(c: &Check, dir: &Path, opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let pref = find_python_ref(opts, &c.base_dir);
    let python = python_for(opts, pref.as_deref());
    // the module path: the folder found first (a checkout's own references win over an
    // installed copy), then whatever the interpreter has installed
    let path_arg = pref
        .as_ref()
        .map_or(String::new(), |p| p.display().to_string());
    let prelude = "import sys\nif sys.argv[1]: sys.path.insert(0, sys.argv[1])\n";
    let probe = std::process::Command::new(&python)
        .arg("-c")
        .arg(format!("{prelude}import tubemem_ref.compare, skfem, scipy"))
        .arg(&path_arg)
        .output();
    let whence = match &pref {
        Some(p) => format!("with {} on its path", p.display()),
        None => "(no python_ref folder found: the installed package was tried)".into(),
    };
    match probe {
        Err(e) => {
            return Ok(Some(format!(
                "no Python interpreter at {} ({e}): the scikit-fem references cannot run; {REFERENCES_HOWTO}",
                python.display()
            )))
        }
        Ok(o) if !o.status.success() => {
            let err = String::from_utf8_lossy(&o.stderr);
            let last = err.lines().last().unwrap_or("").to_string();
            return Ok(Some(format!(
                "the scikit-fem references do not import in {} {whence} ({last}); {REFERENCES_HOWTO}",
                python.display()
            )));
        }
        Ok(_) => {}
    }
    let run_dir = dir.join("run");
    let report = member(c, &c.case_text, &run_dir, r)?;
    let cmp = dir.join("compare");
    let script = format!("{prelude}import json, math\nimport tubemem_ref.compare as compare\nrows = compare.compare(sys.argv[2], sys.argv[3], plot=True)\nclean = [[None if isinstance(v, float) and not math.isfinite(v) else v for v in row] for row in rows]\nprint('TUBEMEM_JSON ' + json.dumps(clean))\n");
    let o = std::process::Command::new(&python)
        .arg("-c")
        .arg(script)
        .arg(&path_arg)
        .arg(&run_dir)
        .arg(&cmp)
        .output()
        .map_err(|e| format!("running {}: {e}", python.display()))?;
    let stdout = String::from_utf8_lossy(&o.stdout);
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        return Err(format!(
            "the references (tubemem_ref.compare) failed: {}",
            err.lines().last().unwrap_or("(no message)")
        ));
    }
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("TUBEMEM_JSON "))
        .ok_or("the references (tubemem_ref.compare) printed no result")?;
    let rows: Vec<Vec<serde_json::Value>> =
        serde_json::from_str(line).map_err(|e| format!("compare.py's result: {e}"))?;
    let num = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    for (q, tol) in &c.spec.tolerance {
        let mut worst: Option<(f64, String)> = None;
        for row in &rows {
            let (stage, quantity) = (num(&row[0]), row[2].as_str().unwrap_or(""));
            let profile_row = match q.as_str() {
                "profile" => Some("profile max |Δλs|"),
                "profile_lambda_z" => Some("profile max |Δλz|"),
                _ => None,
            };
            let (value, note) = if profile_row.is_some_and(|p| quantity == p) {
                (
                    num(&row[3]),
                    format!(
                        "stage {stage}: {quantity} along the tube, at Z = {:.3}",
                        num(&row[4])
                    ),
                )
            } else if quantity == q {
                (
                    num(&row[6]).abs(),
                    format!(
                        "stage {stage}: FE {:.7} against scikit-fem {:.7}",
                        num(&row[3]),
                        num(&row[4])
                    ),
                )
            } else {
                continue;
            };
            if worst.as_ref().is_none_or(|(w, _)| value > *w) {
                worst = Some((value, note));
            }
        }
        match worst {
            Some((v, note)) => r.measures.push(Measure::held(q, v, tol, note)),
            None => r.measures.push(Measure::missing(
                q,
                tol,
                "the references gave no such comparison for this run",
            )),
        }
    }
    r.details = serde_json::json!({ "rows": rows, "material": report.material });
    // the reference's own profile plot, when it drew one
    if let Some(p) = (1..=report.stages.len())
        .map(|k| cmp.join(format!("profile_stage{k}.png")))
        .find(|p| p.is_file())
    {
        r.png = std::fs::read(p).ok();
    }
    Ok(None)
}

fn scale_mesh(t: &mut toml::Table, factor: f64) {
    if let Some(m) = t.get_mut("mesh").and_then(|m| m.as_table_mut()) {
        for key in ["around", "along", "cap_rows"] {
            if let Some(v) = m.get(key).and_then(|v| v.as_integer()) {
                let n = ((v as f64) * factor).round().max(1.0) as i64;
                m.insert(key.into(), toml::Value::Integer(n));
            }
        }
    }
}

fn convergence(c: &Check, dir: &Path, r: &mut CheckResult) -> KindResult {
    let ratio = c.spec.refinement.unwrap_or(2.0);
    let n = c.spec.meshes.unwrap_or(3);
    let start = c.spec.start.unwrap_or(0);
    let base: toml::Table = toml::from_str(&c.case_text).map_err(|e| e.to_string())?;
    if base.get("mesh").and_then(|m| m.get("file")).is_some() {
        return Err(
            "a convergence family needs a generated mesh (`around`, `along`), not a mesh file"
                .into(),
        );
    }
    let mut reports = vec![];
    let mut arounds = vec![];
    for k in 0..n {
        let e = start + k as i32;
        let f = ratio.powi(e);
        let text = vary(&c.case_text, |t| scale_mesh(t, f))?;
        let t: toml::Table = toml::from_str(&text).map_err(|e| e.to_string())?;
        arounds.push(
            t.get("mesh")
                .and_then(|m| m.get("around"))
                .and_then(|v| v.as_integer())
                .unwrap_or(0),
        );
        let d = dir.join(format!("mesh_{k}"));
        r.runs.push(d.display().to_string());
        reports.push(run_member(
            &text,
            &c.base_dir,
            &d,
            &format!("check {} mesh {k}", c.spec.name),
        )?);
    }
    let squeeze = reports[0]
        .steps()
        .last()
        .is_some_and(|s| s.contact.is_some());
    let quantities: Vec<String> = c.spec.quantities.clone().unwrap_or_else(|| {
        let mut q = vec!["w".to_string(), "lambda_z".to_string()];
        if squeeze {
            q.push("force".into());
        }
        q
    });
    // the actual ratios from the element counts around
    let h: Vec<f64> = arounds.iter().map(|&a| 1.0 / a as f64).collect();
    let fine = n - 1;
    let r21 = h[fine - 1] / h[fine];
    let r32 = h[fine - 2] / h[fine - 1];
    let mut table = vec![];
    let mut series = vec![];
    for (qi, q) in quantities.iter().enumerate() {
        let vals: Vec<f64> = reports
            .iter()
            .map(|rep| final_value(rep, q).unwrap_or(f64::NAN))
            .collect();
        // the reference: the closed form at the finest member's last step
        let last = reports[fine].steps().last();
        let reference = last
            .and_then(|s| step_pair(s, q))
            .map(|p| p.1)
            .filter(|_| c.spec.compare_reference.unwrap_or(true));
        let phi = [vals[fine], vals[fine - 1], vals[fine - 2]];
        if phi.iter().any(|v| !v.is_finite()) {
            return Err(format!("`{q}` is not a value of these runs"));
        }
        // the family's values relative to `v`, against (h/h_finest)²
        let against = |v: f64| -> Vec<(f64, f64)> {
            h.iter()
                .zip(&vals)
                .map(|(hh, x)| ((hh * arounds[fine] as f64).powi(2), rel(*x, v)))
                .collect()
        };
        let ordered = c
            .spec
            .order_quantities
            .as_ref()
            .is_none_or(|o| o.contains(q));
        match stats::gci(phi, r21, r32) {
            // an oscillating family has no order: its uncertainty is half the range of its
            // values (Stern, Wilson, Coleman & Paterson 2001, oscillatory convergence)
            Err(stats::GciError::Oscillatory { .. }) if !ordered => {
                let (lo, hi) = phi
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                        (a.min(v), b.max(v))
                    });
                let u = 0.5 * (hi - lo) / phi[0].abs();
                r.measures.push(Measure::reported(
                    &format!("{q} uncertainty"),
                    u,
                    format!(
                        "oscillatory convergence ({:.6e}, {:.6e}, {:.6e}, coarse to fine): no order; half the range over the finest value (Stern et al. 2001)",
                        phi[2], phi[1], phi[0]
                    ),
                ));
                table.push(serde_json::json!({
                    "quantity": q, "values": vals, "oscillatory": true, "uncertainty": u,
                }));
                series.push(Series {
                    label: format!("{q}: φ/φ_finest − 1 (oscillatory)"),
                    points: against(phi[0]),
                    color: COLORS[qi % COLORS.len()],
                    stroke: Stroke::Dashed,
                    width: 2,
                });
            }
            Err(e) => {
                r.measures.push(Measure {
                    quantity: format!("{q} order"),
                    measured: f64::NAN,
                    tolerance: None,
                    source: None,
                    pass: false,
                    note: e.to_string(),
                    at_least: false,
                });
                table.push(
                    serde_json::json!({"quantity": q, "values": vals, "error": e.to_string()}),
                );
            }
            Ok(g) => {
                if let Some(exp) = c.spec.expected_order.as_ref().filter(|_| ordered) {
                    r.measures.push(Measure::expected(
                        &format!("{q} "),
                        "p",
                        g.order,
                        exp,
                        "observed order",
                    ));
                }
                if let Some(reference) = reference {
                    // the reference within the extrapolated value ± GCI (+ a stated tolerance)
                    let dist = ((g.extrapolated - reference) / reference).abs();
                    let extra = c.spec.tolerance.get(q.as_str());
                    let allowed = g.gci_fine + extra.map_or(0.0, |t| t.value);
                    r.measures.push(Measure {
                        quantity: format!("{q} reference"),
                        measured: dist,
                        tolerance: Some(allowed),
                        source: Some(match extra {
                            Some(t) => {
                                format!("GCI of the finest mesh {:.2e} + {}", g.gci_fine, t.source)
                            }
                            None => {
                                format!("GCI of the finest mesh {:.2e} (Fs = 1.25)", g.gci_fine)
                            }
                        }),
                        pass: dist <= allowed,
                        note: format!(
                            "|φ_ext/GPS − 1|: extrapolated {:.9} against GPS {:.9}",
                            g.extrapolated, reference
                        ),
                        at_least: false,
                    });
                }
                r.measures.push(Measure::reported(
                    &format!("{q} GCI"),
                    g.gci_fine,
                    format!(
                        "p = {:.3}, φ_ext = {:.9}, finest φ1 = {:.9}",
                        g.order, g.extrapolated, phi[0]
                    ),
                ));
                table.push(serde_json::json!({
                    "quantity": q, "values": vals, "order": g.order,
                    "extrapolated": g.extrapolated, "gci_fine": g.gci_fine,
                    "relative_error": g.relative_error, "reference": reference,
                }));
                // against GPS when the check compares with it, else against the extrapolated
                // value (the family's own limit: what the mesh error is measured from)
                let (reference_value, label) = match reference {
                    Some(reference) => (reference, format!("{q}: FE/GPS − 1")),
                    None => (
                        g.extrapolated,
                        format!("{q}: φ/φ_ext − 1 (p = {:.2})", g.order),
                    ),
                };
                series.push(Series {
                    label,
                    points: against(reference_value),
                    color: COLORS[qi % COLORS.len()],
                    stroke: Stroke::Solid,
                    width: 2,
                });
            }
        }
    }
    r.details =
        serde_json::json!({ "around": arounds, "r21": r21, "r32": r32, "quantities": table });
    plot(
        &Figure {
            notes: vec![format!("elements around: {arounds:?}")],
            ..Figure::new(
                format!("{}: mesh convergence", c.spec.name),
                "(h/h_finest)² (h ∝ 1/elements around)",
                if c.spec.compare_reference.unwrap_or(true) {
                    "FE/GPS − 1"
                } else {
                    "relative to the family's limit"
                },
                series,
            )
        },
        r,
    );
    Ok(None)
}

fn end_effect(c: &Check, dir: &Path, r: &mut CheckResult) -> KindResult {
    let lengths = c.spec.lengths.clone().unwrap_or_default();
    let law = c.spec.law.unwrap_or(stats::EndLaw::Exponential);
    // the check's own quantity first, then any others fitted from the same runs
    let quantities: Vec<String> = match (&c.spec.quantity, &c.spec.quantities) {
        (Some(q), Some(more)) => std::iter::once(q.clone())
            .chain(more.iter().filter(|m| *m != q).cloned())
            .collect(),
        (None, Some(more)) if !more.is_empty() => more.clone(),
        (q, _) => vec![q.clone().unwrap_or_else(|| "w".into())],
    };
    let q = quantities[0].clone();
    let eps = c.spec.epsilon.unwrap_or(1e-3);
    let base: toml::Table = toml::from_str(&c.case_text).map_err(|e| e.to_string())?;
    let g = base.get("geometry").and_then(|g| g.as_table());
    let num =
        |v: Option<&toml::Value>| v.and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)));
    let radius = num(g.and_then(|g| g.get("radius"))).unwrap_or(1.0);
    let l0 =
        num(g.and_then(|g| g.get("length"))).ok_or("the case has no [geometry] length")? / radius;
    let mut errors = vec![];
    let mut others: Vec<Vec<f64>> = vec![vec![]; quantities.len() - 1];
    for (k, &l) in lengths.iter().enumerate() {
        let text = vary(&c.case_text, |t| {
            if let Some(g) = t.get_mut("geometry").and_then(|g| g.as_table_mut()) {
                g.insert("length".into(), toml::Value::Float(l * radius));
            }
            // the same element length along
            if let Some(m) = t.get_mut("mesh").and_then(|m| m.as_table_mut()) {
                if let Some(a) = m.get("along").and_then(|v| v.as_integer()) {
                    let n = ((a as f64) * l / l0).round().max(2.0) as i64;
                    m.insert("along".into(), toml::Value::Integer(n + n % 2));
                }
            }
        })?;
        let d = dir.join(format!("length_{k}"));
        r.runs.push(d.display().to_string());
        let rep = run_member(
            &text,
            &c.base_dir,
            &d,
            &format!("check {} L/R = {l}", c.spec.name),
        )?;
        let last = rep.steps().last().ok_or("a member run has no step")?;
        let (fe, cf) =
            step_pair(last, &q).ok_or(format!("`{q}` has no closed form at the last step"))?;
        errors.push(rel(fe, cf));
        for (o, more) in others.iter_mut().zip(&quantities[1..]) {
            o.push(step_pair(last, more).map_or(f64::NAN, |(fe, cf)| rel(fe, cf)));
        }
    }
    let fit =
        stats::fit_end_law(law, &lengths, &errors).ok_or("the end-effect law cannot be fitted")?;
    if let Some(e) = &c.spec.decay_rate {
        r.measures.push(Measure::expected(
            "",
            "k",
            fit.k,
            e,
            "fitted decay rate per R",
        ));
    }
    if let Some(e) = &c.spec.amplitude {
        r.measures
            .push(Measure::expected("", "A", fit.a, e, "fitted amplitude"));
    }
    if let Some(t) = &c.spec.max_residual {
        r.measures.push(Measure::held(
            "fit residual",
            fit.relative_residual,
            t,
            "rms residual of the law over max |e − c|".into(),
        ));
    }
    let needed = fit.length_for(eps);
    r.measures.push(Measure::reported(
        "length needed",
        needed,
        format!("L/R ≥ {needed:.2} for an end effect |A f(L/R)| ≤ ε = {eps:e}"),
    ));
    // the other quantities: their laws and lengths, reported; (quantity, errors, fit) of each
    // fitted one, for the details and the plot
    let mut fitted: Vec<(&str, &[f64], stats::EndFit)> = vec![(q.as_str(), &errors, fit)];
    let mut fits = serde_json::Map::new();
    fits.insert(
        q.clone(),
        serde_json::json!({"errors": errors, "fit": fit, "length_for_epsilon": needed}),
    );
    for (more, errs) in quantities[1..].iter().zip(&others) {
        let f = errs
            .iter()
            .all(|e| e.is_finite())
            .then(|| stats::fit_end_law(law, &lengths, errs))
            .flatten();
        match f {
            Some(f) => {
                let n = f.length_for(eps);
                r.measures.push(Measure::reported(
                    &format!("length needed ({more})"),
                    n,
                    format!(
                        "{more}: L/R ≥ {n:.2} for ε = {eps:e}; end effect {:+.3e} at L/R = {l0}, fit residual {:.1e}",
                        f.end_effect(l0),
                        f.relative_residual
                    ),
                ));
                fits.insert(
                    more.clone(),
                    serde_json::json!({"errors": errs, "fit": f, "length_for_epsilon": n}),
                );
                fitted.push((more.as_str(), errs, f));
            }
            None => {
                r.measures.push(Measure::reported(
                    &format!("length needed ({more})"),
                    f64::NAN,
                    format!("{more}: the end-effect law cannot be fitted to {errs:?}"),
                ));
            }
        }
    }
    r.details = serde_json::json!({
        "quantity": q, "lengths": lengths, "errors": errors, "fit": fit,
        "length_for_epsilon": needed, "epsilon": eps, "fits": fits,
    });
    let law_text = match law {
        stats::EndLaw::Exponential => format!(
            "c + A exp(−k L/R): c = {:.3e}, A = {:.3e}, k = {:.4}",
            fit.c, fit.a, fit.k
        ),
        stats::EndLaw::Inverse => format!("c + A/(L/R): c = {:.3e}, A = {:.4e}", fit.c, fit.a),
    };
    r.message = format!("{law_text}; L/R ≥ {needed:.1} for ε = {eps:e}");
    let (lmin, lmax) = lengths
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &l| (a.min(l), b.max(l)));
    // each fitted quantity: the FE points and the law, as log10 |FE/GPS − 1 − c|
    let mut markers = vec![];
    let mut series = vec![];
    let log = |v: f64| v.abs().max(1e-300).log10();
    for (k, &(name, errs, f)) in fitted.iter().enumerate() {
        markers.push(Markers {
            label: format!("FE, {name}"),
            points: lengths
                .iter()
                .zip(errs)
                .map(|(l, e)| (*l, log(e - f.c)))
                .collect(),
            color: COLORS[k % COLORS.len()],
            hollow: false,
        });
        series.push(Series {
            label: if k == 0 {
                format!("{name}: {law_text}")
            } else {
                format!("{name}: fitted law")
            },
            points: (0..=60)
                .map(|j| {
                    let l = lmin + (lmax - lmin) * j as f64 / 60.0;
                    (l, log(f.end_effect(l)))
                })
                .collect(),
            color: COLORS[k % COLORS.len()],
            stroke: Stroke::Solid,
            width: 2,
        });
    }
    plot(
        &Figure {
            markers,
            ..Figure::new(
                format!("{}: end effect on {}", c.spec.name, quantities.join(", ")),
                "tube length L/R",
                "log10 |FE/GPS − 1 − c|",
                series,
            )
        },
        r,
    );
    // the law's measures decide; when they pass the message is the fit
    Ok(None)
}

/// The core of one profile: (core length on the +z side, on the −z side (None for a model
/// symmetric about z = 0), the quantity that ends the core on the +z side). The geometric
/// contact width is compared only where the mid-span flat, π × `contact_width`, spans at least
/// `resolution` (the mesh's node spacing around: the width comes from zero crossings of nodal
/// values, O(h), and a flat narrower than a node spacing is below what it resolves; at a
/// squeeze's first touch, a flat of 5e-4 R, it varies by 1 % along the middle while the
/// contact force per length, compared always, varies by 9e-4).
fn core(
    rings: &[tubemem_fem::post::RingValues],
    eps: f64,
    resolution: f64,
) -> Option<(f64, Option<f64>, String)> {
    let mid = rings
        .iter()
        .min_by(|a, b| a.z_ref.abs().total_cmp(&b.z_ref.abs()))?;
    let m = &mid.values;
    let checks = |r: &tubemem_fem::post::RingValues| -> Option<&'static str> {
        let v = &r.values;
        for (name, a, b) in [
            ("lambda_s", v.lambda_s, m.lambda_s),
            ("lambda_z", v.lambda_z, m.lambda_z),
            ("n_s", v.n_s, m.n_s),
            ("n_z", v.n_z, m.n_z),
        ] {
            if (a / b - 1.0).abs() > eps {
                return Some(name);
            }
        }
        if (v.n_sz - m.n_sz).abs() > eps * m.n_s.abs() {
            return Some("n_sz");
        }
        if std::f64::consts::PI * mid.contact_width >= resolution
            && (r.contact_width / mid.contact_width - 1.0).abs() > eps
        {
            return Some("contact_width");
        }
        if mid.contact_force > 0.0 && (r.contact_force / mid.contact_force - 1.0).abs() > eps {
            return Some("contact_force");
        }
        None
    };
    let side = |sign: f64| -> Option<(f64, String)> {
        let mut s: Vec<_> = rings.iter().filter(|r| sign * r.z_ref >= -1e-12).collect();
        if s.len() < 2 {
            return None;
        }
        s.sort_by(|a, b| a.z_ref.abs().total_cmp(&b.z_ref.abs()));
        let mut core = 0.0;
        for r in &s {
            if let Some(q) = checks(r) {
                return Some((core, q.to_string()));
            }
            core = r.z_ref.abs();
        }
        Some((core, "none".into()))
    };
    let (plus, why) = side(1.0)?;
    let minus = side(-1.0).map(|s| s.0);
    Some((plus, minus, why))
}

fn invariance(c: &Check, dir: &Path, r: &mut CheckResult) -> KindResult {
    let eps = c.spec.epsilon.unwrap_or(1e-3);
    let report = member(c, &c.case_text, &dir.join("run"), r)?;
    let half = 0.5 * report.geometry.length;
    let length = report.geometry.length;
    let mut per_step = vec![];
    let mut worst: Option<(f64, &StepRecord, String)> = None;
    let mut pts = vec![];
    // the node spacing around the mid-span ring of a generated tube, per R (0 for a user mesh: the
    // width is then always compared)
    let case = crate::case::Case::parse(&c.case_text).map_err(|e| crate::error_chain(&e))?;
    let nodes_around = case
        .mesh
        .around
        .map(|n| n * (case.mesh.element.gauss_per_direction() - 1));
    for (i, s) in report.steps().enumerate() {
        if s.profile.is_empty() {
            continue;
        }
        let resolution = nodes_around.map_or(0.0, |n| {
            2.0 * std::f64::consts::PI * s.midspan.lambda_s / n as f64
        });
        let Some((plus, minus, why)) = core(&s.profile, eps, resolution) else {
            continue;
        };
        let minus = minus.unwrap_or(plus);
        let fraction = (plus + minus) / length;
        per_step.push(serde_json::json!({
            "stage": s.stage, "step": s.step, "core_length": (plus + minus) / report.geometry.radius,
            "core_fraction": fraction,
            "boundary_layer_plus": (half - plus) / report.geometry.radius,
            "boundary_layer_minus": (half - minus) / report.geometry.radius,
            "limited_by": why,
        }));
        pts.push(((i + 1) as f64, fraction));
        if worst.as_ref().is_none_or(|(f, _, _)| fraction < *f) {
            worst = Some((fraction, s, why));
        }
    }
    let Some((fraction, s, why)) = worst else {
        return Err("the run has no per-step profiles ([output] profiles = \"stage-end\"?)".into());
    };
    // without `min_core_fraction` the core is reported, not gated
    let tol = c.spec.min_core_fraction.clone();
    r.measures.push(Measure {
        quantity: "core fraction".into(),
        measured: fraction,
        tolerance: tol.as_ref().map(|t| t.value),
        source: tol.as_ref().map(|t| t.source.clone()),
        pass: tol.as_ref().is_none_or(|t| fraction >= t.value),
        at_least: tol.is_some(),
        note: format!(
            "smallest over {} steps, at stage {} step {}: the middle {:.2} R of {:.2} R stay within ε = {eps:e} of mid-span (then {why} leaves it); boundary layer {:.2} R at each cap",
            per_step.len(),
            s.stage,
            s.step,
            fraction * length / report.geometry.radius,
            length / report.geometry.radius,
            (1.0 - fraction) * 0.5 * length / report.geometry.radius,
        ),
    });
    if tol.is_none() {
        r.message = format!(
            "the middle {:.0} % of the tube is translation invariant (ε = {eps:e}), at its smallest (stage {} step {}); reported",
            100.0 * fraction,
            s.stage,
            s.step
        );
    }
    r.details = serde_json::json!({ "epsilon": eps, "steps": per_step });
    plot(
        &Figure::new(
            format!("{}: translation-invariant core", c.spec.name),
            "step (all stages)",
            "core length / L",
            std::iter::once(Series {
                label: format!("core within ε = {eps:e}"),
                points: pts.clone(),
                color: COLORS[0],
                stroke: Stroke::Solid,
                width: 2,
            })
            .chain(tol.as_ref().map(|t| Series {
                label: "required".into(),
                points: vec![(1.0, t.value), (pts.len().max(1) as f64, t.value)],
                color: COLORS[1],
                stroke: Stroke::Dashed,
                width: 2,
            }))
            .collect(),
        ),
        r,
    );
    Ok(None)
}

/// The steps.csv text of a report (the writer's format).
fn steps_csv(report: &RunReport) -> String {
    let mut t = format!("{STEPS_HEADER}\n");
    for s in report.steps() {
        t.push_str(&crate::output::format_row(s));
        t.push('\n');
    }
    t
}

fn close(a: f64, b: f64, rel_err: f64, abs_zero: f64) -> bool {
    (a.abs() <= abs_zero && b.abs() <= abs_zero) || (a - b).abs() <= rel_err * a.abs().max(b.abs())
}

/// Compare two JSON values' numbers (CSVDiff-like); the first difference's path.
fn json_diff(
    path: &str,
    a: &serde_json::Value,
    b: &serde_json::Value,
    rel_err: f64,
    abs_zero: f64,
    worst: &mut f64,
) -> Option<String> {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64()?, y.as_f64()?);
            let d = if x.abs() <= abs_zero && y.abs() <= abs_zero {
                0.0
            } else {
                (x - y).abs() / x.abs().max(y.abs())
            };
            *worst = worst.max(d);
            (!close(x, y, rel_err, abs_zero)).then(|| format!("{path}: {x} against gold {y}"))
        }
        (Value::Object(x), Value::Object(y)) => {
            for (k, v) in y {
                if k == "case" || k == "tubemem_version" {
                    continue; // a label of where the run was started; the build that ran it
                }
                let p = format!("{path}.{k}");
                match x.get(k) {
                    None => return Some(format!("{p}: missing (gold has it)")),
                    Some(w) => {
                        if let Some(d) = json_diff(&p, w, v, rel_err, abs_zero, worst) {
                            return Some(d);
                        }
                    }
                }
            }
            None
        }
        (Value::Array(x), Value::Array(y)) => {
            if x.len() != y.len() {
                return Some(format!(
                    "{path}: {} entries against gold {}",
                    x.len(),
                    y.len()
                ));
            }
            for (k, (v, w)) in x.iter().zip(y).enumerate() {
                if let Some(d) = json_diff(&format!("{path}[{k}]"), v, w, rel_err, abs_zero, worst)
                {
                    return Some(d);
                }
            }
            None
        }
        (x, y) if x == y => None,
        (x, y) => Some(format!("{path}: {x} against gold {y}")),
    }
}

fn gold(c: &Check, dir: &Path, opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let report = member(c, &c.case_text, &dir.join("run"), r)?;
    let steps = steps_csv(&report);
    let summary = serde_json::to_value(report.summary()).map_err(|e| e.to_string())?;
    let gsteps = c.gold_dir.join("steps.csv");
    let gsummary = c.gold_dir.join("summary.json");
    if opts.update_gold {
        std::fs::create_dir_all(&c.gold_dir)
            .map_err(|e| format!("{}: {e}", c.gold_dir.display()))?;
        tubemem_mesh::file::write_whole(&gsteps, steps.as_bytes())
            .map_err(|e| format!("{}: {e}", gsteps.display()))?;
        let text = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())?;
        tubemem_mesh::file::write_whole(&gsummary, (text + "\n").as_bytes())
            .map_err(|e| format!("{}: {e}", gsummary.display()))?;
        r.message = format!(
            "gold files rewritten in {} (--update-gold)",
            c.gold_dir.display()
        );
        return Ok(None);
    }
    let rel_err = c.spec.rel_err.unwrap_or(1e-10);
    let abs_zero = c.spec.abs_zero.unwrap_or(1e-12);
    let gold_steps = std::fs::read_to_string(&gsteps).map_err(|e| {
        format!(
            "no gold file {} ({e}): run `tubemem verify … --update-gold` to create it",
            gsteps.display()
        )
    })?;
    let gold_summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&gsummary).map_err(|e| format!("{}: {e}", gsummary.display()))?,
    )
    .map_err(|e| format!("{}: {e}", gsummary.display()))?;
    // steps: every gold column (columns are only ever appended), row by row
    let parse = |t: &str| -> (Vec<String>, Vec<Vec<String>>) {
        let mut l = t.lines();
        let h = l
            .next()
            .unwrap_or("")
            .split(',')
            .map(String::from)
            .collect();
        (
            h,
            l.map(|x| x.split(',').map(String::from).collect())
                .collect(),
        )
    };
    let (gh, grows) = parse(&gold_steps);
    let (h, rows) = parse(&steps);
    let mut first: Option<String> = None;
    let mut worst = 0.0f64;
    if grows.len() != rows.len() {
        first = Some(format!(
            "steps.csv: {} rows against gold {}",
            rows.len(),
            grows.len()
        ));
    }
    for (ri, (a, b)) in rows.iter().zip(&grows).enumerate() {
        for (gi, col) in gh.iter().enumerate() {
            let Some(ci) = h.iter().position(|x| x == col) else {
                first.get_or_insert(format!("steps.csv: no column `{col}` (gold has it)"));
                continue;
            };
            let (x, y) = (
                a.get(ci).map(String::as_str).unwrap_or(""),
                b.get(gi).map(String::as_str).unwrap_or(""),
            );
            match (x.parse::<f64>(), y.parse::<f64>()) {
                (Ok(x), Ok(y)) => {
                    let d = if x.abs() <= abs_zero && y.abs() <= abs_zero {
                        0.0
                    } else {
                        (x - y).abs() / x.abs().max(y.abs())
                    };
                    worst = worst.max(d);
                    if !close(x, y, rel_err, abs_zero) {
                        first.get_or_insert(format!(
                            "steps.csv row {} `{col}`: {x} against gold {y}",
                            ri + 1
                        ));
                    }
                }
                _ if x == y => {}
                _ => {
                    first.get_or_insert(format!(
                        "steps.csv row {} `{col}`: `{x}` against gold `{y}`",
                        ri + 1
                    ));
                }
            }
        }
    }
    if let Some(d) = json_diff(
        "summary",
        &summary,
        &gold_summary,
        rel_err,
        abs_zero,
        &mut worst,
    ) {
        first.get_or_insert(d);
    }
    r.measures.push(Measure {
        quantity: "largest relative difference".into(),
        measured: worst,
        tolerance: Some(rel_err),
        source: Some(format!(
            "CSVDiff-style rel_err = {rel_err:e}, abs_zero = {abs_zero:e}: the run must reproduce its gold to the solver's tolerance"
        )),
        pass: first.is_none(),
        note: first.clone().unwrap_or_else(|| format!("{} rows and the summary match", rows.len())),
        at_least: false,
    });
    Ok(None)
}
