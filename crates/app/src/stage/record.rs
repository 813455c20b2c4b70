//! The record of one converged step: the mid-span values, the plates' contact, the closed
//! form, the profile and the Newton statistics, with the guards that stop a stage whose step
//! is not a result (an unresolved contact, a non-finite value).

use super::{StageKind, MAX_PENETRATION_FRACTION};
use crate::case::StagePlan;
use crate::observer::BoxError;
use crate::report::*;
use crate::AppError;
use tubemem_fem::contact::Enforcement;
use tubemem_fem::continuation::CriticalKind;
use tubemem_fem::model::{Model, State};
use tubemem_fem::post::{midspan, ring_profile};
use tubemem_fem::stepping::StepInfo;
use tubemem_material::MembraneLaw;

/// What every step of a stage is recorded with.
pub struct RecordInput<'a> {
    pub kind: &'a dyn StageKind,
    pub plan: &'a StagePlan,
    /// the law of the closed form (without the tension-field relaxation)
    pub law: &'a dyn MembraneLaw,
    /// the mid-span λs* the stage's closed form starts from
    /// where the stage's closed form starts (λs*, the gas supply)
    pub start: super::closed_form::ClosedFormStart,
    /// the tube's half-length L/(2R)
    pub half_length: f64,
    /// `[output] profiles = "every"`
    pub every_profile: bool,
    /// the earlier stage that ended with a tube that was not uniform, if this closed-gas stage
    /// starts from it
    pub started_uniform: Option<usize>,
    /// the tracked contact edges (`[mesh] track_contact_edge`, closed gas)
    pub tracked_edges: Option<&'a crate::edge_track::Edges>,
}

/// The record of the converged step `info` (`critical`: the critical point located just
/// before it).
pub(crate) fn step_record(
    r: &RecordInput,
    m: &Model,
    st: &State,
    info: &StepInfo<'_>,
    critical: Option<CriticalKind>,
) -> Result<StepRecord, BoxError> {
    let i = r.plan.index;
    let ms = midspan(m, st).map_err(|e| Box::new(e) as BoxError)?;
    let contact = r.kind.step_contact(m, st, info, r.start);

    let mut vals = vec![
        ms.w,
        ms.lambda_s,
        ms.lambda_z,
        ms.n_s,
        ms.n_z,
        ms.n_sz,
        ms.volume,
    ];
    if let Some(c) = &contact {
        let c = &c.values;
        vals.extend([c.chi, c.force, c.contact_pressure, c.penetration]);
    }
    if let Some(c) = &contact {
        let (pen, rho) = (c.values.penetration, c.values.rho);
        if pen.is_nan() || pen > MAX_PENETRATION_FRACTION * rho {
            return Err(Box::new(AppError::ContactUnresolved {
                stage: i,
                step: info.step,
                penetration: pen,
                rho,
                penalty: c.penalty,
            }) as BoxError);
        }
    }
    if vals.iter().any(|v| !v.is_finite()) {
        return Err(Box::new(AppError::NonFinite {
            stage: i,
            step: info.step,
            values: vals,
        }) as BoxError);
    }
    let (closed_form, walls) =
        r.kind
            .step_closed_form(m, st, info, r.law, &ms, contact.as_ref(), r.start, i)?;
    let profile = if r.every_profile {
        ring_profile(m, st, info.load.contact.as_ref()).map_err(|e| Box::new(e) as BoxError)?
    } else {
        vec![]
    };
    let step_nonuniformity = nonuniformity(&profile, r.half_length);
    let step_fronts = bulge_fronts(&profile);
    Ok(StepRecord {
        stage: i,
        step: info.step,
        load: info.value,
        midspan: ms,
        newton_iterations: info.newton.iterations,
        negative_pivots: info.newton.inertia.negative_pivots,
        residuals: info.newton.history.clone(),
        contact,
        walls,
        closed_form,
        profile,
        arc: r.plan.arc_length.then_some(ArcValues {
            arc_length: info.progress.lambda,
            dw_ds: info.dw_ds,
        }),
        critical,
        nonuniformity: step_nonuniformity,
        gps_applicable: step_nonuniformity.map(|u| u <= NONUNIFORM && r.started_uniform.is_none()),
        negative_pivots_volume: info.negative_conjugate,
        fronts: step_fronts,
        augmentation: matches!(r.plan.enforcement, Some(Enforcement::Augmented { .. }))
            .then_some(info.newton.augmentation),
        edge_tracking: r.tracked_edges.map(|edges| crate::report::EdgeTracking {
            edges: edges.borrow().clone(),
            refits: info.refits,
        }),
        stiffness: None,
    })
}
