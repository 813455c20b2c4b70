//! `tubemem`: the command-line front end.
//!
//! With no arguments it runs the main job (`main_job`): the paper's example in 3D on the
//! embedded default case, against GPS and PS, and the figures, written to `tubemem-out/`.

use anyhow::Context;
use anyhow::Result;
use clap::{CommandFactory, Parser, Subcommand};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use tubemem_app::case::Case;
use tubemem_app::observer::Observer;
use tubemem_app::output::{FolderMode, RunWriter};
use tubemem_app::run::RunOptions;
use tubemem_cli::console::Console;
use tubemem_cli::gps_cmd;

#[derive(Parser, Debug)]
#[command(
    name = "tubemem",
    version,
    about = "Verification suite for pressurized membrane tubes: closed-form generalized plane strain (GPS) and plane strain (PS)",
    long_about = "Verification suite for pressurized membrane tubes.\n\nWith no subcommand, runs the main job: the paper's example (Anssari-Benam–Bucchi law, 𝒩 = 30) in 3D on the embedded default case cases/squeeze_abb30_ls1.3_quad9.toml (9-node elements, the node lines following the contact edges; inflation to λs* = 1.3, gas closed in, squeeze to ρ = 0.8), compared with the GPS and PS closed forms, and the figures with the FE points, all written to ./tubemem-out."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Closed-form GPS / PS solutions (paper Secs. 3.6, 3.7, 4).
    Gps {
        #[command(subcommand)]
        command: gps_cmd::GpsCommand,
    },
    /// Run a finite element case file; writes steps.csv, summary.json, profiles/ and a VTU series.
    Run {
        /// The case file (TOML).
        case: PathBuf,
        /// Output folder (created if missing). A folder that already holds a run is refused.
        #[arg(long, default_value = "tubemem-out/run")]
        out: PathBuf,
        /// Replace the run already in the output folder (only tubemem's own files are removed).
        #[arg(long)]
        overwrite: bool,
        /// Run even a model whose estimated memory exceeds what the machine has available.
        #[arg(long)]
        force: bool,
        /// Continue the run in the output folder from its last checkpoint (the case file must
        /// be the one it started with).
        #[arg(long, conflicts_with = "overwrite")]
        resume: bool,
        /// Also write one line per converged step to this file (stage, step, elapsed time, ϖ,
        /// λs, Newton iterations, residual, fraction of the stage), like an Abaqus .sta file.
        #[arg(long)]
        log: Option<PathBuf>,
    },
    /// Fit a law's parameters to uniaxial, equibiaxial and pure-shear test data (nominal stress
    /// against stretch), with each parameter's standard error and a warning for any the data
    /// do not determine; prints the fitted material table for a case file.
    Fit(tubemem_cli::fit_cmd::FitArgs),
    /// Run verification checks (suite files, or the study of one case) and write results.json,
    /// report.md, report.html and junit.xml. Exit code 0: all passed; 1: a check failed; 2: a
    /// usage or setup error.
    Verify(tubemem_cli::verify_cmd::VerifyArgs),
    /// Where GPS holds: run an atlas file (one FE run per λs* and L/R), fit the end-effect law
    /// per (λs*, ρ, quantity) and write the minimum L/R per ε (atlas.csv) with its maps;
    /// `tubemem atlas predict DIR …` prints the laws' prediction at a point. Exit code 0:
    /// written; 1: member runs failed (kept as errors); 2: a usage or setup error.
    Atlas(tubemem_cli::atlas_cmd::AtlasArgs),
    /// Write the case's model (mesh, symmetry conditions, neo-Hookean or Mooney–Rivlin
    /// material, follower pressure and load steps) as an input deck of another code, to run the
    /// identical model there. Squeeze, confine and arc-length stages and the ABB law are refused
    /// with the reason.
    Export {
        /// The case file (TOML).
        case: PathBuf,
        #[arg(long, value_enum, default_value = "abaqus")]
        format: ExportFormat,
        /// The deck to write.
        #[arg(long)]
        out: PathBuf,
        /// The element for 4-node meshes (9-node meshes are written as Abaqus M3D9).
        #[arg(long, value_enum, default_value = "s4")]
        element: ExportElement,
        /// The bulk modulus over the small-strain shear modulus, K/μ (D1 = 2/K): the solid
        /// elements CalculiX expands shells into need one.
        #[arg(long, default_value_t = 1000.0)]
        bulk_ratio: f64,
    },
    /// Write SVG/PNG and CSV reproductions of the paper's Figs. 5, 6, 7 and a λz-vs-λs figure,
    /// for any law, with FE runs overlaid (their points also as CSV, and an FE − GPS panel under
    /// Figs. 6–7).
    Figures {
        /// Output folder (created if missing).
        #[arg(long, default_value = "tubemem-out/figures")]
        out: PathBuf,
        #[command(flatten)]
        material: tubemem_cli::material_args::OptionalMaterialArgs,
        /// A `tubemem run` output folder whose FE points are drawn over Figs. 5–7 (repeatable).
        /// A run of another law than the curves' is refused.
        #[arg(long)]
        overlay: Vec<PathBuf>,
        /// File formats to write (comma-separated).
        #[arg(long, value_delimiter = ',', default_value = "png,svg")]
        format: Vec<FigureFormat>,
        /// PNG resolution (the canvas is 11 × 7.6 in; 100 dpi = 1100 × 760 pixels).
        #[arg(long, default_value_t = tubemem_app::figures::BASE_DPI)]
        dpi: f64,
    },
    /// Print the JSON Schema of case files (for editors: Taplo and Even Better TOML complete
    /// and check a case file with `#:schema ./case.schema.json` on its first line).
    Schema {
        /// Print the schema of a run's summary.json instead, each key with its meaning.
        #[arg(long)]
        summary: bool,
    },
    /// Print the column dictionary of the CSV files a run writes (steps.csv, profiles,
    /// walls.csv, critical_points.csv, fronts.csv, iterations.csv) as Markdown tables.
    Columns,
    /// Print the shell completion script for bash, zsh, fish, elvish or PowerShell, generated
    /// from these options (bash: `source <(tubemem completions bash)`).
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: tubemem_cli::shell_cmd::Shell,
    },
    /// Write the man pages (tubemem.1 and one per subcommand, tubemem-run.1, …), generated from
    /// these options (read one with `man -l DIR/tubemem-run.1`).
    Man {
        /// Output folder (created if missing). A file there that is not a tubemem man page is
        /// refused and nothing is written.
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
enum ExportFormat {
    /// an Abaqus/CalculiX input deck (.inp)
    Abaqus,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
enum ExportElement {
    /// S4 shells of the case's thickness (CalculiX and Abaqus)
    S4,
    /// M3D4 membranes (CalculiX and Abaqus)
    M3d4,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
enum FigureFormat {
    Png,
    Svg,
}

/// An application error as an `anyhow` chain (its causes kept).
fn app(e: tubemem_app::AppError) -> anyhow::Error {
    anyhow::Error::new(e)
}

fn main_job() -> Result<()> {
    tubemem_cli::say!(
        "tubemem — the paper's example (Anssari-Benam–Bucchi membrane, 𝒩 = 30; ϖ = pR/μH)\n"
    )?;
    let limits = tubemem_app::main_job::paper_limits().map_err(app)?;
    tubemem_cli::say!("{}\n", tubemem_app::main_job::limits_text(&limits))?;
    let mut console = Console::default();
    let job =
        tubemem_app::main_job::run_main_job(&PathBuf::from("tubemem-out"), &mut [&mut console])
            .map_err(app)?;
    tubemem_cli::say!("\n{}", job.table())?;
    for p in &job.figures {
        tubemem_cli::say!("wrote {}", p.display())?;
    }
    Ok(())
}

/// Set by SIGINT or SIGTERM: the run stops at its next Newton iteration and records that it
/// was interrupted.
fn interrupt_flag() -> Option<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    let f = flag.clone();
    // if a handler cannot be installed the run simply cannot be interrupted cleanly
    ctrlc::set_handler(move || f.store(true, Ordering::Relaxed))
        .ok()
        .map(|()| flag)
}

fn run_case(
    case_path: &std::path::Path,
    out: &std::path::Path,
    overwrite: bool,
    force: bool,
    resume: bool,
    log: Option<&std::path::Path>,
) -> Result<()> {
    let case = Case::read(case_path).map_err(|e| app(e.into()))?;
    let inputs = tubemem_app::output_file::case_inputs(case_path, &case);
    let inputs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    // the log is checked before the run folder is touched
    if let Some(path) = log {
        tubemem_app::output_file::check("--log", path, &inputs, tubemem_app::output_file::is_log)
            .map_err(app)?;
        // the run folder may not exist yet: compare absolute paths, canonical where they exist
        let resolved = |p: &std::path::Path| {
            p.canonicalize()
                .or_else(|_| {
                    let parent = p.parent().filter(|d| !d.as_os_str().is_empty());
                    match (parent.map(|d| d.canonicalize()), p.file_name()) {
                        (Some(Ok(d)), Some(n)) => Ok(d.join(n)),
                        _ => std::path::absolute(p),
                    }
                })
                .ok()
        };
        if resolved(path)
            .zip(resolved(out))
            .is_some_and(|(p, o)| p.starts_with(o))
        {
            return Err(app(tubemem_app::AppError::OutputFile {
                key: "--log",
                path: path.to_path_buf(),
                message: format!(
                    "is inside the run folder {}, whose files the run writes and replaces: give a path outside it",
                    out.display()
                ),
            }));
        }
    }
    let (mut writer, checkpoint) = if resume {
        let (w, ck) = RunWriter::resume(out, case.hash(), &inputs).map_err(app)?;
        tubemem_cli::say!(
            "resuming {} from stage {}, step {} ({} steps already in steps.csv)",
            out.display(),
            ck.context.stage,
            ck.progress.step,
            ck.rows
        )?;
        (w, Some(ck))
    } else {
        let mode = if overwrite {
            FolderMode::Overwrite
        } else {
            FolderMode::Fresh
        };
        (
            RunWriter::create(out, mode, case.hash(), &inputs).map_err(app)?,
            None,
        )
    };
    writer = writer
        .checkpoint_every(case.solver.checkpoint_every)
        .frames_of(case.output);
    let mut console = Console::default();
    if let Some(path) = log {
        console = console
            .with_log(path)
            .with_context(|| format!("cannot create the log {}", path.display()))?;
    }
    let options = RunOptions {
        resume: checkpoint,
        force,
        interrupt: interrupt_flag(),
    };
    let outcome = tubemem_app::run::run_with(
        &case,
        &case_path.display().to_string(),
        &options,
        &mut [&mut writer as &mut dyn Observer, &mut console],
    );
    match outcome.error {
        None => {
            tubemem_cli::say!(
                "wrote {}/steps.csv, summary.json, profiles/, tube.pvd ({} VTU frames)",
                out.display(),
                writer.frames()
            )?;
            Ok(())
        }
        Some(e) => {
            // what is on disk: a step whose outputs failed converged but was not kept
            let (converged, written) = (outcome.report.steps().count(), writer.steps_written());
            Err(app(e)).with_context(|| match written {
                0 if converged == 0 => {
                    format!("the run stopped before its first step ({})", out.display())
                }
                _ if written < converged => format!(
                    "the run stopped; {written} of its {converged} converged steps are in {} (steps.csv; the rest could not be written)",
                    out.display()
                ),
                _ => format!(
                    "the run stopped; its {written} converged steps are in {}",
                    out.display()
                ),
            })
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => main_job(),
        Some(Command::Verify(_)) => anyhow::bail!("internal: `verify` is dispatched in main"),
        Some(Command::Atlas(_)) => anyhow::bail!("internal: `atlas` is dispatched in main"),
        Some(Command::Gps { command }) => gps_cmd::run(command),
        Some(Command::Fit(a)) => tubemem_cli::fit_cmd::run(a),
        Some(Command::Schema { summary }) => {
            let schema = if summary {
                tubemem_app::report::summary_schema()
            } else {
                tubemem_app::case::schema()
            };
            let text = serde_json::to_string_pretty(&schema)?;
            tubemem_cli::say!("{text}")?;
            Ok(())
        }
        Some(Command::Columns) => {
            tubemem_cli::say!("{}", tubemem_app::columns::markdown().trim_end())?;
            Ok(())
        }
        Some(Command::Completions { shell }) => {
            tubemem_cli::shell_cmd::completions(shell, Cli::command())
        }
        Some(Command::Man { out }) => {
            let written = tubemem_cli::shell_cmd::man_pages(Cli::command(), &out)?;
            tubemem_cli::say!("wrote {} man pages to {}", written.len(), out.display())?;
            Ok(())
        }
        Some(Command::Run {
            case,
            out,
            overwrite,
            force,
            resume,
            log,
        }) => run_case(&case, &out, overwrite, force, resume, log.as_deref()),
        Some(Command::Export {
            case,
            format: ExportFormat::Abaqus,
            out,
            element,
            bulk_ratio,
        }) => {
            let c = Case::read(&case).map_err(|e| app(e.into()))?;
            let inputs = tubemem_app::output_file::case_inputs(&case, &c);
            let inputs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
            tubemem_app::output_file::check(
                "export --out",
                &out,
                &inputs,
                tubemem_app::output_file::is_deck,
            )
            .map_err(app)?;
            let shell = match element {
                ExportElement::S4 => tubemem_app::export::ShellChoice::S4,
                ExportElement::M3d4 => tubemem_app::export::ShellChoice::M3d4,
            };
            let deck = tubemem_app::export::abaqus_deck(
                &c,
                &case.display().to_string(),
                shell,
                bulk_ratio,
            )
            .with_context(|| format!("cannot export {}", case.display()))?;
            tubemem_mesh::file::write_whole(&out, deck.as_bytes())
                .with_context(|| format!("writing {}", out.display()))?;
            tubemem_cli::say!("wrote {}", out.display())?;
            Ok(())
        }
        Some(Command::Figures {
            out,
            material,
            overlay,
            format,
            dpi,
        }) => {
            use tubemem_app::figures;
            let overlays = overlay
                .iter()
                .map(|d| figures::Overlay::read(d))
                .collect::<tubemem_app::Result<Vec<_>>>()
                .map_err(app)?;
            let opts = figures::FigureOptions {
                png: format.contains(&FigureFormat::Png),
                svg: format.contains(&FigureFormat::Svg),
                dpi,
            };
            let written =
                figures::write_all(&out, material.spec()?, &overlays, &opts).map_err(app)?;
            for p in written {
                tubemem_cli::say!("wrote {}", p.display())?;
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(Command::Verify(a)) = cli.command {
        return ExitCode::from(tubemem_cli::verify_cmd::run(a));
    }
    if let Some(Command::Atlas(a)) = cli.command {
        return ExitCode::from(tubemem_cli::atlas_cmd::run(a));
    }
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e)
            if e.chain().any(|c| {
                matches!(
                    c.downcast_ref::<tubemem_app::AppError>(),
                    Some(tubemem_app::AppError::Interrupted { .. })
                )
            }) =>
        {
            let _ = writeln!(
                std::io::stderr(),
                "error: {}",
                tubemem_material::tidy_numbers(&format!("{e:#}"))
            );
            ExitCode::from(130)
        }
        Err(e) => {
            // a closed standard error cannot be reported anywhere: the exit code says it; the
            // numbers of every cause as a user reads them (1e308, not 309 digits)
            let _ = writeln!(
                std::io::stderr(),
                "error: {}",
                tubemem_material::tidy_numbers(&format!("{e:#}"))
            );
            ExitCode::FAILURE
        }
    }
}
