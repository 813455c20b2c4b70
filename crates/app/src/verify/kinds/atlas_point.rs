//! `atlas-point`: a user's atlas point held to its fitted law. The check's case is an atlas
//! file; the atlas is run (or resumed) under the check's folder, then the FE runs the atlas's
//! tube at a length the atlas did not use, and the measured FE/GPS − 1 of each quantity must
//! agree with the law's prediction c + A f(L/R) within `tolerance.prediction` of the prediction.

use super::{plot, KindResult};
use crate::atlas::{self, Atlas, Member};
use crate::figures::{series_color, Figure, Markers, Series, Stroke};
use crate::verify::suite::Check;
use crate::verify::{CheckResult, Measure, VerifyOptions};
use std::path::Path;

kind!(
    /// The `atlas-point` kind.
    AtlasPoint,
    "atlas-point",
    atlas_point
);

fn atlas_point(c: &Check, dir: &Path, opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let p = c.spec.point.ok_or("an atlas-point check needs `point`")?;
    let a = Atlas::parse(&c.case_text, &c.base_dir).map_err(|e| crate::error_chain(&e))?;
    let tol = c
        .spec
        .tolerance
        .get("prediction")
        .ok_or("an atlas-point check needs `tolerance.prediction`")?;
    let workers = if opts.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        opts.jobs
    };
    let out = dir.join("atlas");
    r.runs.push(out.display().to_string());
    let o =
        atlas::run(&a, &c.case_text, &out, workers, &|_| {}).map_err(|e| crate::error_chain(&e))?;
    if !o.missing.is_empty() {
        return Err(format!(
            "interrupted: atlas runs missing ({})",
            o.missing.join(", ")
        ));
    }
    let held = dir.join("held_out");
    r.runs.push(held.display().to_string());
    let m = Member {
        name: "held_out".into(),
        stretch: p.lambda_s_star,
        length: p.length_ratio,
        case_text: a
            .member_case(p.lambda_s_star, p.length_ratio)
            .map_err(|e| crate::error_chain(&e))?,
    };
    let res = atlas::member::run(&a, &m, &held);
    if let Some(e) = &res.error {
        return Err(format!("the held-out run failed: {e}"));
    }
    let level = res
        .level(p.rho)
        .ok_or(format!("the held-out run has no level ρ = {}", p.rho))?;
    let quantities = c
        .spec
        .quantities
        .clone()
        .unwrap_or(a.spec.quantities.clone());
    let mut markers = vec![];
    let mut series = vec![];
    let mut details = serde_json::Map::new();
    for (k, q) in quantities.iter().enumerate() {
        let point = o
            .points
            .iter()
            .find(|x| x.stretch == p.lambda_s_star && x.rho == p.rho && &x.quantity == q)
            .ok_or(format!(
                "`{q}` is not one of the atlas's quantities at the point"
            ))?;
        let predicted = point.predict(p.length_ratio).ok_or_else(|| {
            let f = point.flag.as_ref();
            format!(
                "{q} has no law at the point ({})",
                f.map_or("no fit".into(), |f| format!("{}: {}", f.flag, f.reason))
            )
        })?;
        let qi = atlas::spec::QUANTITIES
            .iter()
            .position(|x| x == q)
            .ok_or(format!("unknown quantity `{q}`"))?;
        let measured = level.values[qi]
            .ok_or(format!("the held-out run has no closed form for {q}"))?
            .error();
        let off = (measured - predicted).abs() / predicted.abs();
        r.measures.push(Measure::held(
            &format!("prediction ({q})"),
            off,
            tol,
            format!(
                "{q} at L/R = {}: FE/GPS − 1 = {measured:.5e} measured, {predicted:.5e} predicted by the atlas's law",
                p.length_ratio
            ),
        ));
        details.insert(
            q.clone(),
            serde_json::json!({"measured": measured, "predicted": predicted, "fit": point.fit, "errors": point.errors}),
        );
        let fit = point.fit.expect("a prediction has a fit");
        let color = series_color(k);
        let mut pts: Vec<(f64, f64)> = a
            .spec
            .lengths
            .iter()
            .zip(&point.errors)
            .filter_map(|(l, e)| e.map(|e| (*l, e)))
            .collect();
        pts.sort_by(|x, y| x.0.total_cmp(&y.0));
        markers.push(Markers {
            label: format!("{q}: atlas runs"),
            points: pts,
            color,
            hollow: false,
        });
        markers.push(Markers {
            label: format!("{q}: held-out run"),
            points: vec![(p.length_ratio, measured)],
            color,
            hollow: true,
        });
        let lmax = a
            .spec
            .lengths
            .iter()
            .copied()
            .fold(p.length_ratio, f64::max);
        let lmin = a
            .spec
            .lengths
            .iter()
            .copied()
            .fold(p.length_ratio, f64::min);
        series.push(Series {
            label: format!("{q}: c + A/(L/R), c = {:.3e}, A = {:.4e}", fit.c, fit.a),
            points: (0..=60)
                .map(|j| {
                    let l = lmin + (lmax - lmin) * j as f64 / 60.0;
                    (l, fit.c + fit.end_effect(l))
                })
                .collect(),
            color,
            stroke: Stroke::Solid,
            width: 2,
        });
    }
    r.details = serde_json::Value::Object(details);
    r.message = format!(
        "λs* = {}, ρ = {}: the held-out L/R = {} against the atlas's law",
        p.lambda_s_star, p.rho, p.length_ratio
    );
    plot(
        &Figure {
            markers,
            y_from_zero: false,
            ..Figure::new(
                format!("{}: atlas law against a held-out length", c.spec.name),
                "tube length L/R",
                "FE/GPS − 1",
                series,
            )
        },
        r,
    );
    Ok(None)
}
