//! `closed-form`: the mid-span against GPS at every step (and the section under the FE's own
//! pressure for a squeeze), per-quantity relative tolerances; PS reported.

use super::{member, plot, rel, KindResult};
use crate::figures::{series_color, Figure, Series, Stroke};
use crate::quantity::step_pair;
use crate::report::StepRecord;
use crate::verify::suite::Check;
use crate::verify::{CheckResult, Measure, VerifyOptions};
use plotters::style::RGBColor;
use std::path::Path;
use tubemem_gps::Hypothesis;

kind!(
    /// The `closed-form` kind.
    ClosedForm,
    "closed-form",
    closed_form
);

/// Every tolerated quantity against its closed form at every step, with the worst step kept
/// and one curve per quantity drawn. Its length is the list of quantity kinds (per step, the
/// last step only, the Maxwell plateau), each compared its own way.
fn closed_form(c: &Check, dir: &Path, _opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let report = member(c, &c.case_text, &dir.join("run"), r)?;
    let law = report.material_spec.build().map_err(|e| e.to_string())?;
    let steps: Vec<&StepRecord> = report.steps().collect();
    let mut series = vec![];
    // the Maxwell plateau: the steps whose mid-span sits in the propagating bulge
    let maxwell = if c.spec.tolerance.keys().any(|q| q.starts_with("maxwell_")) {
        let m = tubemem_gps::limits::limit_points(law.as_ref(), Hypothesis::Gps)
            .map_err(|e| e.to_string())?
            .maxwell
            .ok_or("the law has no Maxwell pressure (no pressure minimum)")?;
        let polygon = crate::case::Case::parse(&c.case_text)
            .map_err(|e| crate::error_chain(&e))?
            .mesh
            .polygon_factor()
            .ok_or(
                "maxwell_*: the case needs a generated mesh (`around`) for its polygon factor",
            )?;
        Some((m, polygon))
    } else {
        None
    };
    for (k, (q, tol)) in c.spec.tolerance.iter().enumerate() {
        let mut worst: Option<(f64, &StepRecord)> = None;
        let mut pts = vec![];
        let mut compared = 0;
        for (i, s) in steps.iter().enumerate() {
            let pair = match (q.as_str(), maxwell) {
                // the plateau's level: the step of least pressure among those whose mid-span
                // sits in the bulge (within 1 % of the upper coexisting stretch); a front near
                // a cap or near its mirror front only raises the pressure
                ("maxwell_w" | "maxwell_lambda_s", Some((m, polygon))) => {
                    let plateau = steps
                        .iter()
                        .filter(|t| {
                            t.contact.is_none()
                                && (t.midspan.lambda_s / m.lambda_s_upper - 1.0).abs() <= 0.01
                        })
                        .min_by(|a, b| a.midspan.w.total_cmp(&b.midspan.w));
                    match plateau {
                        Some(t) if std::ptr::eq(*t, *s) => Some(if q == "maxwell_w" {
                            (s.midspan.w, m.w * polygon)
                        } else {
                            (s.midspan.lambda_s, m.lambda_s_upper)
                        }),
                        _ => None,
                    }
                }
                ("maxwell_w" | "maxwell_lambda_s", None) => None,
                // the closed form is a uniform tube: not compared where the run found the tube
                // not uniform (a bulge), or a squeeze that started from such a tube
                _ if s.gps_applicable == Some(false) => None,
                _ => match q.strip_prefix("final_") {
                    Some(inner) if i + 1 == steps.len() => step_pair(s, inner),
                    Some(_) => None,
                    None => step_pair(s, q),
                },
            };
            // plotted as the share of the tolerance used, every quantity on one scale; a
            // `final_` quantity's curve shows every step, against the last step's tolerance
            let curve = match q.strip_prefix("final_") {
                Some(inner) if s.gps_applicable != Some(false) => step_pair(s, inner),
                _ => pair,
            };
            if let Some((fe, cf)) = curve.filter(|_| tol.value > 0.0) {
                pts.push(((i + 1) as f64, rel(fe, cf).abs() / tol.value));
            }
            if let Some((fe, cf)) = pair {
                let e = rel(fe, cf);
                compared += 1;
                if worst.is_none_or(|(w, _)| e.abs() > w.abs()) {
                    worst = Some((e, s));
                }
            }
        }
        match worst {
            None => r.measures.push(Measure::missing(
                q,
                tol,
                "no step of this run has this comparison",
            )),
            Some((e, s)) => r.measures.push(Measure::held(
                q,
                e.abs(),
                tol,
                format!(
                    "max |FE/GPS − 1| over {compared} steps, {e:+.3e} at stage {} step {}",
                    s.stage, s.step
                ),
            )),
        }
        series.push(Series {
            label: format!("{q}: |FE/GPS − 1| / tolerance"),
            points: pts,
            color: series_color(k),
            stroke: Stroke::Solid,
            width: 2,
        });
    }
    // PS, reported: ϖ against PS at the same λs (inflation) or the same ρ from λs* (squeeze)
    let mut ps_worst = 0.0f64;
    let mut ps_pts = vec![];
    for (i, s) in steps.iter().enumerate() {
        let ps = match &s.contact {
            None => tubemem_gps::inflate(law.as_ref(), Hypothesis::Ps, s.midspan.lambda_s)
                .map(|p| p.w)
                .ok(),
            Some(ct) => tubemem_gps::flatten(
                law.as_ref(),
                Hypothesis::Ps,
                ct.initial_stretch,
                ct.values.rho,
            )
            .map(|p| p.w)
            .ok(),
        };
        if let Some(p) = ps {
            let e = rel(s.midspan.w, p);
            ps_pts.push(((i + 1) as f64, e));
            if e.abs() > ps_worst.abs() {
                ps_worst = e;
            }
        }
    }
    r.measures.push(Measure::reported(
        "w vs PS",
        ps_worst.abs(),
        format!("max |FE/PS − 1| = {ps_worst:+.3e} (reported: PS fixes λz = 1)"),
    ));
    r.details = serde_json::json!({
        "steps": steps.len(),
        "equations": report.mesh.equations,
        "material": report.material,
    });
    let n = steps.len().max(1) as f64;
    series.push(Series {
        label: "the tolerance".into(),
        points: vec![(1.0, 1.0), (n, 1.0)],
        color: RGBColor(0, 0, 0),
        stroke: Stroke::Dashed,
        width: 1,
    });
    // a `final_` quantity is judged at the last step only: its curve shows the others against
    // that step's tolerance, for the trend
    let notes = if c.spec.tolerance.keys().any(|q| q.starts_with("final_")) {
        vec!["final_*: judged at the last step only; the earlier steps are shown against its tolerance".to_string()]
    } else {
        vec![]
    };
    plot(
        &Figure {
            notes,
            ..Figure::new(
                format!("{}: FE against GPS at every step", c.spec.name),
                "step (all stages)",
                "share of the tolerance used",
                series,
            )
        },
        r,
    );
    Ok(None)
}
