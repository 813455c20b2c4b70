//! The atlas's fits: per (λs*, ρ, quantity) the end-effect law of FE/GPS − 1 against L/R
//! ([`stats::fit_end_law`]), c (the part the length does not change: the mesh's) separated from
//! the end effect A f(L/R); per ε the minimum L/R with |A f(L/R)| ≤ ε; a point where the law
//! does not hold is flagged with its reason and has no number.

use super::member::MemberResult;
use super::spec::{Atlas, QUANTITIES};
use crate::stats::{self, EndFit};
use serde::{Deserialize, Serialize};

/// Why a point has no law.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Flag {
    /// `run-failed`, `no-contact`, `bulging`, `limit-point`, `no-closed-form`, `too-few-lengths`
    /// or `fit-residual`
    pub flag: String,
    pub reason: String,
}

/// One (λs*, ρ, quantity) of the atlas.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Point {
    pub stretch: f64,
    pub rho: f64,
    pub quantity: String,
    /// FE/GPS − 1 per atlas length (None where the run has no value)
    pub errors: Vec<Option<f64>>,
    pub fit: Option<EndFit>,
    /// per ε of the atlas: the minimum L/R (None where flagged)
    pub min_length: Vec<Option<f64>>,
    pub flag: Option<Flag>,
}

impl Point {
    /// The fitted law's FE/GPS − 1 at length `l` (c + A f(l)); None where flagged.
    pub fn predict(&self, l: f64) -> Option<f64> {
        match (&self.flag, &self.fit) {
            (None, Some(f)) => Some(f.c + f.end_effect(l)),
            _ => None,
        }
    }
}

fn flag(flag: &str, reason: impl Into<String>) -> Option<Flag> {
    Some(Flag {
        flag: flag.into(),
        reason: reason.into(),
    })
}

/// The points of the atlas from its members' results (in member order: λs* outer, L/R inner),
/// λs* outer, ρ (the atlas's order) then quantity inner.
pub fn points(atlas: &Atlas, results: &[MemberResult]) -> Vec<Point> {
    let s = &atlas.spec;
    let mut out = vec![];
    for &stretch in &s.stretches {
        let runs: Vec<&MemberResult> = s
            .lengths
            .iter()
            .map(|&l| {
                results
                    .iter()
                    .find(|r| r.stretch == stretch && r.length == l)
                    .expect("a result per member")
            })
            .collect();
        for &rho in &s.rho {
            for q in &s.quantities {
                let qi = QUANTITIES.iter().position(|x| x == q).expect("validated");
                out.push(point(atlas, stretch, rho, q, qi, &runs));
            }
        }
    }
    out
}

fn point(
    atlas: &Atlas,
    stretch: f64,
    rho: f64,
    q: &str,
    qi: usize,
    runs: &[&MemberResult],
) -> Point {
    let s = &atlas.spec;
    let levels: Vec<_> = runs.iter().map(|r| r.level(rho)).collect();
    let errors: Vec<Option<f64>> = levels
        .iter()
        .map(|l| l.and_then(|l| l.values[qi]).map(|p| p.error()))
        .collect();
    let mut p = Point {
        stretch,
        rho,
        quantity: q.to_string(),
        errors: errors.clone(),
        fit: None,
        min_length: vec![None; s.epsilon.len()],
        flag: None,
    };
    let at = |r: &MemberResult| format!("L/R = {}", r.length);
    if rho >= stretch {
        p.flag = flag(
            "no-contact",
            format!("ρ = {rho} is not below λs* = {stretch}: the plates do not reach the tube"),
        );
        return p;
    }
    // a run that did not reach the level first: it says most about the point
    if let Some((r, _)) = runs.iter().zip(&levels).find(|(_, l)| l.is_none()) {
        p.flag = flag(
            "run-failed",
            format!(
                "{} did not reach ρ = {rho}: {}",
                at(r),
                r.error.as_deref().unwrap_or("no value")
            ),
        );
        return p;
    }
    for (r, l) in runs.iter().zip(&levels) {
        match l {
            None => {}
            Some(l) if !l.contact => {
                p.flag = flag(
                    "no-contact",
                    format!("{}: the mid-span ring does not touch the plates yet", at(r)),
                );
                return p;
            }
            Some(l) if l.uniform == Some(false) => {
                p.flag = flag(
                    "bulging",
                    format!(
                        "{}: the tube is not uniform over its central half (a bulge): GPS does not describe it",
                        at(r)
                    ),
                );
                return p;
            }
            Some(l) if l.critical => {
                p.flag = flag(
                    "limit-point",
                    format!(
                        "{}: a critical point was located on the path before ρ = {rho}",
                        at(r)
                    ),
                );
                return p;
            }
            Some(l) if l.values[qi].is_none() => {
                p.flag = flag(
                    "no-closed-form",
                    format!("{}: the GPS flattening has no {q} at ρ = {rho}", at(r)),
                );
                return p;
            }
            Some(_) => {}
        }
    }
    // every length has a value here (the loop above returned otherwise)
    let values: Vec<f64> = errors.iter().map(|e| e.unwrap_or(f64::NAN)).collect();
    let fit = stats::fit_end_law(s.law, &s.lengths, &values);
    let Some(fit) = fit else {
        p.flag = flag("too-few-lengths", "the law cannot be fitted");
        return p;
    };
    p.fit = Some(fit);
    if fit.relative_residual > s.max_residual {
        p.flag = flag(
            "fit-residual",
            format!(
                "the law's relative rms residual {:.3e} is above max_residual = {}: the runs do not follow {}",
                fit.relative_residual,
                s.max_residual,
                law_name(s.law)
            ),
        );
        return p;
    }
    p.min_length = s.epsilon.iter().map(|&e| Some(fit.length_for(e))).collect();
    p
}

/// The law as a formula.
pub fn law_name(law: stats::EndLaw) -> &'static str {
    match law {
        stats::EndLaw::Inverse => "c + A/(L/R)",
        stats::EndLaw::Exponential => "c + A exp(−k L/R)",
    }
}

/// Where a length lies against the lengths an atlas ran: a minimum L/R or a prediction's
/// length outside them is the law's extrapolation, and says so.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Extent {
    /// within the shortest and the longest run
    Within,
    /// shorter than every run: the end effect was already below ε at every length run, so
    /// the minimum is at most the shortest run's length, not the law's value
    BelowRuns,
    /// longer than every run: the law's extrapolation
    BeyondRuns,
}

impl Extent {
    /// atlas.csv's `min_length_extent` value ("" within the runs).
    pub fn name(self) -> &'static str {
        match self {
            Extent::Within => "",
            Extent::BelowRuns => "below-runs",
            Extent::BeyondRuns => "beyond-runs",
        }
    }
}

/// Where `length` lies against `lengths` (the atlas's runs).
pub fn extent(length: f64, lengths: &[f64]) -> Extent {
    let lo = lengths.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = lengths.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if length < lo {
        Extent::BelowRuns
    } else if length > hi {
        Extent::BeyondRuns
    } else {
        Extent::Within
    }
}
