//! The case file (TOML). Every table and key is checked: an unknown or misspelt key, a wrong
//! type or a missing value is reported with its line and column by the TOML reader, and
//! inconsistent values (a control without its target) name the stage and the key.
//!
//! ```toml
//! [geometry]
//! radius = 1.0          # reference radius R (results are per R)
//! length = 20.0         # cylinder length L (between the cap junctions)
//! thickness = 0.01      # undeformed thickness H (dimensional output only)
//! caps = "hemisphere"   # or "rigid-plug": open tube tied to two rigid discs
//!
//! [material]
//! model = "abb"         # "abb" | "mooney-rivlin" | "neo-hookean"
//! shear_modulus = 1.0
//! kuhn = 30             # abb only;  alpha = … for mooney-rivlin
//!
//! [mesh]
//! around = 64           # elements around (multiple of 8)
//! along = 160           # elements along the cylinder (even)
//! cap_rows = 8          # optional: rows in each cap from equator to top face (default around/8)
//! symmetry = "eighth"   # "none" | "half" | "quarter" | "eighth"
//!
//! [solver]              # optional
//! wrinkling = "relaxed" # tension-field relaxation (default) | "none"
//! rtol = 1e-9           # Newton tolerance on ‖R‖/‖f‖
//! max_iterations = 30
//!
//! [[stage]]
//! kind = "inflate"
//! control = "volume"    # "pressure" (target_pressure) | "volume" (target_stretch or target_volume_ratio)
//! target_stretch = 1.3  # mid-span hoop stretch λs*
//! steps = 6             # initial number of load steps (adaptive afterwards)
//! ```

use anyhow::{bail, Context, Result};
use serde::Deserialize;
use std::path::Path;
use tubemem_material::{MaterialSpec, Wrinkling};
use tubemem_mesh::Symmetry;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// the folder of the case file (user mesh paths are relative to it)
    #[serde(skip)]
    pub base_dir: std::path::PathBuf,
    pub geometry: Geometry,
    pub material: MaterialSpec,
    pub mesh: MeshSpec,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(rename = "stage")]
    pub stages: Vec<StageSpec>,
}

/// `[solver]`: optional.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// "relaxed" (tension-field theory, default) or "none"
    #[serde(default)]
    pub wrinkling: Wrinkling,
    /// Newton tolerance on ‖R‖/‖f‖
    #[serde(default = "default_rtol")]
    pub rtol: f64,
    #[serde(default = "default_max_iterations")]
    pub max_iterations: usize,
}

impl Default for SolverSpec {
    fn default() -> Self {
        Self {
            wrinkling: Wrinkling::default(),
            rtol: default_rtol(),
            max_iterations: default_max_iterations(),
        }
    }
}

fn default_rtol() -> f64 {
    1e-9
}
fn default_max_iterations() -> usize {
    30
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    pub radius: f64,
    pub length: f64,
    #[serde(default = "one")]
    pub thickness: f64,
    #[serde(default)]
    pub caps: Caps,
}

fn one() -> f64 {
    1.0
}

#[derive(Debug, Deserialize, Default, PartialEq, Eq, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
pub enum Caps {
    #[default]
    Hemisphere,
    RigidPlug,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// a user mesh (tubemem JSON, see `tubemem_mesh::io`; `python -m tubemem_ref.meshio_io`
    /// converts any meshio-readable quad mesh), relative to the case file's folder
    pub file: Option<String>,
    /// elements around (multiple of 8) of the generated tube
    pub around: Option<usize>,
    /// elements along the cylinder (even) of the generated tube
    pub along: Option<usize>,
    /// rows of elements in each cap between its equator and its top face (default around/8)
    pub cap_rows: Option<usize>,
    #[serde(default)]
    pub symmetry: Symmetry,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    Inflate,
    Squeeze,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ControlKind {
    Pressure,
    Volume,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    pub kind: Kind,
    /// inflate only: "pressure" or "volume" (a squeeze keeps the gas closed)
    pub control: Option<ControlKind>,
    /// squeeze only: the final half-gap ρ = r/R between the plates
    pub target_rho: Option<f64>,
    /// squeeze only: penetration (in R) at the gas pressure that sets the penalty κ = ϖ/tol
    /// (default 1e-3), or the penalty itself
    pub penetration_tolerance: Option<f64>,
    pub penalty: Option<f64>,
    pub target_pressure: Option<f64>,
    pub target_stretch: Option<f64>,
    pub target_volume_ratio: Option<f64>,
    #[serde(default = "default_steps")]
    pub steps: usize,
}

fn default_steps() -> usize {
    8
}

/// What a stage drives, once validated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// reduced pressure ϖ, pressure control
    Pressure(f64),
    /// mid-span hoop stretch λs*, reached with the pressure as a Lagrange multiplier
    Stretch(f64),
    /// total enclosed volume over its reference value, volume control
    VolumeRatio(f64),
    /// squeeze between plates y = ±ρR with the gas closed in
    Rho(f64),
}

impl StageSpec {
    pub fn target(&self, i: usize) -> Result<Target> {
        let which = (
            self.target_pressure,
            self.target_stretch,
            self.target_volume_ratio,
            self.target_rho,
        );
        let t = match (self.kind, self.control, which) {
            (Kind::Inflate, Some(ControlKind::Pressure), (Some(p), None, None, None)) => Target::Pressure(p),
            (Kind::Inflate, Some(ControlKind::Volume), (None, Some(s), None, None)) => Target::Stretch(s),
            (Kind::Inflate, Some(ControlKind::Volume), (None, None, Some(v), None)) => Target::VolumeRatio(v),
            (Kind::Inflate, None, _) => bail!("[[stage]] {}: kind = \"inflate\" needs `control` (\"pressure\" or \"volume\")", i + 1),
            (Kind::Inflate, Some(ControlKind::Pressure), _) => {
                bail!("[[stage]] {}: control = \"pressure\" takes exactly one target, `target_pressure`", i + 1)
            }
            (Kind::Inflate, Some(ControlKind::Volume), _) => bail!(
                "[[stage]] {}: control = \"volume\" takes exactly one target, `target_stretch` (mid-span λs*) or `target_volume_ratio`",
                i + 1
            ),
            (Kind::Squeeze, Some(_), _) => bail!(
                "[[stage]] {}: a squeeze keeps the gas closed (Boyle); it takes no `control`",
                i + 1
            ),
            (Kind::Squeeze, None, (None, None, None, Some(r))) => Target::Rho(r),
            (Kind::Squeeze, None, _) => bail!("[[stage]] {}: kind = \"squeeze\" takes exactly one target, `target_rho`", i + 1),
        };
        let (name, v, ok) = match t {
            Target::Pressure(p) => ("target_pressure", p, p.is_finite() && p >= 0.0),
            Target::Stretch(s) => ("target_stretch", s, s.is_finite() && s >= 1.0),
            Target::VolumeRatio(r) => ("target_volume_ratio", r, r.is_finite() && r >= 1.0),
            Target::Rho(r) => ("target_rho", r, r.is_finite() && r > 0.0),
        };
        if !ok {
            bail!(
                "[[stage]] {}: `{name}` = {v} is out of range (pressure ≥ 0, stretch ≥ 1, volume ratio ≥ 1, rho > 0)",
                i + 1
            );
        }
        if self.steps == 0 {
            bail!("[[stage]] {}: `steps` must be ≥ 1", i + 1);
        }
        if self.kind == Kind::Inflate
            && (self.penalty.is_some() || self.penetration_tolerance.is_some())
        {
            bail!(
                "[[stage]] {}: `penalty` and `penetration_tolerance` belong to squeeze stages",
                i + 1
            );
        }
        if let Some(t) = self.penetration_tolerance {
            if !(t.is_finite() && t > 0.0 && t < 0.1) {
                bail!(
                    "[[stage]] {}: `penetration_tolerance` = {t}: must be in (0, 0.1) (in R)",
                    i + 1
                );
            }
        }
        if let Some(k) = self.penalty {
            if !(k.is_finite() && k > 0.0) {
                bail!(
                    "[[stage]] {}: `penalty` = {k}: must be finite and > 0",
                    i + 1
                );
            }
        }
        Ok(t)
    }
}

impl Case {
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read case file {}", path.display()))?;
        let mut case =
            Self::parse(&text).with_context(|| format!("in case file {}", path.display()))?;
        case.base_dir = path.parent().map(|p| p.to_path_buf()).unwrap_or_default();
        Ok(case)
    }

    pub fn parse(text: &str) -> Result<Self> {
        let case: Case = toml::from_str(text).map_err(|e| anyhow::anyhow!("{e}"))?;
        case.validate()?;
        Ok(case)
    }

    fn validate(&self) -> Result<()> {
        let g = &self.geometry;
        for (k, v) in [
            ("radius", g.radius),
            ("length", g.length),
            ("thickness", g.thickness),
        ] {
            if !(v.is_finite() && v > 0.0) {
                bail!("[geometry] `{k}` = {v}: must be finite and > 0");
            }
        }
        let m = &self.mesh;
        match (&m.file, m.around, m.along) {
            (Some(_), None, None) if m.cap_rows.is_none() && m.symmetry == Symmetry::None => {}
            (Some(_), ..) => bail!(
                "[mesh] `file` gives the whole mesh: drop `around`, `along`, `cap_rows` and `symmetry` (the file sets its own symmetry)"
            ),
            (None, Some(_), Some(_)) => {}
            (None, ..) => bail!("[mesh] needs `around` and `along` (a generated tube) or `file` (a user mesh)"),
        }
        if self.stages.is_empty() {
            bail!("the case has no [[stage]]");
        }
        for (i, s) in self.stages.iter().enumerate() {
            s.target(i)?;
            if s.kind == Kind::Squeeze && i == 0 {
                bail!(
                    "[[stage]] 1: a squeeze needs an inflated tube: put an inflate stage before it"
                );
            }
        }
        self.material.build().context("[material]")?;
        if !(self.solver.rtol > 0.0 && self.solver.rtol < 1e-2) {
            bail!(
                "[solver] `rtol` = {}: must be in (0, 1e-2)",
                self.solver.rtol
            );
        }
        if self.solver.max_iterations == 0 {
            bail!("[solver] `max_iterations` must be ≥ 1");
        }
        Ok(())
    }
}
