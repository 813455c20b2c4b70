//! `gold`: every step and the summary against stored gold files, like MOOSE's CSVDiff.

use super::{member, KindResult};
use crate::output::STEPS_HEADER;
use crate::report::RunReport;
use crate::verify::suite::Check;
use crate::verify::{CheckResult, Measure, VerifyOptions};
use std::path::Path;

kind!(
    /// The `gold` kind.
    Gold,
    "gold",
    gold
);

/// The steps.csv text of a report (the writer's format).
fn steps_csv(report: &RunReport) -> String {
    let mut t = format!("{STEPS_HEADER}\n");
    for s in report.steps() {
        t.push_str(&crate::output::format_row(s));
        t.push('\n');
    }
    t
}

fn close(a: f64, b: f64, rel_err: f64, abs_zero: f64) -> bool {
    (a.abs() <= abs_zero && b.abs() <= abs_zero) || (a - b).abs() <= rel_err * a.abs().max(b.abs())
}

/// Compare two JSON values' numbers (CSVDiff-like); the first difference's path.
fn json_diff(
    path: &str,
    a: &serde_json::Value,
    b: &serde_json::Value,
    rel_err: f64,
    abs_zero: f64,
    worst: &mut f64,
) -> Option<String> {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64()?, y.as_f64()?);
            let d = if x.abs() <= abs_zero && y.abs() <= abs_zero {
                0.0
            } else {
                (x - y).abs() / x.abs().max(y.abs())
            };
            *worst = worst.max(d);
            (!close(x, y, rel_err, abs_zero)).then(|| format!("{path}: {x} against gold {y}"))
        }
        (Value::Object(x), Value::Object(y)) => {
            for (k, v) in y {
                if k == "case" || k == "tubemem_version" {
                    continue; // a label of where the run was started; the build that ran it
                }
                let p = format!("{path}.{k}");
                match x.get(k) {
                    None => return Some(format!("{p}: missing (gold has it)")),
                    Some(w) => {
                        if let Some(d) = json_diff(&p, w, v, rel_err, abs_zero, worst) {
                            return Some(d);
                        }
                    }
                }
            }
            None
        }
        (Value::Array(x), Value::Array(y)) => {
            if x.len() != y.len() {
                return Some(format!(
                    "{path}: {} entries against gold {}",
                    x.len(),
                    y.len()
                ));
            }
            for (k, (v, w)) in x.iter().zip(y).enumerate() {
                if let Some(d) = json_diff(&format!("{path}[{k}]"), v, w, rel_err, abs_zero, worst)
                {
                    return Some(d);
                }
            }
            None
        }
        (x, y) if x == y => None,
        (x, y) => Some(format!("{path}: {x} against gold {y}")),
    }
}

fn gold(c: &Check, dir: &Path, opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let report = member(c, &c.case_text, &dir.join("run"), r)?;
    let steps = steps_csv(&report);
    let summary = serde_json::to_value(report.summary()).map_err(|e| e.to_string())?;
    let gsteps = c.gold_dir.join("steps.csv");
    let gsummary = c.gold_dir.join("summary.json");
    if opts.update_gold {
        std::fs::create_dir_all(&c.gold_dir)
            .map_err(|e| format!("{}: {e}", c.gold_dir.display()))?;
        tubemem_mesh::file::write_whole(&gsteps, steps.as_bytes())
            .map_err(|e| format!("{}: {e}", gsteps.display()))?;
        let text = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())?;
        tubemem_mesh::file::write_whole(&gsummary, (text + "\n").as_bytes())
            .map_err(|e| format!("{}: {e}", gsummary.display()))?;
        r.message = format!(
            "gold files rewritten in {} (--update-gold)",
            c.gold_dir.display()
        );
        return Ok(None);
    }
    let rel_err = c.spec.rel_err.unwrap_or(1e-10);
    let abs_zero = c.spec.abs_zero.unwrap_or(1e-12);
    let gold_steps = std::fs::read_to_string(&gsteps).map_err(|e| {
        format!(
            "no gold file {} ({e}): run `tubemem verify … --update-gold` to create it",
            gsteps.display()
        )
    })?;
    let gold_summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&gsummary).map_err(|e| format!("{}: {e}", gsummary.display()))?,
    )
    .map_err(|e| format!("{}: {e}", gsummary.display()))?;
    // steps: every gold column (columns are only ever appended), row by row
    let parse = |t: &str| -> (Vec<String>, Vec<Vec<String>>) {
        let mut l = t.lines();
        let h = l
            .next()
            .unwrap_or("")
            .split(',')
            .map(String::from)
            .collect();
        (
            h,
            l.map(|x| x.split(',').map(String::from).collect())
                .collect(),
        )
    };
    let (gh, grows) = parse(&gold_steps);
    let (h, rows) = parse(&steps);
    let mut first: Option<String> = None;
    let mut worst = 0.0f64;
    if grows.len() != rows.len() {
        first = Some(format!(
            "steps.csv: {} rows against gold {}",
            rows.len(),
            grows.len()
        ));
    }
    for (ri, (a, b)) in rows.iter().zip(&grows).enumerate() {
        for (gi, col) in gh.iter().enumerate() {
            let Some(ci) = h.iter().position(|x| x == col) else {
                first.get_or_insert(format!("steps.csv: no column `{col}` (gold has it)"));
                continue;
            };
            let (x, y) = (
                a.get(ci).map(String::as_str).unwrap_or(""),
                b.get(gi).map(String::as_str).unwrap_or(""),
            );
            match (x.parse::<f64>(), y.parse::<f64>()) {
                (Ok(xv), Ok(yv)) if !(xv.is_finite() && yv.is_finite()) => {
                    first.get_or_insert(format!(
                        "steps.csv row {} `{col}`: `{x}` against gold `{y}`: not a finite number ({} is corrupt or the run overflowed)",
                        ri + 1,
                        if yv.is_finite() { "the run's steps.csv" } else { "the gold file" }
                    ));
                }
                (Ok(x), Ok(y)) => {
                    let d = if x.abs() <= abs_zero && y.abs() <= abs_zero {
                        0.0
                    } else {
                        (x - y).abs() / x.abs().max(y.abs())
                    };
                    worst = worst.max(d);
                    if !close(x, y, rel_err, abs_zero) {
                        first.get_or_insert(format!(
                            "steps.csv row {} `{col}`: {x} against gold {y}",
                            ri + 1
                        ));
                    }
                }
                _ if x == y => {}
                _ => {
                    first.get_or_insert(format!(
                        "steps.csv row {} `{col}`: `{x}` against gold `{y}`",
                        ri + 1
                    ));
                }
            }
        }
    }
    if let Some(d) = json_diff(
        "summary",
        &summary,
        &gold_summary,
        rel_err,
        abs_zero,
        &mut worst,
    ) {
        first.get_or_insert(d);
    }
    r.measures.push(Measure {
        quantity: "largest relative difference".into(),
        measured: worst,
        tolerance: Some(rel_err),
        source: Some(format!(
            "CSVDiff-style rel_err = {rel_err:e}, abs_zero = {abs_zero:e}: the run must reproduce its gold to the solver's tolerance"
        )),
        pass: first.is_none(),
        note: first.clone().unwrap_or_else(|| format!("{} rows and the summary match", rows.len())),
        at_least: false,
    });
    Ok(None)
}
