//! What a run and a sweep member share: the run folder's writer and a failed run's message.

use crate::errors::TubememError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A run's outcome: its typed report (the summary dict and the step arrays are made from it,
/// not read back from disk), or `TubememError` with the whole cause chain.
pub(crate) fn run_outcome(
    outcome: tubemem_app::report::RunOutcome,
    out: &std::path::Path,
) -> PyResult<tubemem_app::report::RunReport> {
    match outcome.error {
        None => Ok(outcome.report),
        // the exception policy: bad input is ValueError, a solve that fails TubememError
        Some(e) if e.is_input_error() => Err(PyValueError::new_err(e.chain())),
        Some(e) => Err(TubememError::new_err(failure_message(&e, out))),
    }
}

/// A failed run's message: its whole chain, and where its converged steps are.
pub(crate) fn failure_message(e: &tubemem_app::AppError, out: &std::path::Path) -> String {
    format!(
        "{}; the converged steps are in {}",
        e.chain(),
        out.display()
    )
}

/// The writer of a run of `case` into `out`, with the case's checkpoint and frame settings.
pub(crate) fn run_writer(
    case: &tubemem_app::case::Case,
    out: &std::path::Path,
    mode: tubemem_app::output::FolderMode,
    inputs: &[&std::path::Path],
) -> Result<tubemem_app::output::RunWriter, tubemem_app::AppError> {
    Ok(
        tubemem_app::output::RunWriter::create(out, mode, case.hash(), inputs)?
            .checkpoint_every(case.solver.checkpoint_every)
            .frames_of(case.output),
    )
}
