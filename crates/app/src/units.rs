//! The unit boundary. Every dimensional number a user writes (a case file, a CLI option, a
//! Python argument) is read in the case's unit system and converted to the dimensionless core
//! here, once; every dimensional number a user reads is converted back here, with its unit
//! named. The core works in the paper's reduced quantities: lengths per R, pressures ϖ =
//! pR/(μH), resultants N/(μH).
//!
//! Two systems:
//! - **dimensionless** (no `[units]` table): lengths in R, pressures in μH/R (ϖ), resultants in
//!   μH, forces per length in πμH (the paper's reduced force ϖχ, eq. 80), forces in μHR;
//! - **SI** (`[units] system = "SI"`): lengths in m, pressures and moduli in Pa, resultants and
//!   forces per length in N/m, forces in N, contact stiffness in Pa/m.
//!
//! A ratio (ρ = r/R, a stretch, a volume ratio, a relative tolerance) is the same number in
//! both systems, and an angle is in radians in both.

use serde::Serialize;
use tubemem_gps::Scales;

/// What kind of number a key or an output is: how it converts between a unit system and the
/// dimensionless core.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Dimension {
    /// a length: m, or R
    Length,
    /// a pressure: Pa, or μH/R (the reduced pressure ϖ)
    Pressure,
    /// a material modulus (the law's parameters in stress units): Pa, or μ
    Modulus,
    /// a membrane resultant (force per current length): N/m, or μH
    Resultant,
    /// a plate force per unit tube length: N/m, or πμH (the paper's reduced force, eq. 80)
    ForcePerLength,
    /// a force: N, or μHR
    Force,
    /// a contact stiffness (pressure per length of penetration): Pa/m, or μH/R²
    Stiffness,
    /// a ratio (ρ = r/R, a stretch, a volume ratio, a relative tolerance): the same number in
    /// every system
    Ratio,
    /// an angle, in radians in every system
    Angle,
}

impl Dimension {
    /// The unit in each system: (SI, dimensionless).
    pub fn units(self) -> (&'static str, &'static str) {
        match self {
            Dimension::Length => ("m", "R"),
            Dimension::Pressure => ("Pa", "μH/R"),
            Dimension::Modulus => ("Pa", "μ"),
            Dimension::Resultant => ("N/m", "μH"),
            Dimension::ForcePerLength => ("N/m", "πμH"),
            Dimension::Force => ("N", "μHR"),
            Dimension::Stiffness => ("Pa/m", "μH/R²"),
            Dimension::Ratio => ("1", "1"),
            Dimension::Angle => ("rad", "rad"),
        }
    }

    /// The sentence the case reference and the schema give a key of this dimension.
    pub fn describe(self) -> String {
        let (si, core) = self.units();
        match self {
            Dimension::Ratio => "a ratio: the same number in every unit system".into(),
            Dimension::Angle => "radians".into(),
            Dimension::Modulus => format!(
                "{si} under [units] system = \"SI\"; in a dimensionless case any one unit (only the moduli's ratios enter the results)"
            ),
            _ => format!("{si} under [units] system = \"SI\", {core} otherwise"),
        }
    }
}

/// A case's unit system: the scales R, H, μ under SI, none when dimensionless.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Units {
    scales: Option<Scales>,
}

impl Units {
    /// The dimensionless system (no `[units]`).
    pub fn dimensionless() -> Self {
        Self { scales: None }
    }

    /// SI with the case's R (m), H (m) and μ (Pa).
    pub fn si(scales: Scales) -> Self {
        Self {
            scales: Some(scales),
        }
    }

    /// The SI scales (None: dimensionless).
    pub fn scales(&self) -> Option<&Scales> {
        self.scales.as_ref()
    }

    pub fn is_si(&self) -> bool {
        self.scales.is_some()
    }

    /// The system's name as the case file writes it (`"SI"`, or `"dimensionless"`).
    pub fn name(&self) -> &'static str {
        if self.is_si() {
            "SI"
        } else {
            "dimensionless"
        }
    }

    /// What one core unit of `d` is in this system (1 when dimensionless).
    pub fn factor(&self, d: Dimension) -> f64 {
        let Some(s) = &self.scales else {
            return 1.0;
        };
        let (r, h, mu) = (s.radius, s.thickness, s.shear_modulus);
        match d {
            Dimension::Length => r,
            Dimension::Pressure => mu * h / r,
            Dimension::Modulus => mu,
            Dimension::Resultant => mu * h,
            Dimension::ForcePerLength => std::f64::consts::PI * mu * h,
            Dimension::Force => mu * h * r,
            Dimension::Stiffness => mu * h / (r * r),
            Dimension::Ratio | Dimension::Angle => 1.0,
        }
    }

    /// A user's value of `d` (in this system) in the dimensionless core.
    pub fn to_core(&self, d: Dimension, v: f64) -> f64 {
        v / self.factor(d)
    }

    /// A core value of `d` in this system.
    pub fn from_core(&self, d: Dimension, v: f64) -> f64 {
        v * self.factor(d)
    }

    /// The unit of `d` in this system.
    pub fn unit(&self, d: Dimension) -> &'static str {
        let (si, core) = d.units();
        if self.is_si() {
            si
        } else {
            core
        }
    }

    /// `v` (a core value of `d`) in this system with its unit, as `12.3 Pa`; in SI the core
    /// value follows in parentheses where it differs (`4600 Pa (ϖ = 0.744)`).
    pub fn show(&self, d: Dimension, v: f64) -> String {
        let user = self.from_core(d, v);
        let unit = self.unit(d);
        let num = format!("{}", tubemem_material::Num(round_sig(user)));
        match (self.is_si(), d) {
            (_, Dimension::Ratio) => num,
            (true, Dimension::Pressure) => {
                format!("{num} {unit} (ϖ = {})", tubemem_material::Num(round_sig(v)))
            }
            (true, Dimension::Length) => {
                format!("{num} {unit} ({} R)", tubemem_material::Num(round_sig(v)))
            }
            _ => format!("{num} {unit}"),
        }
    }

    /// A user's value `v` of `d` as written, with its unit (`4600 Pa`).
    pub fn written(&self, d: Dimension, v: f64) -> String {
        match d {
            Dimension::Ratio => format!("{}", tubemem_material::Num(v)),
            _ => format!("{} {}", tubemem_material::Num(v), self.unit(d)),
        }
    }
}

/// `v` to 7 significant digits (what a message shows; files keep every digit).
pub fn round_sig(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    // through the decimal text: exact at every magnitude (1e308 stays 1e308)
    format!("{v:.6e}").parse().unwrap_or(v)
}

/// Every key of a case file that carries a dimension, by its path (`stage.` stands for each
/// `[[stage]]`): what the schema and the case reference say of its unit, and what the case
/// converts at the boundary. A key not listed is a count, a name or a switch.
pub const CASE_KEYS: &[(&str, Dimension)] = &[
    ("geometry.radius", Dimension::Length),
    ("geometry.length", Dimension::Length),
    ("geometry.thickness", Dimension::Length),
    ("material.shear_modulus", Dimension::Modulus),
    ("material.c10", Dimension::Modulus),
    ("material.c20", Dimension::Modulus),
    ("material.c30", Dimension::Modulus),
    ("material.c2", Dimension::Modulus),
    ("material.mu", Dimension::Modulus),
    ("material.young_modulus", Dimension::Modulus),
    ("material.poisson_ratio", Dimension::Ratio),
    ("material.kuhn", Dimension::Ratio),
    ("material.alpha", Dimension::Ratio),
    ("material.jm", Dimension::Ratio),
    ("mesh.contact_edge_angle", Dimension::Angle),
    ("solver.rtol", Dimension::Ratio),
    ("stage.target_pressure", Dimension::Pressure),
    ("stage.target_stretch", Dimension::Ratio),
    ("stage.target_volume_ratio", Dimension::Ratio),
    ("stage.target_rho", Dimension::Ratio),
    ("stage.target_gap", Dimension::Length),
    ("stage.penalty", Dimension::Stiffness),
    ("stage.penetration_tolerance", Dimension::Length),
    ("stage.gap_tolerance", Dimension::Length),
    ("stage.plane.offset", Dimension::Length),
    ("stage.plane.target", Dimension::Length),
];

/// The dimension of a case key (`stage.target_pressure`), if it has one.
pub fn case_key(path: &str) -> Option<Dimension> {
    CASE_KEYS.iter().find(|(k, _)| *k == path).map(|(_, d)| *d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn si() -> Units {
        Units::si(Scales::new(0.011, 0.002, 34_000.0).unwrap())
    }

    #[test]
    fn every_dimension_round_trips_and_the_pressure_is_the_papers_eq_67() {
        let u = si();
        // eq. (67): p = ϖ μH/R
        let w = 0.744_117_647_058_823_4;
        assert!((u.from_core(Dimension::Pressure, w) - 4600.0).abs() < 1e-9);
        for d in [
            Dimension::Length,
            Dimension::Pressure,
            Dimension::Modulus,
            Dimension::Resultant,
            Dimension::ForcePerLength,
            Dimension::Force,
            Dimension::Stiffness,
            Dimension::Ratio,
            Dimension::Angle,
        ] {
            let v = 0.37;
            let back = u.to_core(d, u.from_core(d, v));
            assert!((back - v).abs() <= 1e-15, "{d:?}: {back}");
            assert_eq!(Units::dimensionless().to_core(d, v), v);
        }
        // a force is a resultant times a length; a force per length is π resultants (eq. 80)
        let f = u.factor(Dimension::Force);
        assert!((f - u.factor(Dimension::Resultant) * u.factor(Dimension::Length)).abs() < 1e-12);
        let fl = u.factor(Dimension::ForcePerLength);
        assert!((fl - std::f64::consts::PI * u.factor(Dimension::Resultant)).abs() < 1e-12);
    }

    #[test]
    fn a_shown_value_names_its_unit_and_its_core_value() {
        let u = si();
        let s = u.show(Dimension::Pressure, 0.744_117_647_058_823_4);
        assert_eq!(s, "4600 Pa (ϖ = 0.7441176)");
        assert_eq!(Units::dimensionless().show(Dimension::Length, 2.5), "2.5 R");
        assert_eq!(u.show(Dimension::Ratio, 0.8), "0.8");
    }
}
