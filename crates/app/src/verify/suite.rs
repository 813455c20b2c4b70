//! The suite file: `[[check]]` tables, each with a case, a kind and sourced tolerances.
//!
//! ```toml
//! [suite]
//! name = "ci"
//!
//! [[check]]
//! name = "inflate-1.3"
//! case = "../cases/inflate_abb30_ls1.3.toml"   # relative to this file, or an inline table
//! kind = "closed-form"
//! tolerance.w = { value = 1.5e-3, source = "64-gon factor 1/cos(π/64) − 1 = 1.2e-3" }
//! ```

use crate::stats::EndLaw;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A tolerance and where its number comes from.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Tol {
    pub value: f64,
    /// a paper equation, a measured refinement study or a fitted law
    pub source: String,
}

/// An expected value with its admissible distance and source (e.g. an observed order).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    pub value: f64,
    pub within: f64,
    pub source: String,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum CheckKind {
    ClosedForm,
    Reference,
    Convergence,
    EndEffect,
    Invariance,
    Gold,
    Manufactured,
    TensionField,
    AtlasPoint,
}

impl CheckKind {
    pub fn label(self) -> &'static str {
        match self {
            CheckKind::ClosedForm => "closed-form",
            CheckKind::Reference => "reference",
            CheckKind::Convergence => "convergence",
            CheckKind::EndEffect => "end-effect",
            CheckKind::Invariance => "invariance",
            CheckKind::Gold => "gold",
            CheckKind::Manufactured => "manufactured",
            CheckKind::TensionField => "tension-field",
            CheckKind::AtlasPoint => "atlas-point",
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum CaseRef {
    Path(String),
    Inline(toml::Table),
}

/// One `[[check]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckSpec {
    pub name: String,
    pub case: CaseRef,
    pub kind: CheckKind,
    /// per-quantity tolerances (closed-form, reference, convergence: the distance of the
    /// reference from the extrapolated value when it exceeds the GCI)
    #[serde(default)]
    pub tolerance: BTreeMap<String, Tol>,
    // convergence
    /// the mesh refinement ratio between members (around and along are multiplied by it)
    pub refinement: Option<f64>,
    /// number of meshes (at least 3)
    pub meshes: Option<usize>,
    /// the exponent of the first member's refinement relative to the case's mesh (e.g. −1:
    /// one step coarser than the case); default 0
    pub start: Option<i32>,
    /// the quantities studied: convergence, default w, lambda_z, and force for a squeeze;
    /// end-effect, each fitted from the same runs, the measures of the check on the first
    /// (default [`quantity`](Self::quantity) alone)
    pub quantities: Option<Vec<String>>,
    /// convergence: the quantities whose observed order is held to `expected_order` (default
    /// all of `quantities`); the others report their order, or, where the family oscillates,
    /// the half range of its values as their uncertainty (Stern et al. 2001)
    pub order_quantities: Option<Vec<String>>,
    pub expected_order: Option<Expect>,
    /// convergence: a family whose values all agree within this relative spread has
    /// converged below it: where its order cannot be measured (the differences oscillate at
    /// the solver's noise) or is not the expected one, the check reports the spread as the
    /// uncertainty instead of failing (Roache; ASME V&V 20: a family already converged below
    /// the accuracy it is judged against)
    pub converged_below: Option<Tol>,
    /// convergence: whether an observed order outside `expected_order` fails the check
    /// (default true); the `--case` study reports it instead, and its allowance then uses
    /// Roache's safety factor for an order not verified
    pub gate_order: Option<bool>,
    /// compare the extrapolated value with the closed form (default true); the `--case`
    /// study leaves that to its closed-form check, which accounts for the end effect too
    pub compare_reference: Option<bool>,
    // end-effect
    /// tube lengths L/R of the family
    pub lengths: Option<Vec<f64>>,
    pub law: Option<EndLaw>,
    /// the quantity whose error against GPS is fitted (default w)
    pub quantity: Option<String>,
    /// end-effect and invariance tolerance ε (default 1e-3)
    pub epsilon: Option<f64>,
    pub decay_rate: Option<Expect>,
    pub amplitude: Option<Expect>,
    pub max_residual: Option<Tol>,
    // invariance
    pub min_core_fraction: Option<Tol>,
    // gold
    /// the gold folder, relative to the suite file (default `gold/<name>`)
    pub gold: Option<String>,
    pub rel_err: Option<f64>,
    pub abs_zero: Option<f64>,
    // manufactured
    /// how the manufactured state is loaded besides its body force: "none", "pressure"
    /// (default), "volume" or "gas"
    pub loading: Option<tubemem_fem::manufactured::study::MmsLoading>,
    /// the manufactured pressure ϖ* (default 0.4; with `loading = "none"`, 0)
    pub pressure: Option<f64>,
    /// the contact variant: the manufactured state squeezed between the plates y = ±1.15 R,
    /// which must supply a manufactured contact pressure where it lies on them (default false)
    pub plates: Option<bool>,
    // tension-field
    /// the annulus and its rim tractions (default R_in = 1, R_out = 4, T_in = 3e-4,
    /// T_out = 1e-4, per μH)
    pub annulus: Option<tubemem_fem::tension_field::Annulus>,
    // atlas-point
    /// the atlas point held to its law and the held-out length: `{ lambda_s_star, rho,
    /// length_ratio }` (λs* and ρ on the atlas's grid, the length not among its lengths)
    pub point: Option<AtlasPointSpec>,
}

/// `point` of an `atlas-point` check.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtlasPointSpec {
    pub lambda_s_star: f64,
    pub rho: f64,
    pub length_ratio: f64,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuiteMeta {
    pub name: Option<String>,
    pub description: Option<String>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuiteFile {
    #[serde(default)]
    pub suite: SuiteMeta,
    #[serde(rename = "check", default)]
    pub checks: Vec<CheckSpec>,
}

/// A check ready to run: its spec, its case text and the folder its paths are relative to.
#[derive(Clone, Debug)]
pub struct Check {
    pub spec: CheckSpec,
    pub suite: String,
    pub case_text: String,
    pub base_dir: PathBuf,
    /// where gold files live
    pub gold_dir: PathBuf,
}

/// A suite that cannot be used (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct SuiteError {
    pub path: PathBuf,
    pub message: String,
}

/// The quantities a closed-form check can hold to a tolerance.
pub const CLOSED_FORM_QUANTITIES: &[&str] = &[
    "w",
    "lambda_s",
    "lambda_z",
    "n_s",
    "n_z",
    "chi",
    "force",
    "local_lambda_s",
    "local_lambda_z",
    "local_chi",
    "local_force",
    "maxwell_w",
    "maxwell_lambda_s",
    "wall_force",
    "local_wall_force",
    // the flat zone's contact pressure, max |p_c/ϖ − 1| at mid-span, and the largest
    // penetration (in R): deviations, compared as they are
    "flat_pressure",
    "penetration",
    // the run's last step only (a mesh fitted to the contact edge at the end verifies there)
    "final_local_lambda_s",
    "final_local_lambda_z",
    "final_local_chi",
    "final_local_force",
    "final_local_wall_force",
    "final_flat_pressure",
];
/// The quantities of a reference check (FE against scikit-fem).
pub const REFERENCE_QUANTITIES: &[&str] = &[
    "profile",
    "profile_lambda_z",
    "w",
    "lambda_s",
    "lambda_z",
    "chi",
    "force",
    // an arc-length stage's located pressure maximum against the axisymmetric tube's
    "limit_max_w",
    "limit_max_lambda_s",
];
/// The quantities of a tension-field check: the wrinkled radius's relative error, the
/// resultants' L2 error over T_out against the tension-field solution and against Lamé's.
pub const TENSION_FIELD_QUANTITIES: &[&str] = &["wrinkle_radius", "stress", "lame_stress"];
/// Final mid-span quantities of a run (convergence, end-effect).
pub const FINAL_QUANTITIES: &[&str] = &["w", "lambda_s", "lambda_z", "n_s", "n_z", "chi", "force"];

fn tol_ok(path: &Path, name: &str, key: &str, t: &Tol) -> Result<(), SuiteError> {
    if !(t.value.is_finite() && t.value >= 0.0) {
        return Err(SuiteError {
            path: path.to_path_buf(),
            message: format!(
                "check `{name}`: tolerance `{key}` = {} must be finite and ≥ 0",
                t.value
            ),
        });
    }
    if t.source.trim().is_empty() {
        return Err(SuiteError {
            path: path.to_path_buf(),
            message: format!(
                "check `{name}`: tolerance `{key}` has no `source`: say where the number comes from (an equation, a refinement study, a fitted law)"
            ),
        });
    }
    Ok(())
}

/// Validate a check's fields for its kind.
pub fn validate(path: &Path, c: &CheckSpec) -> Result<(), SuiteError> {
    let err = |message: String| SuiteError {
        path: path.to_path_buf(),
        message: format!("check `{}`: {message}", c.name),
    };
    // the name is a folder under --out: `.` and `..` (and any name of dots) would be the
    // output folder itself or its parent, where the check's run would replace a user's files
    if c.name.trim().is_empty()
        || c.name.chars().all(|ch| ch == '.')
        || !c
            .name
            .chars()
            .all(|ch| ch.is_ascii_alphanumeric() || "-_.".contains(ch))
    {
        return Err(err(
            "`name` must be ASCII letters, digits, '-', '_' or '.', not only dots (it names the check's folder under --out)"
                .into(),
        ));
    }
    for (k, t) in &c.tolerance {
        tol_ok(path, &c.name, k, t)?;
    }
    for (k, t) in [
        ("max_residual", &c.max_residual),
        ("min_core_fraction", &c.min_core_fraction),
    ] {
        if let Some(t) = t {
            tol_ok(path, &c.name, k, t)?;
        }
    }
    for (k, e) in [
        ("expected_order", &c.expected_order),
        ("decay_rate", &c.decay_rate),
        ("amplitude", &c.amplitude),
    ] {
        if let Some(e) = e {
            tol_ok(
                path,
                &c.name,
                k,
                &Tol {
                    value: e.within,
                    source: e.source.clone(),
                },
            )?;
        }
    }
    let known = |list: &[&str], keys: &mut dyn Iterator<Item = &String>| {
        for k in keys {
            if !list.contains(&k.as_str()) {
                return Err(err(format!(
                    "unknown quantity `{k}` for a {} check (known: {})",
                    c.kind.label(),
                    list.join(", ")
                )));
            }
        }
        Ok(())
    };
    // the gold comparison's keys on a check of another kind would be read by nothing (a
    // `rel_err = nan` on a closed-form check had passed silently)
    if c.kind != CheckKind::Gold {
        for (key, given) in [
            ("gold", c.gold.is_some()),
            ("rel_err", c.rel_err.is_some()),
            ("abs_zero", c.abs_zero.is_some()),
        ] {
            if given {
                return Err(err(format!(
                    "`{key}` belongs to gold checks; a {} check does not read it: remove it",
                    c.kind.label()
                )));
            }
        }
    }
    match c.kind {
        CheckKind::ClosedForm => {
            known(CLOSED_FORM_QUANTITIES, &mut c.tolerance.keys())?;
            if c.tolerance.is_empty() {
                return Err(err(
                    "a closed-form check needs at least one `tolerance.<quantity>`".into(),
                ));
            }
        }
        CheckKind::Reference => known(REFERENCE_QUANTITIES, &mut c.tolerance.keys())?,
        CheckKind::Convergence => {
            known(FINAL_QUANTITIES, &mut c.tolerance.keys())?;
            if let Some(q) = &c.quantities {
                known(FINAL_QUANTITIES, &mut q.iter())?;
            }
            let r = c.refinement.unwrap_or(2.0);
            if !(r.is_finite() && r > 1.0 && r <= 4.0) {
                return Err(err(format!("`refinement` = {r} must be in (1, 4]")));
            }
            if c.meshes.unwrap_or(3) < 3 {
                return Err(err("`meshes` must be at least 3".into()));
            }
        }
        CheckKind::EndEffect => {
            let l = c.lengths.as_deref().unwrap_or(&[]);
            if l.len() < 3 || l.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(err(
                    "an end-effect check needs `lengths` = at least three L/R > 0".into(),
                ));
            }
            if c.law.is_none() {
                return Err(err(
                    "an end-effect check needs `law` = \"exponential\" (open inflation) or \"inverse\" (gas-closed squeeze)"
                        .into(),
                ));
            }
            if let Some(q) = &c.quantity {
                known(FINAL_QUANTITIES, &mut std::iter::once(q))?;
            }
        }
        CheckKind::Invariance => {
            if c.min_core_fraction.is_none() {
                return Err(err("an invariance check needs `min_core_fraction`".into()));
            }
        }
        CheckKind::Gold => {
            if let Some(r) = c.rel_err {
                if !(r.is_finite() && r > 0.0 && r < 1.0) {
                    return Err(err(format!(
                        "`rel_err` = {r}: must be a finite relative tolerance in (0, 1)"
                    )));
                }
            }
            if let Some(a) = c.abs_zero {
                if !(a.is_finite() && a >= 0.0) {
                    return Err(err(format!("`abs_zero` = {a}: must be finite and ≥ 0")));
                }
            }
        }
        CheckKind::TensionField => {
            known(TENSION_FIELD_QUANTITIES, &mut c.tolerance.keys())?;
            if c.tolerance.is_empty() {
                return Err(err(
                    "a tension-field check needs at least one `tolerance.<quantity>` (wrinkle_radius, stress, lame_stress)".into(),
                ));
            }
            if c.meshes.unwrap_or(4) < 2 {
                return Err(err("`meshes` must be at least 2".into()));
            }
            if let Some(a) = &c.annulus {
                let ordered = a.r_in > 0.0 && a.r_out > a.r_in && a.t_in > 0.0 && a.t_out > 0.0;
                let finite = [a.r_in, a.r_out, a.t_in, a.t_out]
                    .iter()
                    .all(|v| v.is_finite());
                if !(ordered && finite) {
                    return Err(err(
                        "`annulus` needs 0 < r_in < r_out and tractions t_in, t_out > 0".into(),
                    ));
                }
            }
            let a = c.annulus.unwrap_or(DEFAULT_ANNULUS);
            if c.tolerance.contains_key("wrinkle_radius") && a.wrinkle_radius().is_none() {
                return Err(err(format!(
                    "this annulus has no wrinkled zone to measure (Lamé's hoop resultant at the hub is {:.3e} ≥ 0, or T_in R_in > T_out R_out and no tension field balances it): drop `tolerance.wrinkle_radius` or raise t_in",
                    a.lame(a.r_in)[1]
                )));
            }
            if !(0..=5).contains(&c.start.unwrap_or(1)) {
                return Err(err(
                    "`start` of a tension-field check must be 0 … 5 (8·2^start elements around)"
                        .into(),
                ));
            }
        }
        CheckKind::AtlasPoint => {
            known(&["prediction"], &mut c.tolerance.keys())?;
            if !c.tolerance.contains_key("prediction") {
                return Err(err(
                    "an atlas-point check needs `tolerance.prediction` (the measured error's distance from the law's prediction, over the prediction)".into(),
                ));
            }
            match c.point {
                None => {
                    return Err(err(
                        "an atlas-point check needs `point` = { lambda_s_star, rho, length_ratio }"
                            .into(),
                    ))
                }
                Some(p) if !(p.length_ratio.is_finite() && p.length_ratio > 0.0) => {
                    return Err(err(format!(
                        "`point.length_ratio` = {} must be a positive number",
                        p.length_ratio
                    )))
                }
                Some(_) => {}
            }
        }
        CheckKind::Manufactured => {
            if c.expected_order.is_none() {
                return Err(err(
                    "a manufactured check needs `expected_order` (the element's L2 position order: 2 for quad4, 3 for quad9)"
                        .into(),
                ));
            }
            if c.meshes.unwrap_or(4) < 3 {
                return Err(err("`meshes` must be at least 3".into()));
            }
            if let Some(p) = c.pressure {
                if !(p.is_finite() && p >= 0.0) {
                    return Err(err(format!("`pressure` = {p} must be finite and ≥ 0")));
                }
            }
        }
    }
    if let Some(e) = c.epsilon {
        if !(e.is_finite() && e > 0.0) {
            return Err(err(format!("`epsilon` = {e} must be > 0")));
        }
    }
    Ok(())
}

/// Read a suite file into checks (each case read, relative to the suite's folder).
pub fn read_suite(path: &Path) -> Result<(String, Vec<Check>), SuiteError> {
    let err = |message: String| SuiteError {
        path: path.to_path_buf(),
        message,
    };
    let text = tubemem_mesh::io::read_text_limited(path, tubemem_mesh::io::MAX_TEXT_INPUT_BYTES)
        .map_err(|e| err(format!("cannot read it: {e}")))?;
    let file: SuiteFile = toml::from_str(&text).map_err(|e| err(e.to_string()))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let suite = file.suite.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default()
    });
    if file.checks.is_empty() {
        return Err(err("no [[check]] in the suite".into()));
    }
    let mut out = vec![];
    let mut names = std::collections::HashSet::new();
    for spec in file.checks {
        validate(path, &spec)?;
        if !names.insert(spec.name.clone()) {
            return Err(err(format!("two checks are named `{}`", spec.name)));
        }
        let (case_text, base_dir) = match &spec.case {
            CaseRef::Path(p) => {
                let cp = dir.join(p);
                let t = tubemem_mesh::io::read_text_limited(&cp, crate::case::MAX_CASE_FILE_BYTES)
                    .map_err(|e| {
                        err(format!("check `{}`: case {}: {e}", spec.name, cp.display()))
                    })?;
                (t, cp.parent().map(Path::to_path_buf).unwrap_or_default())
            }
            CaseRef::Inline(t) => (
                toml::to_string(t).map_err(|e| err(e.to_string()))?,
                dir.clone(),
            ),
        };
        // the case must be valid before anything runs (an atlas-point check's is an atlas
        // file, whose point must be on its grid at a length it does not run)
        if spec.kind == CheckKind::AtlasPoint {
            let a = crate::atlas::Atlas::parse(&case_text, &base_dir).map_err(|e| {
                err(format!(
                    "check `{}`: its atlas: {}",
                    spec.name,
                    crate::error_chain(&e)
                ))
            })?;
            let p = spec.point.expect("validated");
            let on = |grid: &[f64], v: f64, key: &str| {
                if grid.contains(&v) {
                    Ok(())
                } else {
                    Err(err(format!(
                        "check `{}`: `point.{key}` = {v} is not on the atlas's grid {grid:?}",
                        spec.name
                    )))
                }
            };
            on(&a.spec.stretches, p.lambda_s_star, "lambda_s_star")?;
            on(&a.spec.rho, p.rho, "rho")?;
            if a.spec.lengths.contains(&p.length_ratio) {
                return Err(err(format!(
                    "check `{}`: `point.length_ratio` = {} is one of the atlas's lengths: hold the law at a length it did not fit",
                    spec.name, p.length_ratio
                )));
            }
            if let Some(q) = spec
                .quantities
                .iter()
                .flatten()
                .find(|q| !a.spec.quantities.contains(q))
            {
                return Err(err(format!(
                    "check `{}`: `{q}` is not one of the atlas's quantities {:?}",
                    spec.name, a.spec.quantities
                )));
            }
        } else {
            crate::case::Case::parse(&case_text).map_err(|e| {
                err(format!(
                    "check `{}`: its case: {}",
                    spec.name,
                    crate::error_chain(&e)
                ))
            })?;
        }
        let gold_dir = dir.join(
            spec.gold
                .clone()
                .unwrap_or_else(|| format!("gold/{}", spec.name)),
        );
        out.push(Check {
            spec,
            suite: suite.clone(),
            case_text,
            base_dir,
            gold_dir,
        });
    }
    Ok((suite, out))
}

/// The default annulus: R_in = 1, R_out = 4, T_in = 3 T_out, T_out = 1e-4 (per μH; strains of
/// 1e-4, where the closed form's linear theory holds to 1e-4). L = 1.8057.
pub const DEFAULT_ANNULUS: tubemem_fem::tension_field::Annulus =
    tubemem_fem::tension_field::Annulus {
        r_in: 1.0,
        r_out: 4.0,
        t_in: 3e-4,
        t_out: 1e-4,
    };
