//! The console observer of a run: a progress bar on a terminal (elapsed time, ETA, the step's
//! Newton residual), or one line per converged step when the output is not a terminal; and the
//! closing lines of each stage, printed from the typed report.

use crate::say;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use tubemem_app::case::StagePlan;
use tubemem_app::observer::{BoxError, Observer, StepView};
use tubemem_app::report::{rel, ClosedFormState, LocalSection, RunReport, StageOutcome};
use tubemem_app::units::{Dimension, Units};
use tubemem_fem::model::{Model, State};

/// Prints a run's progress and results.
pub struct Console {
    /// warnings of the report already printed
    warned: usize,
    bar: Option<ProgressBar>,
    terminal: bool,
    /// a write error of a method that cannot return one, reported at the next that can
    pending: Option<std::io::Error>,
    /// `--log FILE`: one line per converged step, like an Abaqus .sta file
    log: Option<std::io::BufWriter<std::fs::File>>,
    started: std::time::Instant,
    /// the case's unit system (from the report at the start): SI values beside the
    /// dimensionless ones
    units: Units,
}

impl Console {
    /// Also write one line per converged step to `path` (created anew).
    pub fn with_log(mut self, path: &std::path::Path) -> std::io::Result<Self> {
        use std::io::Write;
        let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(
            f,
            "{:>6} {:>6} {:>10} {:>14} {:>14} {:>7} {:>10} {:>10}",
            "stage", "step", "elapsed_s", "w", "lambda_s", "newton", "residual", "fraction"
        )?;
        f.flush()?;
        self.log = Some(f);
        Ok(self)
    }
}

impl Default for Console {
    fn default() -> Self {
        Self {
            warned: 0,
            bar: None,
            terminal: std::io::stderr().is_terminal(),
            pending: None,
            log: None,
            started: std::time::Instant::now(),
            units: Units::dimensionless(),
        }
    }
}

impl Observer for Console {
    fn started(&mut self, report: &RunReport, _m: &Model, _s: &State) -> Result<(), BoxError> {
        self.units = report.scales.map_or(Units::dimensionless(), Units::si);
        say!(
            "tubemem run: {} — {} elements, {} equations ({} model), {}",
            report.case,
            report.mesh.elements,
            report.mesh.equations,
            report.mesh.symmetry,
            report.material
        )?;
        Ok(())
    }

    fn coarse_started(&mut self, around: usize, along: usize) {
        // the console's own line; a closed stderr loses it, as it loses every progress line
        let _ = say!(
            "mesh sequencing: the case runs first on the tube of {around} × {along} elements, and each step of this run starts from that run's state"
        );
    }

    fn coarse_finished(&mut self, stages: usize, steps: usize, seconds: f64) {
        let _ = say!(
            "mesh sequencing: the coarse run finished {stages} stage(s) in {steps} step(s), {seconds:.1} s"
        );
    }

    fn coarse_step(&mut self, v: &StepView) {
        let r = v.record;
        let _ = say!(
            "  mesh sequencing: coarse stage {} step {}: ϖ = {:.5}, λs = {:.5}, {} Newton its ({:.0} %)",
            r.stage,
            r.step,
            r.midspan.w,
            r.midspan.lambda_s,
            r.newton_iterations,
            100.0 * v.fraction
        );
    }

    fn stage_started(&mut self, plan: &StagePlan, stages: usize) {
        let label = format!(
            "stage {}/{} ({})",
            plan.index,
            stages,
            plan.describe_in(&self.units)
        );
        if self.terminal {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template(
                    "{prefix} [{bar:30}] {percent:>3}% {elapsed_precise} (ETA {eta}) {msg}",
                )
                .expect("a valid progress template")
                .progress_chars("=> "),
            );
            bar.set_prefix(label);
            self.bar = Some(bar);
        } else if let Err(e) = say!("{label}") {
            self.pending = Some(e);
        }
    }

    fn step(&mut self, v: &StepView) -> Result<(), BoxError> {
        if let Some(e) = self.pending.take() {
            return Err(Box::new(e));
        }
        self.warn(v.report)?;
        let r = v.record;
        let res = r.residuals.last().copied().unwrap_or(f64::NAN);
        let si = match self.units.scales() {
            Some(_) => format!(
                " (p = {:.5e} Pa)",
                self.units.from_core(Dimension::Pressure, r.midspan.w)
            ),
            None => String::new(),
        };
        let msg = format!(
            "step {}: ϖ = {:.5}{si}, λs = {:.5}, {} Newton its, residual {res:.1e}",
            r.step, r.midspan.w, r.midspan.lambda_s, r.newton_iterations
        );
        match &self.bar {
            Some(bar) => {
                bar.set_position((1000.0 * v.fraction.clamp(0.0, 1.0)) as u64);
                bar.set_message(msg);
            }
            None => say!("  stage {} {msg} ({:.0} %)", r.stage, 100.0 * v.fraction)?,
        }
        if let Some(f) = &mut self.log {
            use std::io::Write;
            writeln!(
                f,
                "{:>6} {:>6} {:>10.3} {:>14.8e} {:>14.8e} {:>7} {:>10.2e} {:>10.6}",
                r.stage,
                r.step,
                self.started.elapsed().as_secs_f64(),
                r.midspan.w,
                r.midspan.lambda_s,
                r.newton_iterations,
                res,
                v.fraction
            )?;
            f.flush()?;
        }
        Ok(())
    }

    fn stage_finished(&mut self, report: &RunReport) -> Result<(), BoxError> {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        let Some(stage) = report.stages.last() else {
            return Ok(());
        };
        let StageOutcome::Finished(s) = &stage.outcome else {
            return Ok(());
        };
        let ms = &s.final_state.midspan;
        let (w, ls, lz, chi, force) = values(&s.gps);
        let (ps_w, _, _, ps_chi, ps_force) = values(&s.ps);
        say!(
            "stage {}: ϖ = {:.6} (GPS {:.6}, {:+.3}%; PS {:.6}), λs = {:.6} (GPS {:.6}), λz = {:.6} (GPS {:.6}; PS 1), N_s = {:.6}, N_z = {:.6}, N_sz = {:.1e}",
            s.index, ms.w, w, 100.0 * rel(ms.w, w), ps_w, ms.lambda_s, ls, ms.lambda_z, lz, ms.n_s, ms.n_z, ms.n_sz
        )?;
        if let Some(sc) = report.scales {
            let u = &self.units;
            let si = tubemem_app::report::SiValues::of(
                &sc,
                ms,
                stage
                    .steps
                    .last()
                    .and_then(|st| st.contact.as_ref())
                    .map(|c| &c.values),
            );
            let mut line = format!(
                "         in SI: p = {:.6e} Pa (GPS {:.6e} Pa), N_s = {:.6e} N/m, N_z = {:.6e} N/m",
                si.pressure_pa,
                u.from_core(Dimension::Pressure, w),
                si.n_s_n_per_m,
                si.n_z_n_per_m
            );
            if let (Some(f), Some(h), Some(total)) =
                (si.force_n_per_m, si.half_gap_m, si.plate_force_n)
            {
                line.push_str(&format!(
                    ", half-gap {h:.6e} m, plate force per length {f:.6e} N/m (GPS {:.6e} N/m), total force on one plate {total:.6e} N",
                    u.from_core(Dimension::ForcePerLength, force)
                ));
            }
            say!("{line}")?;
        }
        if let Some(why) = &s.gps_not_applicable {
            say!("         ✗ the comparison with GPS does not apply: {why}")?;
        }
        if let Some(c) = &s.final_state.contact {
            say!(
                "         ρ = {:.4}: χ = {:.5} (GPS {:.5}, PS {:.5}), force ϖχ = {:.5} (GPS {:.5}, {:+.2}%; PS {:.5}), contact pressure {:.4}, penetration {:.1e}",
                c.rho, c.chi, chi, ps_chi, c.force, force, 100.0 * rel(c.force, force), ps_force, c.contact_pressure, c.penetration
            )?;
            if let Some(LocalSection::Solved(l)) = &s.gps_at_fe_pressure {
                say!(
                    "         GPS section at the FE's pressure ϖ = {:.6} (eq. 76, no gas law), relative: λs {:+.2e}, λz {:+.2e}, χ {:+.2e}, force {:+.2e}",
                    ms.w,
                    rel(ms.lambda_s, l.lambda_s),
                    rel(ms.lambda_z, l.lambda_z),
                    rel(c.chi, l.chi),
                    rel(c.force, l.force)
                )?;
            }
        }
        if let (false, Some(e)) = (s.walls.is_empty(), &s.relative_error_vs_gps_at_fe_pressure) {
            say!(
                "         GPS in the same walls at the FE's pressure ϖ = {:.6}, relative: λs {:+.2e}, λz {:+.2e}",
                ms.w,
                e.lambda_s.unwrap_or(f64::NAN),
                e.lambda_z.unwrap_or(f64::NAN)
            )?;
        }
        for (k, w) in s.walls.iter().enumerate() {
            let gps = w.gps.map_or(f64::NAN, |g| g.force);
            let local = w.local.map_or(f64::NAN, |g| g.force);
            // a wall that carries nothing in GPS has no relative error
            let pct = |e: Option<f64>| match e {
                Some(e) if e.is_finite() => format!("{:+.2}%", 100.0 * e),
                _ => "none in GPS".to_string(),
            };
            let relative = |e: Option<f64>| match e {
                Some(e) if e.is_finite() => format!("relative {e:+.2e}"),
                _ => "none in GPS".to_string(),
            };
            say!(
                "         wall {}: contact {:.5} R, force {:.5} (GPS {:.5}, {}; GPS at the FE's pressure {:.5}, {}), penetration {:.1e}",
                k + 1,
                w.fe.contact_length,
                w.fe.force,
                gps,
                pct(w.force_error_vs_gps),
                local,
                relative(w.force_error_vs_gps_at_fe_pressure),
                w.fe.penetration
            )?;
        }
        let ripples: Vec<_> = s.critical_points.iter().filter(|c| c.ripple).collect();
        if let (Some(lo), Some(hi)) = (
            ripples.iter().map(|c| c.midspan.w).reduce(f64::min),
            ripples.iter().map(|c| c.midspan.w).reduce(f64::max),
        ) {
            say!(
                "         {} more limit points within {:.0e} of each other (ϖ {lo:.9} to {hi:.9}): the ripple of the propagating front as it crosses the elements (critical_points.csv)",
                ripples.len(),
                tubemem_app::report::RIPPLE
            )?;
        }
        if let Some(d) = s.cap_boundary_layer {
            let end = if report.geometry.caps == "hemisphere" {
                "cap junction"
            } else {
                "plug"
            };
            let si = match self.units.scales() {
                Some(_) => format!(" ({:.4e} m)", self.units.from_core(Dimension::Length, d)),
                None => String::new(),
            };
            say!(
                "         λs is within 0.1 % of its mid-span value from {d:.3} R{si} inside the {end}"
            )?;
        }
        Ok(())
    }

    fn critical(
        &mut self,
        r: &tubemem_app::report::CriticalRecord,
        _model: &Model,
        _state: &State,
        _mode: Option<&[[f64; 3]]>,
    ) -> Result<(), BoxError> {
        if r.ripple {
            // counted in the stage's closing lines; each is in critical_points.csv
            return Ok(());
        }
        // the 4-node mesh's polygon factor 1/cos(π/n); the 9-node element has none (factor 1)
        let factor = match r.polygon_factor {
            Some(f) if f != 1.0 => " × 1/cos(π/n)",
            _ => "",
        };
        let gps = match (&r.reference, r.w_error_over_polygon) {
            (Some(g), Some(e)) => format!(
                " (vs {} ϖ = {:.7} at λs = {:.5}: FE/(closed form{factor}) − 1 = {e:+.2e})",
                g.what, g.w, g.lambda_s
            ),
            (Some(g), None) => format!(" ({} ϖ = {:.6} at λs = {:.5})", g.what, g.w, g.lambda_s),
            _ => String::new(),
        };
        let mode = r
            .mode_vtu
            .as_ref()
            .map(|v| {
                let png = r
                    .mode_png
                    .as_ref()
                    .map(|p| format!(" and {p}"))
                    .unwrap_or_default();
                format!("; critical mode in {v}{png}")
            })
            .unwrap_or_default();
        let line = format!(
            "  stage {} ◆ {} between steps {} and {}: ϖ = {:.8}, λs = {:.6}, λz = {:.6}, V = {:.5} R³, negative pivots {} → {}{gps}{mode}",
            r.stage,
            r.kind,
            r.step - 1,
            r.step,
            r.midspan.w,
            r.midspan.lambda_s,
            r.midspan.lambda_z,
            r.midspan.volume,
            r.negative_pivots_before,
            r.negative_pivots_after
        );
        match &self.bar {
            Some(bar) => bar.println(line),
            None => say!("{line}")?,
        }
        Ok(())
    }

    fn failed(&mut self, report: &RunReport, _error: &tubemem_app::AppError) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        let _ = self.warn(report);
    }
}

impl Console {
    /// Print the report's warnings not printed yet (to standard error).
    fn warn(&mut self, report: &RunReport) -> std::io::Result<()> {
        use std::io::Write;
        for w in &report.warnings[self.warned.min(report.warnings.len())..] {
            writeln!(std::io::stderr(), "warning: {w}")?;
        }
        self.warned = report.warnings.len();
        Ok(())
    }
}

/// (ϖ, λs, λz, χ, force) of a closed-form state (χ and force NaN for an inflation).
fn values(c: &ClosedFormState) -> (f64, f64, f64, f64, f64) {
    match c {
        ClosedFormState::Inflation(g) => (g.w, g.lambda_s, g.lambda_z, f64::NAN, f64::NAN),
        ClosedFormState::Flattening(g) => (g.w, g.lambda_s, g.lambda_z, g.chi, g.force),
        ClosedFormState::Confine(g) => (g.w, g.lambda_s, g.lambda_z, f64::NAN, f64::NAN),
    }
}
