//! `[mesh] fit_contact_edge = true`: the generated tube's hoop node lines fitted to the
//! contact edges of the case's last contact stage at its end (see `tubemem_mesh::hoop`).
//!
//! The edges are the GPS section's under the FE's own mid-span pressure at the stage's end,
//! not the gas law's: the caps' gas changes that pressure by O(1/L), 1.4 % at L/R = 20, which
//! moves the plates' edge by 0.036 of an element at 64 around, where the node line must lie
//! within about 0.02 of one (the 9-node squeeze's χ error grows from 3e-6 to 1.7e-5). That
//! pressure comes from a locating solve of the same case on a coarse uniform mesh
//! ([`LOCATOR_AROUND`]).
//!
//! For plates y = ±ρR the section's flat zone has the current width c = πχR on each plate,
//! centred on the plate's symmetry line x = 0; a material line at reference angle θ from it
//! has the current arc length λs R θ, so the edges are at
//! ```text
//! θ_edge = c / (2 λs R) = π χ / (2 λs)   from x = 0 (and y = 0's mirror images)
//! ```
//! For any walls symmetric about y = 0, `tubemem_gps::confine::contact_edges` walks the
//! section's outline.

use crate::case::{Case, CaseError, Target};
use crate::{AppError, Result};
use std::f64::consts::{FRAC_PI_2, PI};
use tubemem_gps::section_at_pressure;

pub use crate::report::ContactEdgeFit as Fit;

/// The plates' four edges (from the x axis) at `a` from their symmetry line x = 0.
fn plate_edges(a: f64) -> Vec<f64> {
    vec![FRAC_PI_2 - a, FRAC_PI_2 + a, 1.5 * PI - a, 1.5 * PI + a]
}

/// The reference angle of the plates' contact edge from their symmetry line, π χ / (2 λs).
pub(crate) fn edge_angle(chi: f64, lambda_s: f64) -> f64 {
    PI * chi / (2.0 * lambda_s)
}

/// The plates' contact edges of the GPS section between plates at half-gap `rho` under the
/// pressure `w` (from the stretches `guess`); none when it has no flat. The one computation of
/// the one-off fit and of the tracking ([`crate::edge_track`]).
pub(crate) fn plate_section_edges(
    law: &dyn tubemem_material::MembraneLaw,
    rho: f64,
    w: f64,
    guess: [f64; 2],
) -> std::result::Result<Vec<f64>, tubemem_gps::GpsError> {
    let s = section_at_pressure(law, rho, w, guess)?;
    Ok(if s.chi > 0.0 {
        plate_edges(edge_angle(s.chi, s.lambda_s))
    } else {
        vec![]
    })
}

/// The contact edges of the GPS section in `walls` under the pressure `w` (as
/// [`plate_section_edges`], for any walls symmetric about y = 0).
pub(crate) fn wall_section_edges(
    law: &dyn tubemem_material::MembraneLaw,
    walls: &[tubemem_gps::confine::Wall],
    w: f64,
) -> std::result::Result<Vec<f64>, tubemem_gps::GpsError> {
    let state =
        tubemem_gps::confine::confine_at_pressure(law, tubemem_gps::Hypothesis::Gps, walls, w)?;
    tubemem_gps::confine::contact_edges(walls, &state)
}

/// Where the case's mesh is fitted to the contact edges of its last contact stage, or `None`
/// without `fit_contact_edge` or `contact_edge_angle`. `solve` runs the locating case (the
/// run's own [`crate::run::run_with`], with its interrupt: the run is then
/// [`AppError::Interrupted`]); it is passed in so that this module, which a run uses to build
/// its mesh, does not itself depend on the run.
pub(crate) fn contact_edges(
    case: &Case,
    solve: &mut dyn FnMut(&Case) -> crate::report::RunOutcome,
) -> Result<Option<Fit>> {
    if !case.mesh.fit_contact_edge && case.mesh.contact_edge_angle.is_none() {
        return Ok(None);
    }
    // a user mesh, plugs and a case without a contact stage are refused by validation
    if let Some(a) = case.mesh.contact_edge_angle {
        return Ok(Some(Fit {
            edges: plate_edges(a),
            pressure: None,
            locator_around: None,
        }));
    }
    let plan = case.plan();
    let Some(k) = plan
        .iter()
        .rposition(|p| matches!(p.target, Target::Rho(_) | Target::Confine(_)))
    else {
        return Err(CaseError::Invalid(
            "[mesh] `fit_contact_edge` fits the mesh to a contact edge: the case has no squeeze or confine stage".into(),
        )
        .into());
    };
    let law = case.material.build()?;
    let located = locate(case, k, solve)?;
    let w = located.w;
    let context = |what: &str| {
        format!(
            "[mesh] `fit_contact_edge`: the {what} under the locating solve's pressure ϖ = {w} at the end of [[stage]] {}",
            k + 1
        )
    };
    let edges = match plan[k].target {
        Target::Rho(rho) => {
            plate_section_edges(law.as_ref(), rho, w, [located.lambda_s, located.lambda_z])
                .map_err(|e| AppError::gps(context("section between the plates"), e))?
        }
        _ => {
            let walls = case
                .planes(k)
                .iter()
                .map(|p| p.wall_at(1.0))
                .collect::<std::result::Result<Vec<_>, _>>()
                .map_err(|e| AppError::gps(context("walls"), e))?;
            wall_section_edges(law.as_ref(), &walls, w)
                .map_err(|e| AppError::gps(context("section in the walls"), e))?
        }
    };
    Ok(Some(Fit {
        edges,
        pressure: Some(w),
        locator_around: Some(LOCATOR_AROUND.min(case.mesh.around.unwrap_or(LOCATOR_AROUND))),
    }))
}

/// Elements around of the locating solve: 16. On the shipped 9-node squeeze its mid-span
/// pressure at the end, 0.82030, is 1.1e-3 below the fitted 32-around run's 0.82121; the edge
/// moves by about 0.32 rad per unit of ϖ there, so by 3e-4 rad: 0.0015 of an element at 32
/// around and 0.006 at 128, against the 0.02 of an element within which the node line must
/// lie (the fitted runs converge at order 4.5 up to 128 around, README "Contact").
pub const LOCATOR_AROUND: usize = 16;

/// The mid-span state at the end of stage `k` (0-based) of `case` solved on the coarse
/// uniform mesh of [`LOCATOR_AROUND`] elements around (fewer if the case has fewer), the same
/// case otherwise, in memory.
fn locate(
    case: &Case,
    k: usize,
    solve: &mut dyn FnMut(&Case) -> crate::report::RunOutcome,
) -> Result<tubemem_fem::post::MidSpan> {
    let mut coarse = case.clone();
    let around = case.mesh.around.unwrap_or(LOCATOR_AROUND);
    let n = LOCATOR_AROUND.min(around);
    let scale = |v: usize, even: bool| {
        let x = (v as f64 * n as f64 / around as f64).round() as usize;
        if even {
            (2 * x.div_ceil(2)).max(2)
        } else {
            x.max(1)
        }
    };
    coarse.mesh.around = Some(n);
    coarse.mesh.along = case.mesh.along.map(|v| scale(v, true));
    coarse.mesh.cap_rows = case.mesh.cap_rows.map(|v| scale(v, false));
    coarse.mesh.fit_contact_edge = false;
    coarse.mesh.contact_edge_angle = None;
    coarse.mesh.edge_fit_around = None;
    coarse.stages.truncate(k + 1);
    coarse.truncate_plan(k + 1);
    let outcome = solve(&coarse);
    let located = outcome.report.stages.get(k).and_then(|s| match &s.outcome {
        crate::report::StageOutcome::Finished(f) => Some(f.final_state.midspan),
        _ => None,
    });
    match (outcome.error, located) {
        (None, Some(w)) => Ok(w),
        // stopped by the run's own interrupt: the run is interrupted, not its locator failed
        (Some(e @ AppError::Interrupted { .. }), _) => Err(e),
        (Some(e), _) => Err(AppError::Locator {
            around: n,
            source: Box::new(e),
        }),
        (None, None) => Err(CaseError::Invalid(format!(
            "[mesh] `fit_contact_edge`: the locating solve at {n} around did not reach the end of [[stage]] {}",
            k + 1
        ))
        .into()),
    }
}
