//! The case file (TOML). Every table and key is checked: an unknown or misspelt key, a wrong
//! type or a missing value is reported with its line and column by the TOML reader, and
//! inconsistent values (a control without its target) name the stage and the key.
//!
//! ```toml
//! [geometry]
//! radius = 1.0          # reference radius R (results are per R)
//! length = 20.0         # cylinder length L (between the cap junctions)
//! thickness = 0.01      # undeformed thickness H (optional; needed by [units])
//! caps = "hemisphere"   # or "rigid-plug": open tube tied to two rigid discs
//!
//! [units]               # optional: the numbers are SI (m, Pa); the outputs add SI values
//! system = "SI"
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
//! element = "quad4"     # "quad4" (bilinear, default) | "quad9" (biquadratic, curved geometry)
//! track_contact_edge = true # optional: hoop node lines on the contact edges at every squeeze
//!                       # and confine step (the state carried to the moved mesh)
//! fit_contact_edge = true   # optional, instead: fitted once, to the last contact stage's end
//! contact_edge_angle = 0.5  # optional, instead: fitted once at this angle from x = 0 (rad)
//!
//! [solver]              # optional
//! wrinkling = "relaxed" # tension-field relaxation (default) | "none"
//! rtol = 1e-9           # Newton tolerance on ‖R‖/‖f‖
//! max_iterations = 30
//! checkpoint_every = 1  # restart checkpoints every N converged steps (0: none)
//! factor_threads = 1    # threads inside the factorization's supernodes (0: all); results do not change
//! ordering = "auto"     # or "amd", "nested-dissection" (METIS); results do not change
//! refactorize = "auto"  # or "always", "on-demand": the last factor preconditions GMRES until
//!                       # it stops paying; results agree within the Newton tolerance
//! mesh_sequencing = 0   # L ≥ 1: run on the tube with half the elements first (L levels) and
//!                       # start each load step from its state there; the results are this mesh's
//!
//! [output]              # optional
//! vtu = "every"         # VTU frames: "every" (default) | "stage-end" | "none"
//! vtu_every = 1         # with "every": a frame every N steps (and each stage's last)
//! vtu_format = "binary" # "binary" (default, exact) | "ascii"
//! mirror = false        # true: the whole tube in the VTU, reflected from a reduced model
//! iterations = false    # true: iterations.csv, where each Newton iteration's time went
//!
//! [[stage]]
//! kind = "inflate"
//! control = "volume"    # "pressure" (target_pressure) | "volume" (target_stretch or target_volume_ratio)
//!                       # | "arc-length" (any of the three, reached along the path through limit points)
//! branch = "follow-stable" # arc-length only: at a bifurcation where the path loses stability,
//!                       # switch to the branch along the critical mode (default "stay")
//! target_stretch = 1.3  # mid-span hoop stretch λs*
//! steps = 6             # initial number of load steps (adaptive afterwards)
//!
//! [[stage]]
//! kind = "squeeze"      # the gas closed (Boyle); plates y = ±ρR
//! target_rho = 0.8
//! control = "arc-length" # optional (squeeze and confine): continue the plates' travel by arc
//!                       # length in (x, plate position), critical points located on the way
//! ```

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;
use tubemem_material::{MaterialError, MaterialSpec, Wrinkling};
use tubemem_mesh::{ElementKind, Symmetry};

use crate::units::{Dimension, Units};

/// Why a case was rejected: the TOML reader's message (with line and column), or the table,
/// stage and key at fault.
#[derive(Debug, Error)]
pub enum CaseError {
    #[error("cannot read case file {}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("in case file {}", path.display())]
    In {
        path: PathBuf,
        #[source]
        source: Box<CaseError>,
    },
    #[error(transparent)]
    Syntax(TomlSyntax),
    #[error("{0}")]
    Invalid(String),
    #[error("[material]")]
    Material(#[source] MaterialError),
}

/// The TOML reader's error, kept whole ([`TomlSyntax::toml`]: its message, line and column, and
/// byte span); it displays as the reader's message with its numbers as written in the file
/// (`1e308`, not the 309 digits of Rust's `{}`).
#[derive(Debug)]
pub struct TomlSyntax(pub toml::de::Error);

impl TomlSyntax {
    /// The TOML reader's own error.
    pub fn toml(&self) -> &toml::de::Error {
        &self.0
    }
}

impl std::fmt::Display for TomlSyntax {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&tubemem_material::tidy_numbers(&self.0.to_string()))
    }
}

impl std::error::Error for TomlSyntax {}

/// The longest tube, in radii: 10,000 (the README's studies go to L/R = 80; at 10,000 even one
/// element per radius along is 10,000 rings).
pub const MAX_LENGTH_RATIO: f64 = 1e4;

/// The shortest tube, in radii: 1e-3. The small case's 24 elements along run at L/R = 1e-3 and
/// fail at 1e-4 (elements 4e-6 R long against 0.39 R around), where a huge `radius` under a
/// unit `length` (9.2e18) had been reported as a degenerate element (issue #25, class 6).
pub const MIN_LENGTH_RATIO: f64 = 1e-3;

/// The largest case file read: 1 MiB (a case is a few hundred bytes; a larger file is not one).
pub const MAX_CASE_FILE_BYTES: u64 = 1 << 20;

macro_rules! invalid {
    ($($arg:tt)*) => { return Err(CaseError::Invalid(format!($($arg)*))) };
}

#[derive(Debug, Clone, Deserialize, schemars::JsonSchema)]
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
    #[serde(default)]
    pub output: OutputSpec,
    /// `[units]`: the system the case's numbers are in (none: outputs dimensionless)
    #[serde(default)]
    pub units: Option<UnitsSpec>,
    #[serde(rename = "stage")]
    pub stages: Vec<StageSpec>,
    /// the stages resolved by validation (filled by [`Case::parse`])
    #[serde(skip)]
    plan: Vec<StagePlan>,
    /// the hash of the case text ([`case_hash`])
    #[serde(skip)]
    hash: String,
}

/// The JSON Schema of a case file (draft 2020-12), derived from the types the case is read
/// into, so it takes exactly the keys [`Case::parse`] takes (unknown keys are refused, as
/// `deny_unknown_fields` refuses them). Editors read it to complete and check TOML (Taplo:
/// `#:schema ./case.schema.json` on the first line). The cross-key rules (a squeeze needs
/// `target_rho`, a law's parameter ranges) stay with [`Case::parse`].
///
/// A count (`"format": "uint"`) gets the largest value it can hold as its `maximum`, so that
/// `around = 1e308` is refused as tubemem refuses it. JSON Schema's `integer` is any number
/// with no fractional part, so a whole float written for a count (`around = 16.0`) passes a
/// JSON validator (and Taplo 0.9); tubemem refuses it.
pub fn schema() -> serde_json::Value {
    fn bound_counts(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                if m.get("format").and_then(|f| f.as_str()) == Some("uint") {
                    m.insert("maximum".into(), u64::MAX.into());
                }
                m.values_mut().for_each(bound_counts);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(bound_counts),
            _ => {}
        }
    }
    let mut schema = schemars::schema_for!(Case);
    schema.insert("title".into(), "tubemem case file".into());
    schema.insert(
        "description".into(),
        "A tubemem case: the tube ([geometry]), its law ([material]), its mesh ([mesh]), the solver, the outputs, the units and the stages ([[stage]]).".into(),
    );
    let mut value = schema.to_value();
    bound_counts(&mut value);
    state_units(&mut value);
    value
}

/// Each dimensional key's unit ([`crate::units::CASE_KEYS`]) appended to its description in
/// the schema (and so in the book's case reference): `Unit: m under [units] system = "SI", R
/// otherwise`.
fn state_units(schema: &mut serde_json::Value) {
    // the table each definition of the schema describes
    const TABLES: [(&str, &str); 6] = [
        ("Geometry", "geometry"),
        ("MaterialSpec", "material"),
        ("MeshSpec", "mesh"),
        ("SolverSpec", "solver"),
        ("StageSpec", "stage"),
        ("PlaneSpec", "stage.plane"),
    ];
    fn visit(v: &mut serde_json::Value, table: &str) {
        match v {
            serde_json::Value::Object(m) => {
                if let Some(serde_json::Value::Object(props)) = m.get_mut("properties") {
                    for (key, prop) in props.iter_mut() {
                        let Some(d) = crate::units::case_key(&format!("{table}.{key}")) else {
                            continue;
                        };
                        if let Some(o) = prop.as_object_mut() {
                            let text = o
                                .get("description")
                                .and_then(|d| d.as_str())
                                .unwrap_or("")
                                .to_string();
                            let unit = if table == "geometry" {
                                "Unit: m under [units] system = \"SI\"; in a dimensionless case any one length unit (only L/R enters; R is the unit of the other lengths).".to_string()
                            } else {
                                format!("Unit: {}.", d.describe())
                            };
                            let joined = if text.is_empty() {
                                unit
                            } else {
                                format!("{text}. {unit}")
                            };
                            o.insert("description".into(), joined.into());
                        }
                    }
                }
                for x in m.values_mut() {
                    visit(x, table);
                }
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(|x| visit(x, table)),
            _ => {}
        }
    }
    let Some(defs) = schema.get_mut("$defs").and_then(|d| d.as_object_mut()) else {
        return;
    };
    for (def, table) in TABLES {
        if let Some(d) = defs.get_mut(def) {
            visit(d, table);
        }
    }
}

/// A member run's output defaults (a verify member, an atlas member), written into its case
/// table unless the case sets them: `[output] vtu = vtu` and no checkpoints.
pub(crate) fn member_output_defaults(t: &mut toml::Table, vtu: &str) {
    let output = t
        .entry("output")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let Some(o) = output.as_table_mut() {
        o.entry("vtu")
            .or_insert_with(|| toml::Value::String(vtu.into()));
    }
    let solver = t
        .entry("solver")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let Some(s) = solver.as_table_mut() {
        s.entry("checkpoint_every")
            .or_insert(toml::Value::Integer(0));
    }
}

/// FNV-1a (64 bit) of the case text: the record of which case ran (run.json, summary.json,
/// checkpoints, the VTU field data). The case owns it, so the case module depends on no writer.
pub fn case_hash(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("fnv1a64:{h:016x}")
}

/// Which converged steps get a VTU frame.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Default, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum VtuFrames {
    /// every converged step (every `vtu_every`-th)
    #[default]
    Every,
    /// the last step of each stage
    StageEnd,
    /// none (the reference frame 0 is still written)
    None,
}

/// Which converged steps get a profile along the tube (stage ends always do).
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Default, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ProfileFrames {
    /// every converged step (each costs about one residual assembly)
    #[default]
    Every,
    /// the last step of each stage only
    StageEnd,
}

/// `[output]`: optional.
#[derive(Debug, Deserialize, Clone, Copy, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// "every" (default) | "stage-end" | "none"
    #[serde(default)]
    pub vtu: VtuFrames,
    /// with `vtu = "every"`: a frame every this many steps (and the last of each stage)
    #[serde(default = "default_vtu_every")]
    pub vtu_every: usize,
    /// "binary" (default: base64, exact, about a third of the size) | "ascii"
    #[serde(default)]
    pub vtu_format: VtuFormat,
    /// write the whole tube, the symmetry-reduced model reflected across its planes
    #[serde(default)]
    pub mirror: bool,
    /// "every" (default) | "stage-end": profiles along the tube (with the contact width per
    /// ring) at every converged step, or at stage ends only
    #[serde(default)]
    pub profiles: ProfileFrames,
    /// write iterations.csv: per Newton iteration the assembly, line-search, factorization
    /// and solve times, the residual and the negative pivots
    #[serde(default)]
    pub iterations: bool,
}

/// How VTU arrays are written.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Default, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum VtuFormat {
    #[default]
    Binary,
    Ascii,
}

fn default_vtu_every() -> usize {
    1
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            vtu: VtuFrames::default(),
            vtu_every: default_vtu_every(),
            vtu_format: VtuFormat::default(),
            mirror: false,
            profiles: ProfileFrames::default(),
            iterations: false,
        }
    }
}

/// `[solver]`: optional.
#[derive(Debug, Clone, Deserialize, schemars::JsonSchema)]
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
    /// write a restart checkpoint every this many converged steps (0: none); the last two are
    /// kept, and `tubemem run --resume` continues from the newest
    #[serde(default = "default_checkpoint_every")]
    pub checkpoint_every: usize,
    /// threads of the sparse factorization inside its supernodes: 1 (default) sequential, 0
    /// all of the machine's; the results do not depend on it. A factorization split at the top
    /// separator (nested dissection, 100,000 unknowns or more) runs its two halves side by
    /// side on the run's thread pool whatever this says
    #[serde(default = "default_factor_threads")]
    pub factor_threads: usize,
    /// the sparse factorization's fill-reducing ordering: "auto" (default: AMD and nested
    /// dissection both analysed, the one with fewer flops kept), "amd" or "nested-dissection"
    /// (METIS on the node graph); the results do not depend on it beyond round-off, the
    /// factorization's cost does
    #[serde(default)]
    pub ordering: tubemem_fem::ordering::Ordering,
    /// when Newton factorizes its tangent: "auto" (default: "on-demand" where a factorization
    /// costs at least 50 substitutions in flops, "always" otherwise), "always" (every
    /// iteration, the exact Newton method) or "on-demand" (the last factor preconditions GMRES
    /// on the current tangent, to an inexact-Newton tolerance, and the solve refactorizes when
    /// GMRES or the contraction of the residual says so); convergence is judged on the true
    /// residual, so the results agree within the Newton tolerance
    #[serde(default)]
    pub refactorize: tubemem_fem::model::Refactorization,
    /// levels of mesh sequencing (nested iteration, the `sequencing` module): 0 (default) none;
    /// L ≥ 1 first runs the case on the generated tube with half the elements around, along
    /// and in the caps (sequenced with L − 1 levels), and starts each load step from that
    /// run's converged state at the same point of the stage; the results are this mesh's own,
    /// converged to the same tolerances
    #[serde(default)]
    pub mesh_sequencing: usize,
}

/// The most levels `[solver] mesh_sequencing` takes (each halves the elements in both
/// directions, and runs the case once more).
pub const MAX_SEQUENCING_LEVELS: usize = 4;

fn default_factor_threads() -> usize {
    1
}

fn default_checkpoint_every() -> usize {
    1
}

impl Default for SolverSpec {
    fn default() -> Self {
        Self {
            wrinkling: Wrinkling::default(),
            rtol: default_rtol(),
            max_iterations: default_max_iterations(),
            checkpoint_every: default_checkpoint_every(),
            factor_threads: default_factor_threads(),
            ordering: tubemem_fem::ordering::Ordering::default(),
            refactorize: tubemem_fem::model::Refactorization::default(),
            mesh_sequencing: 0,
        }
    }
}

fn default_rtol() -> f64 {
    1e-9
}
fn default_max_iterations() -> usize {
    30
}

#[derive(Debug, Clone, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    pub radius: f64,
    pub length: f64,
    /// H: changes no dimensionless output (ϖ = pR/(μH)); needed by `[units]`
    #[serde(default)]
    pub thickness: Option<f64>,
    #[serde(default)]
    pub caps: Caps,
}

/// `[units]`: `system = "SI"` says the case's radius, length and thickness are in metres and
/// its shear modulus in pascals; the outputs then carry dimensional values beside the
/// dimensionless ones (pressure in Pa, resultants and forces per length in N/m).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct UnitsSpec {
    pub system: UnitSystem,
}

#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
pub enum UnitSystem {
    #[serde(rename = "SI")]
    Si,
}

#[derive(
    Debug, Deserialize, Serialize, Default, PartialEq, Eq, Clone, Copy, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum Caps {
    #[default]
    Hemisphere,
    RigidPlug,
}

#[derive(Debug, Clone, Deserialize, schemars::JsonSchema)]
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
    /// the element of the generated tube (a user mesh's file sets its own)
    #[serde(default)]
    pub element: ElementKind,
    /// the generated tube's hoop node line nearest the contact edge of the last squeeze moved
    /// onto the closed form's edge at its target (an element boundary where the curvature
    /// jumps), blended back to uniform spacing over the last 2R before each cap
    #[serde(default)]
    pub fit_contact_edge: bool,
    /// the reference angle (radians, from the plates' symmetry line x = 0) where the fitted
    /// node line goes, instead of the one `fit_contact_edge` finds
    pub contact_edge_angle: Option<f64>,
    /// the generated tube's hoop node lines moved onto the closed form's contact edges at
    /// every step of each squeeze and confine stage (under the FE's own pressure), the state
    /// carried over to the moved mesh ([`crate::edge_track`])
    #[serde(default)]
    pub track_contact_edge: bool,
    /// the node lines a fitted or tracked contact edge may take: those of the tube with this
    /// many elements around (a divisor of `around`, multiple of 8; default `around`, the
    /// nearest line). With the same value on every mesh of a refinement study the fitted
    /// meshes are uniform refinements of one another, each element split in two, so the
    /// observed order is the element's own ([`tubemem_mesh::hoop::HoopMap::fitted`])
    pub edge_fit_around: Option<usize>,
}

impl MeshSpec {
    /// The elements around whose node lines a fitted contact edge takes (`edge_fit_around`,
    /// else `around`), for a generated tube.
    pub fn fit_grid(&self) -> Option<usize> {
        self.edge_fit_around.or(self.around)
    }

    /// The generated tube's polygon factor 1/cos(π/n), n elements around: the n-gon prism's
    /// pressure over the smooth tube's at the same state (`None` for a user mesh). The 9-node
    /// element's cross-section is a chain of parabolic arcs through points of the circle, not a
    /// polygon: it has no such first-order facet bias, and its factor is 1 (its remaining,
    /// fourth-order error is measured by `scripts/convergence-tables.sh`).
    pub fn polygon_factor(&self) -> Option<f64> {
        self.around
            .filter(|_| self.file.is_none())
            .map(|n| match self.element {
                ElementKind::Quad4 => 1.0 / (std::f64::consts::PI / n as f64).cos(),
                ElementKind::Quad9 => 1.0,
            })
    }
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    Inflate,
    Squeeze,
    /// planes moved in together with the gas closed (paper Sec. 3.6 for any walls)
    Confine,
}

/// One `[[stage.plane]]` of a confine stage: the wall {x : n·x = d} in the cross-section, the
/// membrane on n·x ≤ d; `offset` is d at the start of the stage and `target` at its end (moved
/// linearly in the stage's load parameter, 0 → 1).
#[derive(Debug, Deserialize, Serialize, Clone, Copy, PartialEq, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// [nx, ny]: the plane is parallel to the tube's axis, so its normal has two components
    /// (three are refused, not truncated)
    #[serde(deserialize_with = "two_components")]
    #[schemars(with = "[f64; 2]")]
    pub normal: [f64; 2],
    /// d at the stage's start, a length (m under `[units] system = "SI"`, R otherwise)
    pub offset: f64,
    /// d at the stage's end, a length (m under SI, R otherwise)
    pub target: f64,
}

/// A plane's `normal`: exactly two numbers.
pub(crate) fn two_components<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let v: Vec<f64> = Deserialize::deserialize(d)?;
    match v.as_slice() {
        [a, b] => Ok([*a, *b]),
        _ => Err(serde::de::Error::custom(format!(
            "`normal` has {} components: give [nx, ny] (a plane is parallel to the tube's axis z)",
            v.len()
        ))),
    }
}

impl PlaneSpec {
    /// Whether the plane's mirror image across x = 0 (`axis` 0) or y = 0 (`axis` 1), with the
    /// same offset and target, is among `planes` (to 1e-12 relative).
    pub(crate) fn mirrored_in(&self, planes: &[PlaneSpec], axis: usize) -> bool {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + a.abs());
        let mut m = self.normal;
        m[axis] = -m[axis];
        planes.iter().any(|q| {
            close(m[0], q.normal[0])
                && close(m[1], q.normal[1])
                && close(self.offset, q.offset)
                && close(self.target, q.target)
        })
    }

    /// The wall at load parameter `t` ∈ [0, 1] (the closed form's convention, unit normal).
    pub(crate) fn wall_at(
        &self,
        t: f64,
    ) -> Result<tubemem_gps::confine::Wall, tubemem_gps::GpsError> {
        tubemem_gps::confine::Wall::new(
            self.normal[0],
            self.normal[1],
            self.offset + t * (self.target - self.offset),
        )
    }
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ControlKind {
    Pressure,
    Volume,
    /// squeeze and confine: the gas closed in at the stage's start (Boyle; the default)
    Gas,
    /// arc-length continuation in (x, ϖ) to any of the three targets
    ArcLength,
}

#[derive(Debug, Clone, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    /// "inflate" (the gas let in), "squeeze" (two plates y = ±r closed on the tube) or
    /// "confine" (any planes moved in)
    pub kind: Kind,
    /// inflate: "pressure", "volume" or "arc-length"; squeeze and confine: "gas" (the default:
    /// the gas closed in at the stage's start, Boyle), "pressure" (a regulated supply: the
    /// pressure held at its value at the stage's start, or ramped to `target_pressure`) or
    /// "arc-length" (the gas closed, the planes' travel continued along the path)
    pub control: Option<ControlKind>,
    /// squeeze only: the final half-gap between the plates as the ratio ρ = r/R (a ratio: the
    /// same number in every unit system); or give `target_gap`
    pub target_rho: Option<f64>,
    /// squeeze only: the final half-gap r between the plates as a length (m under `[units]
    /// system = "SI"`, R otherwise), instead of `target_rho`
    pub target_gap: Option<f64>,
    /// squeeze and confine: the penetration at the gas pressure that sets the penalty κ =
    /// ϖJ/tol, a length (m under SI, R otherwise; default 1e-3 R for the penalty alone, 1e-6
    /// R as the augmented contact's regularization)
    pub penetration_tolerance: Option<f64>,
    /// squeeze and confine: the contact penalty κ itself, a pressure per length of
    /// penetration (Pa/m under SI, μH/R² otherwise), instead of `penetration_tolerance`
    pub penalty: Option<f64>,
    /// squeeze and confine: how the planes are enforced, "augmented" (the default: the penalty
    /// with Uzawa multiplier updates until the gap is within `gap_tolerance`) or "penalty" (the
    /// penalty alone, the membrane sits about `penetration_tolerance` inside)
    pub contact_method: Option<ContactMethod>,
    /// augmented contact: the largest gap the multiplier updates leave where a plane pushes,
    /// a length (m under SI, R otherwise; default 1e-9 R)
    pub gap_tolerance: Option<f64>,
    /// augmented contact: the multiplier updates allowed in one step (default 50)
    pub max_augmentations: Option<usize>,
    /// squeeze and confine: where the planes act on an element, "nodal" (its nodes, each
    /// weighted by its share of the element's area; the default of the augmented contact) or
    /// "gauss" (its Gauss points; the default of the penalty)
    pub contact_points: Option<tubemem_fem::contact::ContactPoints>,
    /// inflate, and squeeze or confine with control = "pressure": the gas pressure to reach
    /// (ramped with the planes' travel; held at its start value when absent), a pressure (Pa
    /// under `[units] system = "SI"`; the reduced pressure ϖ = pR/(μH) otherwise)
    pub target_pressure: Option<f64>,
    /// inflate: the mid-span hoop stretch λs* to reach (a ratio), the pressure following as
    /// the multiplier of the constraint
    pub target_stretch: Option<f64>,
    /// inflate: the enclosed volume over its reference value to reach (a ratio)
    pub target_volume_ratio: Option<f64>,
    /// confine only: the planes
    #[serde(default)]
    pub plane: Vec<PlaneSpec>,
    /// the initial number of load steps (a count; the steps adapt afterwards: a step that
    /// does not converge is halved)
    #[serde(default = "default_steps")]
    pub steps: usize,
    /// arc-length stages: "follow-stable" switches branch at a bifurcation where the path
    /// loses stability, along the critical mode
    pub branch: Option<BranchSpec>,
    /// inflate only, after a squeeze: "held" keeps that squeeze's plates where it left them
    /// while the pressure rises (control = "pressure" or "arc-length" to `target_pressure`):
    /// the inflation between fixed plates, which snaps at a critical pressure
    pub plates: Option<PlatesSpec>,
}

/// `plates` of an inflate stage.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum PlatesSpec {
    /// the previous squeeze's plates stay where it left them
    Held,
}

/// `contact_method` of a squeeze or confine stage.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ContactMethod {
    Penalty,
    Augmented,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum BranchSpec {
    /// stay on the path the continuation is on (the default)
    Stay,
    /// at a bifurcation where K gains a negative pivot, leave along the critical mode
    FollowStable,
}

fn default_steps() -> usize {
    8
}

/// What a stage drives, once validated. Written (summary.json) under the case file's own key,
/// `{"key": "target_stretch", "value": 1.3}` (it had been `{"control": "stretch", …}`, which
/// read as a control the case never named: issue #24 item 11; the old names are read too).
#[derive(schemars::JsonSchema, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "key", content = "value")]
pub enum Target {
    /// reduced pressure ϖ, pressure control
    #[serde(rename = "target_pressure", alias = "pressure")]
    Pressure(f64),
    /// mid-span hoop stretch λs*, reached with the pressure as a Lagrange multiplier
    #[serde(rename = "target_stretch", alias = "stretch")]
    Stretch(f64),
    /// total enclosed volume over its reference value, volume control
    #[serde(rename = "target_volume_ratio", alias = "volume-ratio")]
    VolumeRatio(f64),
    /// squeeze between plates y = ±ρR with the gas closed in
    #[serde(rename = "target_rho", alias = "rho")]
    Rho(f64),
    /// the stage's planes (their number) moved from `offset` to `target` with the gas closed
    #[serde(rename = "planes", alias = "confine")]
    Confine(usize),
}

impl StagePlan {
    /// How the stage's planes are enforced: the case's `enforcement`, penalty when it names
    /// none.
    pub fn contact_enforcement(&self) -> tubemem_fem::contact::Enforcement {
        self.enforcement
            .unwrap_or(tubemem_fem::contact::Enforcement::Penalty)
    }

    /// The stage's `control` as the case file names it: "pressure", "volume" or "arc-length"
    /// (None: a squeeze or confine stage stepped by load, which names no control).
    pub fn control(&self) -> Option<&'static str> {
        match (self.arc_length, self.target) {
            (true, _) => Some("arc-length"),
            (false, Target::Pressure(_)) => Some("pressure"),
            (false, Target::Stretch(_) | Target::VolumeRatio(_)) => Some("volume"),
            (false, Target::Rho(_) | Target::Confine(_)) => match self.gas {
                GasControl::Closed => Some("gas"),
                GasControl::Regulated { .. } => Some("pressure"),
            },
        }
    }
}

impl Target {
    /// The stage label in words, for progress lines (dimensionless).
    pub fn describe(&self) -> String {
        self.describe_in(&Units::dimensionless())
    }

    /// The target as a user reads it in `units`: `ϖ = 0.65`, or `p = 4600 Pa (ϖ = 0.744)`;
    /// `ρ = 0.8`, with the half-gap as a length under SI.
    fn value_in(&self, units: &Units) -> String {
        let n = |v: f64| tubemem_material::Num(crate::units::round_sig(v));
        match *self {
            Target::Pressure(p) if units.is_si() => {
                format!("p = {}", units.show(Dimension::Pressure, p))
            }
            Target::Pressure(p) => format!("ϖ = {}", n(p)),
            Target::Stretch(s) => format!("mid-span λs = {}", n(s)),
            Target::VolumeRatio(r) => format!("V/V0 = {}", n(r)),
            Target::Rho(r) if units.is_si() => format!(
                "ρ = {} (half-gap {} {})",
                n(r),
                n(units.from_core(Dimension::Length, r)),
                units.unit(Dimension::Length)
            ),
            Target::Rho(r) => format!("ρ = {}", n(r)),
            Target::Confine(k) => format!("{k} planes to their targets"),
        }
    }

    /// The stage label in words, for progress lines, its target in `units`.
    pub fn describe_in(&self, units: &Units) -> String {
        let v = self.value_in(units);
        match self {
            Target::Pressure(_) => format!("inflate, pressure control to {v}"),
            Target::Stretch(_) => format!("inflate, stretch control to {v}"),
            Target::VolumeRatio(_) => format!("inflate, volume control to {v}"),
            Target::Rho(_) => format!("squeeze, closed gas, plates to {v}"),
            Target::Confine(_) => format!("confine, closed gas, {v}"),
        }
    }
}

impl StagePlan {
    /// The stage label in words, for progress lines (dimensionless).
    pub fn describe(&self) -> String {
        self.describe_in(&Units::dimensionless())
    }

    /// The stage label in words, its target in `units`.
    pub fn describe_in(&self, units: &Units) -> String {
        if self.held_plates {
            let v = self.target.value_in(units);
            let how = if self.arc_length {
                "arc-length continuation"
            } else {
                "pressure control"
            };
            return format!("inflate between the held plates, {how} to {v}");
        }
        if let GasControl::Regulated { target_pressure } = self.gas {
            let v = self.target.value_in(units);
            let supply = match target_pressure {
                None => "pressure held".to_string(),
                Some(p) => format!("pressure ramped to {}", Target::Pressure(p).value_in(units)),
            };
            return match self.target {
                Target::Confine(_) => format!("confine, {supply}, {v}"),
                _ => format!("squeeze, {supply}, plates to {v}"),
            };
        }
        if !self.arc_length {
            return self.target.describe_in(units);
        }
        let v = self.target.value_in(units);
        match self.target {
            Target::Pressure(_) | Target::Stretch(_) | Target::VolumeRatio(_) => {
                format!("inflate, arc-length continuation to {v}")
            }
            Target::Rho(_) => {
                format!("squeeze, closed gas, arc-length continuation of the plates to {v}")
            }
            Target::Confine(_) => format!("confine, closed gas, arc-length continuation of {v}"),
        }
    }
}

/// How the contact penalty of a squeeze is set.
#[derive(schemars::JsonSchema, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PenaltySpec {
    /// κ given
    Value(f64),
    /// κ = ϖ J / tolerance at the start of the squeeze (`contact::penalty_for`)
    Tolerance(f64),
}

/// A stage resolved once by validation: what the run executes.
#[derive(schemars::JsonSchema, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StagePlan {
    /// 1-based
    pub index: usize,
    pub target: Target,
    pub steps: usize,
    /// squeeze stages only
    pub penalty: Option<PenaltySpec>,
    /// squeeze and confine stages: how the planes are enforced
    #[serde(default)]
    pub enforcement: Option<tubemem_fem::contact::Enforcement>,
    /// squeeze and confine stages: where the planes act on an element
    #[serde(default)]
    pub contact_points: tubemem_fem::contact::ContactPoints,
    /// `control = "arc-length"`: the target is reached along the path by arc-length
    /// continuation, through limit points and snap-backs, with critical points located
    #[serde(default)]
    pub arc_length: bool,
    /// `branch = "follow-stable"` (arc-length stages)
    #[serde(default)]
    pub follow_stable: bool,
    /// squeeze and confine stages: how the gas is supplied while the planes move
    #[serde(default)]
    pub gas: GasControl,
    /// an inflation between the previous squeeze's plates, held where it left them
    /// (`plates = "held"`)
    #[serde(default)]
    pub held_plates: bool,
}

/// How the gas of a squeeze or confine stage is supplied while its planes move.
#[derive(schemars::JsonSchema, Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GasControl {
    /// closed in at the stage's start (Boyle: ϖV fixed), `control = "gas"`
    #[default]
    Closed,
    /// a pressure regulator: ϖ held at its value at the stage's start, or ramped linearly
    /// with the planes' travel to `target_pressure` (reduced), `control = "pressure"`
    Regulated { target_pressure: Option<f64> },
}

/// The penetration tolerance (in R) that sets the penalty of a `contact_method = "penalty"`
/// stage that gives neither `penalty` nor `penetration_tolerance`: penalty converged below
/// 1e-4 in the README's study.
pub const DEFAULT_PENETRATION_TOLERANCE: f64 = 1e-3;

/// The tolerance (in R) that sets the regularizing penalty κ = ϖJ/tol of an augmented contact
/// (the default method) that gives neither `penalty` nor `penetration_tolerance`: 1e-6, where
/// one multiplier update per step reaches the 1e-9 gap on the squeezes at λs* = 1.3 and 6.0,
/// 16 to 128 around, both elements, with nodal contact points (README "Contact"); at 1e-3 the
/// same runs take 7 to 10 updates a step.
pub const DEFAULT_REGULARIZATION_TOLERANCE: f64 = 1e-6;

impl StageSpec {
    /// Resolve the stage (`i` is 0-based), its dimensional keys read in `units` and converted
    /// to the dimensionless core ([`crate::units`]).
    pub fn plan(&self, i: usize, units: &Units) -> Result<StagePlan, CaseError> {
        let target = self.target(i, units)?;
        let augmented = self.contact_method != Some(ContactMethod::Penalty);
        let tolerance = self
            .penetration_tolerance
            .map(|t| units.to_core(Dimension::Length, t));
        let penalty = match (self.kind, self.penalty, tolerance) {
            (Kind::Squeeze | Kind::Confine, Some(k), _) => {
                Some(PenaltySpec::Value(units.to_core(Dimension::Stiffness, k)))
            }
            (Kind::Squeeze | Kind::Confine, None, t) => {
                Some(PenaltySpec::Tolerance(t.unwrap_or(if augmented {
                    DEFAULT_REGULARIZATION_TOLERANCE
                } else {
                    DEFAULT_PENETRATION_TOLERANCE
                })))
            }
            _ => None,
        };
        let enforcement = match (self.kind, self.contact_method) {
            (Kind::Squeeze | Kind::Confine, Some(ContactMethod::Penalty)) => {
                Some(tubemem_fem::contact::Enforcement::Penalty)
            }
            (Kind::Squeeze | Kind::Confine, None | Some(ContactMethod::Augmented)) => {
                Some(tubemem_fem::contact::Enforcement::Augmented {
                    gap_tolerance: self
                        .gap_tolerance
                        .map(|t| units.to_core(Dimension::Length, t))
                        .unwrap_or(tubemem_fem::contact::DEFAULT_GAP_TOLERANCE),
                    max_augmentations: self
                        .max_augmentations
                        .unwrap_or(tubemem_fem::contact::DEFAULT_MAX_AUGMENTATIONS),
                })
            }
            _ => None,
        };
        Ok(StagePlan {
            index: i + 1,
            target,
            steps: self.steps,
            penalty,
            enforcement,
            contact_points: self.contact_points.unwrap_or(if augmented {
                tubemem_fem::contact::ContactPoints::Nodal
            } else {
                tubemem_fem::contact::ContactPoints::Gauss
            }),
            arc_length: self.control == Some(ControlKind::ArcLength),
            follow_stable: self.branch == Some(BranchSpec::FollowStable),
            gas: match (self.kind, self.control) {
                (Kind::Squeeze | Kind::Confine, Some(ControlKind::Pressure)) => {
                    GasControl::Regulated {
                        target_pressure: self
                            .target_pressure
                            .map(|p| units.to_core(Dimension::Pressure, p)),
                    }
                }
                _ => GasControl::Closed,
            },
            held_plates: self.plates == Some(PlatesSpec::Held),
        })
    }

    /// The stage's target, after every check of the keys that combine into it. Its length: one
    /// arm per stage kind and control, each checking its own keys and naming them in its error.
    fn target(&self, i: usize, units: &Units) -> Result<Target, CaseError> {
        if self.branch.is_some() && self.control != Some(ControlKind::ArcLength) {
            invalid!(
                "[[stage]] {}: `branch` belongs to control = \"arc-length\" stages (only a continuation has a path to leave)",
                i + 1
            );
        }
        let rho = match (self.target_rho, self.target_gap) {
            (Some(_), Some(_)) => invalid!(
                "[[stage]] {}: `target_rho` (the half-gap over R, a ratio) and `target_gap` (the half-gap, a length in {}) say the same thing: give one",
                i + 1,
                units.unit(Dimension::Length)
            ),
            (r, g) => r.or(g.map(|g| units.to_core(Dimension::Length, g))),
        };
        let which = (
            self.target_pressure
                .map(|p| units.to_core(Dimension::Pressure, p)),
            self.target_stretch,
            self.target_volume_ratio,
            rho,
        );
        let t = match (self.kind, self.control, which) {
            (Kind::Inflate, Some(ControlKind::Pressure), (Some(p), None, None, None)) => Target::Pressure(p),
            (Kind::Inflate, Some(ControlKind::Volume), (None, Some(s), None, None)) => Target::Stretch(s),
            (Kind::Inflate, Some(ControlKind::Volume), (None, None, Some(v), None)) => Target::VolumeRatio(v),
            (Kind::Inflate, Some(ControlKind::ArcLength), (Some(p), None, None, None)) => Target::Pressure(p),
            (Kind::Inflate, Some(ControlKind::ArcLength), (None, Some(s), None, None)) => Target::Stretch(s),
            (Kind::Inflate, Some(ControlKind::ArcLength), (None, None, Some(v), None)) => Target::VolumeRatio(v),
            (Kind::Inflate, Some(ControlKind::ArcLength), _) => invalid!(
                "[[stage]] {}: control = \"arc-length\" takes exactly one target, `target_pressure`, `target_stretch` (mid-span λs*) or `target_volume_ratio`, reached on the path",
                i + 1
            ),
            (Kind::Inflate, None, _) => invalid!("[[stage]] {}: kind = \"inflate\" needs `control` (\"pressure\", \"volume\" or \"arc-length\")", i + 1),
            (Kind::Inflate, Some(ControlKind::Pressure), _) => {
                invalid!("[[stage]] {}: control = \"pressure\" takes exactly one target, `target_pressure`", i + 1)
            }
            (Kind::Inflate, Some(ControlKind::Volume), _) => invalid!(
                "[[stage]] {}: control = \"volume\" takes exactly one target, `target_stretch` (mid-span λs*) or `target_volume_ratio`",
                i + 1
            ),
            (Kind::Inflate, Some(ControlKind::Gas), _) => invalid!(
                "[[stage]] {}: control = \"gas\" (the gas closed in) belongs to squeeze and confine stages; an inflation lets gas in: control = \"pressure\", \"volume\" or \"arc-length\"",
                i + 1
            ),
            (Kind::Squeeze | Kind::Confine, Some(ControlKind::Volume), _) => invalid!(
                "[[stage]] {}: a {} stage's `control` is \"gas\" (closed in, the default), \"pressure\" (regulated: held, or ramped to `target_pressure`) or \"arc-length\" (the gas closed, continued along the path)",
                i + 1,
                if self.kind == Kind::Squeeze { "squeeze" } else { "confine" }
            ),
            (Kind::Squeeze, Some(ControlKind::Pressure), (_, None, None, Some(r))) => Target::Rho(r),
            (Kind::Squeeze, None | Some(ControlKind::Gas | ControlKind::ArcLength), (Some(_), _, _, _)) => invalid!(
                "[[stage]] {}: `target_pressure` on a squeeze belongs to control = \"pressure\" (a regulated supply); with the gas closed in the pressure follows from Boyle's law",
                i + 1
            ),
            (Kind::Squeeze, None | Some(ControlKind::Gas | ControlKind::ArcLength), (None, None, None, Some(r))) => Target::Rho(r),
            (Kind::Squeeze, _, _) => invalid!("[[stage]] {}: kind = \"squeeze\" takes exactly one target, `target_rho` (the plates' half-gap over R) or `target_gap` (the half-gap as a length)", i + 1),
            (Kind::Confine, Some(ControlKind::Pressure), (_, None, None, None)) => Target::Confine(self.plane.len()),
            (Kind::Confine, None | Some(ControlKind::Gas | ControlKind::ArcLength), (None, None, None, None)) => Target::Confine(self.plane.len()),
            (Kind::Confine, _, _) => invalid!(
                "[[stage]] {}: kind = \"confine\" moves its [[stage.plane]]s to their `target`s; it takes no target_stretch, target_volume_ratio, target_rho or target_gap, and `target_pressure` only with control = \"pressure\"",
                i + 1
            ),
        };
        if self.plates.is_some() && !matches!(t, Target::Pressure(_)) {
            invalid!(
                "[[stage]] {}: `plates = \"held\"` belongs to an inflate stage raising the pressure (control = \"pressure\" or \"arc-length\" with `target_pressure`): the plates of the squeeze before it stay where it left them",
                i + 1
            );
        }
        if self.kind != Kind::Confine && !self.plane.is_empty() {
            invalid!(
                "[[stage]] {}: [[stage.plane]] belongs to kind = \"confine\" stages",
                i + 1
            );
        }
        if let Target::Confine(_) = t {
            if self.plane.is_empty() {
                invalid!(
                    "[[stage]] {}: kind = \"confine\" needs at least one [[stage.plane]] (normal = [nx, ny], offset, target)",
                    i + 1
                );
            }
            if self.plane.len() > tubemem_gps::confine::MAX_WALLS {
                invalid!(
                    "[[stage]] {}: {} [[stage.plane]]s: at most {} (the closed form every step compares with grows as about the 3.7th power of their number)",
                    i + 1,
                    self.plane.len(),
                    tubemem_gps::confine::MAX_WALLS
                );
            }
            for (k, p) in self.plane.iter().enumerate() {
                let finite = p.normal.iter().all(|v| v.is_finite())
                    && p.offset.is_finite()
                    && p.target.is_finite();
                if !finite || p.normal[0].hypot(p.normal[1]) == 0.0 {
                    invalid!(
                        "[[stage]] {}, plane {}: `normal` must be a finite non-zero [nx, ny] and `offset`, `target` finite",
                        i + 1,
                        k + 1
                    );
                }
                if !(p.offset > 0.0 && p.target > 0.0) {
                    invalid!(
                        "[[stage]] {}, plane {}: `offset` = {} and `target` = {} must be > 0: the tube's axis must stay on the membrane's side of every plane (as `tubemem gps confine` requires)",
                        i + 1,
                        k + 1,
                        tubemem_material::Num(p.offset),
                        tubemem_material::Num(p.target)
                    );
                }
            }
            let walls = self
                .plane
                .iter()
                .map(|p| p.wall_at(1.0))
                .collect::<Result<Vec<_>, _>>()
                .and_then(|w| tubemem_gps::confine::check_walls(&w).map(|_| w));
            if let Err(e) = walls {
                invalid!("[[stage]] {}: the planes at their targets: {e}", i + 1);
            }
        }
        let rho_key = if self.target_gap.is_some() {
            "target_gap"
        } else {
            "target_rho"
        };
        if let Target::Rho(r) = t {
            if r.is_finite() && r <= 0.0 {
                invalid!(
                    "[[stage]] {}: `{rho_key}` = {}: no equilibrium there — the plates would have to pass through the tube (ρ → 0 presses it flat, its two walls meeting at y = 0; give ρ > 0)",
                    i + 1,
                    units.show(
                        if self.target_gap.is_some() { Dimension::Length } else { Dimension::Ratio },
                        r
                    )
                );
            }
        }
        let (name, v, ok) = match t {
            Target::Pressure(p) => ("target_pressure", p, p.is_finite() && p >= 0.0),
            // at most the closed form's largest stretch: beyond it the invariants overflow, and
            // an arc length scaled to 1e308 makes the first step NaN
            Target::Stretch(s) => (
                "target_stretch",
                s,
                s.is_finite() && (1.0..=tubemem_gps::MAX_STRETCH).contains(&s),
            ),
            Target::VolumeRatio(r) => ("target_volume_ratio", r, r.is_finite() && r >= 1.0),
            Target::Rho(r) => (rho_key, r, r.is_finite() && r > 0.0),
            Target::Confine(n) => ("plane", n as f64, n >= 1),
        };
        if !ok {
            let d = match t {
                Target::Pressure(_) => Dimension::Pressure,
                Target::Rho(_) if self.target_gap.is_some() => Dimension::Length,
                _ => Dimension::Ratio,
            };
            invalid!(
                "[[stage]] {}: `{name}` = {} is out of range (pressure ≥ 0, stretch in [1, 1e6], volume ratio ≥ 1, rho > 0)",
                i + 1,
                units.show(d, v)
            );
        }
        if let (Kind::Squeeze | Kind::Confine, Some(p)) = (self.kind, self.target_pressure) {
            if !(p.is_finite() && p > 0.0) {
                invalid!(
                    "[[stage]] {}: `target_pressure` = {} is out of range: a regulated squeeze or confinement ramps the pressure to a positive value (the membrane must stay taut to carry the planes)",
                    i + 1,
                    units.show(Dimension::Pressure, p)
                );
            }
        }
        if self.steps == 0 {
            invalid!("[[stage]] {}: `steps` must be ≥ 1", i + 1);
        }
        if self.penalty.is_some() && self.penetration_tolerance.is_some() {
            invalid!(
                "[[stage]] {}: `penalty` and `penetration_tolerance` both set the penalty κ: give one",
                i + 1
            );
        }
        if self.kind == Kind::Inflate
            && (self.penalty.is_some() || self.penetration_tolerance.is_some())
        {
            invalid!(
                "[[stage]] {}: `penalty` and `penetration_tolerance` belong to squeeze stages",
                i + 1
            );
        }
        let contact_key = [
            ("contact_method", self.contact_method.is_some()),
            ("gap_tolerance", self.gap_tolerance.is_some()),
            ("max_augmentations", self.max_augmentations.is_some()),
            ("contact_points", self.contact_points.is_some()),
        ]
        .into_iter()
        .find(|k| k.1);
        if let (Kind::Inflate, Some((key, _))) = (self.kind, contact_key) {
            invalid!(
                "[[stage]] {}: `{key}` belongs to squeeze and confine stages",
                i + 1
            );
        }
        if self.contact_method == Some(ContactMethod::Penalty)
            && (self.gap_tolerance.is_some() || self.max_augmentations.is_some())
        {
            invalid!(
                "[[stage]] {}: `gap_tolerance` and `max_augmentations` set the augmented contact, and this stage has `contact_method` = \"penalty\"",
                i + 1
            );
        }
        for (key, given) in [
            ("gap_tolerance", self.gap_tolerance),
            ("penetration_tolerance", self.penetration_tolerance),
        ] {
            let Some(t) = given else { continue };
            let core = units.to_core(Dimension::Length, t);
            if !(core.is_finite() && core > 0.0 && core < 0.1) {
                invalid!(
                    "[[stage]] {}: `{key}` = {}: must be in (0, 0.1 R){}",
                    i + 1,
                    units.written(Dimension::Length, t),
                    if units.is_si() {
                        format!(
                            " = (0, {} m), R = {} m",
                            tubemem_material::Num(0.1 * units.factor(Dimension::Length)),
                            tubemem_material::Num(units.factor(Dimension::Length))
                        )
                    } else {
                        String::new()
                    }
                );
            }
        }
        if self.max_augmentations == Some(0) {
            invalid!("[[stage]] {}: `max_augmentations` must be ≥ 1", i + 1);
        }
        if let Some(k) = self.penalty {
            if !(k.is_finite() && k > 0.0) {
                invalid!(
                    "[[stage]] {}: `penalty` = {}: must be finite and > 0",
                    i + 1,
                    units.written(Dimension::Stiffness, k)
                );
            }
        }
        if self.target_gap.is_some() && self.kind != Kind::Squeeze {
            invalid!(
                "[[stage]] {}: `target_gap` belongs to squeeze stages",
                i + 1
            );
        }
        Ok(t)
    }
}

impl Case {
    /// Read and validate a case file; user mesh paths are relative to its folder.
    pub fn read(path: &Path) -> Result<Self, CaseError> {
        let text =
            tubemem_mesh::io::read_text_limited(path, MAX_CASE_FILE_BYTES).map_err(|source| {
                CaseError::Read {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        let mut case = Self::parse(&text).map_err(|e| CaseError::In {
            path: path.to_path_buf(),
            source: Box::new(e),
        })?;
        case.base_dir = path.parent().map(|p| p.to_path_buf()).unwrap_or_default();
        Ok(case)
    }

    /// Parse and validate case text (TOML).
    pub fn parse(text: &str) -> Result<Self, CaseError> {
        // every missing parameter of the law at once (serde names only the first)
        if let Some(m) = toml::from_str::<toml::Table>(text)
            .ok()
            .and_then(|t| t.get("material")?.as_table().cloned())
        {
            let model = m.get("model").and_then(|v| v.as_str()).unwrap_or("");
            let known =
                |keys: &[&str]| m.keys().all(|k| k == "model" || keys.contains(&k.as_str()));
            // (an unknown key, often a misspelt one, is serde's to name)
            if let Some((_, keys)) = MaterialSpec::MODELS
                .iter()
                .find(|(n, keys)| *n == model && known(keys))
            {
                let missing: Vec<String> = keys
                    .iter()
                    .filter(|k| !m.contains_key(**k))
                    .map(|k| format!("`{k}`"))
                    .collect();
                if !missing.is_empty() {
                    invalid!(
                        "[material] `model` = \"{model}\" needs {}: missing {}",
                        keys.iter()
                            .map(|k| format!("`{k}`"))
                            .collect::<Vec<_>>()
                            .join(" and "),
                        missing.join(" and ")
                    );
                }
            }
        }
        let mut case: Case = toml::from_str(text).map_err(|e| CaseError::Syntax(TomlSyntax(e)))?;
        case.plan = case.validate()?;
        case.hash = case_hash(text);
        Ok(case)
    }

    /// The case in one line: the tube, its law, its mesh and its stages.
    pub fn describe(&self) -> String {
        let g = &self.geometry;
        let law = self
            .material
            .build()
            .map(|l| l.name())
            .unwrap_or_else(|_| "?".into());
        let mesh = match (&self.mesh.file, self.mesh.around, self.mesh.along) {
            (Some(f), ..) => format!("mesh file {}", f),
            (None, Some(a), Some(b)) => format!(
                "{} {a} × {b}, {}",
                self.mesh.element.name(),
                format!("{:?}", self.mesh.symmetry).to_lowercase()
            ),
            _ => "no mesh".into(),
        };
        let units = self.units();
        let stages: Vec<String> = self.plan.iter().map(|p| p.describe_in(&units)).collect();
        format!(
            "L/R = {}, {} caps; {law}; {mesh}; {}",
            tubemem_material::Num(crate::units::round_sig(g.length / g.radius)),
            format!("{:?}", g.caps).to_lowercase(),
            stages.join(" → ")
        )
    }

    /// The scales R, H, μ of `[units]` (None: the outputs stay dimensionless).
    pub fn scales(&self) -> Option<tubemem_gps::Scales> {
        self.units?;
        let mu = self.material.shear_modulus();
        tubemem_gps::Scales::new(self.geometry.radius, self.geometry.thickness?, mu).ok()
    }

    /// The case's unit system ([`crate::units`]): SI with its scales under `[units] system =
    /// "SI"`, dimensionless otherwise.
    pub fn units(&self) -> Units {
        self.scales().map_or(Units::dimensionless(), Units::si)
    }

    /// The `[[stage.plane]]`s of stage `index` (0-based) in the dimensionless core: offsets
    /// and targets per R, read in the case's units.
    pub fn planes(&self, index: usize) -> Vec<PlaneSpec> {
        let units = self.units();
        self.stages
            .get(index)
            .map(|s| {
                s.plane
                    .iter()
                    .map(|p| PlaneSpec {
                        normal: p.normal,
                        offset: units.to_core(Dimension::Length, p.offset),
                        target: units.to_core(Dimension::Length, p.target),
                    })
                    .collect()
            })
            .unwrap_or_default()
    }

    /// The hash of the case text the case was parsed from.
    pub fn hash(&self) -> &str {
        &self.hash
    }

    /// The resolved stages.
    pub fn plan(&self) -> &[StagePlan] {
        &self.plan
    }

    /// Keep the first `n` resolved stages (with [`Case::stages`] truncated to match: a case
    /// that stops earlier).
    pub(crate) fn truncate_plan(&mut self, n: usize) {
        self.plan.truncate(n);
    }

    /// The resolved stages, to change (a coarse run's looser tolerances).
    pub(crate) fn plan_mut(&mut self) -> &mut [StagePlan] {
        &mut self.plan
    }

    /// `[solver] mesh_sequencing`: a generated capped tube whose counts halve `L` times into
    /// admissible ones, stepped by load steps on a mesh that stays put.
    fn validate_sequencing(&self, plan: &[StagePlan]) -> Result<(), CaseError> {
        let levels = self.solver.mesh_sequencing;
        if levels == 0 {
            return Ok(());
        }
        let max = MAX_SEQUENCING_LEVELS;
        if levels > max {
            invalid!("[solver] `mesh_sequencing` = {levels}: at most {max} levels");
        }
        let m = &self.mesh;
        let (Some(around), Some(along), None) = (m.around, m.along, &m.file) else {
            invalid!(
                "[solver] `mesh_sequencing` runs the case on coarser generated tubes: a user mesh (`file`) has none"
            );
        };
        if self.geometry.caps == Caps::RigidPlug {
            invalid!(
                "[solver] `mesh_sequencing` carries states between capped tubes (caps = \"hemisphere\"); the plugged tube's rigid plugs are not carried"
            );
        }
        let f = 1usize << levels;
        let cap_rows = m.cap_rows.unwrap_or(around / 8);
        let coarse = (around / f, along / f, cap_rows / f);
        if ![around, along, cap_rows]
            .iter()
            .all(|v| v.is_multiple_of(f))
        {
            invalid!(
                "[solver] `mesh_sequencing` = {levels}: [mesh] `around` = {around}, `along` = {along} and the cap rows ({cap_rows}) must each halve {levels} time(s) exactly"
            );
        }
        if let Err(tubemem_mesh::MeshError::InvalidParameter {
            name, requirement, ..
        }) = tubemem_mesh::tube::check_counts(coarse.0, coarse.1, coarse.2)
        {
            invalid!(
                "[solver] `mesh_sequencing` = {levels}: the coarsest tube ({} around, {} along, {} cap rows) is not admissible: `{name}`: {requirement}",
                coarse.0,
                coarse.1,
                coarse.2
            );
        }
        if m.fit_contact_edge || m.contact_edge_angle.is_some() || m.track_contact_edge {
            invalid!(
                "[solver] `mesh_sequencing` carries states between uniform tubes: drop [mesh] `fit_contact_edge`, `contact_edge_angle` and `track_contact_edge`, which move node lines"
            );
        }
        if let Some(p) = plan.iter().find(|p| p.arc_length) {
            invalid!(
                "[[stage]] {}: `control = \"arc-length\"` with [solver] `mesh_sequencing`: the coarse run guides load steps, which the arc-length path does not take",
                p.index
            );
        }
        Ok(())
    }

    /// Its length: a flat list of independent checks of the whole case, each returning its
    /// own error with the key it names; there is no shared logic to factor out.
    fn validate(&self) -> Result<Vec<StagePlan>, CaseError> {
        let g = &self.geometry;
        if self.units.is_some() && g.thickness.is_none() {
            invalid!(
                "[units] `system` = \"SI\" needs [geometry] `thickness` (H, in m): the pressure scale μH/R and the force scale πμH take it"
            );
        }
        for (k, v) in [
            ("radius", Some(g.radius)),
            ("length", Some(g.length)),
            ("thickness", g.thickness),
        ]
        .into_iter()
        .filter_map(|(k, v)| Some((k, v?)))
        {
            if !(v.is_finite() && v > 0.0) {
                invalid!(
                    "[geometry] `{k}` = {}: must be finite and > 0",
                    tubemem_material::Num(v)
                );
            }
        }
        if let (Some(_), Some(h)) = (self.units, g.thickness) {
            let mu = self.material.shear_modulus();
            if let Err(e) = tubemem_gps::Scales::new(g.radius, h, mu) {
                invalid!("[units] `system` = \"SI\" with [geometry] `radius`, `thickness` and [material] `shear_modulus`: {e}");
            }
        }
        let ratio = g.length / g.radius;
        if !(ratio.is_finite() && (MIN_LENGTH_RATIO..=MAX_LENGTH_RATIO).contains(&ratio)) {
            invalid!(
                "[geometry] `length` / `radius` = {} / {}{}: L/R must be in [{}, {}] (results are per R; a longer or shorter tube cannot be meshed)",
                tubemem_material::Num(g.length),
                tubemem_material::Num(g.radius),
                if ratio.is_finite() {
                    format!(" = {}", tubemem_material::Num(ratio))
                } else {
                    " overflows".to_string()
                },
                MIN_LENGTH_RATIO,
                MAX_LENGTH_RATIO
            );
        }
        let m = &self.mesh;
        match (&m.file, m.around, m.along) {
            (Some(_), None, None)
                if m.cap_rows.is_none()
                    && m.symmetry == Symmetry::None
                    && m.element == ElementKind::Quad4 => {}
            (Some(_), ..) => invalid!(
                "[mesh] `file` gives the whole mesh: drop `around`, `along`, `cap_rows`, `symmetry` and `element` (the file sets its own symmetry and element)"
            ),
            (None, Some(around), Some(along)) => {
                // the generator's own admissibility, before anything runs or is written
                let cap_rows = m.cap_rows.unwrap_or(around / 8);
                if m.cap_rows.is_none() && cap_rows == 0 {
                    invalid!(
                        "[mesh] `around` = {around}: the caps take `cap_rows` = around/8 rows by default, 0 here; give `around` ≥ 8 or `cap_rows` ≥ 1"
                    );
                }
                if let Err(tubemem_mesh::MeshError::InvalidParameter {
                    name,
                    value,
                    requirement,
                }) = tubemem_mesh::tube::check_counts(around, along, cap_rows)
                {
                    invalid!(
                        "[mesh] `{name}` = {}: {requirement}",
                        tubemem_material::Num(value)
                    );
                }
            }
            (None, ..) => invalid!("[mesh] needs `around` and `along` (a generated tube) or `file` (a user mesh)"),
        }
        if (m.fit_contact_edge || m.contact_edge_angle.is_some()) && m.file.is_some() {
            invalid!(
                "[mesh] `fit_contact_edge` and `contact_edge_angle` fit the generated tube's node lines; a user mesh (`file`) places its own"
            );
        }
        if (m.fit_contact_edge || m.contact_edge_angle.is_some())
            && self.geometry.caps != Caps::Hemisphere
        {
            invalid!(
                "[mesh] `fit_contact_edge` and `contact_edge_angle` fit the capped tube (caps = \"hemisphere\"); the plugged tube is not fitted"
            );
        }
        if m.track_contact_edge {
            if m.file.is_some() {
                invalid!(
                    "[mesh] `track_contact_edge` moves the generated tube's node lines; a user mesh (`file`) places its own"
                );
            }
            if self.geometry.caps != Caps::Hemisphere {
                invalid!(
                    "[mesh] `track_contact_edge` moves the capped tube's node lines (caps = \"hemisphere\"); the plugged tube is not fitted"
                );
            }
            if m.fit_contact_edge || m.contact_edge_angle.is_some() {
                invalid!(
                    "[mesh] `track_contact_edge` fits the mesh at every step: drop `fit_contact_edge` and `contact_edge_angle`, which fit it once for the last stage's end"
                );
            }
        }
        if let Some(g) = m.edge_fit_around {
            if !(m.fit_contact_edge || m.contact_edge_angle.is_some() || m.track_contact_edge) {
                invalid!(
                    "[mesh] `edge_fit_around` = {g} chooses the node lines a contact edge takes: it needs `fit_contact_edge`, `contact_edge_angle` or `track_contact_edge`"
                );
            }
            if let Some(around) = m.around {
                if g < 8 || !g.is_multiple_of(8) || g > around || !around.is_multiple_of(g) {
                    invalid!(
                        "[mesh] `edge_fit_around` = {g}: must be a multiple of 8 that divides `around` = {around} (the fitted node lines are those of a tube with that many elements around)"
                    );
                }
            }
        }
        if let Some(a) = m.contact_edge_angle {
            if !(a.is_finite() && a > 0.0 && a < std::f64::consts::FRAC_PI_2) {
                invalid!(
                    "[mesh] `contact_edge_angle` = {}: must be in (0, π/2), radians from the plates' symmetry line x = 0",
                    tubemem_material::Num(a)
                );
            }
        }
        if self.stages.is_empty() {
            invalid!("the case has no [[stage]]");
        }
        let units = self.units();
        let mut plan = Vec::with_capacity(self.stages.len());
        for (i, s) in self.stages.iter().enumerate() {
            let mut p = s.plan(i, &units)?;
            // held plates are enforced as the squeeze that placed them
            if let (true, Some(prev)) = (p.held_plates, plan.last()) {
                let prev: &StagePlan = prev;
                p.enforcement = prev.enforcement;
                p.contact_points = prev.contact_points;
            }
            plan.push(p);
            if matches!(s.kind, Kind::Squeeze | Kind::Confine) && i == 0 {
                invalid!(
                    "[[stage]] 1: a squeeze or confine stage needs an inflated tube: put an inflate stage before it"
                );
            }
            let after_plates = i > 0
                && (self.stages[i - 1].kind == Kind::Squeeze
                    || self.stages[i - 1].plates.is_some());
            if s.plates.is_some() && !after_plates {
                invalid!(
                    "[[stage]] {}: `plates = \"held\"` holds the plates of the squeeze just before it: put a squeeze stage before this one",
                    i + 1
                );
            }
        }
        let law = self.material.build().map_err(CaseError::Material)?;
        // a law stable only up to some stretch (a Yeoh law with a negative coefficient): every
        // inflation target's GPS state must lie below it
        if let Some(limit) = law.stable_limit() {
            for (k, p) in plan.iter().enumerate() {
                let Target::Stretch(ls) = p.target else {
                    continue;
                };
                let Ok(st) = tubemem_gps::inflate(law.as_ref(), tubemem_gps::Hypothesis::Gps, ls)
                else {
                    continue;
                };
                let lz = st.lambda_z;
                let i1 = ls * ls + lz * lz + 1.0 / (ls * ls * lz * lz);
                if i1 >= limit {
                    invalid!(
                        "[[stage]] {}: `target_stretch` = {}: [material] {} is stable only for I1 < {:.5} (its membrane tangent loses positive definiteness there), and the GPS state at λs* = {} (λz = {:.5}) has I1 = {:.5}: lower the target, or fit the law over the stretches the tube reaches",
                        k + 1,
                        tubemem_material::Num(ls),
                        law.name(),
                        limit,
                        tubemem_material::Num(ls),
                        lz,
                        i1
                    );
                }
            }
        }
        // a squeeze must close the plates on the tube: where the plan fixes the half-height at
        // its start (a stretch-controlled inflation ends with the mid-span ring at λs* R, a
        // squeeze with the plates at ρR), `target_rho` must be below it
        let mut height: Option<(f64, String)> = None;
        for (k, p) in plan.iter().enumerate() {
            match p.target {
                Target::Stretch(s) => {
                    height = Some((
                        s,
                        format!(
                            "the mid-span half-height λs* = {} that [[stage]] {} inflates to",
                            tubemem_material::Num(s),
                            k + 1
                        ),
                    ))
                }
                Target::Rho(r) => {
                    if let Some((h, what)) = &height {
                        if r >= *h {
                            let given = match self.stages[k].target_gap {
                                Some(g) => format!(
                                    "`target_gap` = {} (ρ = {})",
                                    units.written(Dimension::Length, g),
                                    tubemem_material::Num(crate::units::round_sig(r))
                                ),
                                None => format!("`target_rho` = {}", tubemem_material::Num(r)),
                            };
                            invalid!(
                                "[[stage]] {}: {given}: the plates must close on the tube, below {what} (ρ < {})",
                                k + 1,
                                tubemem_material::Num(*h)
                            );
                        }
                    }
                    height = Some((
                        r,
                        format!(
                            "the plates' half-gap ρ = {} of the squeeze [[stage]] {}",
                            tubemem_material::Num(r),
                            k + 1
                        ),
                    ));
                }
                _ => height = None,
            }
        }
        if !(self.solver.rtol > 0.0 && self.solver.rtol < 1e-2) {
            invalid!(
                "[solver] `rtol` = {}: must be in (0, 1e-2)",
                self.solver.rtol
            );
        }
        if self.solver.max_iterations == 0 {
            invalid!("[solver] `max_iterations` must be ≥ 1");
        }
        if self.output.vtu_every == 0 {
            invalid!("[output] `vtu_every` must be ≥ 1");
        }
        if self.mesh.fit_contact_edge
            && !plan
                .iter()
                .any(|p| matches!(p.target, Target::Rho(_) | Target::Confine(_)))
        {
            invalid!(
                "[mesh] `fit_contact_edge` fits the mesh to a contact edge: the case has no squeeze or confine stage"
            );
        }
        if self.mesh.track_contact_edge {
            let contact: Vec<usize> = (0..plan.len())
                .filter(|&k| matches!(plan[k].target, Target::Rho(_) | Target::Confine(_)))
                .collect();
            if contact.is_empty() {
                invalid!(
                    "[mesh] `track_contact_edge` follows contact edges: the case has no squeeze or confine stage"
                );
            }
            for &k in &contact {
                let p = &plan[k];
                if p.arc_length {
                    invalid!(
                        "[[stage]] {}: `control = \"arc-length\"` with `[mesh] track_contact_edge`: the tracked mesh moves between load steps, which the arc-length path does not take; use load stepping, or `fit_contact_edge`",
                        k + 1
                    );
                }
                if matches!(
                    p.enforcement,
                    Some(tubemem_fem::contact::Enforcement::Augmented { .. })
                ) && p.contact_points != tubemem_fem::contact::ContactPoints::Nodal
                {
                    invalid!(
                        "[[stage]] {}: `contact_points = \"gauss\"` with the augmented Lagrangian and `[mesh] track_contact_edge`: Gauss-point multipliers cannot be carried to a moved mesh; use the nodal points (the default)",
                        k + 1
                    );
                }
                if matches!(p.target, Target::Confine(_)) {
                    let planes = &self.stages[k].plane;
                    if !planes.iter().all(|q| q.mirrored_in(planes, 1)) {
                        invalid!(
                            "[mesh] `track_contact_edge`: the planes of [[stage]] {} are not symmetric about y = 0 (each plane's mirror image among them), which the closed form's contact edges need",
                            k + 1
                        );
                    }
                }
            }
        }
        self.validate_sequencing(&plan)?;
        // the fit of a confine stage needs its walls symmetric about y = 0 (the closed form
        // leaves the section's rotation against the material free otherwise)
        if let Some(k) = plan
            .iter()
            .rposition(|p| matches!(p.target, Target::Rho(_) | Target::Confine(_)))
            .filter(|&k| self.mesh.fit_contact_edge && matches!(plan[k].target, Target::Confine(_)))
        {
            let planes = &self.stages[k].plane;
            let mirrored = planes.iter().all(|p| p.mirrored_in(planes, 1));
            if !mirrored {
                invalid!(
                    "[mesh] `fit_contact_edge`: the planes of [[stage]] {} are not symmetric about y = 0 (each plane's mirror image among them), which the fit of their contact edges needs",
                    k + 1
                );
            }
        }
        Ok(plan)
    }
}
