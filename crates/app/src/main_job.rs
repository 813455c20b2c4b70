//! The main job (`tubemem` with no arguments, the README's first command): the paper's example
//! end to end on the embedded default case `cases/squeeze_abb30_ls1.3_quad9.toml`.
//!
//! 1. The closed form: limit points and Maxwell pressure of the GPS inflation curve.
//! 2. The 3D FE run: the capped tube inflated to λs* = 1.3, the gas closed in, squeezed to
//!    ρ = 0.8; a table of the FE mid-span values against GPS and PS at every squeeze step, taken
//!    from the run's typed report.
//! 3. The paper's Fig. 7 companion: the same law's tube inflated through the bulge to λs* = 6
//!    and squeezed to ρ = 3 (`cases/squeeze_abb30_ls6.0_fig7.toml`).
//! 4. The figures (Figs. 5–7, λz) with the FE points of both runs overlaid.

use crate::case::Case;
use crate::observer::Observer;
use crate::output::{FolderMode, RunWriter};
use crate::report::RunReport;
use crate::run::run;
use crate::{figures, AppError, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tubemem_gps::limits::{limit_points, Limits};
use tubemem_gps::{flatten, Hypothesis};
use tubemem_material::laws::AnssariBenamBucchi;

/// The embedded default case.
pub const DEFAULT_CASE: &str = include_str!("../../../cases/squeeze_abb30_ls1.3_quad9.toml");

/// The embedded Fig. 7 companion (λs* = 6).
pub const FIG7_CASE: &str = include_str!("../../../cases/squeeze_abb30_ls6.0_fig7.toml");

/// One squeeze step of the main job's table.
pub struct SqueezeRow {
    pub rho: f64,
    pub w: f64,
    pub gps_w: f64,
    pub ps_w: f64,
    pub force: f64,
    pub gps_force: f64,
    pub ps_force: f64,
    /// the GPS section's force under the FE's own pressure
    pub local_force: Option<f64>,
}

/// What the main job computed.
pub struct MainJob {
    pub limits: Limits,
    pub run_dir: PathBuf,
    pub report: RunReport,
    /// the Fig. 7 companion's run folder and report
    pub fig7_dir: PathBuf,
    pub fig7_report: RunReport,
    pub rows: Vec<SqueezeRow>,
    pub figures: Vec<PathBuf>,
}

/// The closed-form part of the main job: limit points and Maxwell pressure of the paper's law.
pub fn paper_limits() -> Result<Limits> {
    let law = AnssariBenamBucchi::new(1.0, 30.0)?;
    limit_points(&law, Hypothesis::Gps).map_err(|e| AppError::gps("the limit points", e))
}

/// The closed-form header line.
pub fn limits_text(l: &Limits) -> String {
    match (l.max, l.min, l.maxwell) {
        (Some(mx), Some(mn), Some(m)) => format!(
            "Closed form, GPS inflation: pressure maximum ϖ = {:.6} at λs = {:.6}, minimum ϖ = {:.6} at λs = {:.6}, Maxwell ϖ = {:.6} (PS has no limit point)",
            mx.w, mx.lambda_s, mn.w, mn.lambda_s, m.w
        ),
        _ => "Closed form, GPS inflation: no limit points found".into(),
    }
}

/// Run the embedded case `text` into the main job's own folder `dir` (each run of the main job
/// replaces the last), `observers` beside its writer.
fn run_embedded(
    text: &str,
    dir: &Path,
    label: &str,
    observers: &mut [&mut dyn Observer],
) -> Result<RunReport> {
    let case = Case::parse(text)?;
    let mut writer = RunWriter::create(dir, FolderMode::Overwrite, case.hash(), &[])?;
    let mut all: Vec<&mut dyn Observer> = vec![&mut writer];
    all.extend(observers.iter_mut().map(|o| &mut **o as &mut dyn Observer));
    run(&case, label, &mut all).into_result()
}

/// Run the main job into `out`; `observers` see the FE runs (e.g. a progress display).
pub fn run_main_job(out: &Path, observers: &mut [&mut dyn Observer]) -> Result<MainJob> {
    let law = AnssariBenamBucchi::new(1.0, 30.0)?;
    let limits = paper_limits()?;
    let run_dir = out.join("squeeze");
    let report = run_embedded(
        DEFAULT_CASE,
        &run_dir,
        "embedded default: cases/squeeze_abb30_ls1.3_quad9.toml",
        observers,
    )?;
    let mut rows = vec![];
    for s in report.steps() {
        let (Some(c), Some(g)) = (&s.contact, &s.closed_form.gps_flattening) else {
            continue;
        };
        // PS from the run's λs* at the same ρ; GPS as the run computed it at this step
        let p = flatten(&law, Hypothesis::Ps, c.initial_stretch, c.values.rho)
            .map_err(|e| AppError::gps("the PS flattening", e))?;
        rows.push(SqueezeRow {
            rho: c.values.rho,
            w: s.midspan.w,
            gps_w: g.w,
            ps_w: p.w,
            force: c.values.force,
            gps_force: g.force,
            ps_force: p.force,
            local_force: s
                .closed_form
                .local
                .as_ref()
                .and_then(|l| l.as_ref().ok())
                .map(|l| l.force),
        });
    }
    // Fig. 7's FE points: the companion run from λs* = 6
    let fig7_dir = out.join("squeeze_ls6");
    let fig7_report = run_embedded(
        FIG7_CASE,
        &fig7_dir,
        "embedded Fig. 7 companion: cases/squeeze_abb30_ls6.0_fig7.toml",
        observers,
    )?;
    // the FE points from the reports themselves, not read back from the files just written
    let overlays = [
        figures::Overlay::from_report(&report, "embedded default case", &run_dir),
        figures::Overlay::from_report(&fig7_report, "fig7 companion", &fig7_dir),
    ];
    let figures = figures::write_all(
        &out.join("figures"),
        Some(figures::PAPER_LAW),
        &overlays,
        &figures::FigureOptions::default(),
    )?;
    Ok(MainJob {
        limits,
        run_dir,
        report,
        fig7_dir,
        fig7_report,
        rows,
        figures,
    })
}

impl MainJob {
    /// The FE-versus-closed-form table of the squeeze.
    pub fn table(&self) -> String {
        let mut t = String::new();
        let _ = writeln!(
            t,
            "Squeeze, mid-span: FE against GPS and PS flattening at the same ρ (from the FE's λs*)"
        );
        let _ = writeln!(
            t,
            "{:>7} {:>9} {:>9} {:>9} {:>8} {:>9} {:>9} {:>9} {:>8} {:>10}",
            "ρ", "ϖ FE", "ϖ GPS", "ϖ PS", "FE−GPS", "force FE", "GPS", "PS", "FE−GPS", "FE−GPS(ϖ)"
        );
        for r in &self.rows {
            let local = r
                .local_force
                .map_or("n/a".to_string(), |l| format!("{:+.1e}", r.force / l - 1.0));
            let _ = writeln!(
                t,
                "{:>7.4} {:>9.5} {:>9.5} {:>9.5} {:>+7.2}% {:>9.5} {:>9.5} {:>9.5} {:>+7.2}% {:>10}",
                r.rho,
                r.w,
                r.gps_w,
                r.ps_w,
                100.0 * (r.w / r.gps_w - 1.0),
                r.force,
                r.gps_force,
                r.ps_force,
                100.0 * (r.force / r.gps_force - 1.0),
                local
            );
        }
        let _ = writeln!(
            t,
            "(FE−GPS(ϖ): the force's relative error against the GPS section under the FE's own pressure, eq. 76 without the gas law;\n \
             the hoop node lines follow the contact edges at every step, so every step verifies at the element's order.\n \
             The FE differs from GPS mostly by the end effect, which acts through the gas: the ends keep gas the plates do not squeeze; see the README)"
        );
        t
    }
}
