//! The main job (`tubemem` with no arguments, the README's first command): the paper's example
//! end to end on the embedded default case `cases/squeeze_abb30_ls1.3.toml`.
//!
//! 1. The closed form: limit points and Maxwell pressure of the GPS inflation curve.
//! 2. The 3D FE run: the capped tube inflated to λs* = 1.3, the gas closed in, squeezed to
//!    ρ = 0.8; a table of the FE mid-span values against GPS and PS at every squeeze step.
//! 3. The figures (Figs. 5–7, λz) with the FE points overlaid.

use crate::case::Case;
use crate::{figures, run_cmd};
use anyhow::{Context, Result};
use std::path::Path;
use tubemem_gps::limits::limit_points;
use tubemem_gps::{flatten, Hypothesis};
use tubemem_material::laws::AnssariBenamBucchi;

/// The embedded default case.
pub const DEFAULT_CASE: &str = include_str!("../../../cases/squeeze_abb30_ls1.3.toml");

pub fn run(out: &Path) -> Result<()> {
    let law = AnssariBenamBucchi::new(1.0, 30.0)?;
    println!("tubemem — the paper's example (Anssari-Benam–Bucchi membrane, 𝒩 = 30; ϖ = pR/μH)\n");
    let l = limit_points(&law, Hypothesis::Gps)?;
    if let (Some(mx), Some(mn), Some(m)) = (l.max, l.min, l.maxwell) {
        println!(
            "Closed form, GPS inflation: pressure maximum ϖ = {:.6} at λs = {:.6}, minimum ϖ = {:.6} at λs = {:.6}, Maxwell ϖ = {:.6} (PS has no limit point)\n",
            mx.w, mx.lambda_s, mn.w, mn.lambda_s, m.w
        );
    }
    let case = Case::parse(DEFAULT_CASE).context("the embedded default case")?;
    let run_dir = out.join("squeeze");
    run_cmd::run_case(
        &case,
        "embedded default: cases/squeeze_abb30_ls1.3.toml",
        &run_dir,
    )?;

    // FE against the closed forms at every squeeze step
    let steps = std::fs::read_to_string(run_dir.join("steps.csv"))?;
    let mut lines = steps.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |n: &str| {
        header
            .iter()
            .position(|h| *h == n)
            .with_context(|| format!("steps.csv has no `{n}`"))
    };
    let (cw, crho, cforce, cdisp) = (col("w")?, col("rho")?, col("force")?, col("displacement")?);
    let (cgw, cgf, clocal) = (col("gps_w")?, col("gps_force")?, col("local_force")?);
    println!(
        "\nSqueeze, mid-span: FE against GPS and PS flattening at the same ρ (from the FE's λs*)"
    );
    println!(
        "{:>7} {:>9} {:>9} {:>9} {:>8} {:>9} {:>9} {:>9} {:>8} {:>10}",
        "ρ", "ϖ FE", "ϖ GPS", "ϖ PS", "FE−GPS", "force FE", "GPS", "PS", "FE−GPS", "FE−GPS(ϖ)"
    );
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        if f.get(crho).is_none_or(|v| v.is_empty()) {
            continue;
        }
        let num = |i: usize| f[i].parse::<f64>().unwrap_or(f64::NAN);
        let (w, rho, force, d) = (num(cw), num(crho), num(cforce), num(cdisp));
        // GPS as the run wrote it at this step; PS solved here from the run's λs* = ρ + d
        let (gw, gforce, local) = (num(cgw), num(cgf), num(clocal));
        let p = flatten(&law, Hypothesis::Ps, rho + d, rho)?;
        println!(
            "{rho:>7.4} {w:>9.5} {:>9.5} {:>9.5} {:>+7.2}% {force:>9.5} {:>9.5} {:>9.5} {:>+7.2}% {:>+9.2}%",
            gw,
            p.w,
            100.0 * (w / gw - 1.0),
            gforce,
            p.force,
            100.0 * (force / gforce - 1.0),
            100.0 * (force / local - 1.0)
        );
    }
    println!(
        "(FE−GPS(ϖ): the force against the GPS section under the FE's own pressure, eq. 76 without the gas law.\n \
         The FE differs from GPS mostly by the end effect, which acts through the gas: the ends keep gas the plates do not squeeze; see the README)\n"
    );
    for p in figures::write_all(&out.join("figures"), 30.0, std::slice::from_ref(&run_dir))? {
        println!("wrote {}", p.display());
    }
    Ok(())
}
