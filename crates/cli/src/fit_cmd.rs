//! `tubemem fit`: a law's parameters from uniaxial, equibiaxial and pure-shear test data.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use tubemem_app::fit::{
    common_unit, default_start, material_table, read_test_file, run_fit_with, save_figure,
    StressUnit, STRESS_UNITS,
};
use tubemem_material::fit::{FitOptions, Mode, DEFAULT_STARTS};

#[derive(Args, Debug, Clone)]
pub struct FitArgs {
    /// The law: a model name (its starting values estimated from the data), or the keys of a
    /// material table with starting values, e.g. 'model = "ogden", mu = [0.1, 0.01], alpha =
    /// [2, 5]', or a TOML file with a material table. Every number of the table is fitted,
    /// but those given to --fix.
    #[arg(long)]
    pub law: String,
    /// Uniaxial test: CSV with a header naming a `stretch` and a `nominal_stress` column, the
    /// stress's unit as its suffix (`stretch,nominal_stress_mpa`), then one row per point.
    #[arg(long)]
    pub uniaxial: Option<PathBuf>,
    /// Equibiaxial test: CSV as --uniaxial.
    #[arg(long)]
    pub equibiaxial: Option<PathBuf>,
    /// Pure-shear (planar tension) test: CSV as --uniaxial.
    #[arg(long)]
    pub pure_shear: Option<PathBuf>,
    /// A uniaxial test history (repeatable): CSV with a header naming `time` (or `time_s`, in
    /// seconds), `stretch` and `nominal_stress_UNIT` (or `force`, proportional to it, unit
    /// unknown). With histories the law is viscoelastic: the base law and a Prony series are
    /// fitted together.
    #[arg(long, value_name = "CSV")]
    pub history: Vec<PathBuf>,
    /// The Prony series' start for --history, as g:τ pairs (τ in seconds), e.g. 0.3:1,0.2:30.
    #[arg(long)]
    pub prony: Option<String>,
    /// Without --prony: this many Prony terms, their τ spread by decades over the data's
    /// time scales.
    #[arg(long, default_value_t = 3)]
    pub prony_terms: usize,
    /// The stresses' unit where the headers name none: Pa, kPa, MPa, GPa or psi. With a unit
    /// the fit works in Pa and prints the table for a case in SI.
    #[arg(long, value_name = "UNIT")]
    pub stress_unit: Option<String>,
    /// Hold a parameter at a value, e.g. --fix c30=0 (repeatable).
    #[arg(long, value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Bound a parameter, e.g. --bound c20=-1e4:1e4 (repeatable; an open side as -inf or inf).
    #[arg(long, value_name = "NAME=LOW:HIGH")]
    pub bound: Vec<String>,
    /// Starts tried besides the law's own (the best sum of squares is kept).
    #[arg(long, default_value_t = DEFAULT_STARTS)]
    pub starts: usize,
    /// Print the result as JSON (parameters, standard errors, correlation, warnings).
    #[arg(long)]
    pub json: bool,
    /// Write the fit's figure to PLOT.svg and PLOT.png.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Replace an existing PLOT.svg or PLOT.png that this command did not write.
    #[arg(long)]
    pub overwrite: bool,
}

/// `NAME=VALUE` of --fix.
fn fixed(s: &str) -> Result<(String, f64)> {
    let (n, v) = s
        .split_once('=')
        .with_context(|| format!("--fix {s}: give NAME=VALUE, e.g. --fix c30=0"))?;
    let v: f64 = v
        .trim()
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
        .with_context(|| format!("--fix {s}: `{}` is not a finite number", v.trim()))?;
    Ok((n.trim().to_string(), v))
}

/// `NAME=LOW:HIGH` of --bound.
fn bounded(s: &str) -> Result<(String, (f64, f64))> {
    let parse = |t: &str| -> Option<f64> {
        match t.trim() {
            "-inf" => Some(f64::NEG_INFINITY),
            "inf" | "+inf" => Some(f64::INFINITY),
            x => x.parse().ok().filter(|v: &f64| v.is_finite()),
        }
    };
    let (n, range) = s
        .split_once('=')
        .with_context(|| format!("--bound {s}: give NAME=LOW:HIGH, e.g. --bound c20=-1:1"))?;
    let (lo, hi) = range
        .split_once(':')
        .and_then(|(a, b)| Some((parse(a)?, parse(b)?)))
        .with_context(|| {
            format!("--bound {s}: LOW:HIGH must be two numbers (or -inf, inf), e.g. -1:1")
        })?;
    Ok((n.trim().to_string(), (lo, hi)))
}

pub fn run(a: FitArgs) -> Result<()> {
    if !a.history.is_empty() {
        if a.uniaxial.is_some() || a.equibiaxial.is_some() || a.pure_shear.is_some() {
            bail!("--history fits a viscoelastic law to histories; --uniaxial, --equibiaxial and --pure-shear fit an elastic law to curves: give one kind");
        }
        if a.stress_unit.is_some() {
            bail!("--stress-unit: a history names its stress's unit in its header (`nominal_stress_kpa`), or gives a `force` of unknown unit");
        }
        return crate::fit_history_cmd::run(crate::fit_history_cmd::HistoryFit {
            law: &a.law,
            history: &a.history,
            prony: a.prony.as_deref(),
            prony_terms: a.prony_terms,
            opts: FitOptions {
                fixed: a.fix.iter().map(|s| fixed(s)).collect::<Result<_>>()?,
                bounds: a.bound.iter().map(|s| bounded(s)).collect::<Result<_>>()?,
                starts: a.starts,
            },
            plot: a.plot.as_deref(),
            overwrite: a.overwrite,
            json: a.json,
        });
    }
    if a.prony.is_some() {
        bail!("--prony is the start of a viscoelastic fit: give --history files");
    }
    let unit: Option<StressUnit> = match &a.stress_unit {
        None => None,
        Some(u) => Some(
            STRESS_UNITS
                .iter()
                .copied()
                .find(|s| s.name.eq_ignore_ascii_case(u.trim()))
                .with_context(|| {
                    format!(
                        "--stress-unit {u}: one of {}",
                        STRESS_UNITS.map(|s| s.name).join(", ")
                    )
                })?,
        ),
    };
    // the figure's files checked against the inputs and existing files before anything is read
    if let Some(stem) = &a.plot {
        let law_file = Some(PathBuf::from(&a.law)).filter(|p| p.is_file());
        let inputs: Vec<&std::path::Path> = [&a.uniaxial, &a.equibiaxial, &a.pure_shear, &law_file]
            .into_iter()
            .flatten()
            .map(|p| p.as_path())
            .collect();
        crate::fit_print::check_plot(stem, &inputs, "Fit of the", a.overwrite)?;
    }
    let mut files = vec![];
    for (path, mode) in [
        (&a.uniaxial, Mode::Uniaxial),
        (&a.equibiaxial, Mode::Equibiaxial),
        (&a.pure_shear, Mode::PureShear),
    ] {
        if let Some(p) = path {
            files.push((p.clone(), read_test_file(p, mode, unit)?));
        }
    }
    if files.is_empty() {
        bail!("give test data: --uniaxial, --equibiaxial and/or --pure-shear CSV files");
    }
    let unit = common_unit(&files)?;
    let data: Vec<_> = files.into_iter().map(|(_, f)| f.data).collect();
    // a model name, unless it is a table (has `=`) or a file; a bare name is never read as a
    // file of that name in the working folder
    let table = a.law.contains('=') || a.law.ends_with(".toml");
    let start = if table {
        crate::material_args::law_of(&a.law)?
    } else {
        default_start(a.law.trim(), &data)?
    };
    let opts = FitOptions {
        fixed: a.fix.iter().map(|s| fixed(s)).collect::<Result<_>>()?,
        bounds: a.bound.iter().map(|s| bounded(s)).collect::<Result<_>>()?,
        starts: a.starts,
    };
    let result = run_fit_with(&start, &data, &opts)?;
    if let Some(stem) = &a.plot {
        let figure_opts = tubemem_app::figures::FigureOptions::default();
        for p in save_figure(&result, &data, unit, stem, &figure_opts)? {
            // standard output stays one JSON object with --json
            if a.json {
                eprintln!("wrote {}", p.display());
            } else {
                crate::say!("wrote {}", p.display())?;
            }
        }
    }
    let unit_name = unit.map_or("(data)", |u| u.name);
    if a.json {
        crate::say!("{}", serde_json::to_string_pretty(&result)?)?;
    } else {
        crate::say!(
            "{}: {} points, residual standard deviation {:.3e} {unit_name} (largest residual {:.2} % of the largest stress)\n{}",
            if result.converged {
                "converged"
            } else {
                "NOT CONVERGED"
            },
            result.points,
            result.residual_std,
            100.0 * result.max_relative_residual,
            result.stop_reason
        )?;
        crate::fit_print::parameter_lines(&result, unit_name)?;
        for w in &result.warnings {
            crate::say!("warning: {w}")?;
        }
        crate::say!("\n{}", material_table(&result.spec, unit))?;
    }
    if !result.converged {
        bail!(
            "the fit did not converge: {} (the best iterate is printed above, not a fitted law)",
            result.stop_reason
        );
    }
    Ok(())
}
