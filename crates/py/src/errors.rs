//! The exception policy: bad input is `ValueError`, a solve or run that fails
//! `tubemem.TubememError` (a `RuntimeError`) with the whole cause chain.

use pyo3::create_exception;
use pyo3::exceptions::PyRuntimeError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tubemem_gps::GpsError;
use tubemem_material::MaterialError;

create_exception!(
    tubemem,
    TubememError,
    PyRuntimeError,
    "A closed-form solve or finite element run that failed; the message names the stage, step and residual."
);

pub(crate) fn gps_err(e: GpsError) -> PyErr {
    let msg = tubemem_app::error_chain(&e);
    match e {
        // a pressure above the plates' critical one, or plates the tube does not reach, is
        // an input with no answer
        GpsError::InvalidInput { .. }
        | GpsError::Walls { .. }
        | GpsError::Unstable { .. }
        | GpsError::Snaps { .. }
        | GpsError::NoContact { .. }
        | GpsError::PlatesOutside { .. } => PyValueError::new_err(msg),
        // a material parameter out of range, or a stretch asked for beyond the locking limit,
        // is bad input
        GpsError::Material {
            source:
                MaterialError::InvalidParameter { .. }
                | MaterialError::Parameter { .. }
                | MaterialError::Expression { .. }
                | MaterialError::Inadmissible { .. }
                | MaterialError::Locking { .. },
            ..
        } => PyValueError::new_err(msg),
        _ => TubememError::new_err(msg),
    }
}

pub(crate) fn material_err(e: MaterialError) -> PyErr {
    match e {
        // a stretch beyond the locking limit, asked for directly, is bad input too
        MaterialError::InvalidParameter { .. }
        | MaterialError::Parameter { .. }
        | MaterialError::Expression { .. }
        | MaterialError::Inadmissible { .. }
        | MaterialError::InvalidState { .. }
        | MaterialError::Locking { .. } => {
            PyValueError::new_err(tubemem_material::tidy_numbers(&e.to_string()))
        }
        _ => TubememError::new_err(tubemem_material::tidy_numbers(&e.to_string())),
    }
}
