use thiserror::Error;
use tubemem_material::MaterialError;

/// Why a closed-form computation failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GpsError {
    /// An input outside its admissible range (λs < 1, ρ ≥ λs*, a point count < 2, …).
    #[error("invalid input `{name}` = {}: {requirement}", tubemem_material::Num(*value))]
    InvalidInput {
        name: &'static str,
        value: f64,
        requirement: &'static str,
    },
    /// The material law rejected a state on the way (typically the locking limit). The cause
    /// is `source()`, not repeated in this message: print the chain.
    #[error("{stage} at {at}")]
    Material {
        stage: &'static str,
        at: String,
        #[source]
        source: MaterialError,
    },
    /// Plates asked to close to a half-gap not inside the tube they start from (a viscoelastic
    /// cycle's plates start where they touch the inflated tube, ρ = λs).
    #[error("the plates close from first contact at ρ = {touch:.6} (the inflated λs) to ρ = {}: give 0 < ρ < {touch:.6}", tubemem_material::Num(*rho))]
    PlatesOutside { rho: f64, touch: f64 },
    /// A set of walls that cannot hold the section (open, empty, too short a perimeter).
    #[error("{message}")]
    Walls { message: String },
    /// The equations' solution is a compressed membrane (N_s < 0, so ϖ < 0 and a negative
    /// plate force): a branch a softening energy or one with a pole allows, which a membrane
    /// cannot carry. Reported, never returned as an answer.
    #[error(
        "{stage} at {at}: the solution found is a compressed membrane (N_s = {} μH < 0, ϖ = {}), which a membrane cannot carry; the law's energy softens or has a pole on this path, so no tensile state continues it",
        tubemem_material::Num(*n_s), tubemem_material::Num(*w)
    )]
    Compressive {
        stage: &'static str,
        at: String,
        n_s: f64,
        w: f64,
    },
    /// A pressure-controlled state past a limit point: between plates at half-gap ρ the section
    /// carries at most ϖc on its branch (the first maximum of ϖ along the states at that ρ), and
    /// the pressure asked is above it, so the state jumps (snaps) to another branch, which no
    /// continuation follows.
    #[error(
        "{stage} at {at}: the pressure ϖ = {} is above the largest the section between these plates carries on its branch, ϖc = {} (reached at λs = {}): past this limit point a pressure-controlled section snaps to another state",
        tubemem_material::Num(*w), tubemem_material::Num(*w_critical), tubemem_material::Num(*lambda_s_critical)
    )]
    Unstable {
        stage: &'static str,
        at: String,
        w: f64,
        w_critical: f64,
        lambda_s_critical: f64,
    },
    /// A pressure-controlled path that reaches a state where the section between its plates
    /// stops being stable (dϖ/dλs along the states at that ρ changes sign there) though no
    /// pressure maximum lies before it on those states (they start on a falling branch): the
    /// squeeze snaps there.
    #[error(
        "{stage} at {at}: the section loses its stability under pressure control at λs = {} (ϖ stops rising along the states between these plates; they carry no higher pressure on this branch): the squeeze snaps here, to a state no continuation follows",
        tubemem_material::Num(*lambda_s)
    )]
    Snaps {
        stage: &'static str,
        at: String,
        w: f64,
        lambda_s: f64,
    },
    /// The plates do not touch the tube: at this pressure the free tube is narrower than the
    /// gap (its hoop stretch below ρ), so there is no squeezed section to answer with.
    #[error(
        "{stage} at {at}: the plates do not touch the tube (the free tube at this pressure has λs = {} < ρ = {})",
        tubemem_material::Num(*lambda_s), tubemem_material::Num(*rho)
    )]
    NoContact {
        stage: &'static str,
        at: String,
        lambda_s: f64,
        rho: f64,
    },
    /// The caller asked a long computation to stop (Ctrl-C during a run's limit-point scan).
    #[error("interrupted")]
    Interrupted,
    /// Newton did not converge, even after step cut-back.
    #[error(
        "{stage} did not converge at {at}: {}",
        residual_words(*residual, *iterations)
    )]
    NoConvergence {
        stage: &'static str,
        at: String,
        residual: f64,
        iterations: usize,
    },
}

/// The residual of a Newton solve that did not converge, in words: a non-finite one says that
/// the equations could not be evaluated (never "residual NaN").
fn residual_words(residual: f64, iterations: usize) -> String {
    if residual.is_finite() {
        format!("residual {residual:.3e} after {iterations} iterations")
    } else {
        format!(
            "the equations could not be evaluated after {iterations} iterations (the residual is not a finite number: the law's stress or tangent overflows, vanishes or is undefined on this path)"
        )
    }
}

pub(crate) fn invalid(name: &'static str, value: f64, requirement: &'static str) -> GpsError {
    GpsError::InvalidInput {
        name,
        value,
        requirement,
    }
}
