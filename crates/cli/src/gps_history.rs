//! `tubemem gps history`: the GPS free inflation in time with a viscoelastic (QLV Prony) law
//! ([`tubemem_gps::visco`]): a ramp of the pressure, the hoop stretch or the enclosed volume to
//! a target, then a hold (creep at constant pressure, relaxation at fixed volume).
use crate::material_args::{add_si, MaterialArgs, UnitArgs};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use tubemem_app::units::Dimension;
use tubemem_gps::visco::{inflation_history, Control, Segment};
use tubemem_material::viscoelastic::{Prony, PronyTerm};

/// The header of `gps history --csv` (dimensionless columns; SI ones follow with --radius).
pub const HISTORY_HEADER: &str = "time,w,lambda_s,lambda_z,n_s,n_z";

#[derive(Copy, Clone, Debug, ValueEnum)]
pub enum HistoryControl {
    /// the pressure (ϖ, or Pa with --radius and --thickness): held, the tube creeps
    Pressure,
    /// the hoop stretch λs
    Stretch,
    /// the enclosed volume per unit reference length over πR², v = λs² λz: held, the
    /// pressure relaxes
    Volume,
}

impl From<HistoryControl> for Control {
    fn from(c: HistoryControl) -> Self {
        match c {
            HistoryControl::Pressure => Control::Pressure,
            HistoryControl::Stretch => Control::Stretch,
            HistoryControl::Volume => Control::Volume,
        }
    }
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct HistoryArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[command(flatten)]
    units: UnitArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: crate::gps_cmd::Hyp,
    /// The Prony series as g:τ pairs separated by commas, e.g. 0.3:1,0.2:10 (τ in the time
    /// unit of --ramp and --hold; g∞ = 1 − Σ g > 0; the base law's modulus is the
    /// instantaneous one)
    #[arg(long)]
    prony: String,
    /// What the ramp drives and the hold keeps.
    #[arg(long, value_enum)]
    control: HistoryControl,
    /// The ramp's target (ϖ or Pa, λs, or v).
    #[arg(long)]
    to: f64,
    /// The ramp's duration (0: a jump, the instantaneous response).
    #[arg(long, default_value_t = 0.0)]
    ramp: f64,
    /// The hold's duration after the ramp (0: none).
    #[arg(long, default_value_t = 0.0)]
    hold: f64,
    /// The largest error in ϖ, λs and λz the time steps may leave (their Richardson estimate).
    #[arg(long, default_value_t = 1e-10)]
    tolerance: f64,
    /// Write every step to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Replace an existing --csv file that this command did not write.
    #[arg(long)]
    overwrite: bool,
    /// Print one JSON object (the end state, the steps and the error estimate).
    #[arg(long)]
    json: bool,
}

/// `--prony 0.3:1,0.2:10`, naming the term a fault is in.
pub fn parse_prony(text: &str) -> Result<Prony> {
    let terms = text
        .split(',')
        .enumerate()
        .map(|(i, pair)| {
            let (g, tau) = pair.split_once(':').with_context(|| {
                format!("--prony term {} = {pair:?}: write g:τ, e.g. 0.3:1", i + 1)
            })?;
            let num = |s: &str, what: &str| {
                s.trim().parse::<f64>().with_context(|| {
                    format!(
                        "--prony term {} = {pair:?}: {what} {s:?} is not a number",
                        i + 1
                    )
                })
            };
            Ok(PronyTerm {
                g: num(g, "g")?,
                tau: num(tau, "τ")?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Prony::new(terms).map_err(|e| anyhow::anyhow!("--prony: {e}"))
}

pub fn run(a: HistoryArgs) -> Result<()> {
    let law = a.material.build()?;
    let units = a.units.units(law.as_ref())?;
    let prony = parse_prony(&a.prony)?;
    let control: Control = a.control.into();
    let to = match control {
        Control::Pressure => units.to_core(Dimension::Pressure, a.to),
        _ => a.to,
    };
    for (flag, v) in [("--ramp", a.ramp), ("--hold", a.hold)] {
        if !(v.is_finite() && v >= 0.0) {
            bail!("{flag} = {v}: a duration must be finite and ≥ 0");
        }
    }
    let mut program = vec![Segment {
        control,
        target: Some(to),
        duration: a.ramp,
    }];
    if a.hold > 0.0 {
        program.push(Segment {
            control,
            target: None,
            duration: a.hold,
        });
    }
    if let Some(csv) = &a.csv {
        let law_file = a
            .material
            .law
            .as_ref()
            .map(PathBuf::from)
            .filter(|p| p.is_file());
        let inputs: Vec<&std::path::Path> = law_file.iter().map(|p| p.as_path()).collect();
        tubemem_app::output_file::check("--csv", csv, &inputs, |text| {
            a.overwrite || text.starts_with(HISTORY_HEADER)
        })
        .map_err(|e| anyhow::anyhow!(e.chain()))?;
    }
    let h = inflation_history(
        law.as_ref(),
        &prony,
        a.hypothesis.into(),
        &program,
        16,
        a.tolerance,
    )
    .map_err(|e| {
        let e = anyhow::anyhow!(e).context("the viscoelastic inflation");
        // under a pressure the likely cause is the pressure maximum: name it and its
        // long-term value (the base law's scaled by g∞)
        let max = (matches!(control, Control::Pressure))
            .then(|| tubemem_gps::limits::limit_points(law.as_ref(), a.hypothesis.into()).ok())
            .flatten()
            .and_then(|l| l.max)
            .filter(|m| to > m.w * prony.g_infinity());
        match max {
            Some(m) => e.context(format!(
                "the target ϖ = {4:.6} is above the long-term pressure maximum ϖ = {2:.6} (g∞ = {3} times the base law's {0} maximum {1:.6}): as the law relaxes the tube passes its pressure maximum and bulges, and no inflated state follows",
                a.hypothesis_label(),
                m.w,
                m.w * prony.g_infinity(),
                prony.g_infinity(),
                to
            )),
            None => e,
        }
    })?;
    let last = *h.points.last().expect("a history has its start");
    if let Some(csv) = &a.csv {
        let si = units.is_si();
        let header = if si {
            format!("{HISTORY_HEADER},pressure_pa,n_s_n_per_m,n_z_n_per_m")
        } else {
            HISTORY_HEADER.to_string()
        };
        let rows = h.points.iter().map(|p| {
            let mut r = vec![p.time, p.w, p.lambda_s, p.lambda_z, p.n_s, p.n_z];
            if si {
                r.push(units.from_core(Dimension::Pressure, p.w));
                r.push(units.from_core(Dimension::Resultant, p.n_s));
                r.push(units.from_core(Dimension::Resultant, p.n_z));
            }
            r
        });
        tubemem_app::curves::write_csv(csv, &header, rows)
            .map_err(|e| anyhow::anyhow!(e.chain()))?;
    }
    let mut v = serde_json::to_value(last)?;
    add_si(&mut v, &units);
    if let Some(map) = v.as_object_mut() {
        map.insert("steps_per_segment".into(), h.steps_per_segment.into());
        map.insert("error_estimate".into(), h.error_estimate.into());
        map.insert("g_infinity".into(), prony.g_infinity().into());
    }
    if a.json {
        crate::say!("{v}")?;
    } else {
        crate::say!(
            "{} viscoelastic inflation ({} Prony terms, g∞ = {}): at t = {} (the Prony series' time unit) ϖ = {:.9}, λs = {:.9}, λz = {:.9} ({} steps per segment, time-step error ≤ {:.1e}){}",
            a.hypothesis_label(),
            prony.terms().len(),
            prony.g_infinity(),
            last.time,
            last.w,
            last.lambda_s,
            last.lambda_z,
            h.steps_per_segment,
            h.error_estimate,
            a.csv
                .as_ref()
                .map(|c| format!("; wrote {} states to {}", h.points.len(), c.display()))
                .unwrap_or_default()
        )?;
        if units.is_si() {
            crate::say!(
                "  pressure {} Pa",
                units.from_core(Dimension::Pressure, last.w)
            )?;
        }
    }
    Ok(())
}

impl HistoryArgs {
    fn hypothesis_label(&self) -> &'static str {
        tubemem_gps::Hypothesis::from(self.hypothesis).label()
    }
}
