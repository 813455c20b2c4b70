//! `gps_history`: the GPS section in time with a viscoelastic law (issue #63), the cycle of
//! `tubemem gps history` ([`tubemem_gps::visco::cycle`]).

use crate::errors::gps_err;
use crate::table::Table;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tubemem_gps::visco::cycle::{run_cycle, Cycle, PlatesLeg, Steps};
use tubemem_gps::visco::{Control, Supply, TimePoint};
use tubemem_material::viscoelastic::{Prony, PronyTerm};

fn table<'py>(py: Python<'py>, points: &[&TimePoint], plates: bool) -> PyResult<Bound<'py, PyAny>> {
    let col = |f: &dyn Fn(&TimePoint) -> f64| points.iter().map(|p| f(p)).collect::<Vec<f64>>();
    let mut cols = vec![
        ("time".to_string(), col(&|p| p.time)),
        ("w".to_string(), col(&|p| p.w)),
        ("lambda_s".to_string(), col(&|p| p.lambda_s)),
        ("lambda_z".to_string(), col(&|p| p.lambda_z)),
        ("n_s".to_string(), col(&|p| p.n_s)),
        ("n_z".to_string(), col(&|p| p.n_z)),
    ];
    if plates {
        cols.push(("rho".to_string(), col(&|p| p.rho.unwrap_or(p.lambda_s))));
        cols.push(("chi".to_string(), col(&|p| p.chi)));
        cols.push(("force".to_string(), col(&|p| p.force)));
    }
    Ok(Bound::new(py, Table::from_columns(py, cols)?)?.into_any())
}

/// The GPS section in time with a QLV Prony law on `material` (its μ the instantaneous
/// modulus): `control` ("pressure", "stretch" or "volume") ramped from the unloaded tube to
/// `to` over `ramp` (0: a jump), held for `hold`; then, with `plates_to`, plates y = ±ρR
/// closing from first contact to ρ = `plates_to` over `squeeze_time`, held `plates_hold`, and
/// with `release` returned to first contact, the gas closed (`supply="gas"`) or the pressure
/// held (`"pressure"`). `prony`: [(g, tau), …] (tau in the time unit of the durations).
/// Steps per segment are doubled until their error estimate is below `tolerance`, or fixed
/// (`steps`). Returns a dict: `history` (Table: time, w, lambda_s, lambda_z, n_s, n_z of the
/// free tube), `plates` (Table of the steps with plates, with rho, chi, force; None without
/// plates), `touch` (where the plates first touched), `loop_area` (the plates' work per plate
/// and unit length over the cycle, πμHR; None without a release), `loop_closed` (whether the
/// release ends with no contact where the plates first touched: only then is the loop's area
/// the energy dissipated; a tube squeezed before it relaxed creeps wider and is still pressed
/// there; None without a release), `error_estimate` (None with
/// fixed steps), `steps_per_segment`, `g_infinity`.
#[pyfunction]
#[pyo3(signature = (prony, control, to, ramp=0.0, hold=0.0, material=None, hypothesis="gps", *, plates_to=None, squeeze_time=0.0, plates_hold=0.0, release=false, supply="gas", tolerance=1e-10, steps=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn gps_history<'py>(
    py: Python<'py>,
    prony: Vec<(f64, f64)>,
    control: &str,
    to: f64,
    ramp: f64,
    hold: f64,
    material: Option<&Bound<'py, PyAny>>,
    hypothesis: &str,
    plates_to: Option<f64>,
    squeeze_time: f64,
    plates_hold: f64,
    release: bool,
    supply: &str,
    tolerance: f64,
    steps: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let law = crate::gps::law(material)?;
    let hyp = crate::gps::hypothesis(hypothesis)?;
    let prony = Prony::new(
        prony
            .into_iter()
            .map(|(g, tau)| PronyTerm { g, tau })
            .collect(),
    )
    .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let control = match control {
        "pressure" => Control::Pressure,
        "stretch" => Control::Stretch,
        "volume" => Control::Volume,
        other => {
            return Err(PyValueError::new_err(format!(
                "control = {other:?}: \"pressure\", \"stretch\" or \"volume\""
            )))
        }
    };
    let supply = match supply {
        "gas" => Supply::Gas,
        "pressure" => Supply::Pressure,
        other => {
            return Err(PyValueError::new_err(format!(
                "supply = {other:?}: \"gas\" (closed in) or \"pressure\" (held)"
            )))
        }
    };
    if plates_to.is_none() && (release || squeeze_time > 0.0 || plates_hold > 0.0) {
        return Err(PyValueError::new_err(
            "squeeze_time, plates_hold and release move plates: give plates_to",
        ));
    }
    let cycle = Cycle {
        control,
        to,
        ramp,
        hold,
        plates: plates_to.map(|rho| PlatesLeg {
            supply,
            to: rho,
            travel: squeeze_time,
            hold: plates_hold,
            release,
        }),
    };
    let steps = match steps {
        Some(n) => Steps::Fixed(n),
        None => Steps::Tolerance(tolerance),
    };
    let r = py
        .detach(|| run_cycle(law.as_ref(), &prony, hyp, &cycle, steps))
        .map_err(gps_err)?;
    let h = &r.history;
    let free: Vec<&TimePoint> = h.points.iter().filter(|p| p.rho.is_none()).collect();
    let with: Vec<&TimePoint> = h.points.iter().filter(|p| p.rho.is_some()).collect();
    let d = PyDict::new(py);
    d.set_item("history", table(py, &free, false)?)?;
    d.set_item(
        "plates",
        if with.is_empty() {
            py.None().into_bound(py)
        } else {
            table(py, &with, true)?
        },
    )?;
    d.set_item("touch", r.touch)?;
    d.set_item("loop_area", r.loop_area)?;
    d.set_item("loop_closed", r.loop_area.map(|_| h.end().chi == 0.0))?;
    d.set_item(
        "error_estimate",
        Some(h.error_estimate).filter(|e| e.is_finite()),
    )?;
    d.set_item("steps_per_segment", h.steps_per_segment)?;
    d.set_item("g_infinity", prony.g_infinity())?;
    Ok(d.into_any())
}
