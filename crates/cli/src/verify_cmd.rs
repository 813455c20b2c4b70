//! `tubemem verify`: runs suites of checks (or the study of one case) and writes results.json,
//! report.md, report.html and junit.xml. Exit codes: 0 every check passed (or was skipped with
//! its reason), 1 a check failed or could not run, 2 a usage or setup error (a bad suite file,
//! a case that does not parse, an output folder that cannot be written).

use std::io::Write;
use std::path::PathBuf;
use tubemem_app::verify::{self, report::Results, Event, VerifyOptions};

#[derive(clap::Args, Debug)]
pub struct VerifyArgs {
    /// Suite files (TOML; see the README's "tubemem verify" section).
    pub suites: Vec<PathBuf>,
    /// Instead of suites: the study of this case: three meshes refined by 2 from the case's
    /// (n, 2n, 4n around), the end effect from three lengths (gas closed: L, 2L, 4L; an
    /// inflation: L/2, L, 2L), the translation-invariant core, the references, then the FE
    /// against GPS with an allowance built from those estimates.
    #[arg(long, conflicts_with = "suites")]
    pub case: Option<PathBuf>,
    /// With --case: the cheaper family: meshes n/2, n, 2n around (n the case's; n, 2n, 4n where
    /// n/2 is not a valid mesh) and lengths L, 1.5L, 2L (gas closed) or L/2, 3L/4, L (an
    /// inflation). About a sixth of the full study's cost.
    #[arg(long, requires = "case")]
    pub quick: bool,
    /// With --case: the accuracy asked for, relative (default 1e-3): the tube length whose end
    /// effect is below it, the translation-invariant core within it, and a mesh family whose
    /// values agree within it counts as converged.
    #[arg(long, requires = "case", value_name = "EPS")]
    pub epsilon: Option<f64>,
    /// Output folder: a folder per check, results.json, report.md, report.html, junit.xml.
    #[arg(long)]
    pub out: PathBuf,
    /// Checks run at once (default: the number of cores).
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
    /// Run only the checks whose name contains this text.
    #[arg(long)]
    pub filter: Option<String>,
    /// Rewrite the gold files of `gold` checks from this run (on request only).
    #[arg(long)]
    pub update_gold: bool,
    /// The Python interpreter that runs the scikit-fem references (the `reference` checks):
    /// default $TUBEMEM_PYTHON, else the .venv next to the python_ref folder found, else
    /// python3. Outside the checkout, install the references in it (pip install ./python_ref).
    #[arg(long)]
    pub python: Option<PathBuf>,
    /// The python_ref folder to import the references from, when they are not installed in the
    /// interpreter: default $TUBEMEM_PYTHON_REF, else the python_ref of a checkout above the
    /// case (or suite) or the working folder.
    #[arg(long)]
    pub python_ref: Option<PathBuf>,
}

/// Exit code 2: the verification could not be set up.
fn setup(message: impl std::fmt::Display) -> u8 {
    let message = tubemem_material::tidy_numbers(&message.to_string());
    let _ = writeln!(std::io::stderr(), "error: {message}");
    2
}

pub fn run(a: VerifyArgs) -> u8 {
    // SIGINT or SIGTERM: the checks not started are skipped, the runs in progress stop at
    // their next Newton iteration, the report of what ran is written, exit code 130
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let f = flag.clone();
    if ctrlc::set_handler(move || f.store(true, std::sync::atomic::Ordering::Relaxed)).is_ok() {
        verify::set_interrupt(flag);
    }
    let opts = VerifyOptions {
        jobs: a.jobs,
        filter: a.filter.clone(),
        update_gold: a.update_gold,
        python: a.python.clone(),
        python_ref: a.python_ref.clone(),
    };
    let progress = |e: Event| {
        let mut err = std::io::stderr().lock();
        let _ = match e {
            Event::Started { .. } => Ok(()),
            Event::Finished {
                done,
                total,
                result: r,
            } => writeln!(
                err,
                "[{done}/{total}] {:<7} {:<12} {} ({:.1} s): {}",
                r.status.label(),
                r.kind,
                r.name,
                r.seconds,
                r.message
            ),
        };
    };
    if let Err(e) = std::fs::create_dir_all(&a.out) {
        return setup(format!("--out {}: {e}", a.out.display()));
    }
    let t0 = std::time::Instant::now();
    let (names, results, verdict) = if let Some(case) = &a.case {
        let _ = writeln!(
            std::io::stderr(),
            "study of {}: end effect, invariance, references and the mesh convergence, then the closed form",
            case.display()
        );
        let study = verify::study::StudyOptions {
            quick: a.quick,
            epsilon: a.epsilon.unwrap_or(verify::study::DEFAULT_EPSILON),
        };
        match verify::study::run_study(case, &a.out, &study, &opts, &progress) {
            Ok(s) => (
                vec![format!("study of {}", case.display())],
                s.results,
                Some(s.verdict),
            ),
            Err(e) => return setup(tubemem_app::error_chain(&e)),
        }
    } else {
        if a.suites.is_empty() {
            return setup("give suite files (e.g. verify/ci.toml) or --case CASE.toml");
        }
        let mut checks = vec![];
        let mut names = vec![];
        for s in &a.suites {
            match verify::suite::read_suite(s) {
                Ok((name, c)) => {
                    names.push(name);
                    checks.extend(c);
                }
                Err(e) => return setup(e),
            }
        }
        let n = checks
            .iter()
            .filter(|c| {
                opts.filter
                    .as_deref()
                    .is_none_or(|f| c.spec.name.contains(f))
            })
            .count();
        if n == 0 {
            return setup(format!(
                "no check matches --filter {:?}",
                opts.filter.as_deref().unwrap_or("")
            ));
        }
        let _ = writeln!(
            std::io::stderr(),
            "{n} check{} from {}",
            if n == 1 { "" } else { "s" },
            names.join(", ")
        );
        match verify::run_checks(&checks, &a.out, &opts, &progress) {
            Ok(r) => (names, r, None),
            Err(e) => return setup(e.chain()),
        }
    };
    let results = Results::new(names, t0.elapsed().as_secs_f64(), &results, verdict);
    let written = match verify::report::write_all(&a.out, &results) {
        Ok(w) => w,
        Err(e) => return setup(e.chain()),
    };
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{}", results.verdict);
    for p in written {
        let _ = writeln!(out, "wrote {}", p.display());
    }
    if verify::interrupted() {
        let _ = writeln!(
            std::io::stderr(),
            "interrupted: the report holds the checks that ran; those not started are skipped"
        );
        return 130;
    }
    if results.ok() {
        0
    } else {
        1
    }
}
