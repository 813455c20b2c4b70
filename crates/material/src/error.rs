use thiserror::Error;

/// A number as a message shows it: plain where that is short (1.3, 0.001), in scientific notation
/// where plain would be long or meaningless (1e308, 2.5e-9), and `NaN`/`inf` as such. Messages
/// show the user's value, never a 309-digit integer.
#[derive(Clone, Copy, Debug)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    /// A precision (`{:.6}`) is kept: digits after the point when plain, of the mantissa when
    /// scientific.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        let scientific = v != 0.0 && v.is_finite() && !(1e-4..1e15).contains(&v.abs());
        match (scientific, f.precision()) {
            (true, Some(p)) => write!(f, "{v:.p$e}"),
            (true, None) => write!(f, "{v:e}"),
            (false, Some(p)) => write!(f, "{v:.p$}"),
            (false, None) => write!(f, "{v}"),
        }
    }
}

/// The messages of other crates (serde's "invalid type: floating point `1000…0`") with every
/// number of more than 17 digits written as [`Num`] writes it: the one rule for a number a
/// user reads, applied where a message is not ours to format.
pub fn tidy_numbers(message: &str) -> String {
    let b = message.as_bytes();
    let mut out = String::with_capacity(message.len());
    let mut i = 0;
    while i < b.len() {
        // a number: optional sign, digits, optional fraction, optional exponent
        let start = i;
        let mut j = i;
        if matches!(b[j], b'-' | b'+') && j + 1 < b.len() && b[j + 1].is_ascii_digit() {
            j += 1;
        }
        if j < b.len()
            && b[j].is_ascii_digit()
            && (start == 0 || !(b[start - 1].is_ascii_alphanumeric() || b[start - 1] == b'.'))
        {
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            if j + 1 < b.len() && b[j] == b'.' && b[j + 1].is_ascii_digit() {
                j += 1;
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
            }
            let digits = b[start..j].iter().filter(|c| c.is_ascii_digit()).count();
            if digits > 17 {
                if let Ok(v) = message[start..j].parse::<f64>() {
                    out.push_str(&Num(v).to_string());
                    i = j;
                    continue;
                }
            }
            out.push_str(&message[start..j]);
            i = j;
            continue;
        }
        let c = message[i..].chars().next().unwrap_or(' ');
        out.push(c);
        i += c.len_utf8();
    }
    out
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
    /// The state lies beyond the stretch at which the law loses stability (its membrane
    /// tangent stops being positive definite: a fitted law with a negative coefficient).
    #[error(
        "the {law} law is stable only for I1 < {limit:.6} (equibiaxial stretch {stretch:.5}; its membrane tangent loses positive definiteness there): I1 = {i1:.6} is beyond it"
    )]
    Unstable {
        law: String,
        i1: f64,
        limit: f64,
        stretch: f64,
    },
    /// A parameter (of a law with named or indexed parameters) outside its admissible range.
    /// (The text fields of this and the next two variants are boxed `str`s, so that the error
    /// stays as small as the paper's laws' errors.)
    #[error("invalid material parameter `{name}` = {}: {requirement}", Num(*value))]
    Parameter {
        name: Box<str>,
        value: f64,
        requirement: Box<str>,
    },
    /// An energy written as text that cannot be parsed.
    #[error("the energy `{energy}`, column {column}: {message}")]
    Expression {
        energy: Box<str>,
        column: usize,
        message: Box<str>,
    },
    /// A law that is not admissible as a whole (an energy that is not finite or not convex at
    /// the reference state, parameters that contradict each other).
    #[error("the {law} law is not admissible: {reason}")]
    Inadmissible { law: Box<str>, reason: Box<str> },
    /// The energy or one of its derivatives is not finite at this state.
    #[error("the {law} energy is not finite at I1 = {i1}, I2 = {i2}")]
    NonFinite { law: String, i1: f64, i2: f64 },
}
