//! `tubemem gps history`: the GPS free inflation in time with a viscoelastic (QLV Prony) law
//! ([`tubemem_gps::visco`]): a ramp of the pressure, the hoop stretch or the enclosed volume to
//! a target, then a hold (creep at constant pressure, relaxation at fixed volume); then, with
//! `--plates-to`, two frictionless plates closing from first contact at a speed, held, and
//! released (the force–gap loop), the gas closed or the pressure regulated.
use crate::material_args::{add_si, MaterialArgs, UnitArgs};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use tubemem_app::units::Dimension;
use tubemem_gps::visco::cycle::{run_cycle, Cycle, PlatesLeg, Steps};
use tubemem_gps::visco::{Control, Supply};
use tubemem_material::viscoelastic::{Prony, PronyTerm};

/// The header of `gps history --csv` (dimensionless columns; SI ones follow with --radius).
pub const HISTORY_HEADER: &str = "time,w,lambda_s,lambda_z,n_s,n_z,rho,chi,force";

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

#[derive(Copy, Clone, Debug, ValueEnum)]
pub enum PlateSupply {
    /// the gas closed in when the plates start (Boyle)
    Gas,
    /// the pressure held at its value when the plates start (a regulator)
    Pressure,
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct HistoryArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[command(flatten)]
    units: UnitArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: crate::material_args::Hyp,
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
    /// After the inflation: plates y = ±ρR closing from first contact to this half-gap ρ.
    #[arg(long)]
    plates_to: Option<f64>,
    /// The plates' travel time (0: a jump).
    #[arg(long, default_value_t = 0.0)]
    squeeze_time: f64,
    /// How the gas is supplied while the plates move: closed in ("gas") or regulated at the
    /// inflated pressure ("pressure").
    #[arg(long, value_enum, default_value = "gas")]
    supply: PlateSupply,
    /// The time the plates are held at --plates-to.
    #[arg(long, default_value_t = 0.0)]
    plates_hold: f64,
    /// Then release the plates back to where they first touched, over --squeeze-time, and
    /// report the force–gap loop's area (the work the plates did on the tube over the cycle).
    #[arg(long)]
    release: bool,
    /// The largest error in ϖ, λs, λz and the force the time steps may leave (their
    /// estimate, the difference between the last two step counts).
    #[arg(long, default_value_t = 1e-10)]
    tolerance: f64,
    /// Instead of --tolerance: exactly this many equal steps per segment, no error estimate
    /// (for measuring the integration's order).
    #[arg(long)]
    steps: Option<usize>,
    /// Write every step to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// With --plates-to and --release: draw the force–gap loop as STEM.svg and STEM.png.
    #[arg(long, value_name = "STEM")]
    plot: Option<PathBuf>,
    /// With --plot: also draw the same cycle with these plates' travel times (comma
    /// separated, e.g. 0.3,3,30), one loop per speed.
    #[arg(long, value_delimiter = ',')]
    travel_times: Vec<f64>,
    /// Replace an existing --csv or --plot file that this command did not write.
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
    let cycle = a.cycle(&units)?;
    let steps = match a.steps {
        Some(n) => Steps::Fixed(n),
        None => Steps::Tolerance(a.tolerance),
    };
    a.check_outputs()?;
    let result = run_cycle(law.as_ref(), &prony, a.hypothesis.into(), &cycle, steps)
        .map_err(|e| a.explain(e, law.as_ref(), &prony, cycle.to))?;
    if let Some(stem) = &a.plot {
        plot_loops(&a, law.as_ref(), &prony, &cycle, steps, &result, stem)?;
    }
    if let Some(csv) = &a.csv {
        write_csv(csv, &result.history, &units)?;
    }
    let v = end_json(&result, &units, &prony)?;
    if a.json {
        crate::say!("{v}")?;
        return Ok(());
    }
    print_text(&a, &result, &units, &prony)
}

impl HistoryArgs {
    /// The load program the arguments give (the target in the core's units), refused where
    /// plates' options come without plates or a figure without its cycle.
    fn cycle(&self, units: &tubemem_app::units::Units) -> Result<Cycle> {
        let control: Control = self.control.into();
        let to = match control {
            Control::Pressure => units.to_core(Dimension::Pressure, self.to),
            _ => self.to,
        };
        if self.plates_to.is_none()
            && (self.release || self.squeeze_time > 0.0 || self.plates_hold > 0.0)
        {
            bail!("--squeeze-time, --plates-hold and --release move plates: give --plates-to ρ");
        }
        if self.plot.is_some() && !(self.plates_to.is_some() && self.release) {
            bail!("--plot draws the force–gap loop: give --plates-to ρ and --release");
        }
        if !self.travel_times.is_empty() && self.plot.is_none() {
            bail!("--travel-times adds loops to the figure: give --plot STEM");
        }
        if let Some(t) = self
            .travel_times
            .iter()
            .find(|t| !(t.is_finite() && **t >= 0.0))
        {
            bail!("--travel-times: {t} is not a travel time (finite and ≥ 0)");
        }
        Ok(Cycle {
            control,
            to,
            ramp: self.ramp,
            hold: self.hold,
            plates: self.plates_to.map(|rho| PlatesLeg {
                supply: match self.supply {
                    PlateSupply::Gas => Supply::Gas,
                    PlateSupply::Pressure => Supply::Pressure,
                },
                to: rho,
                travel: self.squeeze_time,
                hold: self.plates_hold,
                release: self.release,
            }),
        })
    }

    /// The --csv and --plot files may be written (before anything is computed).
    fn check_outputs(&self) -> Result<()> {
        let law_file = self
            .material
            .law
            .as_ref()
            .map(PathBuf::from)
            .filter(|p| p.is_file());
        let inputs: Vec<&std::path::Path> = law_file.iter().map(|p| p.as_path()).collect();
        if let Some(csv) = &self.csv {
            tubemem_app::output_file::check("--csv", csv, &inputs, |text| {
                self.overwrite || text.starts_with(HISTORY_HEADER)
            })
            .map_err(|e| anyhow::anyhow!(e.chain()))?;
        }
        if let Some(stem) = &self.plot {
            crate::fit_print::check_plot(
                stem,
                &inputs,
                tubemem_app::figures::LOOPS_TITLE,
                self.overwrite,
            )?;
        }
        Ok(())
    }

    /// The cycle's failure, with the likely cause under a pressure: the long-term pressure
    /// maximum (the base law's scaled by g∞) below the target `to`.
    fn explain(
        &self,
        e: tubemem_gps::GpsError,
        law: &dyn tubemem_material::MembraneLaw,
        prony: &Prony,
        to: f64,
    ) -> anyhow::Error {
        let e = anyhow::anyhow!(e).context("the viscoelastic inflation");
        let max = (matches!(self.control, HistoryControl::Pressure))
            .then(|| tubemem_gps::limits::limit_points(law, self.hypothesis.into()).ok())
            .flatten()
            .and_then(|l| l.max)
            .filter(|m| to > m.w * prony.g_infinity());
        match max {
            Some(m) => e.context(format!(
                "the target ϖ = {4:.6} is above the long-term pressure maximum ϖ = {2:.6} (g∞ = {3} times the base law's {0} maximum {1:.6}): as the law relaxes the tube passes its pressure maximum and bulges, and no inflated state follows",
                self.hypothesis_label(),
                m.w,
                m.w * prony.g_infinity(),
                prony.g_infinity(),
                to
            )),
            None => e,
        }
    }
}

/// `--csv`: every state of the history, the SI columns after the dimensionless ones.
fn write_csv(
    csv: &std::path::Path,
    h: &tubemem_gps::visco::TimeHistory,
    units: &tubemem_app::units::Units,
) -> Result<()> {
    let si = units.is_si();
    let header = if si {
        format!("{HISTORY_HEADER},pressure_pa,n_s_n_per_m,n_z_n_per_m,force_n_per_m")
    } else {
        HISTORY_HEADER.to_string()
    };
    // ρ is empty before the plates come (no NaN in a file a user reads)
    let mut text = format!("{header}\n");
    for p in &h.points {
        let mut r = vec![
            Some(p.time),
            Some(p.w),
            Some(p.lambda_s),
            Some(p.lambda_z),
            Some(p.n_s),
            Some(p.n_z),
            p.rho,
            Some(p.chi),
            Some(p.force),
        ];
        if si {
            r.push(Some(units.from_core(Dimension::Pressure, p.w)));
            r.push(Some(units.from_core(Dimension::Resultant, p.n_s)));
            r.push(Some(units.from_core(Dimension::Resultant, p.n_z)));
            r.push(Some(units.from_core(Dimension::ForcePerLength, p.force)));
        }
        if r.iter().flatten().any(|v| !v.is_finite()) {
            bail!("internal error: a non-finite value was computed at t = {}; please report this input", p.time);
        }
        let cells: Vec<String> = r
            .iter()
            .map(|v| v.map(|v| v.to_string()).unwrap_or_default())
            .collect();
        text.push_str(&cells.join(","));
        text.push('\n');
    }
    tubemem_app::output_file::write_whole(csv, text.as_bytes())
        .map_err(|e| anyhow::anyhow!(e.chain()))?;
    Ok(())
}

/// The end state as JSON, with the SI values, the steps, the estimate, g∞ and the loop's area.
fn end_json(
    result: &tubemem_gps::visco::cycle::CycleResult,
    units: &tubemem_app::units::Units,
    prony: &Prony,
) -> Result<serde_json::Value> {
    let h = &result.history;
    let mut v = serde_json::to_value(h.end())?;
    add_si(&mut v, units);
    if let Some(map) = v.as_object_mut() {
        map.insert("steps_per_segment".into(), h.steps_per_segment.into());
        // fixed steps (--steps): no estimate (null, not NaN)
        map.insert(
            "error_estimate".into(),
            Some(h.error_estimate).filter(|e| e.is_finite()).into(),
        );
        map.insert("g_infinity".into(), prony.g_infinity().into());
        if let Some(area) = result.loop_area {
            map.insert("loop_area".into(), area.into());
            // back where the plates first touched with no contact: a closed loop
            map.insert("loop_closed".into(), (h.end().chi == 0.0).into());
            if units.is_si() {
                map.insert(
                    "loop_area_j_per_m".into(),
                    units
                        .from_core(Dimension::Force, std::f64::consts::PI * area)
                        .into(),
                );
            }
        }
    }
    Ok(v)
}

/// The end state in words.
fn print_text(
    a: &HistoryArgs,
    result: &tubemem_gps::visco::cycle::CycleResult,
    units: &tubemem_app::units::Units,
    prony: &Prony,
) -> Result<()> {
    let h = &result.history;
    let last = h.end();
    crate::say!(
        "{} viscoelastic tube ({} Prony terms, g∞ = {}): at t = {} (the Prony series' time unit) ϖ = {:.9}, λs = {:.9}, λz = {:.9} ({} steps per segment, {}){}",
        a.hypothesis_label(),
        prony.terms().len(),
        prony.g_infinity(),
        last.time,
        last.w,
        last.lambda_s,
        last.lambda_z,
        h.steps_per_segment,
        if h.error_estimate.is_finite() {
            format!("time-step error ≤ {:.1e}", h.error_estimate)
        } else {
            "fixed steps: no error estimate".to_string()
        },
        a.csv
            .as_ref()
            .map(|c| format!("; wrote {} states to {}", h.points.len(), c.display()))
            .unwrap_or_default()
    )?;
    if let Some(rho) = last.rho {
        let si = if units.is_si() {
            format!(
                " ({:.6e} N/m)",
                units.from_core(Dimension::ForcePerLength, last.force)
            )
        } else {
            String::new()
        };
        crate::say!(
            "  plates at ρ = {rho:.6} R: χ = {:.9}, force ϖχ = {:.9} πμH per unit length{si}",
            last.chi,
            last.force
        )?;
    }
    if let Some(area) = result.loop_area {
        let si = if units.is_si() {
            format!(
                " ({:.6e} J/m)",
                units.from_core(Dimension::Force, std::f64::consts::PI * area)
            )
        } else {
            String::new()
        };
        // still pressed at the end: the tube crept wider during the cycle and the path is not
        // a closed loop, so its work is not the energy dissipated
        let what = if last.chi > 0.0 {
            format!(
                "; the tube is still in contact where the plates first touched (χ = {:.6e}: it crept wider during the cycle), so this is not a closed loop's dissipation",
                last.chi
            )
        } else {
            " (dissipated)".to_string()
        };
        crate::say!(
            "  force–gap loop: the plates did {area:.6e} πμHR{si} of work per plate and unit length over the cycle{what}"
        )?;
    }
    if units.is_si() {
        crate::say!(
            "  pressure {:.6e} Pa",
            units.from_core(Dimension::Pressure, last.w)
        )?;
    }
    Ok(())
}

/// `--plot`: the run's loop and one per `--travel-times` (the same cycle, other travel times).
fn plot_loops(
    a: &HistoryArgs,
    law: &dyn tubemem_material::MembraneLaw,
    prony: &Prony,
    cycle: &Cycle,
    steps: Steps,
    result: &tubemem_gps::visco::cycle::CycleResult,
    stem: &std::path::Path,
) -> Result<()> {
    let mut results = vec![(cycle.plates.map_or(0.0, |p| p.travel), result.clone())];
    for &t in &a.travel_times {
        let mut c = *cycle;
        if let Some(p) = &mut c.plates {
            p.travel = t;
        }
        let r = run_cycle(law, prony, a.hypothesis.into(), &c, steps)
            .with_context(|| format!("the cycle with the plates' travel time {t}"))?;
        results.push((t, r));
    }
    results.sort_by(|x, y| x.0.total_cmp(&y.0));
    let loops: Vec<_> = results
        .iter()
        .map(|(t, r)| tubemem_app::figures::Loop {
            travel: *t,
            touch: r.touch.unwrap_or(f64::NAN),
            points: &r.history.points,
        })
        .collect();
    let terms: Vec<String> = prony
        .terms()
        .iter()
        .map(|p| format!("{}:{}", p.g, p.tau))
        .collect();
    let fig = tubemem_app::figures::loops_figure(
        &format!("{} ({})", law.name(), a.hypothesis_label()),
        &terms.join(","),
        &loops,
    );
    let files = tubemem_app::figures::save(&fig, stem, &Default::default())
        .map_err(|e| anyhow::anyhow!(tubemem_app::error_chain(&e)))?;
    if !a.json {
        for f in files {
            crate::say!("wrote {}", f.display())?;
        }
    }
    Ok(())
}

impl HistoryArgs {
    fn hypothesis_label(&self) -> &'static str {
        tubemem_gps::Hypothesis::from(self.hypothesis).label()
    }
}
