//! [`MaterialSpec`]: the typed material description case files, the CLI and Python name, and
//! the law it builds.

use crate::{laws, relaxed, MaterialError, MembraneLaw};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A typed material description (what case files and the CLI name); [`MaterialSpec::build`]
/// validates it into a law.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "model", rename_all = "kebab-case", deny_unknown_fields)]
pub enum MaterialSpec {
    /// Anssari-Benam & Bucchi generalized neo-Hookean (paper eqs. 19–23).
    Abb { shear_modulus: f64, kuhn: f64 },
    /// Mooney–Rivlin (paper eq. 83).
    MooneyRivlin { shear_modulus: f64, alpha: f64 },
    /// Neo-Hookean (α = 0).
    NeoHookean { shear_modulus: f64 },
    /// Yeoh, three terms, coefficients in stress units (μ = 2 C10); C20 and C30 default to 0.
    Yeoh {
        c10: f64,
        #[serde(default)]
        c20: f64,
        #[serde(default)]
        c30: f64,
    },
    /// Gent: μ and the locking parameter Jm.
    Gent { shear_modulus: f64, jm: f64 },
    /// Gent–Gent (Pucci & Saccomandi): μ, Jm and the I2 modulus C2 (stress units).
    GentGent {
        shear_modulus: f64,
        jm: f64,
        c2: f64,
    },
    /// Arruda–Boyce eight-chain: μ and N, the Kuhn segments per chain (locking stretch √N).
    ArrudaBoyce { shear_modulus: f64, kuhn: f64 },
    /// Ogden, N terms: lists `mu` (stress units) and `alpha`.
    Ogden { mu: Vec<f64>, alpha: Vec<f64> },
    /// Saint-Venant–Kirchhoff in plane stress (compressible): Young's modulus and Poisson's
    /// ratio.
    #[serde(rename = "saint-venant-kirchhoff", alias = "svk")]
    Svk {
        young_modulus: f64,
        poisson_ratio: f64,
    },
    /// An energy W/(μH) of I1 and I2, written as text, with its named parameters.
    Invariants {
        energy: String,
        #[serde(default)]
        parameters: BTreeMap<String, f64>,
        shear_modulus: f64,
    },
    /// A principal-stretch energy W/(μH) = w(λ1) + w(λ2) + w(λ3), w written as text in the
    /// stretch `l`, with its named parameters.
    Principal {
        energy: String,
        #[serde(default)]
        parameters: BTreeMap<String, f64>,
        shear_modulus: f64,
    },
}

/// Whether compressive states are relaxed (tension-field theory) or kept as computed.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Wrinkling {
    /// Pipkin's relaxed energy: no compressive resultant (the default for finite elements).
    #[default]
    Relaxed,
    /// The law as it is (compressive resultants allowed).
    None,
}

impl MaterialSpec {
    /// Each `model` a case file names, with the parameters it requires.
    pub const MODELS: [(&'static str, &'static [&'static str]); 11] = [
        ("abb", &["shear_modulus", "kuhn"]),
        ("mooney-rivlin", &["shear_modulus", "alpha"]),
        ("neo-hookean", &["shear_modulus"]),
        ("yeoh", &["c10"]),
        ("gent", &["shear_modulus", "jm"]),
        ("gent-gent", &["shear_modulus", "jm", "c2"]),
        ("arruda-boyce", &["shear_modulus", "kuhn"]),
        ("ogden", &["mu", "alpha"]),
        (
            "saint-venant-kirchhoff",
            &["young_modulus", "poisson_ratio"],
        ),
        ("invariants", &["energy", "shear_modulus"]),
        ("principal", &["energy", "shear_modulus"]),
    ];

    /// The paper's law: Anssari-Benam–Bucchi with μ = 1 and 𝒩 = 30.
    pub const PAPER: MaterialSpec = MaterialSpec::Abb {
        shear_modulus: 1.0,
        kuhn: 30.0,
    };

    /// The model's name as a case file writes it.
    pub fn model(&self) -> &'static str {
        match self {
            MaterialSpec::Abb { .. } => "abb",
            MaterialSpec::MooneyRivlin { .. } => "mooney-rivlin",
            MaterialSpec::NeoHookean { .. } => "neo-hookean",
            MaterialSpec::Yeoh { .. } => "yeoh",
            MaterialSpec::Gent { .. } => "gent",
            MaterialSpec::GentGent { .. } => "gent-gent",
            MaterialSpec::ArrudaBoyce { .. } => "arruda-boyce",
            MaterialSpec::Ogden { .. } => "ogden",
            MaterialSpec::Svk { .. } => "saint-venant-kirchhoff",
            MaterialSpec::Invariants { .. } => "invariants",
            MaterialSpec::Principal { .. } => "principal",
        }
    }

    /// The modulus μ the dimensionless results are per (ϖ = pR/(μH), N/(μH)): the law's
    /// `shear_modulus`, or the one its parameters define (2 C10, ½ Σ μp αp, E/(2(1 + ν))).
    pub fn shear_modulus(&self) -> f64 {
        match self {
            MaterialSpec::Abb { shear_modulus, .. }
            | MaterialSpec::MooneyRivlin { shear_modulus, .. }
            | MaterialSpec::NeoHookean { shear_modulus }
            | MaterialSpec::Gent { shear_modulus, .. }
            | MaterialSpec::GentGent { shear_modulus, .. }
            | MaterialSpec::ArrudaBoyce { shear_modulus, .. }
            | MaterialSpec::Invariants { shear_modulus, .. }
            | MaterialSpec::Principal { shear_modulus, .. } => *shear_modulus,
            MaterialSpec::Yeoh { c10, .. } => 2.0 * c10,
            MaterialSpec::Ogden { mu, alpha } => {
                0.5 * mu.iter().zip(alpha).map(|(m, a)| m * a).sum::<f64>()
            }
            MaterialSpec::Svk {
                young_modulus,
                poisson_ratio,
            } => young_modulus / (2.0 * (1.0 + poisson_ratio)),
        }
    }

    /// Whether the law is incompressible (every law but Saint-Venant–Kirchhoff).
    pub fn incompressible(&self) -> bool {
        !matches!(self, MaterialSpec::Svk { .. })
    }

    /// The law with the chosen wrinkling model.
    pub fn build_with(&self, wrinkling: Wrinkling) -> Result<Box<dyn MembraneLaw>, MaterialError> {
        Ok(match (wrinkling, self) {
            (Wrinkling::None, _) => self.build()?,
            // the paper's laws keep their own monomorphized relaxation
            (
                Wrinkling::Relaxed,
                &MaterialSpec::Abb {
                    shear_modulus,
                    kuhn,
                },
            ) => Box::new(relaxed::Relaxed::new(laws::AnssariBenamBucchi::new(
                shear_modulus,
                kuhn,
            )?)),
            (
                Wrinkling::Relaxed,
                &MaterialSpec::MooneyRivlin {
                    shear_modulus,
                    alpha,
                },
            ) => Box::new(relaxed::Relaxed::new(laws::MooneyRivlin::new(
                shear_modulus,
                alpha,
            )?)),
            (Wrinkling::Relaxed, &MaterialSpec::NeoHookean { shear_modulus }) => {
                Box::new(relaxed::Relaxed::new(laws::neo_hookean(shear_modulus)?))
            }
            (Wrinkling::Relaxed, _) => Box::new(relaxed::Relaxed::new(self.build()?)),
        })
    }

    /// Validate the parameters and build the law.
    pub fn build(&self) -> Result<Box<dyn MembraneLaw>, MaterialError> {
        Ok(match self {
            &MaterialSpec::Abb {
                shear_modulus,
                kuhn,
            } => Box::new(laws::AnssariBenamBucchi::new(shear_modulus, kuhn)?),
            &MaterialSpec::MooneyRivlin {
                shear_modulus,
                alpha,
            } => Box::new(laws::MooneyRivlin::new(shear_modulus, alpha)?),
            &MaterialSpec::NeoHookean { shear_modulus } => {
                Box::new(laws::neo_hookean(shear_modulus)?)
            }
            &MaterialSpec::Yeoh { c10, c20, c30 } => Box::new(laws::Yeoh::new(c10, c20, c30)?),
            &MaterialSpec::Gent { shear_modulus, jm } => {
                Box::new(laws::Gent::new(shear_modulus, jm)?)
            }
            &MaterialSpec::GentGent {
                shear_modulus,
                jm,
                c2,
            } => Box::new(laws::GentGent::new(shear_modulus, jm, c2)?),
            &MaterialSpec::ArrudaBoyce {
                shear_modulus,
                kuhn,
            } => Box::new(laws::ArrudaBoyce::new(shear_modulus, kuhn)?),
            MaterialSpec::Ogden { mu, alpha } => Box::new(laws::Ogden::new(mu, alpha)?),
            &MaterialSpec::Svk {
                young_modulus,
                poisson_ratio,
            } => Box::new(laws::SaintVenantKirchhoff::new(
                young_modulus,
                poisson_ratio,
            )?),
            MaterialSpec::Invariants {
                energy,
                parameters,
                shear_modulus,
            } => Box::new(laws::expression::InvariantLaw::new(
                energy,
                parameters,
                *shear_modulus,
            )?),
            MaterialSpec::Principal {
                energy,
                parameters,
                shear_modulus,
            } => Box::new(laws::expression::PrincipalLaw::new(
                energy,
                parameters,
                *shear_modulus,
            )?),
        })
    }
}
