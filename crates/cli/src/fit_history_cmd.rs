//! `tubemem fit --history …`: a viscoelastic (QLV Prony) law from test histories (issue #63).

use anyhow::{bail, Result};
use std::path::{Path, PathBuf};
use tubemem_app::fit::default_start;
use tubemem_app::fit_history::{
    default_prony, prony_table, read_history_file, run_fit_histories, save_history_figure,
};
use tubemem_material::fit::{FitOptions, Mode, TestData};

/// What `tubemem fit --history` was given (`fit_cmd` checks the rest of its flags).
pub struct HistoryFit<'a> {
    /// a model name, a material table or a TOML file (as `--law`)
    pub law: &'a str,
    pub history: &'a [PathBuf],
    /// `--prony` g:τ pairs
    pub prony: Option<&'a str>,
    pub prony_terms: usize,
    pub opts: FitOptions,
    pub plot: Option<&'a Path>,
    pub overwrite: bool,
    pub json: bool,
}

pub fn run(a: HistoryFit) -> Result<()> {
    if !(1..=tubemem_material::viscoelastic::MAX_TERMS).contains(&a.prony_terms) {
        bail!(
            "--prony-terms {}: give 1 to {}",
            a.prony_terms,
            tubemem_material::viscoelastic::MAX_TERMS
        );
    }
    // the figure's files checked before anything is read
    if let Some(stem) = a.plot {
        let law_file = Some(PathBuf::from(a.law)).filter(|p| p.is_file());
        let inputs: Vec<&Path> = a
            .history
            .iter()
            .chain(&law_file)
            .map(|p| p.as_path())
            .collect();
        crate::fit_print::check_plot(stem, &inputs, "Prony terms to", a.overwrite)?;
    }
    let files = a
        .history
        .iter()
        .map(|p| read_history_file(p, Mode::Uniaxial))
        .collect::<Result<Vec<_>, _>>()?;
    let units: Vec<_> = files
        .iter()
        .map(|f| (f.unit.map(|u| u.name), f.proportional))
        .collect();
    if units.windows(2).any(|w| w[0] != w[1]) {
        bail!("the histories give their stresses in different units (or some as a force of unknown unit): give them all alike");
    }
    let (unit, proportional) = units[0];
    let data: Vec<_> = files.into_iter().map(|f| f.data).collect();
    let table = a.law.contains('=') || a.law.ends_with(".toml");
    let start = if table {
        crate::material_args::law_of(a.law)?
    } else {
        // the elastic start from each history's loading points (stretch and stress until the
        // largest stretch): the instantaneous law's scale
        let loading: Vec<TestData> = data
            .iter()
            .map(|h| {
                let top =
                    h.stretch
                        .iter()
                        .enumerate()
                        .fold(0, |b, (i, l)| if *l > h.stretch[b] { i } else { b });
                TestData {
                    mode: Mode::Uniaxial,
                    stretch: h.stretch[..=top].to_vec(),
                    stress: h.stress[..=top].to_vec(),
                }
            })
            .collect();
        default_start(a.law.trim(), &loading)?
    };
    let prony0 = match a.prony {
        Some(p) => crate::gps_history::parse_prony(p)?.terms().to_vec(),
        None => default_prony(&data, a.prony_terms),
    };
    let result = run_fit_histories(&start, &prony0, &data, &a.opts)?;
    let unit_name = if proportional {
        "(force)"
    } else {
        unit.unwrap_or("(data)")
    };
    if let Some(stem) = a.plot {
        let y = if proportional {
            "force (proportional to the nominal stress; unit not stated)".to_string()
        } else {
            format!("nominal stress P ({unit_name})")
        };
        for p in save_history_figure(
            &result,
            &data,
            &y,
            stem,
            &tubemem_app::figures::FigureOptions::default(),
        )? {
            if a.json {
                eprintln!("wrote {}", p.display());
            } else {
                crate::say!("wrote {}", p.display())?;
            }
        }
    }
    if a.json {
        crate::say!("{}", serde_json::to_string_pretty(&result)?)?;
    } else {
        crate::say!(
            "{}: {} points in {} histories, residual standard deviation {:.3e} {unit_name} (largest residual {:.2} % of the largest stress)\n{}",
            if result.converged { "converged" } else { "NOT CONVERGED" },
            result.points,
            data.len(),
            result.residual_std,
            100.0 * result.max_relative_residual,
            result.stop_reason
        )?;
        crate::fit_print::parameter_lines(&result, unit_name)?;
        crate::say!("per history (rms residual in {unit_name}, largest residual over the history's largest stress):")?;
        for t in &result.tests {
            crate::say!(
                "  {:<32} {:>5} points  rms {:.3e}  max {:.2} %",
                t.name,
                t.points,
                t.rms,
                100.0 * t.max_relative
            )?;
        }
        for w in &result.warnings {
            crate::say!("warning: {w}")?;
        }
        if proportional {
            crate::say!("note: the data give a force of unknown unit; the moduli are in its units (scale them to the specimen's section before using the law), the Prony series and the law's shape are physical")?;
        }
        crate::say!(
            "\n{}{}",
            tubemem_app::fit::material_table(&result.spec, None),
            result.prony.as_deref().map(prony_table).unwrap_or_default()
        )?;
    }
    if !result.converged {
        bail!(
            "the fit did not converge: {} (the best iterate is printed above, not a fitted law)",
            result.stop_reason
        );
    }
    Ok(())
}
