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
    shorten_lines(&out)
}

/// The longest line of a message a user reads, in characters: a parser that quotes the input
/// line (TOML's reader, serde's) would otherwise echo a 945 KB energy or a 10 MB CSV line.
pub const MAX_MESSAGE_LINE: usize = 1200;

/// Every line of `message` longer than [`MAX_MESSAGE_LINE`] characters cut to its first 800
/// and last 200, with the count of those left out between them. tubemem's own longest
/// messages (a limit point with its advice and residual history) are about 500 characters, so
/// only an echoed input is ever cut.
pub fn shorten_lines(message: &str) -> String {
    const HEAD: usize = 800;
    const TAIL: usize = 200;
    if message
        .lines()
        .all(|l| l.chars().count() <= MAX_MESSAGE_LINE)
    {
        return message.to_string();
    }
    let mut out: Vec<String> = vec![];
    for line in message.split('\n') {
        let n = line.chars().count();
        if n <= MAX_MESSAGE_LINE {
            out.push(line.to_string());
        } else {
            let head: String = line.chars().take(HEAD).collect();
            let tail: String = line.chars().skip(n - TAIL).collect();
            out.push(format!(
                "{head} … ({} characters left out) … {tail}",
                n - HEAD - TAIL
            ));
        }
    }
    out.join("\n")
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
    /// A law's energy, stress or tangent overflowed (boxed: the state it names would make
    /// every error that carries a material error larger).
    #[error("{0}")]
    NonFinite(Box<NonFiniteState>),
}

/// Where a law overflowed: [`MaterialError::NonFinite`].
#[derive(Debug, Clone, PartialEq, Error)]
#[error(
    "the {law} law's {what} is not finite at the stretches λ1 = {}, λ2 = {} (I1 = {}, I2 = {})",
    Num(stretches[0]), Num(stretches[1]), Num(*i1), Num(*i2)
)]
pub struct NonFiniteState {
    pub law: String,
    /// what overflowed: the energy or its derivatives, the stress, the tangent
    pub what: &'static str,
    pub stretches: [f64; 2],
    pub i1: f64,
    pub i2: f64,
}

impl MaterialError {
    /// [`MaterialError::NonFinite`]: `what` of `law` overflowed at the state of invariants
    /// `a` = tr C, `b` = det C (its stretches and I1, I2 are named).
    pub fn non_finite(law: String, what: &'static str, a: f64, b: f64) -> Self {
        let disc = (0.25 * a * a - b).max(0.0).sqrt();
        MaterialError::NonFinite(Box::new(NonFiniteState {
            law,
            what,
            stretches: [(0.5 * a + disc).sqrt(), (0.5 * a - disc).max(0.0).sqrt()],
            i1: a + 1.0 / b,
            i2: a / b + b,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_lines_of_a_message_are_cut_to_an_excerpt() {
        let line = format!("energy = \"{}\"", "I1 + ".repeat(200_000));
        let msg = format!("TOML parse error at line 1, column 5\n{line}\n   ^\nexpected a value");
        let s = tidy_numbers(&msg);
        assert!(s.len() < 1200, "{}", s.len());
        assert!(s.contains("characters left out") && s.ends_with("expected a value"));
        assert_eq!(tidy_numbers("short\nlines"), "short\nlines");
        let ours = "no equilibrium beyond the limit point; use volume control ".repeat(10);
        assert_eq!(shorten_lines(&ours), ours);
    }
}
