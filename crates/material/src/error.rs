use thiserror::Error;

/// Why a material law or a stretch state was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MaterialError {
    /// A material parameter is outside its admissible range.
    #[error("invalid material parameter `{name}` = {value}: {requirement}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        requirement: &'static str,
    },
    /// A stretch (or a Cauchy–Green component) that no deformation can produce.
    #[error("invalid deformation: {what} = {value} ({requirement})")]
    InvalidState {
        what: &'static str,
        value: f64,
        requirement: &'static str,
    },
    /// The state lies at or beyond the locking (finite-extensibility) limit of the law.
    #[error(
        "stretch beyond the locking limit of the {law} law: I1 = {i1:.6} but the law requires I1 < {limit:.6}"
    )]
    Locking { law: String, i1: f64, limit: f64 },
    /// The energy or one of its derivatives is not finite at this state.
    #[error("the {law} energy is not finite at I1 = {i1}, I2 = {i2}")]
    NonFinite { law: String, i1: f64, i2: f64 },
}
