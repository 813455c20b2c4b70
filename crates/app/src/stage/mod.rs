//! Stage kinds: what an `[[stage]]` of each kind loads, controls, monitors and compares with.
//!
//! [`crate::run`] drives every stage the same way (set-up, steps or arc length, records,
//! summary); what differs between kinds lives here, one type per kind behind [`StageKind`]:
//!
//! | kind | type | load parameter | closed form |
//! |---|---|---|---|
//! | inflate | [`inflate::Inflate`] (pressure, stretch or volume control) | ϖ, λs at a node, or V | GPS/PS inflation |
//! | squeeze | [`squeeze::Squeeze`] (gas closed or regulated) | plate half-gap h | GPS/PS flattening (Boyle, or at the held pressure), section at the FE's ϖ |
//! | inflate, `plates = "held"` | [`held::HeldPlates`] | ϖ (the previous squeeze's plates held) | the section between the plates at the FE's ϖ, its critical pressure |
//! | confine | [`confine::Confine`] (gas closed or regulated) | t ∈ [0, 1] along the planes' paths | GPS/PS confinement by the same walls |
//!
//! How a squeeze or confine stage's gas is supplied ([`GasControl`]) is one value the kind
//! holds: closed in (ϖV fixed, the load [`Loading::Gas`]) or regulated (ϖ prescribed at each
//! value of the load parameter, [`Loading::Pressure`], held or ramped linearly from the
//! stage's start to its `target_pressure`); the closed form follows it ([`closed_form::Supply`]).
//!
//! **Adding a stage kind**: a `Target` variant in [`crate::case`] (its TOML key, its validation
//! and its `describe`), a type here implementing [`StageKind`] (its range, load, arc-length
//! monitor and loading, and the closed form it is compared with, step by step and at the
//! stage's end), and its arm in [`kind_of`]. **Adding a control** of an inflation (a new
//! controlled quantity): a [`inflate::Control`] variant and its arms in `inflate.rs`.

pub mod closed_form;
pub mod confine;
pub mod critical;
pub mod failure;
pub mod held;
pub mod inflate;
pub mod profile;
pub mod record;
pub mod setup;
pub mod squeeze;
pub mod summary;

use crate::case::{GasControl, PenaltySpec, PlaneSpec, StagePlan, Target};
use crate::observer::BoxError;
use crate::report::{
    ClosedFormState, ContactRecord, FinalContact, LocalSection, RelativeErrors, StepClosedForm,
    StepRecord, WallSummary,
};
use crate::Result;
use tubemem_fem::contact::{ContactPoints, Enforcement};
use tubemem_fem::continuation::ArcLoading;
use tubemem_fem::model::{Load, Loading, Model, State};
use tubemem_fem::post::{MidSpan, WallValues};
use tubemem_fem::stepping::StepInfo;
use tubemem_gps::limits::Limits;
use tubemem_material::MembraneLaw;

/// The largest penetration of the plates, as a fraction of the plate half-gap ρ, that a squeeze
/// step accepts: 5 %. Beyond it the contact is not resolved (the shipped squeezes penetrate
/// 0.2 % of ρ at the default tolerance), and the results would be the penalty's, not the
/// membrane's.
pub const MAX_PENETRATION_FRACTION: f64 = 0.05;

/// What a stage's load needs besides the kind: fixed at the stage's set-up.
#[derive(Clone, Copy, Debug)]
pub struct LoadParts {
    /// the node whose hoop stretch a stretch control holds
    pub node: usize,
    /// ϖV of the closed gas (squeeze and confine), 0 otherwise
    pub pv: f64,
    /// the pressure ϖ at the stage's start (a regulated stage's held pressure)
    pub start_pressure: f64,
    /// the load parameter's range (from, to)
    pub range: (f64, f64),
    /// the planes' penalty κ (squeeze and confine)
    pub penalty: f64,
    /// an inflation between held plates: their half-gap
    pub held_plates: Option<f64>,
    pub enforcement: Enforcement,
    pub points: ContactPoints,
}

/// What the load range of a stage is computed from, at its start.
pub struct RangeInput<'a> {
    pub model: &'a Model,
    pub state: &'a State,
    pub node: usize,
    /// the reference volume of the whole tube
    pub v0: f64,
    /// the mid-span values at the stage's start
    pub start: &'a MidSpan,
    /// the previous stage's final contact, if it was a squeeze
    pub previous_squeeze: Option<FinalContact>,
    /// the previous stage was a confine stage that finished: its walls may still touch the
    /// tube, within the penetration a step accepts
    pub continues_confine: bool,
    /// the stage's `penalty` or `penetration_tolerance`
    pub penalty: Option<PenaltySpec>,
    /// the case's units, for what a refusal says
    pub units: &'a crate::units::Units,
}

/// The closed-form comparison of a stage's final state.
pub struct StageComparison {
    pub gps: ClosedFormState,
    pub ps: ClosedFormState,
    pub gps_errors: RelativeErrors,
    pub ps_errors: RelativeErrors,
    pub local_section: Option<LocalSection>,
    pub local_errors: Option<RelativeErrors>,
    pub walls: Vec<WallSummary>,
}

/// One kind of stage. Every method but the range, the load and the arc-length parts has the
/// inflation's answer as its default.
pub trait StageKind {
    /// "inflate", "squeeze" or "confine": the summary's `kind`
    fn name(&self) -> &'static str;

    /// Whether the gas is closed in (ϖV fixed at the stage's start): the load parameter is
    /// the planes' then, not a pressure or a volume.
    fn closed_gas(&self) -> bool {
        false
    }

    /// Whether the stage moves planes against the tube (squeeze, confine), whatever its gas.
    fn presses(&self) -> bool {
        false
    }

    /// An inflation's pressure-controlled target ϖ, if this is one (a failure short of it is
    /// explained by the free inflation's pressure maximum; a regulated squeeze's ramp is not
    /// such a target).
    fn target_pressure(&self) -> Option<f64> {
        None
    }

    /// Warnings about the target before the stage runs (a target outside the closed form's
    /// validity, or on the falling branch of its curve).
    fn warnings(
        &self,
        _plan: &StagePlan,
        _law: &dyn MembraneLaw,
        _limits: Option<&Limits>,
    ) -> Vec<String> {
        vec![]
    }

    /// The controlled quantity other than ϖ (a node's hoop coordinate, the total volume), if
    /// the stage's steps are measured in one.
    fn controlled_value(&self, _model: &Model, _state: &State, _node: usize) -> Option<f64> {
        None
    }

    /// The closed form's estimate of the target's pressure, for the pre-stress.
    fn pressure_estimate(&self, _law: &dyn MembraneLaw) -> Option<f64> {
        None
    }

    /// Where the first step of a controlled stage from `from` in `steps` steps lands
    /// (infinite: the stage has no controlled quantity).
    fn first_step(&self, _from: f64, _steps: usize, _v0: f64) -> f64 {
        f64::INFINITY
    }

    /// The load parameter's range (from, to) and the planes' penalty (0 without planes), or
    /// why the stage cannot start.
    fn range(&self, input: &RangeInput) -> std::result::Result<(f64, f64, f64), String>;

    /// The load at each value of the load parameter.
    fn load(&self, parts: &LoadParts) -> Box<dyn Fn(f64) -> Load>;

    /// The value an arc-length stage is monitored by (and reaches its target in).
    fn arc_monitor(&self, model: &Model, node: usize) -> Box<dyn Fn(&State) -> f64>;

    /// How an arc-length stage is loaded.
    fn arc_loading(&self, _parts: &LoadParts) -> ArcLoading {
        ArcLoading::Pressure(None)
    }

    /// The mid-span contact with the plates at a converged step, if the stage has plates.
    fn step_contact(
        &self,
        _model: &Model,
        _state: &State,
        _info: &StepInfo<'_>,
        _start: closed_form::ClosedFormStart,
    ) -> Option<ContactRecord> {
        None
    }

    /// How the closed form's squeeze is supplied with gas (closed, or regulated as the stage;
    /// the run makes a closed one that follows a regulated squeeze the mixed path).
    fn supply(&self) -> closed_form::Supply {
        closed_form::Supply::Closed
    }

    /// The closed form of one step and the walls' values (confine), or an error that stops
    /// the stage (an unresolved contact).
    #[allow(clippy::too_many_arguments)]
    fn step_closed_form(
        &self,
        _model: &Model,
        _state: &State,
        _info: &StepInfo<'_>,
        law: &dyn MembraneLaw,
        ms: &MidSpan,
        contact: Option<&ContactRecord>,
        start: closed_form::ClosedFormStart,
        _stage: usize,
    ) -> std::result::Result<(StepClosedForm, Vec<WallValues>), BoxError> {
        Ok((
            closed_form::step_closed_form(
                law,
                ms,
                contact.map(|c| (&c.values, start.lambda_s)),
                start.supply,
            ),
            vec![],
        ))
    }

    /// The closed-form comparison of the stage's final state `ms` (with its plates' contact,
    /// and the last step's record).
    fn stage_comparison(
        &self,
        law: &dyn MembraneLaw,
        ms: &MidSpan,
        contact: Option<&ContactRecord>,
        last: Option<&StepRecord>,
        start: closed_form::ClosedFormStart,
    ) -> Result<StageComparison> {
        closed_form::stage_closed_form(law, ms, contact, last.map(|l| &l.closed_form), start.supply)
    }

    /// Said when the final tube is not uniform and the kind knows why (an inflation past the
    /// pressure maximum); starts with "; ".
    fn unstable_note(&self, _ms: &MidSpan, _limits: Option<&Limits>) -> String {
        String::new()
    }

    /// The planes of a confine stage.
    fn planes(&self) -> Option<&[PlaneSpec]> {
        None
    }

    /// The closed form's pressure maximum of the stage's own path, when it is not the free
    /// inflation's (an inflation between plates held at half-gap `held_plates`): the
    /// reference of a maximum the arc length locates, and of a target above it.
    fn limit_reference(
        &self,
        _law: &dyn MembraneLaw,
        _held_plates: Option<f64>,
    ) -> Option<crate::report::CriticalReference> {
        None
    }
}

/// The kind of a planned stage (`planes`: the stage's `[[stage.plane]]`s).
pub fn kind_of(plan: &StagePlan, planes: &[PlaneSpec]) -> Box<dyn StageKind> {
    match plan.target {
        Target::Pressure(target) if plan.held_plates => Box::new(held::HeldPlates { target }),
        Target::Pressure(p) => Box::new(inflate::Inflate {
            control: inflate::Control::Pressure(p),
        }),
        Target::Stretch(s) => Box::new(inflate::Inflate {
            control: inflate::Control::Stretch(s),
        }),
        Target::VolumeRatio(r) => Box::new(inflate::Inflate {
            control: inflate::Control::VolumeRatio(r),
        }),
        Target::Rho(rho) => Box::new(squeeze::Squeeze { rho, gas: plan.gas }),
        Target::Confine(_) => Box::new(confine::Confine {
            planes: planes.to_vec(),
            gas: plan.gas,
        }),
    }
}

impl LoadParts {
    /// A regulated stage's pressure at load parameter `v`: its start pressure held, or ramped
    /// linearly over the load parameter's range to `target` (exactly `target` at its end).
    pub fn regulated_pressure(&self, v: f64, target: Option<f64>) -> f64 {
        let (from, to) = self.range;
        match target {
            None => self.start_pressure,
            Some(t) if v == to || from == to => t,
            Some(t) => self.start_pressure + (t - self.start_pressure) * (v - from) / (to - from),
        }
    }
}

/// The load of a stage with planes: the gas as `gas` supplies it (ϖV fixed, or the regulated
/// pressure at each value of the load parameter), and the planes `planes(value, κ)` at each
/// value of the load parameter, with the stage's enforcement and contact points.
fn planes_load(
    parts: &LoadParts,
    gas: GasControl,
    planes: impl Fn(f64, f64) -> tubemem_fem::contact::Contact + 'static,
) -> Box<dyn Fn(f64) -> Load> {
    let p = *parts;
    Box::new(move |v| {
        let loading = match gas {
            GasControl::Closed => Loading::Gas { pv: p.pv },
            GasControl::Regulated { target_pressure } => {
                Loading::Pressure(p.regulated_pressure(v, target_pressure))
            }
        };
        Load::with_contact(
            loading,
            planes(v, p.penalty)
                .with_enforcement(p.enforcement)
                .with_points(p.points),
        )
    })
}

/// The penalty κ of a stage with planes: given, or from its tolerance with the pressure and the
/// area stretch J at its start.
fn penalty_of(spec: Option<PenaltySpec>, state: &State, start: &MidSpan) -> f64 {
    use tubemem_fem::contact::penalty_for;
    match spec {
        Some(PenaltySpec::Value(k)) => k,
        Some(PenaltySpec::Tolerance(t)) => penalty_for(state.p, start.lambda_s * start.lambda_z, t),
        None => penalty_for(
            state.p,
            start.lambda_s * start.lambda_z,
            crate::case::DEFAULT_PENETRATION_TOLERANCE,
        ),
    }
}
