//! `tubemem gps …` and the default job.
use crate::material_args::MaterialArgs;
use anyhow::{bail, Result};
use clap::{Args, Subcommand, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;
use tubemem_app::curves::{
    flattening_values, inflation_values, FLATTENING_HEADER, INFLATION_HEADER,
};
use tubemem_gps::limits::{limit_points, Limits};
use tubemem_gps::{flatten, flattening_curve, inflate, inflation_curve, Hypothesis};

fn write_csv(
    path: &std::path::Path,
    header: &str,
    rows: impl Iterator<Item = Vec<f64>>,
) -> Result<()> {
    tubemem_app::curves::write_csv(path, header, rows).map_err(|e| anyhow::anyhow!(e.chain()))
}

#[derive(Copy, Clone, Debug, ValueEnum)]
pub enum Hyp {
    /// generalized plane strain (λz from the end-cap balance)
    Gps,
    /// plane strain (λz = 1)
    Ps,
}

impl From<Hyp> for Hypothesis {
    fn from(h: Hyp) -> Self {
        match h {
            Hyp::Gps => Hypothesis::Gps,
            Hyp::Ps => Hypothesis::Ps,
        }
    }
}

#[derive(Subcommand, Debug)]
pub enum GpsCommand {
    /// Free inflation (eqs. 66 and 70): one state at --stretch, or a curve --from/--to/--points into --csv.
    Inflate(InflateArgs),
    /// Flattening between two plates with the gas closed in (eqs. 76–79): one state at --rho, or a curve --to/--points into --csv.
    Flatten(FlattenArgs),
    /// Pressure maximum and minimum of the inflation curve and the Maxwell pressure.
    Limits(LimitsArgs),
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct InflateArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: Hyp,
    /// Hoop stretch λs (≥ 1) for a single state.
    #[arg(long)]
    stretch: Option<f64>,
    /// First λs of a curve.
    #[arg(long)]
    from: Option<f64>,
    /// Last λs of a curve.
    #[arg(long)]
    to: Option<f64>,
    /// Number of points of a curve (≥ 2).
    #[arg(long)]
    points: Option<usize>,
    /// Write the curve to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Print one JSON object (a single state) instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct FlattenArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: Hyp,
    /// The inflated hoop stretch λs* at which the gas is closed in.
    #[arg(long)]
    initial_stretch: f64,
    /// Half-gap ρ = r/R (0 < ρ < λs*) for a single state.
    #[arg(long)]
    rho: Option<f64>,
    /// Last ρ of a curve that starts at ρ = λs*.
    #[arg(long)]
    to: Option<f64>,
    /// Number of points of a curve (≥ 2).
    #[arg(long)]
    points: Option<usize>,
    /// Write the curve to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct LimitsArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: Hyp,
    #[arg(long)]
    json: bool,
}

/// Refuse to print a non-finite number: it would be a silent wrong answer.
fn ensure_finite(values: &[f64]) -> Result<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        bail!("internal error: a non-finite value was computed ({values:?}); please report this input")
    }
}

fn print_state<T: Serialize>(state: &T, json: bool) -> Result<()> {
    let v = serde_json::to_value(state)?;
    if json {
        crate::say!("{v}")?;
    } else if let Some(map) = v.as_object() {
        for (k, x) in map {
            crate::say!("{k:>13} = {x}")?;
        }
    }
    Ok(())
}

pub fn run(cmd: GpsCommand) -> Result<()> {
    match cmd {
        GpsCommand::Inflate(a) => {
            let law = a.material.build()?;
            let hyp = a.hypothesis.into();
            match (a.stretch, a.to, a.points, &a.csv) {
                (Some(ls), None, None, None) if a.from.is_none() => {
                    let s = inflate(law.as_ref(), hyp, ls)?;
                    ensure_finite(&inflation_values(&s))?;
                    print_state(&s, a.json)
                }
                (None, Some(to), Some(points), Some(csv)) => {
                    let from = a.from.unwrap_or(1.0);
                    let c = inflation_curve(law.as_ref(), hyp, from, to, points)?;
                    write_csv(csv, INFLATION_HEADER, c.iter().map(inflation_values))?;
                    crate::say!("wrote {} {} inflation states (λs {from} → {to}) to {}", c.len(), hyp.label(), csv.display())?;
                    Ok(())
                }
                _ => bail!("give either --stretch λs (one state) or --to, --points and --csv (a curve, with optional --from)"),
            }
        }
        GpsCommand::Flatten(a) => {
            let law = a.material.build()?;
            let hyp = a.hypothesis.into();
            match (a.rho, a.to, a.points, &a.csv) {
                (Some(rho), None, None, None) => {
                    let s = flatten(law.as_ref(), hyp, a.initial_stretch, rho)?;
                    ensure_finite(&flattening_values(&s))?;
                    print_state(&s, a.json)
                }
                (None, Some(to), Some(points), Some(csv)) => {
                    let c = flattening_curve(law.as_ref(), hyp, a.initial_stretch, to, points)?;
                    write_csv(csv, FLATTENING_HEADER, c.iter().map(flattening_values))?;
                    crate::say!(
                        "wrote {} {} flattening states (ρ {} → {to}) to {}",
                        c.len(),
                        hyp.label(),
                        a.initial_stretch,
                        csv.display()
                    )?;
                    Ok(())
                }
                _ => bail!("give either --rho ρ (one state) or --to, --points and --csv (a curve)"),
            }
        }
        GpsCommand::Limits(a) => {
            let law = a.material.build()?;
            let l = limit_points(law.as_ref(), a.hypothesis.into())?;
            print_limits(&l, a.json)
        }
    }
}

fn print_limits(l: &Limits, json: bool) -> Result<()> {
    let mut nums = vec![];
    for p in [l.max, l.min].into_iter().flatten() {
        nums.extend([p.lambda_s, p.lambda_z, p.w]);
    }
    if let Some(m) = l.maxwell {
        nums.extend([m.w, m.lambda_s_lower, m.lambda_s_upper]);
    }
    ensure_finite(&nums)?;
    if json {
        let v = serde_json::json!({ "max": l.max, "min": l.min, "maxwell": l.maxwell });
        crate::say!("{v}")?;
        return Ok(());
    }
    let point = |name: &str, p: Option<tubemem_gps::limits::LimitPoint>| match p {
        Some(p) => crate::say!(
            "{name:>8}: ϖ = {:.10}  at λs = {:.10}, λz = {:.10}",
            p.w,
            p.lambda_s,
            p.lambda_z
        ),
        None => crate::say!("{name:>8}: none"),
    };
    point("maximum", l.max)?;
    point("minimum", l.min)?;
    match l.maxwell {
        Some(m) => crate::say!(
            " Maxwell: ϖ = {:.10}  coexisting λs = {:.10} and {:.10}",
            m.w,
            m.lambda_s_lower,
            m.lambda_s_upper
        )?,
        None => crate::say!(" Maxwell: none")?,
    }
    crate::say!(
        "(inflation curve scanned for λs from 1 to {:.3})",
        l.scanned_to
    )?;
    Ok(())
}
