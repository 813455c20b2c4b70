//! The atlas file: a case template (every table of a case file except `[[stage]]`) and an
//! `[atlas]` table naming the grid. Read and validated whole before any run starts; each member
//! case is built and parsed here too, so a template the case reader refuses fails the atlas at
//! once, naming the member.

use super::AtlasError;
use crate::case::Case;
use crate::stats::EndLaw;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The quantities an atlas can fit: the mid-span FE against GPS at the same ρ (the flattening
/// between plates; for planes, the confined section, whose `wall_force` is the worst wall's).
pub const QUANTITIES: [&str; 6] = ["w", "force", "chi", "lambda_s", "lambda_z", "wall_force"];
/// Those of a squeeze between plates (the default).
pub const PLATE_QUANTITIES: [&str; 5] = ["w", "force", "chi", "lambda_s", "lambda_z"];
/// Those of a confinement by planes.
pub const PLANE_QUANTITIES: [&str; 4] = ["w", "wall_force", "lambda_s", "lambda_z"];

/// `[[atlas.plane]]`: a plane of a confine atlas, parallel to the tube's axis, n·x ≤ d.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AtlasPlane {
    /// [nx, ny] (normalized by the case reader; three components are refused, not truncated)
    #[serde(deserialize_with = "crate::case::two_components")]
    pub normal: [f64; 2],
    /// a wall that stays at d = `offset` (in R); without it the plane moves with ρ: d = ρ at
    /// each level
    pub offset: Option<f64>,
}

/// The `[atlas]` table.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AtlasSpec {
    /// the mid-span hoop stretches λs* the tube is inflated to (each a member family)
    pub stretches: Vec<f64>,
    /// the half-gaps ρ = r/R along each squeeze path at which the errors are taken and fitted;
    /// each is the end of a squeeze stage, so the FE lands on it exactly
    pub rho: Vec<f64>,
    /// the tube lengths L/R run for each λs* (at least three: c, A and a residual)
    pub lengths: Vec<f64>,
    /// elements along per R of tube length (`[mesh] along` = this × L/R, rounded up to even)
    pub along_per_radius: f64,
    /// the tolerances ε on |FE/GPS − 1|'s end effect for which the minimum L/R is reported
    #[serde(default = "default_epsilon")]
    pub epsilon: Vec<f64>,
    /// the quantities fitted (default: w, force, chi, lambda_s, lambda_z between plates; w,
    /// wall_force, lambda_s, lambda_z between planes)
    #[serde(default)]
    pub quantities: Vec<String>,
    /// planes instead of plates: a confine stage per level, the moving planes at d = ρ
    #[serde(default)]
    pub plane: Vec<AtlasPlane>,
    /// a confine atlas: where the moving planes start, λs* + this (in R; default 0.05)
    #[serde(default = "default_start_gap")]
    pub start_gap: f64,
    /// the end-effect law; default from the physics of the stage: the gas-closed squeeze's
    /// error falls as 1/(L/R) (the caps keep gas the plates do not squeeze), "inverse"
    #[serde(default = "default_law")]
    pub law: EndLaw,
    /// the largest relative rms residual of a fit before its point is flagged
    #[serde(default = "default_max_residual")]
    pub max_residual: f64,
    /// the largest step in ρ within a squeeze stage
    #[serde(default = "default_rho_step")]
    pub rho_step: f64,
    /// the plane-strain map (closed forms only): its λs* and ρ ranges and points per axis
    #[serde(default)]
    pub ps_map: PsMapSpec,
    /// keys added to the generated inflate stage (default: control = "volume", steps = 6)
    #[serde(default)]
    pub inflate: toml::Table,
    /// keys added to every generated squeeze (or confine) stage (contact_method, …)
    #[serde(default)]
    pub squeeze: toml::Table,
    /// the most member runs (λs* × L/R) the atlas may have (default 1000, the guard against
    /// a grid mistyped by orders of magnitude); raise it to run a larger atlas on purpose
    #[serde(default = "default_max_runs")]
    pub max_runs: usize,
}

/// The default guard on an atlas's runs ([`AtlasSpec::max_runs`]): at a few seconds per run
/// on 2 cores, an hour's work.
pub const DEFAULT_MAX_RUNS: usize = 1000;

fn default_max_runs() -> usize {
    DEFAULT_MAX_RUNS
}

/// `[atlas.ps_map]`: the grid of the closed-form map of |PS/GPS − 1|.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PsMapSpec {
    /// [low, high] λs* (default: the atlas's stretches' range, widened to [1.05, …] at least)
    pub stretches: Option<[f64; 2]>,
    /// [low, high] ρ (default: the lowest ρ of the atlas to the highest λs*)
    pub rho: Option<[f64; 2]>,
    /// points per axis (default 41)
    pub points: Option<usize>,
}

fn default_epsilon() -> Vec<f64> {
    vec![1e-2, 1e-3]
}
fn default_start_gap() -> f64 {
    0.05
}
fn default_law() -> EndLaw {
    EndLaw::Inverse
}
/// The bound the verify suites hold an end-effect fit to (the paper suite's squeeze fits have
/// 0.005–0.007, the inflation's exponential 6e-4: a tenfold margin over the worst).
fn default_max_residual() -> f64 {
    0.05
}
fn default_rho_step() -> f64 {
    0.05
}

/// One FE run of the atlas: a λs* and a length.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Member {
    /// its folder under `runs/`: `ls<λs*>_lr<L/R>`
    pub name: String,
    pub stretch: f64,
    pub length: f64,
    /// the case file it runs (written as `runs/<name>/case.toml`)
    pub case_text: String,
}

/// A validated atlas.
#[derive(Clone, Debug)]
pub struct Atlas {
    pub spec: AtlasSpec,
    /// the case template: the atlas file without `[atlas]`
    pub template: toml::Table,
    /// where relative paths of the template (a user mesh) are resolved
    pub base_dir: PathBuf,
    /// every run, λs* outer, length inner
    pub members: Vec<Member>,
    /// the law of the template's `[material]`
    pub material: tubemem_material::MaterialSpec,
}

fn bad(key: &str, message: impl Into<String>) -> AtlasError {
    AtlasError::Invalid {
        key: key.to_string(),
        message: message.into(),
    }
}

/// `n` with its noun: "1 stretch", "2 stretches".
fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// A name part for a number: 1.3 → "1.3", 40 → "40".
fn tag(v: f64) -> String {
    format!("{v}")
}

impl Atlas {
    /// Read and validate an atlas file.
    pub fn read(path: &Path) -> Result<Self, AtlasError> {
        let text = tubemem_mesh::io::read_text_limited(path, crate::case::MAX_CASE_FILE_BYTES)
            .map_err(|source| AtlasError::Read {
                path: path.to_path_buf(),
                source,
            })?;
        let base = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        Self::parse(&text, &base)
    }

    /// Validate an atlas given as text; relative paths resolve against `base_dir`.
    pub fn parse(text: &str, base_dir: &Path) -> Result<Self, AtlasError> {
        #[derive(Deserialize)]
        struct Only {
            atlas: Option<AtlasSpec>,
        }
        // the [atlas] table typed (an unknown or mistyped key is named with its line)
        let only: Only = toml::from_str(text).map_err(AtlasError::Syntax)?;
        let mut spec = only.atlas.ok_or_else(|| {
            bad(
                "atlas",
                "the file has no [atlas] table (stretches, rho, lengths, along_per_radius)",
            )
        })?;
        let mut template: toml::Table = toml::from_str(text).map_err(AtlasError::Syntax)?;
        // `quantities = []` written out is a mistake, not the default (the key left out)
        let written_empty = template
            .get("atlas")
            .and_then(|a| a.get("quantities"))
            .and_then(|q| q.as_array())
            .is_some_and(|q| q.is_empty());
        if written_empty {
            return Err(bad(
                "atlas.quantities",
                "is empty: name at least one quantity, or leave the key out for the stage's default set",
            ));
        }
        template.remove("atlas");
        if template.contains_key("stage") {
            return Err(bad(
                "stage",
                "an atlas makes its own stages (inflate to each λs*, squeeze through each ρ): remove the [[stage]] tables and put stage keys in [atlas.inflate] or [atlas.squeeze]",
            ));
        }
        if spec.quantities.is_empty() {
            let q: &[&str] = if spec.plane.is_empty() {
                &PLATE_QUANTITIES
            } else {
                &PLANE_QUANTITIES
            };
            spec.quantities = q.iter().map(|s| s.to_string()).collect();
        }
        if spec.max_runs == 0 {
            return Err(bad(
                "atlas.max_runs",
                "= 0 allows no run: give the most member runs the atlas may start (≥ 1), or leave the key out for 1000",
            ));
        }
        let runs = spec.stretches.len().saturating_mul(spec.lengths.len());
        if runs > spec.max_runs {
            return Err(bad(
                "atlas.max_runs",
                format!(
                    "the grid has {} × {} = {runs} member runs, more than max_runs = {}: check the grid, or raise `max_runs` to run it on purpose",
                    count(spec.stretches.len(), "stretch", "stretches"),
                    count(spec.lengths.len(), "length", "lengths"),
                    spec.max_runs
                ),
            ));
        }
        check(&spec, &template)?;
        let mut members = vec![];
        let mut material = None;
        for &s in &spec.stretches {
            for &l in &spec.lengths {
                let name = format!("ls{}_lr{}", tag(s), tag(l));
                let case_text = member_case(&spec, &template, s, l)?;
                // the member case as the case reader sees it: refused here, before any run
                let case = Case::parse(&case_text).map_err(|source| AtlasError::Member {
                    member: name.clone(),
                    source,
                })?;
                material.get_or_insert(case.material);
                members.push(Member {
                    name,
                    stretch: s,
                    length: l,
                    case_text,
                });
            }
        }
        Ok(Atlas {
            spec,
            template,
            base_dir: base_dir.to_path_buf(),
            members,
            material: material.expect("at least one member (stretches and lengths are not empty)"),
        })
    }

    /// The ρ levels below λs* (the squeeze's stage ends), highest first.
    pub fn levels(&self, stretch: f64) -> Vec<f64> {
        levels(&self.spec, stretch)
    }

    /// The case file of one member ([`member_case`]).
    pub fn member_case(&self, stretch: f64, length: f64) -> Result<String, AtlasError> {
        member_case(&self.spec, &self.template, stretch, length)
    }
}

/// The ρ levels of `spec` below λs*, highest first.
pub fn levels(spec: &AtlasSpec, stretch: f64) -> Vec<f64> {
    let mut r: Vec<f64> = spec.rho.iter().copied().filter(|&r| r < stretch).collect();
    r.sort_by(|a, b| b.total_cmp(a));
    r
}

/// The case file of one member: the template at length L/R (along ∝ L), inflated to λs*,
/// then one squeeze stage per ρ level, each in steps of at most `rho_step`.
pub fn member_case(
    spec: &AtlasSpec,
    template: &toml::Table,
    stretch: f64,
    length: f64,
) -> Result<String, AtlasError> {
    let mut t = template.clone();
    let geometry = t
        .entry("geometry")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .ok_or_else(|| bad("geometry", "must be a table"))?;
    let radius = match geometry.get("radius") {
        None => 1.0,
        Some(v) => v
            .as_float()
            .or(v.as_integer().map(|i| i as f64))
            .ok_or_else(|| bad("geometry.radius", "must be a number"))?,
    };
    if geometry.contains_key("length") {
        return Err(bad(
            "geometry.length",
            "an atlas sets the length from [atlas] lengths: remove it",
        ));
    }
    geometry.insert("length".into(), toml::Value::Float(length * radius));
    // the atlas's plane offsets are per R; a member case in SI reads its lengths in metres
    let length_unit = if t.contains_key("units") { radius } else { 1.0 };
    let mesh = t
        .entry("mesh")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .ok_or_else(|| bad("mesh", "must be a table"))?;
    if mesh.contains_key("along") {
        return Err(bad(
            "mesh.along",
            "an atlas sets the elements along from [atlas] along_per_radius: remove it",
        ));
    }
    let along = (spec.along_per_radius * length).ceil() as i64;
    mesh.insert("along".into(), toml::Value::Integer(along + along % 2));
    // lean member folders: no VTU unless the template asks, no checkpoints
    crate::case::member_output_defaults(&mut t, "none");
    let mut stages = vec![];
    let mut inflate = toml::Table::new();
    inflate.insert("kind".into(), "inflate".into());
    inflate.insert("control".into(), "volume".into());
    inflate.insert("steps".into(), toml::Value::Integer(6));
    inflate.extend(spec.inflate.clone());
    inflate.insert("target_stretch".into(), toml::Value::Float(stretch));
    stages.push(toml::Value::Table(inflate));
    // the plates start at the tube's half-height (≥ λs*: the cap junction can stand out); the
    // moving planes of a confine atlas at λs* + start_gap
    let mut from = if spec.plane.is_empty() {
        stretch
    } else {
        stretch + spec.start_gap
    };
    for rho in levels(spec, stretch) {
        let mut s = toml::Table::new();
        let n = ((from - rho) / spec.rho_step).ceil().max(1.0) as i64;
        if spec.plane.is_empty() {
            s.insert("kind".into(), "squeeze".into());
            s.extend(spec.squeeze.clone());
            s.insert("target_rho".into(), toml::Value::Float(rho));
        } else {
            s.insert("kind".into(), "confine".into());
            s.extend(spec.squeeze.clone());
            let planes = spec
                .plane
                .iter()
                .map(|p| {
                    let mut t = toml::Table::new();
                    t.insert(
                        "normal".into(),
                        toml::Value::Array(
                            p.normal.iter().map(|&v| toml::Value::Float(v)).collect(),
                        ),
                    );
                    let (a, b) = p.offset.map_or((from, rho), |d| (d, d));
                    t.insert("offset".into(), toml::Value::Float(a * length_unit));
                    t.insert("target".into(), toml::Value::Float(b * length_unit));
                    toml::Value::Table(t)
                })
                .collect();
            s.insert("plane".into(), toml::Value::Array(planes));
        }
        s.insert("steps".into(), toml::Value::Integer(n));
        stages.push(toml::Value::Table(s));
        from = rho;
    }
    t.insert("stage".into(), toml::Value::Array(stages));
    toml::to_string(&t).map_err(|e| bad("atlas", format!("the member case cannot be written: {e}")))
}

fn check(s: &AtlasSpec, template: &toml::Table) -> Result<(), AtlasError> {
    let positive = |key: &str, v: &[f64]| -> Result<(), AtlasError> {
        if v.is_empty() {
            return Err(bad(key, "is empty"));
        }
        if let Some(x) = v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
            return Err(bad(key, format!("{x} is not a positive number")));
        }
        let mut sorted = v.to_vec();
        sorted.sort_by(f64::total_cmp);
        if sorted.windows(2).any(|w| w[0] == w[1]) {
            return Err(bad(key, "has a repeated value"));
        }
        Ok(())
    };
    positive("atlas.stretches", &s.stretches)?;
    if let Some(x) = s.stretches.iter().find(|x| **x <= 1.0) {
        return Err(bad(
            "atlas.stretches",
            format!("λs* = {x}: an inflated tube has λs* > 1"),
        ));
    }
    positive("atlas.rho", &s.rho)?;
    positive("atlas.lengths", &s.lengths)?;
    if s.lengths.len() < 3 {
        return Err(bad(
            "atlas.lengths",
            format!(
                "{} lengths: the end-effect law has two coefficients and needs a third length for its residual",
                s.lengths.len()
            ),
        ));
    }
    positive("atlas.epsilon", &s.epsilon)?;
    if !(s.along_per_radius.is_finite() && s.along_per_radius > 0.0) {
        return Err(bad(
            "atlas.along_per_radius",
            format!("{} is not a positive number", s.along_per_radius),
        ));
    }
    if !(s.rho_step.is_finite() && s.rho_step > 0.0) {
        return Err(bad(
            "atlas.rho_step",
            format!("{} is not a positive number", s.rho_step),
        ));
    }
    if !(s.max_residual.is_finite() && s.max_residual > 0.0) {
        return Err(bad(
            "atlas.max_residual",
            format!("{} is not a positive number", s.max_residual),
        ));
    }
    if s.quantities.is_empty() {
        return Err(bad("atlas.quantities", "is empty"));
    }
    // plates have a contact force and width; planes have each wall's force
    let (allowed, what): (&[&str], &str) = if s.plane.is_empty() {
        (&PLATE_QUANTITIES, "between plates")
    } else {
        (&PLANE_QUANTITIES, "between [[atlas.plane]] walls")
    };
    if let Some(q) = s.quantities.iter().find(|q| !allowed.contains(&q.as_str())) {
        return Err(bad(
            "atlas.quantities",
            format!("{q:?} is not one of {} ({what})", allowed.join(", ")),
        ));
    }
    for (k, p) in s.plane.iter().enumerate() {
        let key = format!("atlas.plane[{}]", k + 1);
        if !(p.normal.iter().all(|v| v.is_finite()) && p.normal[0].hypot(p.normal[1]) > 0.0) {
            return Err(bad(
                &format!("{key}.normal"),
                format!("{:?} is not a finite non-zero [nx, ny]", p.normal),
            ));
        }
        if let Some(d) = p.offset.filter(|d| !(d.is_finite() && *d > 0.0)) {
            return Err(bad(
                &format!("{key}.offset"),
                format!("{d}: a wall n·x ≤ d must have d > 0 (the tube's axis on its side)"),
            ));
        }
    }
    if !s.plane.is_empty() && s.plane.iter().all(|p| p.offset.is_some()) {
        return Err(bad(
            "atlas.plane",
            "every plane has an `offset`, so none moves with ρ: leave `offset` out of the pressing planes",
        ));
    }
    if !(s.start_gap.is_finite() && s.start_gap >= 0.0) {
        return Err(bad(
            "atlas.start_gap",
            format!("{} is not ≥ 0", s.start_gap),
        ));
    }
    for &st in &s.stretches {
        if !s.rho.iter().any(|&r| r < st) {
            return Err(bad(
                "atlas.rho",
                format!("no level is below λs* = {st}: the plates would not touch the tube"),
            ));
        }
    }
    if let Some(n) = s.ps_map.points {
        if !(3..=400).contains(&n) {
            return Err(bad("atlas.ps_map.points", format!("{n} is outside 3–400")));
        }
    }
    for (key, r) in [
        ("atlas.ps_map.stretches", s.ps_map.stretches),
        ("atlas.ps_map.rho", s.ps_map.rho),
    ] {
        if let Some([a, b]) = r {
            if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b) {
                return Err(bad(
                    key,
                    format!("[{a}, {b}] must be two increasing positive numbers"),
                ));
            }
        }
    }
    if let Some([a, _]) = s.ps_map.stretches {
        if a <= 1.0 {
            return Err(bad(
                "atlas.ps_map.stretches",
                format!("λs* = {a}: an inflated tube has λs* > 1"),
            ));
        }
    }
    for key in [
        "kind",
        "target_stretch",
        "target_pressure",
        "target_volume_ratio",
    ] {
        if s.inflate.contains_key(key) {
            return Err(bad(
                &format!("atlas.inflate.{key}"),
                "is set by the atlas (an inflate stage to each λs*)",
            ));
        }
    }
    for key in [
        "kind",
        "target_rho",
        "target_gap",
        "steps",
        "plane",
        "target",
        "offset",
    ] {
        if s.squeeze.contains_key(key) {
            return Err(bad(
                &format!("atlas.squeeze.{key}"),
                "is set by the atlas (a squeeze stage to each ρ, steps from rho_step)",
            ));
        }
    }
    if template.get("mesh").and_then(|m| m.get("file")).is_some() {
        return Err(bad(
            "mesh.file",
            "an atlas builds its tubes (a user mesh has one length)",
        ));
    }
    Ok(())
}
