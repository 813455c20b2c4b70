//! `invariance`: the middle region within which every profile quantity stays within ε of its
//! mid-span value, at every step.

use super::{member, plot, KindResult};
use crate::figures::{series_color, Figure, Series, Stroke};
use crate::report::StepRecord;
use crate::verify::suite::Check;
use crate::verify::{CheckResult, Measure, VerifyOptions};
use std::path::Path;

kind!(
    /// The `invariance` kind.
    Invariance,
    "invariance",
    invariance
);

/// The core of one profile: (core length on the +z side, on the −z side (None for a model
/// symmetric about z = 0), the quantity that ends the core on the +z side). The geometric
/// contact width is compared only where the mid-span flat, π × `contact_width`, spans at least
/// `resolution` (the mesh's node spacing around: the width comes from zero crossings of nodal
/// values, O(h), and a flat narrower than a node spacing is below what it resolves; at a
/// squeeze's first touch, a flat of 5e-4 R, it varies by 1 % along the middle while the
/// contact force per length, compared always, varies by 9e-4).
fn core(
    rings: &[tubemem_fem::post::RingValues],
    eps: f64,
    resolution: f64,
) -> Option<(f64, Option<f64>, String)> {
    let mid = rings
        .iter()
        .min_by(|a, b| a.z_ref.abs().total_cmp(&b.z_ref.abs()))?;
    let m = &mid.values;
    let checks = |r: &tubemem_fem::post::RingValues| -> Option<&'static str> {
        let v = &r.values;
        for (name, a, b) in [
            ("lambda_s", v.lambda_s, m.lambda_s),
            ("lambda_z", v.lambda_z, m.lambda_z),
            ("n_s", v.n_s, m.n_s),
            ("n_z", v.n_z, m.n_z),
        ] {
            if (a / b - 1.0).abs() > eps {
                return Some(name);
            }
        }
        if (v.n_sz - m.n_sz).abs() > eps * m.n_s.abs() {
            return Some("n_sz");
        }
        if std::f64::consts::PI * mid.contact_width >= resolution
            && (r.contact_width / mid.contact_width - 1.0).abs() > eps
        {
            return Some("contact_width");
        }
        if mid.contact_force > 0.0 && (r.contact_force / mid.contact_force - 1.0).abs() > eps {
            return Some("contact_force");
        }
        None
    };
    let side = |sign: f64| -> Option<(f64, String)> {
        let mut s: Vec<_> = rings.iter().filter(|r| sign * r.z_ref >= -1e-12).collect();
        if s.len() < 2 {
            return None;
        }
        s.sort_by(|a, b| a.z_ref.abs().total_cmp(&b.z_ref.abs()));
        let mut core = 0.0;
        for r in &s {
            if let Some(q) = checks(r) {
                return Some((core, q.to_string()));
            }
            core = r.z_ref.abs();
        }
        Some((core, "none".into()))
    };
    let (plus, why) = side(1.0)?;
    let minus = side(-1.0).map(|s| s.0);
    Some((plus, minus, why))
}

fn invariance(c: &Check, dir: &Path, _opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let eps = c.spec.epsilon.unwrap_or(1e-3);
    let report = member(c, &c.case_text, &dir.join("run"), r)?;
    // the profiles' reference z is in R (the dimensionless core), whatever the case's units:
    // the tube's length is taken in R too, L/R
    let length = report.geometry.length / report.geometry.radius;
    let half = 0.5 * length;
    let units = report.scales.map_or(
        crate::units::Units::dimensionless(),
        crate::units::Units::si,
    );
    let in_units = |v: f64| units.show(crate::units::Dimension::Length, v);
    let mut per_step = vec![];
    let mut worst: Option<(f64, &StepRecord, String)> = None;
    let mut pts = vec![];
    // the node spacing around the mid-span ring of a generated tube, per R (0 for a user mesh: the
    // width is then always compared)
    let case = crate::case::Case::parse(&c.case_text).map_err(|e| crate::error_chain(&e))?;
    let nodes_around = case
        .mesh
        .around
        .map(|n| n * (case.mesh.element.gauss_per_direction() - 1));
    for (i, s) in report.steps().enumerate() {
        if s.profile.is_empty() {
            continue;
        }
        let resolution = nodes_around.map_or(0.0, |n| {
            2.0 * std::f64::consts::PI * s.midspan.lambda_s / n as f64
        });
        let Some((plus, minus, why)) = core(&s.profile, eps, resolution) else {
            continue;
        };
        let minus = minus.unwrap_or(plus);
        let fraction = (plus + minus) / length;
        // a core longer than the tube is a unit mix-up, never a result (issue #60)
        if !(0.0..=1.0 + 1e-9).contains(&fraction) {
            return Err(format!(
                "stage {} step {}: the invariant core {:.6} R is not within the tube's length {:.6} R: the profile and the tube's length disagree in their units",
                s.stage, s.step, plus + minus, length
            ));
        }
        per_step.push(serde_json::json!({
            "stage": s.stage, "step": s.step, "core_length": plus + minus,
            "core_fraction": fraction,
            "boundary_layer_plus": half - plus,
            "boundary_layer_minus": half - minus,
            "limited_by": why,
        }));
        pts.push(((i + 1) as f64, fraction));
        if worst.as_ref().is_none_or(|(f, _, _)| fraction < *f) {
            worst = Some((fraction, s, why));
        }
    }
    let Some((fraction, s, why)) = worst else {
        return Err("the run has no per-step profiles ([output] profiles = \"stage-end\"?)".into());
    };
    // without `min_core_fraction` the core is reported, not gated
    let tol = c.spec.min_core_fraction.clone();
    r.measures.push(Measure {
        quantity: "core fraction".into(),
        measured: fraction,
        tolerance: tol.as_ref().map(|t| t.value),
        source: tol.as_ref().map(|t| t.source.clone()),
        pass: tol.as_ref().is_none_or(|t| fraction >= t.value),
        at_least: tol.is_some(),
        note: format!(
            "smallest over {} steps, at stage {} step {}: the middle {} of {} stay within ε = {eps:e} of mid-span (then {why} leaves it); boundary layer {} at each cap",
            per_step.len(),
            s.stage,
            s.step,
            in_units(fraction * length),
            in_units(length),
            in_units((1.0 - fraction) * 0.5 * length),
        ),
    });
    if tol.is_none() {
        r.message = format!(
            "the middle {:.0} % of the tube is translation invariant (ε = {eps:e}), at its smallest (stage {} step {}); reported",
            100.0 * fraction,
            s.stage,
            s.step
        );
    }
    r.details = serde_json::json!({ "epsilon": eps, "steps": per_step });
    plot(
        &Figure::new(
            format!("{}: translation-invariant core", c.spec.name),
            "step (all stages)",
            "core length / L",
            std::iter::once(Series {
                label: format!("core within ε = {eps:e}"),
                points: pts.clone(),
                color: series_color(0),
                stroke: Stroke::Solid,
                width: 2,
            })
            .chain(tol.as_ref().map(|t| Series {
                label: "required".into(),
                points: vec![(1.0, t.value), (pts.len().max(1) as f64, t.value)],
                color: series_color(1),
                stroke: Stroke::Dashed,
                width: 2,
            }))
            .collect(),
        ),
        r,
    );
    Ok(None)
}
