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
    /// Membrane law (or give any law with --law).
    #[arg(long, value_enum)]
    pub material: Option<Model>,
    /// Any law, as the keys of a case file's material table, e.g.
    /// 'model = "yeoh", c10 = 0.5, c20 = -0.01, c30 = 0.001', or a TOML file holding a
    /// material table (a case file) or its keys.
    #[arg(long, conflicts_with_all = ["material", "kuhn", "alpha"])]
    pub law: Option<String>,
    /// Kuhn segment number 𝒩 (> 1) of the abb law.
    #[arg(long)]
    pub kuhn: Option<f64>,
    /// Hardening parameter α (≥ 0) of the mooney-rivlin law.
    #[arg(long)]
    pub alpha: Option<f64>,
    /// Shear modulus μ: in Pa with --radius and --thickness (the SI values are then printed
    /// beside the dimensionless ones), else a scale no dimensionless result depends on.
    #[arg(long, default_value_t = 1.0)]
    pub shear_modulus: f64,
}

/// The tube's size for SI outputs: with both, the law's moduli are read in Pa, the results are
/// printed in SI beside the dimensionless ones, and a pressure given is read in Pa.
#[derive(Args, Debug, Clone, Default)]
pub struct UnitArgs {
    /// The tube's radius R in m (with --thickness: SI outputs, pressures in Pa).
    #[arg(long, requires = "thickness")]
    pub radius: Option<f64>,
    /// The membrane's undeformed thickness H in m (with --radius).
    #[arg(long, requires = "radius")]
    pub thickness: Option<f64>,
}

impl UnitArgs {
    /// The unit system: SI with R, H and the law's μ (Pa), or dimensionless.
    pub fn units(&self, law: &dyn MembraneLaw) -> Result<tubemem_app::units::Units> {
        use tubemem_app::units::Units;
        match (self.radius, self.thickness) {
            (Some(r), Some(h)) => Ok(Units::si(
                tubemem_gps::Scales::new(r, h, law.shear_modulus()).map_err(|e| {
                    anyhow::anyhow!(
                        "--radius {r} --thickness {h}: {}",
                        tubemem_app::error_chain(&e)
                    )
                })?,
            )),
            _ => Ok(Units::dimensionless()),
        }
    }
}

/// The SI twins of a closed-form state's dimensional keys (`w` → `pressure_pa`, `n_s` →
/// `n_s_n_per_m`, `force` → `force_n_per_m`, `rho` → `half_gap_m`), added to its JSON object
/// under SI; nothing when dimensionless.
pub fn add_si(v: &mut serde_json::Value, units: &tubemem_app::units::Units) {
    use tubemem_app::units::Dimension;
    let Some(map) = v.as_object_mut() else {
        return;
    };
    if !units.is_si() {
        return;
    }
    for (key, name, d) in [
        ("w", "pressure_pa", Dimension::Pressure),
        ("n_s", "n_s_n_per_m", Dimension::Resultant),
        ("n_z", "n_z_n_per_m", Dimension::Resultant),
        ("force", "force_n_per_m", Dimension::ForcePerLength),
        ("rho", "half_gap_m", Dimension::Length),
        ("r", "half_height_m", Dimension::Length),
    ] {
        if let Some(x) = map.get(key).and_then(|x| x.as_f64()) {
            map.insert(name.into(), units.from_core(d, x).into());
        }
    }
}

/// The spec of `--material` with its parameters, or why the flags do not make one.
pub fn spec_of(
    material: Model,
    kuhn: Option<f64>,
    alpha: Option<f64>,
    mu: f64,
) -> Result<MaterialSpec> {
    Ok(match (material, kuhn, alpha) {
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
            if kuhn.is_some() && m != Model::Abb {
                "--kuhn"
            } else {
                "--alpha"
            }
        ),
    })
}

/// The law of `--law`: a TOML file with a material table or its keys, or those keys inline.
pub fn law_of(text: &str) -> Result<MaterialSpec> {
    let path = std::path::Path::new(text);
    let table: toml::Table = if !text.contains('=') && path.is_file() {
        let file =
            tubemem_mesh::io::read_text_limited(path, tubemem_app::case::MAX_CASE_FILE_BYTES)
                .map_err(|e| anyhow::anyhow!("--law {}: {e}", path.display()))?;
        let mut t: toml::Table =
            toml::from_str(&file).map_err(|e| anyhow::anyhow!("--law {}: {e}", path.display()))?;
        match t.remove("material") {
            Some(toml::Value::Table(m)) => m,
            _ => t,
        }
    } else {
        let wrapped: toml::Table = toml::from_str(&format!("m = {{ {text} }}"))
            .map_err(|e| anyhow::anyhow!("--law: not the keys of a [material] table ({e})"))?;
        match wrapped.get("m") {
            Some(toml::Value::Table(m)) => m.clone(),
            _ => bail!("--law: not the keys of a [material] table"),
        }
    };
    let spec: MaterialSpec = toml::Value::Table(table).try_into().map_err(|e| {
        anyhow::anyhow!("--law: {}", tubemem_material::tidy_numbers(&e.to_string()))
    })?;
    Ok(spec)
}

impl MaterialArgs {
    pub fn spec(&self) -> Result<MaterialSpec> {
        match (&self.law, self.material) {
            (Some(law), _) => law_of(law),
            (None, Some(m)) => spec_of(m, self.kuhn, self.alpha, self.shear_modulus),
            (None, None) => bail!(
                "give the membrane law: --material abb|mooney-rivlin|neo-hookean with its parameters, or --law with a [material] table's keys"
            ),
        }
    }

    pub fn build(&self) -> Result<Box<dyn MembraneLaw>> {
        Ok(self.spec()?.build()?)
    }
}

/// The law of `tubemem figures`: optional, since an overlaid run says its own.
#[derive(Args, Debug, Clone)]
pub struct OptionalMaterialArgs {
    /// Membrane law of the curves (default: the overlaid runs' law, else the paper's abb 𝒩 = 30).
    #[arg(long, value_enum)]
    pub material: Option<Model>,
    /// Kuhn segment number 𝒩 (> 1) of the abb law (alone, it means --material abb).
    #[arg(long)]
    pub kuhn: Option<f64>,
    /// Hardening parameter α (≥ 0) of the mooney-rivlin law.
    #[arg(long)]
    pub alpha: Option<f64>,
}

impl OptionalMaterialArgs {
    pub fn spec(&self) -> Result<Option<MaterialSpec>> {
        match (self.material, self.kuhn, self.alpha) {
            (None, None, None) => Ok(None),
            (None, Some(_), _) => spec_of(Model::Abb, self.kuhn, self.alpha, 1.0).map(Some),
            (None, None, Some(_)) => {
                bail!("--alpha needs --material mooney-rivlin")
            }
            (Some(m), k, a) => spec_of(m, k, a, 1.0).map(Some),
        }
    }
}

/// `--hypothesis` of the `gps` commands.
#[derive(Copy, Clone, Debug, ValueEnum)]
pub enum Hyp {
    /// generalized plane strain (λz from the end-cap balance)
    Gps,
    /// plane strain (λz = 1)
    Ps,
}

impl From<Hyp> for tubemem_gps::Hypothesis {
    fn from(h: Hyp) -> Self {
        match h {
            Hyp::Gps => tubemem_gps::Hypothesis::Gps,
            Hyp::Ps => tubemem_gps::Hypothesis::Ps,
        }
    }
}
