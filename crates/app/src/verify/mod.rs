//! `tubemem verify`: the verification suite as a product.
//!
//! A suite file ([`suite`]) lists checks; each runs its case (and its mesh or length family)
//! into its own folder and compares what the typed [`RunReport`] says with a reference. The
//! kinds (closed-form, reference, convergence, end-effect, invariance, gold) are one file each
//! in [`kinds`], behind the [`kinds::VerifyKind`] trait; [`quantity`] maps a quantity's name to
//! its FE and closed-form values.
//!
//! Checks run in parallel (rayon, `jobs` threads). [`report`] writes results.json, report.md,
//! a self-contained report.html and junit.xml. [`study`] builds the checks for a user's own
//! case (`tubemem verify --case`).

pub mod kinds;
pub mod report;
// the quantity lookup and the statistics (GCI, end-effect fits) are the crate's: the atlas uses
// them too
pub use crate::{quantity, stats};
pub mod study;
pub mod suite;

use crate::case::Case;
use crate::output::{FolderMode, RunWriter};
use crate::report::RunReport;
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

/// The verification's interrupt flag, installed now if none is (a library caller such as the
/// Python module sets it from its own signal checks, and clears it before each call).
pub fn interrupt_flag() -> Arc<AtomicBool> {
    INTERRUPT
        .get_or_init(|| Arc::new(AtomicBool::new(false)))
        .clone()
}

/// Whether the verification was interrupted.
pub fn interrupted() -> bool {
    INTERRUPT.get().is_some_and(|f| f.load(Ordering::Relaxed))
}
use kinds::VerifyKind;
use suite::{Check, Tol};

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
    /// `measured` held to `tol` (passes when finite and at most the tolerance).
    pub fn held(quantity: &str, measured: f64, tol: &Tol, note: String) -> Self {
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
    /// A fitted or observed value `found` against an expectation `value ± within`.
    pub fn expected(label: &str, symbol: &str, found: f64, e: &suite::Expect, note: &str) -> Self {
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
    /// A number reported without a tolerance.
    pub fn reported(quantity: &str, measured: f64, note: String) -> Self {
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
    /// the kind's label (`closed-form`, …)
    pub kind: &'static str,
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
    // each check is a folder under `out`: one name in two suites would be one folder, the
    // second run refused by the first's lock (and blamed on this very process)
    let mut seen: std::collections::HashMap<&str, &str> = Default::default();
    for c in checks {
        if let Some(other) = seen.insert(&c.spec.name, &c.suite) {
            return Err(crate::AppError::Folder {
                path: out.join(&c.spec.name),
                message: format!(
                    "check `{}` is in suite `{other}` and in suite `{}`: check names must be unique across the suites of one run (each is a folder under --out); rename one",
                    c.spec.name, c.suite
                ),
            });
        }
    }
    // a user's own results.json (or report.md, …) in `out` is refused before any check runs
    report::check_folder(out)?;
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
            kind: c.spec.kind.label(),
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
    run_check_with(kinds::kind_of(c.spec.kind), c, out, opts)
}

/// Run check `c` as `kind` into `out/<name>/`: the kind's measures decide the status (pass
/// when every measure passes), its error or skip reason becomes the message, its figure the
/// plot. The kind given here wins over `c`'s own `kind`.
pub fn run_check_with(
    kind: &dyn VerifyKind,
    c: &Check,
    out: &Path,
    opts: &VerifyOptions,
) -> CheckResult {
    let t0 = std::time::Instant::now();
    let dir = out.join(&c.spec.name);
    let mut r = CheckResult {
        kind: kind.label(),
        ..CheckResult::empty(c)
    };
    let outcome = match std::fs::create_dir_all(&dir) {
        Err(e) => Err(format!("cannot create {}: {e}", dir.display())),
        Ok(()) => kind.evaluate(c, &dir, opts, &mut r),
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
                // nothing held to a tolerance (every measure reported): say what was measured
                if r.message.is_empty() {
                    r.message = r
                        .measures
                        .iter()
                        .map(|m| format!("{}: {}", m.quantity, m.note))
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
    /// the study's ε is not an accuracy
    #[error("--epsilon {0}: the accuracy asked for must be a relative number in (0, 0.5)")]
    Epsilon(f64),
}

/// A kind's error message: the whole chain.
impl From<VerifyError> for String {
    fn from(e: VerifyError) -> String {
        crate::error_chain(&e)
    }
}

/// A case text with edits applied to its TOML tables. Member runs write VTU at stage ends only
/// and no checkpoints, unless the case says otherwise.
pub fn vary(text: &str, edit: impl FnOnce(&mut toml::Table)) -> Result<String, VerifyError> {
    let mut t: toml::Table = toml::from_str(text).map_err(VerifyError::Toml)?;
    edit(&mut t);
    crate::case::member_output_defaults(&mut t, "stage-end");
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
