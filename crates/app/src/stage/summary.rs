//! The summary of a finished stage: its final mid-span values and contact, the cap boundary
//! layer, the wrinkled extent, the closed-form comparison of its kind, and whether the closed
//! form applies (a uniform tube, from a uniform start).

use super::profile::{boundary_layer, wrinkle_report};
use super::record::RecordInput;
use crate::report::*;
use crate::{AppError, Result};
use tubemem_fem::contact::Contact;
use tubemem_fem::model::{Model, State};
use tubemem_fem::post::{midspan, ring_profile};
use tubemem_gps::limits::Limits;

/// The report of the stage that ended at `state` with `steps` and the critical points
/// `criticals`.
pub(crate) fn stage_report(
    r: &RecordInput,
    limits: Option<&Limits>,
    model: &Model,
    state: &State,
    steps: Vec<StepRecord>,
    criticals: Vec<CriticalRecord>,
) -> Result<StageReport> {
    let i = r.plan.index;
    let (ms, contact, its, neg) = match steps.last() {
        Some(l) => (l.midspan, l.contact, l.newton_iterations, l.negative_pivots),
        None => (
            midspan(model, state).map_err(|source| AppError::Post { stage: i, source })?,
            None,
            0,
            0,
        ),
    };
    // the stage end's profile: the last step's, or computed for it (with its plates)
    let rings = match steps.last() {
        Some(l) if !l.profile.is_empty() => l.profile.clone(),
        _ => {
            let plates = contact.map(|c| {
                Contact::plates(c.values.rho, c.penalty)
                    .with_enforcement(r.plan.contact_enforcement())
                    .with_points(r.plan.contact_points)
            });
            ring_profile(model, state, plates.as_ref())
                .map_err(|source| AppError::Post { stage: i, source })?
        }
    };
    let layer = boundary_layer(&rings, r.half_length, ms.lambda_s, 1e-3);
    let stage_nonuniformity = nonuniformity(&rings, r.half_length);
    let unstable_note = r.kind.unstable_note(&ms, limits);
    let wrinkling = wrinkle_report(model, state, i)?;
    let comparison =
        r.kind
            .stage_comparison(r.law, &ms, contact.as_ref(), steps.last(), r.start)?;
    let summary = StageSummary {
        index: i,
        kind: r.kind.name().into(),
        control: r.plan.control().map(String::from),
        target: r.plan.target,
        final_state: StageFinal {
            midspan: ms,
            newton_iterations: its,
            stage_steps: steps.len(),
            stage_newton_iterations: steps.iter().map(|s| s.newton_iterations).sum(),
            negative_pivots: neg,
            contact: contact.map(|c| FinalContact {
                rho: c.values.rho,
                chi: c.values.chi,
                chi_geometric: c.values.chi_geometric,
                force: c.values.force,
                displacement: c.displacement,
                contact_pressure: c.values.contact_pressure,
                penetration: c.values.penetration,
                total_plate_force: c.values.total_force,
                penalty: c.penalty,
                initial_stretch: c.initial_stretch,
            }),
        },
        cap_boundary_layer: layer,
        wrinkling,
        profile: format!("profiles/stage{i}_final.csv"),
        gps: comparison.gps,
        ps: comparison.ps,
        relative_error_vs_gps: comparison.gps_errors,
        relative_error_vs_ps: comparison.ps_errors,
        gps_at_fe_pressure: comparison.local_section,
        relative_error_vs_gps_at_fe_pressure: comparison.local_errors,
        walls: comparison.walls,
        planes: r.kind.planes().map(<[_]>::to_vec).unwrap_or_default(),
        initial_stretch: r.kind.planes().map(|_| r.start.lambda_s),
        critical_points: criticals,
        nonuniformity: stage_nonuniformity,
        gps_applicable: stage_nonuniformity.is_none_or(|u| u <= NONUNIFORM)
            && r.started_uniform.is_none(),
        gps_not_applicable: match (stage_nonuniformity.filter(|u| *u > NONUNIFORM), r.started_uniform) {
            (Some(u), _) => Some(format!(
                "the tube is not uniform: λs varies by {:.1} % over the central half of the cylinder (more than {} %){}",
                100.0 * u,
                100.0 * NONUNIFORM,
                unstable_note
            )),
            (None, Some(k)) => Some(format!(
                "the stage starts from the end of stage {k}, where the tube was not uniform, and the closed form starts from a uniform tube"
            )),
            (None, None) => None,
        },
    };
    Ok(StageReport {
        plan: *r.plan,
        steps,
        outcome: StageOutcome::Finished(Box::new(summary)),
        profile: rings,
    })
}
