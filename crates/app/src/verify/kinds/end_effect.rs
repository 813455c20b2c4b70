//! `end-effect`: a length family: the mid-span error against GPS fitted to c + A exp(−k L/R)
//! (open inflation) or c + A/(L/R) (gas-closed squeeze) ([`stats`](crate::stats)).

use super::{plot, rel, KindResult};
use crate::figures::{series_color, Figure, Markers, Series, Stroke};
use crate::quantity::step_pair;
use crate::verify::suite::Check;
use crate::verify::{run_member, stats, vary, CheckResult, Measure, VerifyOptions};
use std::path::Path;

kind!(
    /// The `end-effect` kind.
    EndEffect,
    "end-effect",
    end_effect
);

/// The length family run, then per quantity the end-effect law fitted, its residual, rate and
/// amplitude held, the length for ε, and the plot. Its length is that sequence, on one
/// family's table.
fn end_effect(c: &Check, dir: &Path, _opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let lengths = c.spec.lengths.clone().unwrap_or_default();
    let law = c.spec.law.unwrap_or(stats::EndLaw::Exponential);
    // the check's own quantity first, then any others fitted from the same runs
    let quantities: Vec<String> = match (&c.spec.quantity, &c.spec.quantities) {
        (Some(q), Some(more)) => std::iter::once(q.clone())
            .chain(more.iter().filter(|m| *m != q).cloned())
            .collect(),
        (None, Some(more)) if !more.is_empty() => more.clone(),
        (q, _) => vec![q.clone().unwrap_or_else(|| "w".into())],
    };
    let q = quantities[0].clone();
    let eps = c.spec.epsilon.unwrap_or(1e-3);
    let base: toml::Table = toml::from_str(&c.case_text).map_err(|e| e.to_string())?;
    let g = base.get("geometry").and_then(|g| g.as_table());
    let num =
        |v: Option<&toml::Value>| v.and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)));
    let radius = num(g.and_then(|g| g.get("radius"))).unwrap_or(1.0);
    let l0 =
        num(g.and_then(|g| g.get("length"))).ok_or("the case has no [geometry] length")? / radius;
    let mut errors = vec![];
    let mut others: Vec<Vec<f64>> = vec![vec![]; quantities.len() - 1];
    for (k, &l) in lengths.iter().enumerate() {
        let text = vary(&c.case_text, |t| {
            if let Some(g) = t.get_mut("geometry").and_then(|g| g.as_table_mut()) {
                g.insert("length".into(), toml::Value::Float(l * radius));
            }
            // the same element length along
            if let Some(m) = t.get_mut("mesh").and_then(|m| m.as_table_mut()) {
                if let Some(a) = m.get("along").and_then(|v| v.as_integer()) {
                    let n = ((a as f64) * l / l0).round().max(2.0) as i64;
                    m.insert("along".into(), toml::Value::Integer(n + n % 2));
                }
            }
        })?;
        let d = dir.join(format!("length_{k}"));
        r.runs.push(d.display().to_string());
        let rep = run_member(
            &text,
            &c.base_dir,
            &d,
            &format!("check {} L/R = {l}", c.spec.name),
        )?;
        let last = rep.steps().last().ok_or("a member run has no step")?;
        let (fe, cf) =
            step_pair(last, &q).ok_or(format!("`{q}` has no closed form at the last step"))?;
        errors.push(rel(fe, cf));
        for (o, more) in others.iter_mut().zip(&quantities[1..]) {
            o.push(step_pair(last, more).map_or(f64::NAN, |(fe, cf)| rel(fe, cf)));
        }
    }
    let fit =
        stats::fit_end_law(law, &lengths, &errors).ok_or("the end-effect law cannot be fitted")?;
    if let Some(e) = &c.spec.decay_rate {
        r.measures.push(Measure::expected(
            "",
            "k",
            fit.k,
            e,
            "fitted decay rate per R",
        ));
    }
    if let Some(e) = &c.spec.amplitude {
        r.measures
            .push(Measure::expected("", "A", fit.a, e, "fitted amplitude"));
    }
    if let Some(t) = &c.spec.max_residual {
        r.measures.push(Measure::held(
            "fit residual",
            fit.relative_residual,
            t,
            "rms residual of the law over max |e − c|".into(),
        ));
    }
    let needed = fit.length_for(eps);
    r.measures.push(Measure::reported(
        "length needed",
        needed,
        format!("L/R ≥ {needed:.2} for an end effect |A f(L/R)| ≤ ε = {eps:e}"),
    ));
    // the other quantities: their laws and lengths, reported; (quantity, errors, fit) of each
    // fitted one, for the details and the plot
    let mut fitted: Vec<(&str, &[f64], stats::EndFit)> = vec![(q.as_str(), &errors, fit)];
    let mut fits = serde_json::Map::new();
    fits.insert(
        q.clone(),
        serde_json::json!({"errors": errors, "fit": fit, "length_for_epsilon": needed}),
    );
    for (more, errs) in quantities[1..].iter().zip(&others) {
        let f = errs
            .iter()
            .all(|e| e.is_finite())
            .then(|| stats::fit_end_law(law, &lengths, errs))
            .flatten();
        match f {
            Some(f) => {
                let n = f.length_for(eps);
                r.measures.push(Measure::reported(
                    &format!("length needed ({more})"),
                    n,
                    format!(
                        "{more}: L/R ≥ {n:.2} for ε = {eps:e}; end effect {:+.3e} at L/R = {l0}, fit residual {:.1e}",
                        f.end_effect(l0),
                        f.relative_residual
                    ),
                ));
                fits.insert(
                    more.clone(),
                    serde_json::json!({"errors": errs, "fit": f, "length_for_epsilon": n}),
                );
                fitted.push((more.as_str(), errs, f));
            }
            None => {
                r.measures.push(Measure::reported(
                    &format!("length needed ({more})"),
                    f64::NAN,
                    format!("{more}: the end-effect law cannot be fitted to {errs:?}"),
                ));
            }
        }
    }
    r.details = serde_json::json!({
        "quantity": q, "lengths": lengths, "errors": errors, "fit": fit,
        "length_for_epsilon": needed, "epsilon": eps, "fits": fits,
    });
    let law_text = match law {
        stats::EndLaw::Exponential => format!(
            "c + A exp(−k L/R): c = {:.3e}, A = {:.3e}, k = {:.4}",
            fit.c, fit.a, fit.k
        ),
        stats::EndLaw::Inverse => format!("c + A/(L/R): c = {:.3e}, A = {:.4e}", fit.c, fit.a),
    };
    r.message = format!("{law_text}; L/R ≥ {needed:.1} for ε = {eps:e}");
    let (lmin, lmax) = lengths
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &l| (a.min(l), b.max(l)));
    // each fitted quantity: the FE points and the law, as log10 |FE/GPS − 1 − c|
    let mut markers = vec![];
    let mut series = vec![];
    let log = |v: f64| v.abs().max(1e-300).log10();
    for (k, &(name, errs, f)) in fitted.iter().enumerate() {
        markers.push(Markers {
            label: format!("FE, {name}"),
            points: lengths
                .iter()
                .zip(errs)
                .map(|(l, e)| (*l, log(e - f.c)))
                .collect(),
            color: series_color(k),
            hollow: false,
        });
        series.push(Series {
            label: if k == 0 {
                format!("{name}: {law_text}")
            } else {
                format!("{name}: fitted law")
            },
            points: (0..=60)
                .map(|j| {
                    let l = lmin + (lmax - lmin) * j as f64 / 60.0;
                    (l, log(f.end_effect(l)))
                })
                .collect(),
            color: series_color(k),
            stroke: Stroke::Solid,
            width: 2,
        });
    }
    plot(
        &Figure {
            markers,
            ..Figure::new(
                format!("{}: end effect on {}", c.spec.name, quantities.join(", ")),
                "tube length L/R",
                "log10 |FE/GPS − 1 − c|",
                series,
            )
        },
        r,
    );
    // the law's measures decide; when they pass the message is the fit
    Ok(None)
}
