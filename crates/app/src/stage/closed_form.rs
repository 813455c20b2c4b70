//! The closed form a stage is compared with, at each step and at its end: GPS inflation or
//! flattening from the FE's own mid-span values, PS at the stage's end, and for a squeeze the
//! section at the FE's pressure.

use crate::report::*;
use crate::{AppError, Result};
use tubemem_gps::regulated::{
    between_plates, flatten_closed_from, free_start, squeeze_at_pressure,
};
use tubemem_gps::{flatten, inflate, section_at_pressure, FlatteningState, GpsError, Hypothesis};
use tubemem_material::MembraneLaw;

/// How the closed form's squeeze is supplied with gas, as the FE's stage is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Supply {
    /// closed in the free tube at λs* (Boyle, eq. 77₂: [`flatten`])
    Closed,
    /// a regulated pressure: the section at the FE's own (prescribed) pressure, reached from the
    /// free tube at λs* by [`squeeze_at_pressure`] (which picks the branch)
    Regulated,
    /// the mixed path: squeezed from λs* with the pressure regulated to half-gap `rho` under
    /// the pressure `w`, then the gas closed in there ([`flatten_closed_from`])
    ClosedAfterRegulated { rho: f64, w: f64 },
    /// an inflation between held plates: the section between them at the FE's pressure, from
    /// the stress-free tube ([`between_plates`]) when they are closer than its radius, as
    /// [`Supply::Regulated`] otherwise
    HeldPlates,
}

impl From<crate::case::GasControl> for Supply {
    /// A stage's own supply (the run makes a closed one after a regulated squeeze the mixed
    /// path, [`Supply::ClosedAfterRegulated`]).
    fn from(gas: crate::case::GasControl) -> Self {
        match gas {
            crate::case::GasControl::Closed => Supply::Closed,
            crate::case::GasControl::Regulated { .. } => Supply::Regulated,
        }
    }
}

/// Where a stage's closed form starts: the free tube's λs*, and how the gas is supplied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedFormStart {
    pub lambda_s: f64,
    pub supply: Supply,
}

/// The flattening at half-gap `rho` from the free tube at `ls0` under `supply`, `w` the FE's
/// pressure (a regulated supply's).
pub(crate) fn flattening(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    supply: Supply,
    ls0: f64,
    rho: f64,
    w: f64,
) -> std::result::Result<FlatteningState, GpsError> {
    match supply {
        Supply::Closed => flatten(law, hyp, ls0, rho),
        Supply::HeldPlates if rho < 1.0 => Ok(between_plates(law, hyp, rho, w)?.as_flattening(ls0)),
        Supply::Regulated | Supply::HeldPlates => {
            let s = squeeze_at_pressure(law, hyp, free_start(law, hyp, ls0)?, rho, w)?;
            Ok(s.as_flattening(ls0))
        }
        Supply::ClosedAfterRegulated { rho: r1, w: w1 } => {
            let s1 = squeeze_at_pressure(law, hyp, free_start(law, hyp, ls0)?, r1, w1)?;
            Ok(flatten_closed_from(law, hyp, s1, rho)?.as_flattening(ls0))
        }
    }
}

/// The closed form at one step (see [`StepClosedForm`]).
pub(crate) fn step_closed_form(
    law: &dyn MembraneLaw,
    ms: &tubemem_fem::post::MidSpan,
    squeeze: Option<(&tubemem_fem::post::ContactValues, f64)>,
    supply: Supply,
) -> StepClosedForm {
    match squeeze {
        None => StepClosedForm {
            gps_inflation: inflate(law, Hypothesis::Gps, ms.lambda_s).ok(),
            gps_flattening: None,
            local: None,
            gps_confine: None,
            local_confine: None,
        },
        Some((c, ls0)) => {
            let g = flattening(law, Hypothesis::Gps, supply, ls0, c.rho, ms.w).ok();
            let local = g.map(|g| {
                section_at_pressure(law, c.rho, ms.w, [g.lambda_s, g.lambda_z])
                    .map_err(|e| e.to_string())
            });
            StepClosedForm {
                gps_inflation: None,
                gps_flattening: g,
                local,
                gps_confine: None,
                local_confine: None,
            }
        }
    }
}

/// The closed-form comparison of a stage's final state: GPS and PS, and for a squeeze the
/// section at the FE's pressure. GPS and the section are the last step's (solved once, for its
/// steps.csv row); only PS is solved here.
pub(crate) fn stage_closed_form(
    law: &dyn MembraneLaw,
    ms: &tubemem_fem::post::MidSpan,
    contact: Option<&ContactRecord>,
    last: Option<&StepClosedForm>,
    supply: Supply,
) -> Result<super::StageComparison> {
    let local = last.and_then(|l| l.local.as_ref());
    let one = |hyp: Hypothesis| -> Result<(ClosedFormState, RelativeErrors)> {
        Ok(match contact {
            None => {
                let known = last
                    .and_then(|l| l.gps_inflation)
                    .filter(|_| hyp == Hypothesis::Gps);
                let s = match known {
                    Some(s) => s,
                    None => inflate(law, hyp, ms.lambda_s).map_err(|e| {
                        AppError::gps(format!("{} inflation at the FE's λs", hyp.label()), e)
                    })?,
                };
                (
                    ClosedFormState::Inflation(s),
                    RelativeErrors {
                        w: Some(rel(ms.w, s.w)),
                        lambda_z: Some(rel(ms.lambda_z, s.lambda_z)),
                        n_s: Some(rel(ms.n_s, s.n_s)),
                        n_z: Some(rel(ms.n_z, s.n_z)),
                        ..Default::default()
                    },
                )
            }
            Some(c) => {
                let known = last
                    .and_then(|l| l.gps_flattening)
                    .filter(|_| hyp == Hypothesis::Gps);
                let s = match known {
                    Some(s) => s,
                    None => flattening(law, hyp, supply, c.initial_stretch, c.values.rho, ms.w)
                        .map_err(|e| {
                            AppError::gps(format!("{} flattening at the FE's ρ", hyp.label()), e)
                        })?,
                };
                (
                    ClosedFormState::Flattening(s),
                    RelativeErrors {
                        w: Some(rel(ms.w, s.w)),
                        lambda_s: Some(rel(ms.lambda_s, s.lambda_s)),
                        lambda_z: Some(rel(ms.lambda_z, s.lambda_z)),
                        chi: Some(rel(c.values.chi, s.chi)),
                        force: Some(rel(c.values.force, s.force)),
                        ..Default::default()
                    },
                )
            }
        })
    };
    let ((gps, gps_errors), (ps, ps_errors)) = (one(Hypothesis::Gps)?, one(Hypothesis::Ps)?);
    let (section, errors) = match (contact, local) {
        (Some(c), Some(Ok(l))) => (
            Some(LocalSection::Solved(*l)),
            Some(RelativeErrors {
                w: None,
                lambda_s: Some(rel(ms.lambda_s, l.lambda_s)),
                lambda_z: Some(rel(ms.lambda_z, l.lambda_z)),
                chi: Some(rel(c.values.chi, l.chi)),
                force: Some(rel(c.values.force, l.force)),
                ..Default::default()
            }),
        ),
        (Some(_), Some(Err(e))) => (Some(LocalSection::Failed { error: e.clone() }), None),
        _ => (None, None),
    };
    Ok(super::StageComparison {
        gps,
        ps,
        gps_errors,
        ps_errors,
        local_section: section,
        local_errors: errors,
        walls: vec![],
    })
}
