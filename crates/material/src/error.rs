use thiserror::Error;

/// A number as a message shows it: plain where that is short (1.3, 0.001), in scientific notation
/// where plain would be long or meaningless (1e308, 2.5e-9), and `NaN`/`inf` as such. Messages
/// show the user's value, never a 309-digit integer.
#[derive(Clone, Copy, Debug)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v != 0.0 && v.is_finite() && !(1e-4..1e15).contains(&v.abs()) {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}

/// Why a material law or a stretch state was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MaterialError {
    /// A material parameter is outside its admissible range.
    #[error("invalid material parameter `{name}` = {}: {requirement}", Num(*value))]
    InvalidParameter {
        name: &'static str,
        value: f64,
        requirement: &'static str,
    },
    /// A stretch (or a Cauchy–Green component) that no deformation can produce.
    #[error("invalid deformation: {what} = {} ({requirement})", Num(*value))]
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
