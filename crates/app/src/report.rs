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
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct MeshInfo {
    /// nodes of the mesh
    pub nodes: usize,
    /// elements of the mesh
    pub elements: usize,
    /// equations (free degrees of freedom)
    pub equations: usize,
    /// the symmetry reduction: "none", "half", "quarter" or "eighth"
    pub symmetry: String,
    /// "quad4" or "quad9"
    #[serde(default)]
    pub element: String,
    /// nonzeros of the sparse LDLᵀ factor
    #[serde(default)]
    pub factor_nnz: usize,
    /// floating-point operations of one numeric factorization
    #[serde(default)]
    pub factor_flops: f64,
    /// the fill-reducing ordering of the factorization, "amd" or "nested-dissection" (with
    /// `[solver] ordering = "auto"`, the one whose factorization has fewer flops)
    #[serde(default)]
    pub ordering: String,
    /// the unknowns of the top separator when the factorization is split there, its two halves
    /// factorized side by side (large nested-dissection factors); absent for a whole factor
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split_separator: Option<usize>,
    /// whether Newton reuses the factor across linearizations (`[solver] refactorize`, with
    /// "auto" resolved by the factorization's cost)
    #[serde(default)]
    pub reuses_factor: bool,
    /// where the hoop node line was fitted to the contact edge (`[mesh] fit_contact_edge`)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_edge_fit: Option<ContactEdgeFit>,
}

#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct GeometryInfo {
    /// the reference radius R (the case's units; 1 when dimensionless)
    pub radius: f64,
    /// the cylinder's length L between the cap junctions
    pub length: f64,
    /// as the case gave it (no value is made up when it did not)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// "hemisphere" or "rigid-plug"
    pub caps: String,
}

/// The closed form at one step: GPS at the same mid-span λs (inflation) or at the same ρ from
/// the run's λs* (squeeze, eqs. 76–77), and for a squeeze the GPS section under the FE's own
/// mid-span pressure (eq. 76 without the gas law: the local mechanics, free of the end effect
/// that acts through the shared gas). A closed form without a solution is `None` (the run goes
/// on; the stage summary says why).
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
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
#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema, Deserialize)]
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
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
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
    /// an arc-length step: the path's arc length at this step and dϖ/ds of its unit tangent
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arc: Option<ArcValues>,
    /// a critical point located between the previous step and this one
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub critical: Option<tubemem_fem::continuation::CriticalKind>,
    /// the largest |λs(Z)/λs(0) − 1| over the central half of the cylinder ([`nonuniformity`];
    /// `None` when the step has no profile)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nonuniformity: Option<f64>,
    /// whether the comparison with the closed form applies at this step: the tube is uniform
    /// over its central half ([`NONUNIFORM`]) and, for a squeeze or confine stage, it was
    /// uniform when the stage started (`None` when the step has no profile)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gps_applicable: Option<bool>,
    /// an arc-length step: the negative pivots under volume control (a closed tube's
    /// stability; `negative_pivots` is then the pressure-control count)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub negative_pivots_volume: Option<usize>,
    /// the reference heights Z of the bulge fronts ([`bulge_fronts`]), lowest first; empty
    /// when the tube has no bulge
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fronts: Vec<f64>,
    /// a step of an augmented-Lagrangian contact (`contact_method = "augmented"`): the
    /// multiplier updates, their Newton iterations, the gap left where a plane pushes and the
    /// last multiplier change
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub augmentation: Option<tubemem_fem::newton::Augmentation>,
    /// a step of a squeeze or confine stage with `[mesh] track_contact_edge`: where the hoop
    /// node lines were fitted at this step, and how often the mesh moved after its first solve
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_tracking: Option<EdgeTracking>,
    /// a squeeze step after the stage's first: the plates' stiffness over the step
    /// ([`Stiffness`])
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<Stiffness>,
}

/// The effective stiffness of the plates over one squeeze step, a gripper's −dF/dgap: the
/// secant −ΔF/Δgap between the stage's previous converged step and this one, the gap 2ρ
/// between the plates (in R). The FE's and the closed form's are taken over the same two plate
/// positions, so they compare without the step size's error.
#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema, Deserialize, PartialEq)]
pub struct Stiffness {
    /// the mid-span force per length: −Δforce/Δ(2ρ), force over πμH, so in πμH/R
    pub force: f64,
    /// the same from the closed form's force at the two steps (absent where either has none)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gps_force: Option<f64>,
    /// the total force on one plate (the whole tube): −Δplate_force/Δ(2ρ), in μH
    pub plate_force: f64,
}

impl Stiffness {
    /// The stiffness over the step from `before` to `after` (the same stage's), if both press
    /// the plates and the plates moved.
    pub fn between(before: &StepRecord, after: &StepRecord) -> Option<Self> {
        let (a, b) = (before.contact.as_ref()?, after.contact.as_ref()?);
        let dgap = 2.0 * (b.values.rho - a.values.rho);
        if before.stage != after.stage || dgap == 0.0 || !dgap.is_finite() {
            return None;
        }
        let gps = |r: &StepRecord| r.closed_form.gps_flattening.map(|g| g.force);
        Some(Self {
            force: -(b.values.force - a.values.force) / dgap,
            gps_force: match (gps(before), gps(after)) {
                (Some(fa), Some(fb)) => Some(-(fb - fa) / dgap),
                _ => None,
            },
            plate_force: -(b.values.total_force - a.values.total_force) / dgap,
        })
    }
}

/// Where the mesh of a step with `[mesh] track_contact_edge` was fitted
/// ([`crate::edge_track`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, schemars::JsonSchema, serde::Deserialize)]
pub struct EdgeTracking {
    /// the contact edges the hoop node lines lie on (reference angles from the x axis,
    /// radians; empty: the uniform mesh, no contact)
    pub edges: Vec<f64>,
    /// the times the mesh moved after the step's first solve, each followed by a re-solve
    pub refits: usize,
}

/// A profile holds a bulge when its largest hoop stretch exceeds its smallest by more than this
/// (relative): ten times [`NONUNIFORM`], and far below the bulges of the paper's law (λs 1.2 →
/// 5.9, a factor of 5).
pub const BULGE: f64 = 0.1;

/// A crossing of the mid level is a bulge front only where λs(Z) flattens on both sides of it:
/// some segment on each side, before the profile ends, slopes by at most this share of the
/// crossing's slope. A front is a transition between two coexisting states, whose slope decays
/// away from it on both sides (a tanh-like profile: 7 % of its peak two widths away). The fall
/// of λs toward a cap junction is not: the cap layer decays away from the cap, so its slope
/// grows all the way to the junction, and that side never flattens (issue #24: a uniform
/// Mooney–Rivlin tube at λs* = 1.4 falls 14 % over its last 0.5 R, and was reported as a bulge).
pub const FRONT_FLATTENING: f64 = 0.2;

/// The fronts of a bulge: where λs(Z) crosses the level halfway between its smallest and
/// largest values along the profile (linear interpolation between rings), in increasing Z, and
/// flattens on both sides ([`FRONT_FLATTENING`]); empty without a bulge ([`BULGE`]).
pub fn bulge_fronts(rings: &[RingValues]) -> Vec<f64> {
    let ls: Vec<f64> = rings.iter().map(|r| r.values.lambda_s).collect();
    let (Some(lo), Some(hi)) = (
        ls.iter().copied().reduce(f64::min),
        ls.iter().copied().reduce(f64::max),
    ) else {
        return vec![];
    };
    if hi.is_nan() || lo.is_nan() || hi <= lo * (1.0 + BULGE) {
        return vec![];
    }
    let level = 0.5 * (lo + hi);
    // |dλs/dZ| of segment k (rings k, k + 1)
    let slope: Vec<f64> = rings
        .windows(2)
        .map(|w| {
            let dz = w[1].z_ref - w[0].z_ref;
            if dz == 0.0 {
                0.0
            } else {
                ((w[1].values.lambda_s - w[0].values.lambda_s) / dz).abs()
            }
        })
        .collect();
    let flattens = |c: usize, mut side: Box<dyn Iterator<Item = usize>>| {
        side.any(|k| slope[k] <= FRONT_FLATTENING * slope[c])
    };
    rings
        .windows(2)
        .enumerate()
        .filter_map(|(c, w)| {
            let (a, b) = (w[0].values.lambda_s - level, w[1].values.lambda_s - level);
            let crosses = a * b < 0.0 || (b == 0.0 && a != 0.0);
            (crosses
                && flattens(c, Box::new((0..c).rev()))
                && flattens(c, Box::new(c + 1..slope.len())))
            .then(|| w[0].z_ref + (w[1].z_ref - w[0].z_ref) * a / (a - b))
        })
        .collect()
}

/// A tube whose hoop stretch varies by more than this (relative) over the central half of its
/// cylinder is not translation invariant there, and the GPS closed form (a uniform tube) does not
/// apply to it. A uniform tube's end effect at a quarter length from mid-span is below 1e-3 in
/// the shipped cases (the boundary layer is 3R at λs* = 1.3, 2R at λs* = 6, against the 5R
/// between the quarter point and the cap at L/R = 20); a bulge changes λs by O(1) (1.2 → 5.9),
/// and Mooney–Rivlin α = 0.1 driven past its maximum to λs* = 2 varies by 24 %.
pub const NONUNIFORM: f64 = 1e-2;

/// The largest |λs(Z)/λs(0) − 1| over the rings with |Z| ≤ L/4 (`half` = L/2R), λs(0) the ring
/// nearest mid-span.
pub fn nonuniformity(rings: &[RingValues], half: f64) -> Option<f64> {
    let mid = rings
        .iter()
        .min_by(|a, b| a.z_ref.abs().total_cmp(&b.z_ref.abs()))?;
    rings
        .iter()
        .filter(|r| r.z_ref.abs() <= 0.5 * half + 1e-9)
        .map(|r| (r.values.lambda_s / mid.values.lambda_s - 1.0).abs())
        .reduce(f64::max)
}

/// Two successive limit points whose pressures differ by less than this (relative) are a ripple
/// of the discrete path: a bulge front that crosses an element boundary makes the pressure
/// oscillate about the Maxwell plateau with the element length as period, and each oscillation
/// is a pair of limit points. The bound is the accuracy claimed for the plateau (1e-4, the
/// Maxwell check); the ripples measured on the λs* = 6 tubes (32 around, 4 elements per R along)
/// are below 1e-8, a tube's real pair (ϖmax 0.761 → plateau 0.453) differs by 40 %.
pub const RIPPLE: f64 = 1e-4;

/// The closed-form value a located limit point is compared with.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct CriticalReference {
    /// "GPS limit point (maximum)", "GPS limit point (minimum)" or "Maxwell pressure"
    pub what: String,
    pub w: f64,
    /// the limit point's λs, or the upper coexisting λs of the Maxwell state
    pub lambda_s: f64,
}

/// Where an arc-length step is on its path.
#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct ArcValues {
    pub arc_length: f64,
    pub dw_ds: f64,
}

/// The final state of a stage (the `final` entry of summary.json).
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct StageFinal {
    #[serde(flatten)]
    pub midspan: MidSpan,
    /// Newton iterations of the stage's last step
    pub newton_iterations: usize,
    /// converged steps of the stage
    pub stage_steps: usize,
    /// Newton iterations of the whole stage
    pub stage_newton_iterations: usize,
    /// negative pivots of the stiffness at the stage's end (0: stable)
    pub negative_pivots: usize,
    #[serde(skip_serializing_if = "Option::is_none", flatten)]
    pub contact: Option<FinalContact>,
}

#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct FinalContact {
    pub rho: f64,
    pub chi: f64,
    pub chi_geometric: f64,
    pub force: f64,
    pub displacement: f64,
    pub contact_pressure: f64,
    pub penetration: f64,
    /// the total force on one plate (all symmetry copies, caps included), over μH R
    pub total_plate_force: f64,
    /// the contact penalty κ the stage used
    pub penalty: f64,
    /// the mid-span λs* at the start of the squeeze
    pub initial_stretch: f64,
}

/// Relative errors FE − closed form (inflation: w, λz, N_s, N_z; squeeze: w, λs, λz, χ, force).
#[derive(Clone, Debug, Default, Serialize, schemars::JsonSchema, Deserialize)]
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
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
#[serde(untagged)]
pub enum ClosedFormState {
    // (untagged: deserialization tries the variants in order, so the larger one comes first)
    Confine(Box<ConfineState>),
    Flattening(FlatteningState),
    Inflation(InflationState),
}

/// The section at the FE's pressure, or why it has no solution.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
#[serde(untagged)]
pub enum LocalSection {
    Solved(SectionState),
    Failed { error: String },
}

/// Elements in one regime at a stage end, with the range of reference height they occupy.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct RegimeExtent {
    /// how many elements are in the regime
    pub elements: usize,
    /// the lowest reference height Z they reach
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_ref_min: Option<f64>,
    /// the highest reference height Z they reach
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_ref_max: Option<f64>,
}

#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct Wrinkling {
    /// elements wrinkled at the stage end (N1 > 0 ≥ N2)
    pub wrinkled: RegimeExtent,
    /// elements slack at the stage end (N1 ≤ 0)
    pub slack: RegimeExtent,
}

/// The summary of a finished stage (one entry of summary.json's `stages`).
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct StageSummary {
    /// the stage, from 1 in the case file's order
    pub index: usize,
    /// "inflate", "squeeze" or "confine"
    pub kind: String,
    /// the case file's `control` ([`crate::case::StagePlan::control`])
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<String>,
    /// the stage's target in the case file's words: `{key, value}`
    pub target: Target,
    /// the FE mid-span state at the stage's end
    #[serde(rename = "final")]
    pub final_state: StageFinal,
    /// the distance from the cap junction beyond which λs stays within 0.1 % of its mid-span value (R)
    #[serde(rename = "cap_boundary_layer_0.1pct")]
    pub cap_boundary_layer: Option<f64>,
    /// the elements wrinkled and slack at the stage end
    pub wrinkling: Wrinkling,
    /// the profile CSV, relative to the run folder
    pub profile: String,
    /// the GPS closed form at the same λs (inflation) or ρ from the run's λs* (squeeze, eqs. 76–77), or in the same walls (confine)
    pub gps: ClosedFormState,
    /// the plane-strain closed form (λz = 1) at the same λs or ρ (eqs. 70, 78–79)
    pub ps: ClosedFormState,
    /// FE/GPS − 1 of each quantity
    pub relative_error_vs_gps: RelativeErrors,
    /// FE/PS − 1 of each quantity
    pub relative_error_vs_ps: RelativeErrors,
    /// the GPS section under the FE's own mid-span pressure: `local` as in steps.csv's
    /// `local_*` columns (the old key `gps_at_fe_pressure` is read too)
    #[serde(
        rename = "local",
        alias = "gps_at_fe_pressure",
        skip_serializing_if = "Option::is_none"
    )]
    pub gps_at_fe_pressure: Option<LocalSection>,
    #[serde(
        rename = "relative_error_vs_local",
        alias = "relative_error_vs_gps_at_fe_pressure",
        skip_serializing_if = "Option::is_none"
    )]
    /// FE/local − 1: against the GPS section under the FE's own pressure
    pub relative_error_vs_gps_at_fe_pressure: Option<RelativeErrors>,
    /// a confine stage: each wall at the end, FE against GPS and the section at the FE's
    /// pressure
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub walls: Vec<WallSummary>,
    /// a confine stage: its planes as the case gave them
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub planes: Vec<crate::case::PlaneSpec>,
    /// a confine stage: the inflated λs* its closed form starts from (a confine stage that
    /// continues one starts from the same λs*, as a squeeze continuing a squeeze does)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_stretch: Option<f64>,
    /// an arc-length stage: the critical points located on its path, in path order
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub critical_points: Vec<CriticalRecord>,
    /// the stage end's [`nonuniformity`], and whether the comparison with the closed form
    /// applies (the tube is uniform over its central half to [`NONUNIFORM`]); when it does not,
    /// `gps_not_applicable` says why
    pub nonuniformity: Option<f64>,
    pub gps_applicable: bool,
    /// why the comparison with the closed form does not apply (absent when it does)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gps_not_applicable: Option<String>,
}

/// One wall at the end of a confine stage.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct WallSummary {
    /// the FE's mid-span contact on the wall
    pub fe: WallValues,
    /// GPS for the same walls from the run's λs*
    pub gps: Option<tubemem_gps::confine::WallContact>,
    /// GPS in the same walls under the FE's own pressure
    pub local: Option<tubemem_gps::confine::WallContact>,
    /// FE/GPS − 1 of the force per unit length
    pub force_error_vs_gps: Option<f64>,
    #[serde(
        rename = "force_error_vs_local",
        alias = "force_error_vs_gps_at_fe_pressure"
    )]
    /// FE/local − 1 of the force per unit length
    pub force_error_vs_gps_at_fe_pressure: Option<f64>,
}

/// A stage that failed: its error and the last converged mid-span state.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct StageFailure {
    /// the stage, from 1
    pub index: usize,
    /// the error, with its stage, step and cause
    pub error: String,
    /// the last converged mid-span state (absent: none converged)
    pub last_converged: Option<MidSpan>,
    /// the critical points an arc-length stage located before it failed
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub critical_points: Vec<CriticalRecord>,
}

/// A critical point located on an arc-length stage's path
/// ([`tubemem_fem::continuation`]): a limit point of the pressure or a bifurcation.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct CriticalRecord {
    /// the stage, from 1
    pub stage: usize,
    /// it lies between the stage's converged steps `step − 1` and `step`
    pub step: usize,
    /// "limit-max", "limit-min", "bifurcation" or "neutral"
    pub kind: tubemem_fem::continuation::CriticalKind,
    /// the path's arc length from the stage start (scaled norm: RMS displacement in R, ϖ)
    pub arc_length: f64,
    /// the final bracket on the arc length (≤ 1e-8 when located)
    pub bracket: f64,
    /// the mid-span values at the point (ϖ, λs, λz, resultants, volume ratio)
    #[serde(flatten)]
    pub midspan: MidSpan,
    /// negative pivots of the pressure-control stiffness before and after the point
    pub negative_pivots_before: usize,
    /// negative pivots of the pressure-control stiffness after the point
    pub negative_pivots_after: usize,
    /// a limit point: the closed form it is compared with — the Maxwell pressure when the
    /// mid-span λs is beyond the uniform curve's minimum (the mid-span then sits in the upper
    /// phase of a bulge, whose pressure is Maxwell's); otherwise the GPS limit point of the
    /// same kind (the uniform tube's maximum or minimum) —
    /// and the FE pressure over it divided by the mesh's polygon factor 1/cos(π/n), minus one:
    /// the end effect plus the discretization error beyond the facets'
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<CriticalReference>,
    /// the mesh's polygon factor 1/cos(π/n)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon_factor: Option<f64>,
    /// ϖ over the reference ϖ divided by the polygon factor, minus one
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub w_error_over_polygon: Option<f64>,
    /// a limit point within [`RIPPLE`] (relative, in ϖ) of the stage's previous one: the
    /// ripple of a propagating front crossing the elements, not a limit point of the tube
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub ripple: bool,
    /// a bifurcation: the eigenvalue of K nearest zero at the point (inverse iteration) and the
    /// VTU holding its mode (field `mode`), relative to the run folder
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode_eigenvalue: Option<f64>,
    /// the VTU holding the mode (point field `mode`), relative to the run folder
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode_vtu: Option<String>,
    /// the same mode along the tube as a PNG (the ring means of its radial and axial
    /// components against the reference Z), relative to the run folder
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode_png: Option<String>,
}

/// One stage of the report: its plan, its steps and how it ended.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct StageReport {
    pub plan: StagePlan,
    pub steps: Vec<StepRecord>,
    pub outcome: StageOutcome,
    /// the profile along the tube at the stage end
    pub profile: Vec<RingValues>,
}

#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
#[serde(untagged)]
pub enum StageOutcome {
    Finished(Box<StageSummary>),
    Failed(StageFailure),
}

/// A whole run.
#[derive(Clone, Debug, Serialize, schemars::JsonSchema, Deserialize)]
pub struct RunReport {
    pub case: String,
    pub mesh: MeshInfo,
    /// the law's name with its parameters
    pub material: String,
    pub material_spec: MaterialSpec,
    pub geometry: GeometryInfo,
    pub units: String,
    /// the hash of the case text ([`crate::case::case_hash`]), as in run.json
    #[serde(default)]
    pub case_hash: String,
    /// `[units]`: R, H, μ in SI (None: dimensionless)
    #[serde(default)]
    pub scales: Option<tubemem_gps::Scales>,
    pub stages: Vec<StageReport>,
    /// what the run noticed that a user should know (a target outside the closed form's
    /// validity, …), in order
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// summary.json: the report without the steps and profiles.
#[derive(Serialize, schemars::JsonSchema)]
pub struct Summary<'a> {
    /// what the run noticed that a user should know, in order (absent: nothing)
    #[serde(skip_serializing_if = "<[String]>::is_empty")]
    pub warnings: &'a [String],
    /// the tubemem version that ran the case (as run.json)
    pub tubemem_version: &'static str,
    /// the hash of the case text, as in run.json and the VTU field data
    pub case_hash: &'a str,
    /// the case file's path as given to the run
    pub case: &'a str,
    /// the mesh and its factorization
    pub mesh: &'a MeshInfo,
    /// the law's name with its parameters, in words
    pub material: &'a str,
    /// the law as the case file's `[material]` table
    pub material_spec: &'a MaterialSpec,
    /// the tube: radius, length, thickness and caps as run
    pub geometry: &'a GeometryInfo,
    /// the text of [`UNITS`] without `[units]`; with it, the scales and the SI factors
    pub units: serde_json::Value,
    /// each stage in order: its summary when it finished, its failure otherwise
    pub stages: Vec<&'a StageOutcome>,
    /// with `[units]`: each finished stage's final state in SI
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_si: Option<Vec<Option<SiValues>>>,
}

/// A state in SI units (`[units] system = "SI"`): p = ϖ μH/R (eq. 67), N = n μH, the plate
/// force per length F = force · πμH (eq. 80), lengths times R, the total plate force times
/// μHR.
#[derive(Clone, Copy, Debug, Serialize, schemars::JsonSchema, Deserialize, PartialEq)]
pub struct SiValues {
    pub pressure_pa: f64,
    pub n_s_n_per_m: f64,
    pub n_z_n_per_m: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_n_per_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub half_gap_m: Option<f64>,
    /// the total force on one plate (the whole tube, caps included), N
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plate_force_n: Option<f64>,
}

impl SiValues {
    /// The SI values of mid-span `m` (and of the plates' `contact`) at scales `s`.
    pub fn of(
        s: &tubemem_gps::Scales,
        m: &MidSpan,
        contact: Option<&tubemem_fem::post::ContactValues>,
    ) -> Self {
        Self {
            pressure_pa: s.pressure(m.w),
            n_s_n_per_m: s.resultant(m.n_s),
            n_z_n_per_m: s.resultant(m.n_z),
            force_n_per_m: contact.map(|c| s.force_per_length(c.force)),
            half_gap_m: contact.map(|c| c.rho * s.radius),
            plate_force_n: contact
                .map(|c| c.total_force * s.shear_modulus * s.thickness * s.radius),
        }
    }
}

impl RunReport {
    /// The report of a run that stopped before its model was built (a case that cannot be
    /// meshed, a law that cannot be built): the case's own values, no mesh, no stages.
    pub fn empty(case: &crate::case::Case, label: &str) -> Self {
        RunReport {
            case: label.to_string(),
            mesh: MeshInfo {
                nodes: 0,
                elements: 0,
                equations: 0,
                symmetry: String::new(),
                element: String::new(),
                factor_nnz: 0,
                factor_flops: 0.0,
                ordering: String::new(),
                split_separator: None,
                reuses_factor: false,
                contact_edge_fit: None,
            },
            material: String::new(),
            material_spec: case.material.clone(),
            geometry: GeometryInfo {
                radius: case.geometry.radius,
                length: case.geometry.length,
                thickness: case.geometry.thickness,
                caps: String::new(),
            },
            units: UNITS.into(),
            case_hash: case.hash().to_string(),
            scales: case.scales(),
            stages: vec![],
            warnings: vec![],
        }
    }
}

pub const UNITS: &str = "dimensionless: R = 1, μH = 1, w = pR/(μH), resultants N/(μH), force = plate force per length/(πμH)";

impl RunReport {
    /// The summary.json view.
    pub fn summary(&self) -> Summary<'_> {
        Summary {
            tubemem_version: env!("CARGO_PKG_VERSION"),
            case_hash: &self.case_hash,
            case: &self.case,
            mesh: &self.mesh,
            material: &self.material,
            material_spec: &self.material_spec,
            geometry: &self.geometry,
            units: match &self.scales {
                None => serde_json::Value::String(self.units.clone()),
                Some(s) => serde_json::json!({
                    "system": "SI",
                    "radius_m": s.radius,
                    "thickness_m": s.thickness,
                    "shear_modulus_pa": s.shear_modulus,
                    "pressure_pa_per_w": s.pressure(1.0),
                    "n_per_m_per_resultant": s.resultant(1.0),
                    "n_per_m_per_force": s.force_per_length(1.0),
                    "m_per_length": s.radius,
                }),
            },
            stages: self.stages.iter().map(|s| &s.outcome).collect(),
            final_si: self.scales.map(|sc| {
                self.stages
                    .iter()
                    .map(|st| {
                        let last = st.steps.last()?;
                        Some(SiValues::of(
                            &sc,
                            &last.midspan,
                            last.contact.as_ref().map(|c| &c.values),
                        ))
                    })
                    .collect()
            }),
            warnings: &self.warnings,
        }
    }

    /// Every step of every stage, in order.
    pub fn steps(&self) -> impl Iterator<Item = &StepRecord> {
        self.stages.iter().flat_map(|s| s.steps.iter())
    }

    /// Every located critical point of every stage (finished or failed), in order.
    pub fn critical_points(&self) -> impl Iterator<Item = &CriticalRecord> {
        self.stages.iter().flat_map(|s| match &s.outcome {
            StageOutcome::Finished(f) => f.critical_points.iter(),
            StageOutcome::Failed(f) => f.critical_points.iter(),
        })
    }
}

/// (FE − closed form)/|closed form|.
pub fn rel(fe: f64, cf: f64) -> f64 {
    (fe - cf) / cf.abs().max(1e-300)
}

/// Where the fitted node lines go (`[mesh] fit_contact_edge`, [`crate::edge_fit`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, schemars::JsonSchema, serde::Deserialize)]
pub struct ContactEdgeFit {
    /// the contact edges' reference angles, from the x axis, in [0, 2π) (radians)
    pub edges: Vec<f64>,
    /// the locating solve's mid-span pressure ϖ at the stage's end (`None`: the angle was
    /// given as `contact_edge_angle`)
    pub pressure: Option<f64>,
    /// the locating solve's elements around
    pub locator_around: Option<usize>,
}

/// A run's outcome: the report (always, with every converged step) and the error if it failed.
pub struct RunOutcome {
    pub report: RunReport,
    pub error: Option<crate::AppError>,
}

impl RunOutcome {
    pub fn into_result(self) -> crate::Result<RunReport> {
        match self.error {
            None => Ok(self.report),
            Some(e) => Err(e),
        }
    }
}

/// The JSON Schema of summary.json, with each key's meaning from the doc comments of the types
/// it is written from ([`Summary`]): the book's summary.json reference is generated from it.
pub fn summary_schema() -> serde_json::Value {
    // the schema of what is written (a key skipped when empty is optional), not of what is read
    let generator = schemars::generate::SchemaSettings::draft2020_12()
        .for_serialize()
        .into_generator();
    generator
        .into_root_schema_for::<Summary<'static>>()
        .to_value()
}
