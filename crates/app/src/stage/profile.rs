//! The profile values of a stage's end: the cap boundary layer and where the membrane is
//! wrinkled or slack.

use crate::report::*;
use crate::{AppError, Result};
use tubemem_fem::model::{Model, State};
use tubemem_fem::post::{cell_values, Regime};

/// Distance (in R) from the cap junction (or plug) at which λs comes within `tol` of its
/// mid-span value and stays there all the way to mid-span; `None` if it never does.
pub(crate) fn boundary_layer(
    rings: &[tubemem_fem::post::RingValues],
    half_length: f64,
    mid: f64,
    tol: f64,
) -> Option<f64> {
    let mut side: Vec<_> = rings.iter().filter(|r| r.z_ref >= -1e-12).collect();
    side.sort_by(|a, b| b.z_ref.total_cmp(&a.z_ref)); // from the junction inwards
    let within =
        |r: &&tubemem_fem::post::RingValues| ((r.values.lambda_s - mid) / mid).abs() <= tol;
    let first_inside = side.iter().position(within)?;
    if side[first_inside..].iter().all(within) {
        Some(half_length - side[first_inside].z_ref)
    } else {
        None
    }
}

/// Where the membrane is wrinkled or slack at the end of a stage.
pub(crate) fn wrinkle_report(model: &Model, state: &State, stage: usize) -> Result<Wrinkling> {
    let cells = cell_values(model, state).map_err(|source| AppError::Post { stage, source })?;
    let mesh = model.mesh();
    let extent = |regime: Regime| {
        let zs: Vec<f64> = cells
            .iter()
            .zip(&mesh.quads)
            .filter(|(c, _)| c.regime() == regime)
            .map(|(_, q)| q.iter().map(|&i| mesh.nodes[i][2]).sum::<f64>() / 4.0)
            .collect();
        let (lo, hi) = zs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &z| {
                (a.min(z), b.max(z))
            });
        RegimeExtent {
            elements: zs.len(),
            z_ref_min: (!zs.is_empty()).then_some(lo),
            z_ref_max: (!zs.is_empty()).then_some(hi),
        }
    };
    Ok(Wrinkling {
        wrinkled: extent(Regime::Wrinkled),
        slack: extent(Regime::Slack),
    })
}
