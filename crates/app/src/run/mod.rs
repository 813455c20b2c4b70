//! The FE run of a case: plan → mesh → model → stepping → [`RunReport`], with observers called
//! at every converged step (writers, progress displays, interrupt checks).

//!
//! The run is a loop over the case's stages ([`run_with`]): build the model
//! (`runner::Runner`), restore a checkpoint if resuming, then for each stage its kind
//! ([`crate::stage::kind_of`]), its start (set up or restored) and its driving
//! (`drive::drive_stage`: load steps or arc length, a record per converged step), with the
//! observers told at each point.

mod drive;
mod runner;

use crate::case::Case;
use crate::checkpoint::Checkpoint;
use crate::observer::Observer;
use crate::report::*;
use crate::{AppError, Result};
use drive::drive_stage;
use runner::Runner;

/// How a run is driven from outside.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// continue from this checkpoint (its case hash must be the case's)
    pub resume: Option<Checkpoint>,
    /// skip the memory guard (a model estimated larger than the available memory is tried)
    pub force: bool,
    /// once set (by a signal handler, or Python's Ctrl-C), the run stops at the next Newton
    /// iteration with [`AppError::Interrupted`], keeping every converged step
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// Build the mesh a case asks for.
pub fn build_mesh(case: &Case) -> Result<tubemem_mesh::Mesh> {
    build_mesh_with_fit(case, None).map(|(m, _)| m)
}

/// [`build_mesh`], with where its node line was fitted to the contact edge (`[mesh]
/// fit_contact_edge`, [`crate::edge_fit`]: a locating run of the case on a coarse mesh, which
/// `interrupt` stops as it stops the run, [`RunOptions::interrupt`]).
pub(crate) fn build_mesh_with_fit(
    case: &Case,
    interrupt: Option<&std::sync::Arc<std::sync::atomic::AtomicBool>>,
) -> Result<(tubemem_mesh::Mesh, Option<ContactEdgeFit>)> {
    let options = RunOptions {
        interrupt: interrupt.cloned(),
        ..Default::default()
    };
    crate::model_setup::mesh_of(case, &mut |coarse| {
        run_with(coarse, "contact-edge locator", &options, &mut [])
    })
}

/// Run a validated case; `label` names it in the report. Observers see every converged step as
/// it comes. The outcome always carries the report (every converged step) and, if the run
/// failed, the error, which every observer has also been told of.
pub fn run(case: &Case, label: &str, observers: &mut [&mut dyn Observer]) -> RunOutcome {
    run_with(case, label, &RunOptions::default(), observers)
}

/// [`run`] with options.
pub fn run_with(
    case: &Case,
    label: &str,
    options: &RunOptions,
    observers: &mut [&mut dyn Observer],
) -> RunOutcome {
    let mut report = None;
    let error = run_inner(case, label, options, observers, &mut report).err();
    let report = report.unwrap_or_else(|| RunReport::empty(case, label));
    if let Some(e) = &error {
        for o in observers.iter_mut() {
            o.failed(&report, e);
        }
    }
    RunOutcome { report, error }
}

fn run_inner(
    case: &Case,
    label: &str,
    options: &RunOptions,
    observers: &mut [&mut dyn Observer],
    slot: &mut Option<RunReport>,
) -> Result<()> {
    let (mut runner, contact_edge_fit) = Runner::build(case, options, observers)?;
    let report = slot.insert(runner.initial_report(label, contact_edge_fit));
    if let Some(w) = runner.coarse.as_ref().and_then(|c| c.warning.clone()) {
        report.warnings.push(w);
    }
    if let Some(w) = thickness_warning(case) {
        report.warnings.push(w);
    }
    if let Some(ck) = &options.resume {
        runner.restore(ck, label, report)?;
    }
    for o in observers.iter_mut() {
        o.started(report, &runner.model, &runner.state)
            .map_err(|source| AppError::Observer {
                stage: 0,
                step: 0,
                source,
            })?;
    }
    let stages = case.plan().len();
    for plan in case.plan() {
        let i = plan.index;
        if options.resume.as_ref().is_some_and(|c| i < c.context.stage) {
            continue; // finished before the restart: in the restored report
        }
        for o in observers.iter_mut() {
            o.stage_started(plan, stages);
        }
        let kind = crate::stage::kind_of(plan, &case.planes(i - 1));
        let resume_here = options.resume.as_ref().filter(|c| c.context.stage == i);
        let start = runner.stage_start(kind.as_ref(), plan, stages, report, resume_here)?;
        drive_stage(
            &mut runner,
            kind.as_ref(),
            plan,
            stages,
            start,
            report,
            observers,
        )?;
        if let Some(w) = length_warning(case, report) {
            report.warnings.push(w);
        }
        for o in observers.iter_mut() {
            o.stage_finished(report)
                .map_err(|source| AppError::Output {
                    what: format!("the results of stage {i}"),
                    source,
                })?;
        }
    }
    for o in observers.iter_mut() {
        o.finished(report).map_err(|source| AppError::Output {
            what: "the run's results".into(),
            source,
        })?;
    }
    Ok(())
}

/// The largest H/R of a thin shell: 1/20 (Ventsel & Krauthammer, *Thin Plates and Shells*,
/// 2001, §10.1: a shell is thin where max(h/R) ≤ 1/20; beyond it the bending and transverse
/// shear a membrane model leaves out are no longer small against the membrane forces).
pub const THIN_MEMBRANE_RATIO: f64 = 1.0 / 20.0;

/// A warning when the case's H/R is beyond thin-membrane theory's range.
fn thickness_warning(case: &Case) -> Option<String> {
    let h = case.geometry.thickness? / case.geometry.radius;
    (h > THIN_MEMBRANE_RATIO).then(|| {
        format!(
            "[geometry] thickness / radius = H/R = {:.3} is beyond thin-membrane theory's range (H/R ≤ 1/20, Ventsel & Krauthammer 2001): the membrane model leaves out bending and transverse shear, whose share grows with H/R; the results are the membrane's, and a shell model would differ by O(H/R)",
            h
        )
    })
}

/// A warning when a finished stage's tube has no translation-invariant middle: the caps'
/// boundary layers (λs within 0.1 % of mid-span from `cap_boundary_layer` inside each
/// junction) meet at mid-span, so no part of it is the uniform tube GPS describes.
fn length_warning(case: &Case, report: &RunReport) -> Option<String> {
    let StageOutcome::Finished(s) = &report.stages.last()?.outcome else {
        return None;
    };
    let half = 0.5 * case.geometry.length / case.geometry.radius;
    let layer = s.cap_boundary_layer?;
    (layer >= 0.9 * half).then(|| {
        format!(
            "stage {}: the caps' boundary layers (λs within 0.1 % of mid-span only {layer:.3} R inside each junction) fill the tube (L/2 = {half:.3} R): no middle part is translation invariant, and the mid-span differs from GPS by the end effect; `tubemem verify --case` gives the length an accuracy needs",
            s.index
        )
    })
}
