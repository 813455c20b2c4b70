//! # tubemem-app — the application layer
//!
//! Everything between a case file and the files a run leaves behind, as a library that the
//! `tubemem` binary and the Python module call (neither reads back what a run wrote):
//!
//! ```text
//! case (TOML, validated) → plan (resolved stages) → mesh → model → stepping
//!        → typed RunReport (StageReport, StepRecord: Serialize)
//!        → observers: RunWriter (steps.csv, summary.json, profiles/, VTU/PVD), progress, …
//! ```
//!
//! * [`case`]: the case file and its validation into a plan of [`case::StagePlan`]s (stage targets resolved
//!   once).
//! * [`model_setup`]: the mesh a case asks for and the memory guard.
//! * [`stage`]: one type per stage kind (inflate, squeeze, confine) behind
//!   [`stage::StageKind`], and what every kind shares (set-up, critical points, closed forms).
//! * [`run`]: the FE run, a loop over the plan's stages: [`run::run`] returns a
//!   [`report::RunReport`] and calls [`observer::Observer`]s at every converged step and stage
//!   end.
//! * [`checkpoint`]: the restart point, its binary format and its validation in one place.
//! * [`output`]: the writer that turns the report into files while the run goes on.
//! * [`curves`], [`figures`], [`main_job`]: closed-form curves, the paper's figures, and the
//!   main job on the embedded default case.
//!
//! Errors are typed ([`AppError`], [`case::CaseError`]) and keep their cause as `source()`.

pub mod atlas;
pub mod case;
pub mod checkpoint;
pub mod columns;
pub mod curves;
pub mod edge_fit;
pub mod edge_track;
pub mod export;
pub mod figures;
pub mod fit;
pub mod fit_history;
mod journal;
pub mod main_job;
pub mod model_setup;
pub mod observer;
pub mod output;
pub mod output_file;
pub mod quantity;
pub mod report;
pub mod run;
pub mod sequencing;
pub mod stage;
pub mod stats;
pub mod units;
pub mod verify;

use std::path::PathBuf;
use thiserror::Error;

pub use tubemem_fem::error_chain;

/// A failure of the application layer, with the stage, file or key it concerns.
#[derive(Debug, Error)]
pub enum AppError {
    #[error(transparent)]
    Case(#[from] case::CaseError),
    #[error("[mesh] file = {file:?}")]
    MeshFile {
        file: String,
        #[source]
        source: tubemem_mesh::MeshError,
    },
    #[error("[mesh]")]
    Mesh(#[source] tubemem_mesh::MeshError),
    #[error("building the finite element model")]
    Model(#[source] tubemem_fem::FemError),
    #[error("[[stage]] {stage}: {message}")]
    StageInput { stage: usize, message: String },
    #[error("stage {stage} of {stages} failed{}", unstable.map(|n| format!(" from an unstable state: its last converged state has {n} negative pivot{} of the tangent stiffness (past a limit or bifurcation point — a bulge or another mode is taking over)", if n == 1 { "" } else { "s" })).unwrap_or_default())]
    Stage {
        stage: usize,
        stages: usize,
        /// the negative pivots of the last converged state, when it has any
        unstable: Option<usize>,
        #[source]
        source: tubemem_fem::FemError,
    },
    /// A pressure-controlled stage asked for a pressure above the path's maximum: after its
    /// Newton failure, arc-length continuation from the last converged step located the limit
    /// point below the target.
    #[error("stage {stage} of {stages}: no equilibrium at ϖ = {target} beyond the limit point ϖmax ≈ {w_max:.7} (located at mid-span λs = {lambda_s:.5} by arc-length continuation from the last converged step; use volume or arc-length control)")]
    BeyondLimit {
        stage: usize,
        stages: usize,
        target: f64,
        w_max: f64,
        lambda_s: f64,
        #[source]
        source: Box<tubemem_fem::FemError>,
    },
    #[error("stage {stage}, step {step}: a non-finite mid-span value was computed: {values:?}")]
    NonFinite {
        stage: usize,
        step: usize,
        values: Vec<f64>,
    },
    #[error("stage {stage}: post-processing")]
    Post {
        stage: usize,
        #[source]
        source: tubemem_fem::FemError,
    },
    #[error("{context}")]
    Gps {
        context: String,
        #[source]
        source: tubemem_gps::GpsError,
    },
    #[error("[material]")]
    Material(#[from] tubemem_material::MaterialError),
    #[error("{}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("writing {what}")]
    Output {
        what: String,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    #[error("figure {}: {message}", path.display())]
    Figure { path: PathBuf, message: String },
    #[error("overlay {}: {message}", path.display())]
    Overlay { path: PathBuf, message: String },
    #[error("stage {stage}, step {step}: the plates penetrate the membrane by {penetration:.3e} R, {:.1} % of the plate half-gap ρ = {rho:.4} (more than {:.0} %): the penalty κ = {penalty:.3e} cannot hold them; raise `penalty` or lower `penetration_tolerance`", 100.0 * penetration / rho, 100.0 * crate::stage::MAX_PENETRATION_FRACTION)]
    ContactUnresolved {
        stage: usize,
        step: usize,
        penetration: f64,
        rho: f64,
        penalty: f64,
    },
    #[error("the model is too large for this machine: about {equations} equations need an estimated {:.1} GiB, and {:.1} GiB are available (estimate: 8 MiB + 240 B·n·log2 n, fitted to peak memory at 4.5k–104k equations; use --force to try anyway)", *estimate_bytes as f64 / (1u64 << 30) as f64, *available_bytes as f64 / (1u64 << 30) as f64)]
    TooLarge {
        equations: usize,
        estimate_bytes: u64,
        available_bytes: u64,
    },
    #[error("[mesh] `fit_contact_edge`: the locating solve ({around} elements around) failed")]
    Locator {
        around: usize,
        #[source]
        source: Box<AppError>,
    },
    #[error(
        "[solver] `mesh_sequencing`: the coarse run ({around} elements around) built no model"
    )]
    Sequencing {
        around: usize,
        #[source]
        source: Box<AppError>,
    },
    #[error("interrupted at stage {stage} after {steps} converged steps of it")]
    Interrupted { stage: usize, steps: usize },
    #[error("output folder {}: {message}", path.display())]
    Folder { path: PathBuf, message: String },
    #[error("{key} {}: {message}", path.display())]
    OutputFile {
        key: &'static str,
        path: PathBuf,
        message: String,
    },
    /// An observer of the run (the run writer, the console, a Python callback) failed on a
    /// converged step (stage 0, step 0: the reference state, before the first stage).
    #[error("{}", if *stage == 0 { "the outputs of the reference state failed".to_string() } else { format!("stage {stage}, step {step} converged, but its outputs failed") })]
    Observer {
        stage: usize,
        step: usize,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

impl AppError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        AppError::Io {
            path: path.into(),
            source,
        }
    }
    pub(crate) fn gps(context: impl Into<String>, source: tubemem_gps::GpsError) -> Self {
        AppError::Gps {
            context: context.into(),
            source,
        }
    }
    /// Whether the failure is the input's (a case, mesh or folder the run cannot take) rather
    /// than a solve's: front ends map the first to their bad-input error (Python's ValueError).
    pub fn is_input_error(&self) -> bool {
        matches!(
            self,
            AppError::Case(_)
                | AppError::MeshFile { .. }
                | AppError::Mesh(_)
                | AppError::Material(_)
                | AppError::StageInput { .. }
                | AppError::TooLarge { .. }
                | AppError::Folder { .. }
                | AppError::OutputFile { .. }
                | AppError::Overlay { .. }
        )
    }

    /// The whole message, cause after cause.
    pub fn chain(&self) -> String {
        error_chain(self)
    }
}

pub type Result<T, E = AppError> = std::result::Result<T, E>;
