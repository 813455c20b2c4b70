//! The `--material` family of flags, shared by every subcommand that needs a law.
use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use tubemem_material::{MaterialSpec, MembraneLaw};

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Model {
    /// Anssari-Benam–Bucchi generalized neo-Hookean (needs --kuhn)
    Abb,
    /// Mooney–Rivlin, paper eq. (83) (needs --alpha)
    MooneyRivlin,
    /// neo-Hookean
    NeoHookean,
}

#[derive(Args, Debug, Clone)]
pub struct MaterialArgs {
    /// Membrane law.
    #[arg(long, value_enum)]
    pub material: Model,
    /// Kuhn segment number 𝒩 (> 1) of the abb law.
    #[arg(long)]
    pub kuhn: Option<f64>,
    /// Hardening parameter α (≥ 0) of the mooney-rivlin law.
    #[arg(long)]
    pub alpha: Option<f64>,
    /// Shear modulus μ (only scales dimensional output; results here are per μH).
    #[arg(long, default_value_t = 1.0)]
    pub shear_modulus: f64,
}

impl MaterialArgs {
    pub fn spec(&self) -> Result<MaterialSpec> {
        let mu = self.shear_modulus;
        Ok(match (self.material, self.kuhn, self.alpha) {
            (Model::Abb, Some(kuhn), None) => MaterialSpec::Abb {
                shear_modulus: mu,
                kuhn,
            },
            (Model::Abb, None, _) => {
                bail!("--material abb needs --kuhn (the Kuhn segment number 𝒩 > 1)")
            }
            (Model::MooneyRivlin, None, Some(alpha)) => MaterialSpec::MooneyRivlin {
                shear_modulus: mu,
                alpha,
            },
            (Model::MooneyRivlin, _, None) => {
                bail!("--material mooney-rivlin needs --alpha (the hardening parameter α ≥ 0)")
            }
            (Model::NeoHookean, None, None) => MaterialSpec::NeoHookean { shear_modulus: mu },
            (m, _, _) => bail!(
                "--material {} does not take {}",
                m.to_possible_value()
                    .map(|v| v.get_name().to_string())
                    .unwrap_or_default(),
                if self.kuhn.is_some() && m != Model::Abb {
                    "--kuhn"
                } else {
                    "--alpha"
                }
            ),
        })
    }

    pub fn build(&self) -> Result<Box<dyn MembraneLaw>> {
        Ok(self.spec()?.build()?)
    }
}
