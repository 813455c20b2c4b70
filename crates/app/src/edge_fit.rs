//! `[mesh] fit_contact_edge = true`: the generated tube's hoop node lines fitted to the
//! closed form's contact edges at the case's contact target (see `tubemem_mesh::hoop`).
//!
//! For plates y = ±ρR the GPS section's flat zone has the current width c = πχR on each plate,
//! centred on the plate's symmetry line x = 0; a material line at reference angle θ from it
//! has the current arc length λs R θ, so the edge is at
//! ```text
//! θ_edge = c / (2 λs R) = π χ / (2 λs)   from x = 0,  i.e. at π/2 − θ_edge from the x axis
//! ```
//! (λs, χ of the GPS flattening to the last squeeze stage's ρ after inflating to the inflate
//! stage's λs*). The closed form's state differs from the FE's by the end effect, O(1/L), and
//! the FE's edge by that much from the fitted line.

use crate::case::{Case, CaseError, Target};
use crate::{AppError, Result};
use tubemem_gps::{flatten, section_at_pressure, Hypothesis};

/// Where the fitted node line goes.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Fit {
    /// the contact edge's reference angle from the plates' symmetry line x = 0 (radians)
    pub from_symmetry_line: f64,
    /// the locating solve's mid-span pressure ϖ at the squeeze's end (`None`: the angle was
    /// given as `contact_edge_angle`)
    pub pressure: Option<f64>,
    /// the locating solve's elements around
    pub locator_around: Option<usize>,
}

impl Fit {
    /// The edges in the first quadrant, from the x axis (for `tubemem_mesh::hoop`).
    pub fn edges(&self) -> Vec<f64> {
        vec![std::f64::consts::FRAC_PI_2 - self.from_symmetry_line]
    }
}

/// Where the case's mesh is fitted to the contact edge of its last squeeze, or `None` without
/// `fit_contact_edge` or `contact_edge_angle`. The edge is the GPS section's under the FE's
/// own mid-span pressure at the squeeze's end (not the gas law's: the caps' gas changes that
/// pressure by O(1/L), 1.4 % at L/R = 20, which moves the edge by 0.036 of an element at 64
/// around, where the node line must lie within about 0.02 of one): that pressure comes from a
/// locating solve of the same case on a coarse uniform mesh ([`LOCATOR_AROUND`]).
pub fn contact_edges(case: &Case) -> Result<Option<Fit>> {
    if let Some(a) = case.mesh.contact_edge_angle {
        return Ok(Some(Fit {
            from_symmetry_line: a,
            pressure: None,
            locator_around: None,
        }));
    }
    if !case.mesh.fit_contact_edge {
        return Ok(None);
    }
    if case.mesh.file.is_some() || case.geometry.caps != crate::case::Caps::Hemisphere {
        return Err(CaseError::Invalid(
            "[mesh] `fit_contact_edge` fits the generated capped tube (caps = \"hemisphere\"); a user mesh places its own node lines (see the README's contact section)".into(),
        )
        .into());
    }
    let plan = case.plan();
    let Some(k) = plan
        .iter()
        .rposition(|p| matches!(p.target, Target::Rho(_) | Target::Confine(_)))
    else {
        return Err(CaseError::Invalid(
            "[mesh] `fit_contact_edge` fits the mesh to a squeeze's contact edge: the case has no squeeze stage".into(),
        )
        .into());
    };
    let Target::Rho(rho) = plan[k].target else {
        return Err(CaseError::Invalid(format!(
            "[mesh] `fit_contact_edge`: the last contact stage, [[stage]] {}, is a confine stage; only squeezes between plates are fitted so far",
            k + 1
        ))
        .into());
    };
    // the stretch the squeeze starts from: the last inflation before it, by its target λs*
    let start = plan[..k].iter().rev().find_map(|p| match p.target {
        Target::Stretch(s) => Some(Ok(s)),
        Target::Rho(_) | Target::Confine(_) => None,
        _ => Some(Err(p.index)),
    });
    let initial_stretch = match start {
        Some(Ok(s)) => s,
        Some(Err(i)) => {
            return Err(CaseError::Invalid(format!(
                "[mesh] `fit_contact_edge`: the inflation before the squeeze, [[stage]] {i}, must give `target_stretch` (the closed form's edge is found from the stretch the squeeze starts at)"
            ))
            .into())
        }
        None => {
            return Err(CaseError::Invalid(
                "[mesh] `fit_contact_edge`: no inflate stage with `target_stretch` before the squeeze".into(),
            )
            .into())
        }
    };
    let law = case.material.build()?;
    let gps = flatten(law.as_ref(), Hypothesis::Gps, initial_stretch, rho).map_err(|e| {
        AppError::gps(
            format!(
                "[mesh] `fit_contact_edge`: the closed form at [[stage]] {} (ρ = {rho})",
                k + 1
            ),
            e,
        )
    })?;
    // the FE's mid-span pressure at the target, from the locating solve
    let w = locate_pressure(case, k)?;
    let section = section_at_pressure(law.as_ref(), rho, w, [gps.lambda_s, gps.lambda_z])
        .map_err(|e| {
            AppError::gps(
                format!(
                    "[mesh] `fit_contact_edge`: the section at the locating solve's pressure ϖ = {w} (ρ = {rho})"
                ),
                e,
            )
        })?;
    Ok(Some(Fit {
        from_symmetry_line: edge_angle(section.chi, section.lambda_s),
        pressure: Some(w),
        locator_around: Some(LOCATOR_AROUND.min(case.mesh.around.unwrap_or(LOCATOR_AROUND))),
    }))
}

/// The reference angle of the plates' contact edge from their symmetry line, π χ / (2 λs).
pub fn edge_angle(chi: f64, lambda_s: f64) -> f64 {
    std::f64::consts::PI * chi / (2.0 * lambda_s)
}

/// Elements around of the locating solve: 16, where the 9-node element's mid-span pressure
/// at the squeeze's end is within 1e-4 of its value at 64 around (measured on the shipped
/// 9-node squeeze, README "Contact"), which moves the edge by 3e-5 rad, 3e-4 of an element at
/// 64 around.
pub const LOCATOR_AROUND: usize = 16;

/// The mid-span pressure at the end of stage `k` (0-based) of `case` solved on the coarse
/// uniform mesh of [`LOCATOR_AROUND`] elements around (fewer if the case has fewer), the same
/// case otherwise, in memory.
fn locate_pressure(case: &Case, k: usize) -> Result<f64> {
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
    coarse.stages.truncate(k + 1);
    coarse.truncate_plan(k + 1);
    let outcome = crate::run::run(&coarse, "contact-edge locator", &mut []);
    let located = outcome.report.stages.get(k).and_then(|s| match &s.outcome {
        crate::report::StageOutcome::Finished(f) => Some(f.final_state.midspan.w),
        _ => None,
    });
    match (outcome.error, located) {
        (None, Some(w)) => Ok(w),
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
