//! `tubemem fit`: a law's parameters from uniaxial, equibiaxial and pure-shear test data.

use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use tubemem_app::fit::{default_start, material_table, read_test, run_fit, save_figure};
use tubemem_material::fit::Mode;

#[derive(Args, Debug, Clone)]
pub struct FitArgs {
    /// The law: a model name (its starting values estimated from the data), or the keys of a
    /// material table with starting values, e.g. 'model = "ogden", mu = [0.1, 0.01], alpha =
    /// [2, 5]', or a TOML file with a material table. Every number of the table is fitted.
    #[arg(long)]
    pub law: String,
    /// Uniaxial test: CSV of stretch, nominal stress (a header line, then one pair a line).
    #[arg(long)]
    pub uniaxial: Option<PathBuf>,
    /// Equibiaxial test: CSV of stretch, nominal stress.
    #[arg(long)]
    pub equibiaxial: Option<PathBuf>,
    /// Pure-shear (planar tension) test: CSV of stretch, nominal stress.
    #[arg(long)]
    pub pure_shear: Option<PathBuf>,
    /// Print the result as JSON (parameters, standard errors, correlation, warnings).
    #[arg(long)]
    pub json: bool,
    /// Write the fit's figure to PLOT.svg and PLOT.png.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

pub fn run(a: FitArgs) -> Result<()> {
    let mut data = vec![];
    for (path, mode) in [
        (&a.uniaxial, Mode::Uniaxial),
        (&a.equibiaxial, Mode::Equibiaxial),
        (&a.pure_shear, Mode::PureShear),
    ] {
        if let Some(p) = path {
            data.push(read_test(p, mode)?);
        }
    }
    if data.is_empty() {
        bail!("give test data: --uniaxial, --equibiaxial and/or --pure-shear CSV files");
    }
    let start = if a.law.contains('=') || std::path::Path::new(&a.law).is_file() {
        crate::material_args::law_of(&a.law)?
    } else {
        default_start(a.law.trim(), &data)?
    };
    let result = run_fit(&start, &data)?;
    if let Some(stem) = &a.plot {
        let opts = tubemem_app::figures::FigureOptions::default();
        for p in save_figure(&result, &data, stem, &opts)? {
            // standard output stays one JSON object with --json
            if a.json {
                eprintln!("wrote {}", p.display());
            } else {
                crate::say!("wrote {}", p.display())?;
            }
        }
    }
    if a.json {
        crate::say!("{}", serde_json::to_string_pretty(&result)?)?;
        return Ok(());
    }
    crate::say!(
        "{} points, residual standard deviation {:.3e} (largest residual {:.2} % of the largest stress); {} after {} evaluations",
        result.points,
        result.residual_std,
        100.0 * result.max_relative_residual,
        result.termination,
        result.evaluations
    )?;
    for p in &result.parameters {
        crate::say!(
            "  {:<20} {:>14.6e} ± {:.2e}{}",
            p.name,
            p.value,
            p.std_error,
            if p.determined {
                ""
            } else {
                "   not determined by the data"
            }
        )?;
    }
    for w in &result.warnings {
        crate::say!("warning: {w}")?;
    }
    crate::say!("\n{}", material_table(&result.spec))?;
    Ok(())
}
