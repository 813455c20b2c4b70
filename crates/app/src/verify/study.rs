//! `tubemem verify --case MY_CASE.toml`: the study a user wants for their own tube, built
//! from the case and run as checks:
//!
//! 1. `convergence`: three meshes around the user's (one coarser and one finer by 2; with
//!    `quick`, two coarser and the user's), observed order (expected 2: the bilinear facets'
//!    polygon error 1/cos(π/n) − 1 ∝ n⁻²), Richardson extrapolation and GCI (the extrapolated
//!    value against GPS is the closed-form check's to judge, with the end effect);
//! 2. `end-effect`: the tube at L/2, L and 2L (quick: L/2, 3L/4, L), the law fitted
//!    (exponential for an inflation, 1/L for a squeeze or confine stage with the gas closed) and the length
//!    needed for ε = 1e-3;
//! 3. `invariance`: the translation-invariant core of the user's run (ε = 1e-3), which must be
//!    at least half the tube;
//! 4. `closed-form`: the user's run against GPS at every step. Its tolerance is what the other
//!    checks explain: |discretization error (Richardson)| + |end effect at L (fitted law)| + GCI
//!    (the difference must be accounted for by the mesh and the ends);
//! 5. `reference`: against the scikit-fem references when Python has them (else skipped).
//!
//! The verdict says whether GPS describes the tube's mid-span and to what accuracy.

use super::stats::EndLaw;
use super::suite::{CaseRef, Check, CheckKind, CheckSpec, Expect, Tol};
use super::{run_checks, CheckResult, Event, Status, VerifyOptions};
use std::collections::BTreeMap;
use std::path::Path;

fn spec(name: &str, kind: CheckKind, case: &str) -> CheckSpec {
    CheckSpec {
        name: name.into(),
        case: CaseRef::Path(case.into()),
        kind,
        tolerance: BTreeMap::new(),
        refinement: None,
        meshes: None,
        start: None,
        quantities: None,
        expected_order: None,
        compare_reference: None,
        lengths: None,
        law: None,
        quantity: None,
        epsilon: None,
        decay_rate: None,
        amplitude: None,
        max_residual: None,
        min_core_fraction: None,
        gold: None,
        rel_err: None,
        abs_zero: None,
    }
}

/// The study's outcome: its checks and the verdict.
pub struct Study {
    pub results: Vec<CheckResult>,
    pub verdict: String,
}

/// The study's check `name` among `results`, by name: `--filter` may have left any out.
fn named<'a>(results: &'a [CheckResult], name: &str) -> Option<&'a CheckResult> {
    results.iter().find(|r| r.name == name)
}

/// Build and run the study of `case_path` into `out`.
pub fn run_study(
    case_path: &Path,
    out: &Path,
    quick: bool,
    opts: &VerifyOptions,
    progress: &(dyn Fn(Event) + Sync),
) -> Result<Study, String> {
    let text =
        std::fs::read_to_string(case_path).map_err(|e| format!("{}: {e}", case_path.display()))?;
    let case = crate::case::Case::parse(&text)
        .map_err(|e| format!("{}: {}", case_path.display(), crate::error_chain(&e)))?;
    if case.mesh.file.is_some() {
        return Err(
            "the study refines a generated mesh: give `around` and `along`, not a mesh file".into(),
        );
    }
    // the gas closed in (a squeeze or a confine stage last): the end effect falls as 1/L
    let last_kind = case.stages.last().map(|s| s.kind);
    let squeeze = last_kind == Some(crate::case::Kind::Squeeze);
    let closed_gas = squeeze || last_kind == Some(crate::case::Kind::Confine);
    let l = case.geometry.length / case.geometry.radius;
    let base_dir = case_path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let name = case_path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "case".into());
    let mk = |spec: CheckSpec| Check {
        spec,
        suite: format!("study of {name}"),
        case_text: text.clone(),
        base_dir: base_dir.clone(),
        gold_dir: base_dir.clone(),
    };
    let path = case_path.display().to_string();
    let mut conv = spec("convergence", CheckKind::Convergence, &path);
    conv.refinement = Some(2.0);
    conv.meshes = Some(3);
    // one or two levels coarser than the user's mesh, never below 8 elements around
    let around = case.mesh.around.unwrap_or(8) as f64;
    let coarsest = -((around / 8.0).log2().floor().max(0.0) as i32);
    let start = (if quick { -2 } else { -1 }).max(coarsest);
    conv.start = Some(start);
    conv.expected_order = Some(match case.mesh.element {
        tubemem_mesh::ElementKind::Quad4 => Expect {
            value: 2.0,
            within: 0.5,
            source: "bilinear facets: the polygon error 1/cos(π/n) − 1 ≈ π²/(2n²) is O(n⁻²)"
                .into(),
        },
        tubemem_mesh::ElementKind::Quad9 => Expect {
            value: 4.0,
            within: 0.5,
            source: "biquadratic isoparametric geometry: the volume, the Rivlin sphere's limit pressure and the tube's mid-span ϖ converge at order 4 (crates/fem/src/tests_quad9.rs, scripts/convergence-tables.py)".into(),
        },
    });
    let mut end = spec("end-effect", CheckKind::EndEffect, &path);
    end.lengths = Some(if quick {
        vec![0.5 * l, 0.75 * l, l]
    } else {
        vec![0.5 * l, l, 2.0 * l]
    });
    end.law = Some(if closed_gas {
        EndLaw::Inverse
    } else {
        EndLaw::Exponential
    });
    end.epsilon = Some(1e-3);
    let mut inv = spec("invariance", CheckKind::Invariance, &path);
    inv.epsilon = Some(1e-3);
    inv.min_core_fraction = Some(Tol {
        value: 0.5,
        source:
            "the study's criterion: GPS describes a tube whose middle half is translation invariant"
                .into(),
    });
    let mut reference = spec("reference", CheckKind::Reference, &path);
    reference.tolerance.insert(
        "profile".into(),
        Tol {
            value: 5e-3,
            source: "the FE end-cap profile against the axisymmetric one: 1.07e-4 at 64 around, 5.7e-4 at 16 around (README), with room for coarser meshes".into(),
        },
    );
    // the end effect first: the convergence check's reference is GPS up to the end effect
    let mut results = run_checks(&[mk(end), mk(inv), mk(reference)], out, opts, progress)
        .map_err(|e| e.chain())?;
    let q = "w";
    let fit = named(&results, "end-effect").and_then(|r| r.details.get("fit"));
    let end_at_l = fit.and_then(|f| {
        let a = f["a"].as_f64()?;
        let k = f["k"].as_f64()?;
        Some(if closed_gas {
            a / l
        } else {
            a * (-k * l).exp()
        })
    });
    // ϖ (and the force of a squeeze): λz and the resultants match GPS to ~1e-8 on any mesh,
    // with no discretization signal to extrapolate
    conv.quantities = Some(if squeeze {
        vec!["w".into(), "force".into()]
    } else {
        vec!["w".into()]
    });
    // the extrapolated value against GPS is judged by the closed-form check below, which
    // allows for the end effect and the mesh together
    conv.compare_reference = Some(false);
    results.extend(run_checks(&[mk(conv)], out, opts, progress).map_err(|e| e.chain())?);
    let conv_r = named(&results, "convergence");
    let end_r = named(&results, "end-effect");
    let (have_end, have_conv) = (end_r.is_some(), conv_r.is_some());
    let table = conv_r
        .and_then(|r| r.details.get("quantities"))
        .and_then(|t| t.as_array());
    let w_row = table.and_then(|t| t.iter().find(|r| r["quantity"] == q));
    let values = w_row.and_then(|r| r["values"].as_array());
    // the user's mesh is member −start
    let user = (-start) as usize;
    let user_value = values.and_then(|v| v.get(user)).and_then(|v| v.as_f64());
    let extrapolated = w_row.and_then(|r| r["extrapolated"].as_f64());
    let gci = w_row.and_then(|r| r["gci_fine"].as_f64());
    let discretization = match (user_value, extrapolated) {
        (Some(u), Some(e)) => Some(u / e - 1.0),
        _ => None,
    };
    let needed = end_r.and_then(|r| r.details.get("length_for_epsilon")?.as_f64());
    let mut cf = spec("closed-form", CheckKind::ClosedForm, &path);
    let (tol, source) = match (discretization, end_at_l, gci) {
        (Some(d), Some(e), Some(g)) => (
            d.abs() + e.abs() + g,
            format!(
                "this study: discretization {d:+.2e} (Richardson, check `convergence`) + end effect {e:+.2e} at L/R = {l} (fitted law, check `end-effect`) + GCI {g:.1e}"
            ),
        ),
        _ => (
            f64::NAN,
            "the convergence or end-effect check did not give an estimate".into(),
        ),
    };
    cf.tolerance.insert(q.into(), Tol { value: tol, source });
    let cf_results = if tol.is_finite() {
        run_checks(&[mk(cf)], out, opts, progress).map_err(|e| e.chain())?
    } else {
        vec![]
    };
    results.extend(cf_results);
    let cf_r = named(&results, "closed-form");
    let measured = cf_r.and_then(|r| r.measures.first()).map(|m| m.measured);
    let core = named(&results, "invariance")
        .and_then(|r| r.measures.first())
        .map(|m| m.measured);
    let all_ok = results
        .iter()
        .all(|r| matches!(r.status, Status::Pass | Status::Skipped));
    let mut verdict = String::new();
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| matches!(r.status, Status::Fail | Status::Error))
        .map(|r| r.name.as_str())
        .collect();
    // what `--filter` left out of the comparison with GPS
    let left_out = opts
        .filter
        .as_deref()
        .filter(|_| !(have_end && have_conv))
        .map(|f| {
            format!(
                "the comparison with GPS was not made: it needs the end-effect and convergence checks, and --filter {f:?} left {} out; ",
                match (have_end, have_conv) {
                    (false, false) => "both",
                    (false, true) => "end-effect",
                    _ => "convergence",
                }
            )
        });
    match (measured, discretization, end_at_l) {
        (Some(m), Some(d), Some(e)) if all_ok => {
            verdict = format!(
                "GPS describes the mid-span of this tube: ϖ agrees with GPS to {m:.1e} at every step, of which the mesh accounts for {d:+.1e} (GCI {:.0e}) and the ends for {e:+.1e}; ",
                gci.unwrap_or(f64::NAN)
            );
        }
        _ if !failed.is_empty() => {
            verdict = format!(
                "GPS does NOT describe the mid-span of this tube as it is run: {}{} did not pass; ",
                measured.map_or(String::new(), |m| format!(
                    "ϖ differs from GPS by up to {m:.1e}, and "
                )),
                failed.join(", ")
            );
            verdict.push_str(left_out.as_deref().unwrap_or(""));
        }
        _ => verdict.push_str(
            left_out
                .as_deref()
                .unwrap_or("the comparison with GPS could not be made (see the checks); "),
        ),
    }
    // past the GPS pressure maximum the uniform state is unstable: say so
    let last_ls = results
        .iter()
        .find(|r| r.name == "closed-form")
        .and_then(|_| case.stages.last().and_then(|s| s.target_stretch));
    if let (Ok(law), Some(ls)) = (case.material.build(), last_ls) {
        if let Ok(lim) =
            tubemem_gps::limits::limit_points(law.as_ref(), tubemem_gps::Hypothesis::Gps)
        {
            if let Some(mx) = lim.max.filter(|mx| ls > mx.lambda_s) {
                match lim.min.filter(|mn| ls >= mn.lambda_s) {
                    // beyond both limit points the uniform state is stable again, but the path
                    // to it went through a bulge, whose fronts may still be near the caps
                    Some(mn) => verdict.push_str(&format!(
                        "the target λs* = {ls} lies beyond both GPS limit points (maximum ϖ = {:.4} at λs = {:.3}, minimum {:.4} at {:.3}): a uniform tube is stable there again, but the path to it passes a bulge that propagates to the caps, and the tube may still be transitioning near them; ",
                        mx.w, mx.lambda_s, mn.w, mn.lambda_s
                    )),
                    None => verdict.push_str(&format!(
                        "the target λs* = {ls} lies past the GPS pressure maximum (ϖ = {:.4} at λs = {:.3}), where the uniform state is unstable and a bulge forms; ",
                        mx.w, mx.lambda_s
                    )),
                }
            }
        }
    }
    if let Some(c) = core {
        verdict.push_str(&format!(
            "the middle {:.0} % of the tube is translation invariant (ε = 1e-3); ",
            100.0 * c
        ));
    }
    if let Some(n) = needed {
        verdict.push_str(&format!(
            "an end effect below ε = 1e-3 needs L/R ≥ {n:.1} (this tube: {l})."
        ));
    }
    Ok(Study { results, verdict })
}
