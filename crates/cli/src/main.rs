//! `tubemem`: the command-line front end.
//!
//! With no arguments it runs the main job (`main_job`): the paper's example in 3D on the
//! embedded default case, against GPS and PS, and the figures, written to `tubemem-out/`.

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use tubemem_cli::{figures, gps_cmd, main_job, run_cmd};

#[derive(Parser, Debug)]
#[command(
    name = "tubemem",
    version,
    about = "Verification suite for pressurized membrane tubes: closed-form generalized plane strain (GPS) and plane strain (PS)",
    long_about = "Verification suite for pressurized membrane tubes.\n\nWith no subcommand, runs the main job: the paper's example (Anssari-Benam–Bucchi law, 𝒩 = 30) in 3D on the embedded default case cases/squeeze_abb30_ls1.3.toml (inflation to λs* = 1.3, gas closed in, squeeze to ρ = 0.8), compared with the GPS and PS closed forms, and the figures with the FE points, all written to ./tubemem-out."
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
        /// Output folder (created if missing).
        #[arg(long, default_value = "tubemem-out/run")]
        out: PathBuf,
    },
    /// Write PNG and CSV reproductions of the paper's Figs. 5, 6, 7 and a λz-vs-λs figure.
    Figures {
        /// Output folder (created if missing).
        #[arg(long, default_value = "tubemem-out/figures")]
        out: PathBuf,
        /// Kuhn segment number 𝒩 of the Anssari-Benam–Bucchi law.
        #[arg(long, default_value_t = 30.0)]
        kuhn: f64,
        /// A `tubemem run` output folder whose FE points are drawn over Figs. 5–7 (repeatable).
        #[arg(long)]
        overlay: Vec<PathBuf>,
    },
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => main_job::run(&PathBuf::from("tubemem-out")),
        Some(Command::Gps { command }) => gps_cmd::run(command),
        Some(Command::Run { case, out }) => run_cmd::run(&case, &out),
        Some(Command::Figures { out, kuhn, overlay }) => {
            let written = figures::write_all(&out, kuhn, &overlay)?;
            for p in written {
                println!("wrote {}", p.display());
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
