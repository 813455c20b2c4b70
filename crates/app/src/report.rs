//! The typed results of a run. All of it is `Serialize`; [`crate::output`] turns it into files
//! (`summary.json` is [`RunReport::summary`]), the CLI prints from it, and the Python module
//! returns it as arrays and dicts.

use crate::case::{StagePlan, Target};
use serde::{Deserialize, Serialize};
use tubemem_fem::post::WallValues;
use tubemem_fem::post::{ContactValues, MidSpan, RingValues};
use tubemem_gps::confine::ConfineState;
use tubemem_gps::{FlatteningState, InflationState, SectionState};
use tubemem_material::MaterialSpec;

/// What the mesh and model are.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MeshInfo {
    pub nodes: usize,
    pub elements: usize,
    pub equations: usize,
    pub symmetry: String,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GeometryInfo {
    pub radius: f64,
    pub length: f64,
    pub thickness: f64,
    pub caps: String,
}

/// The closed form at one step: GPS at the same mid-span λs (inflation) or at the same ρ from
/// the run's λs* (squeeze, eqs. 76–77), and for a squeeze the GPS section under the FE's own
/// mid-span pressure (eq. 76 without the gas law: the local mechanics, free of the end effect
/// that acts through the shared gas). A closed form without a solution is `None` (the run goes
/// on; the stage summary says why).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StepClosedForm {
    pub gps_inflation: Option<InflationState>,
    pub gps_flattening: Option<FlatteningState>,
    /// `None` for inflation steps or when the GPS flattening itself failed
    pub local: Option<Result<SectionState, String>>,
    /// a confine step: GPS for the same walls from the run's λs* (eqs. 55–60)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gps_confine: Option<ConfineState>,
    /// a confine step: the section in the same walls under the FE's own pressure
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub local_confine: Option<ConfineState>,
}

/// Contact values of a squeeze step (mid-span, [`ContactValues`]) with the displacement λs* − ρ.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct ContactRecord {
    #[serde(flatten)]
    pub values: ContactValues,
    /// reduced displacement λs* − ρ (eq. 81)
    pub displacement: f64,
    /// the mid-span λs* at the start of the squeeze
    pub initial_stretch: f64,
    pub penalty: f64,
}

/// One converged step.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StepRecord {
    pub stage: usize,
    pub step: usize,
    /// the stage's load parameter at this step (ϖ, the controlled coordinate, the total volume
    /// or the plate height ρ)
    pub load: f64,
    pub midspan: MidSpan,
    pub newton_iterations: usize,
    pub negative_pivots: usize,
    /// the Newton residual history of the step
    pub residuals: Vec<f64>,
    pub contact: Option<ContactRecord>,
    /// a confine step: each wall's mid-span contact, for the whole tube, in the case's order
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub walls: Vec<WallValues>,
    pub closed_form: StepClosedForm,
    /// the profile along the tube at this step (`[output] profiles = "every"`, the default;
    /// empty otherwise)
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub profile: Vec<RingValues>,
}

/// The final state of a stage (the `final` entry of summary.json).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageFinal {
    #[serde(flatten)]
    pub midspan: MidSpan,
    pub newton_iterations: usize,
    pub stage_steps: usize,
    pub stage_newton_iterations: usize,
    pub negative_pivots: usize,
    #[serde(skip_serializing_if = "Option::is_none", flatten)]
    pub contact: Option<FinalContact>,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct FinalContact {
    pub rho: f64,
    pub chi: f64,
    pub chi_geometric: f64,
    pub force: f64,
    pub displacement: f64,
    pub contact_pressure: f64,
    pub penetration: f64,
    pub total_plate_force: f64,
    pub penalty: f64,
    pub initial_stretch: f64,
}

/// Relative errors FE − closed form (inflation: w, λz, N_s, N_z; squeeze: w, λs, λz, χ, force).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct RelativeErrors {
    pub w: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lambda_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lambda_z: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub n_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub n_z: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chi: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force: Option<f64>,
}

/// A closed-form state of either kind.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ClosedFormState {
    // (untagged: deserialization tries the variants in order, so the larger one comes first)
    Confine(Box<ConfineState>),
    Flattening(FlatteningState),
    Inflation(InflationState),
}

/// The section at the FE's pressure, or why it has no solution.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
pub enum LocalSection {
    Solved(SectionState),
    Failed { error: String },
}

/// Elements in one regime at a stage end, with the range of reference height they occupy.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RegimeExtent {
    pub elements: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_ref_min: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_ref_max: Option<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Wrinkling {
    pub wrinkled: RegimeExtent,
    pub slack: RegimeExtent,
}

/// The summary of a finished stage (one entry of summary.json's `stages`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageSummary {
    pub index: usize,
    pub kind: String,
    pub target: Target,
    #[serde(rename = "final")]
    pub final_state: StageFinal,
    #[serde(rename = "cap_boundary_layer_0.1pct")]
    pub cap_boundary_layer: Option<f64>,
    pub wrinkling: Wrinkling,
    /// the profile CSV, relative to the run folder
    pub profile: String,
    pub gps: ClosedFormState,
    pub ps: ClosedFormState,
    pub relative_error_vs_gps: RelativeErrors,
    pub relative_error_vs_ps: RelativeErrors,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gps_at_fe_pressure: Option<LocalSection>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relative_error_vs_gps_at_fe_pressure: Option<RelativeErrors>,
    /// a confine stage: each wall at the end, FE against GPS and the section at the FE's
    /// pressure
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub walls: Vec<WallSummary>,
    /// a confine stage: its planes as the case gave them
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub planes: Vec<crate::case::PlaneSpec>,
}

/// One wall at the end of a confine stage.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WallSummary {
    pub fe: WallValues,
    pub gps: Option<tubemem_gps::confine::WallContact>,
    pub local: Option<tubemem_gps::confine::WallContact>,
    /// FE/GPS − 1 of the force per unit length
    pub force_error_vs_gps: Option<f64>,
    pub force_error_vs_gps_at_fe_pressure: Option<f64>,
}

/// A stage that failed: its error and the last converged mid-span state.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageFailure {
    pub index: usize,
    pub error: String,
    pub last_converged: Option<MidSpan>,
}

/// One stage of the report: its plan, its steps and how it ended.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageReport {
    pub plan: StagePlan,
    pub steps: Vec<StepRecord>,
    pub outcome: StageOutcome,
    /// the profile along the tube at the stage end
    pub profile: Vec<RingValues>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
pub enum StageOutcome {
    Finished(Box<StageSummary>),
    Failed(StageFailure),
}

/// A whole run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunReport {
    pub case: String,
    pub mesh: MeshInfo,
    /// the law's name with its parameters
    pub material: String,
    pub material_spec: MaterialSpec,
    pub geometry: GeometryInfo,
    pub units: String,
    pub stages: Vec<StageReport>,
    /// what the run noticed that a user should know (a target outside the closed form's
    /// validity, …), in order
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// summary.json: the report without the steps and profiles.
#[derive(Serialize)]
pub struct Summary<'a> {
    #[serde(skip_serializing_if = "<[String]>::is_empty")]
    pub warnings: &'a [String],
    pub case: &'a str,
    pub mesh: &'a MeshInfo,
    pub material: &'a str,
    pub material_spec: &'a MaterialSpec,
    pub geometry: &'a GeometryInfo,
    pub units: &'a str,
    pub stages: Vec<&'a StageOutcome>,
}

pub const UNITS: &str = "dimensionless: R = 1, μH = 1, w = pR/(μH), resultants N/(μH), force = plate force per length/(πμH)";

impl RunReport {
    /// The summary.json view.
    pub fn summary(&self) -> Summary<'_> {
        Summary {
            case: &self.case,
            mesh: &self.mesh,
            material: &self.material,
            material_spec: &self.material_spec,
            geometry: &self.geometry,
            units: &self.units,
            stages: self.stages.iter().map(|s| &s.outcome).collect(),
            warnings: &self.warnings,
        }
    }

    /// Every step of every stage, in order.
    pub fn steps(&self) -> impl Iterator<Item = &StepRecord> {
        self.stages.iter().flat_map(|s| s.steps.iter())
    }
}

/// (FE − closed form)/|closed form|.
pub fn rel(fe: f64, cf: f64) -> f64 {
    (fe - cf) / cf.abs().max(1e-300)
}
