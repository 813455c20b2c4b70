//! The manufactured deformations: smooth maps of space x*(X), written once for any [`Real`]
//! scalar (plain numbers, dual numbers).

use tubemem_material::dual::Real;

/// A smooth map x*(X) of space.
pub trait Field: Send + Sync {
    fn name(&self) -> String;
    fn map<T: Real>(&self, p: [T; 3]) -> [T; 3];
}

/// The tube's manufactured field: an inflation (hoop stretch `hoop`, axial `axial`), an
/// ovalization (`oval`·cos 2θ in the radius), a shear (a rotation about the axis by
/// `shear`·sin 2θ·cos(πz/Λ): the hoop displacement varies along the tube), a warping
/// (`warp`·cos 2θ in the axial stretch) and an axial wave (`wave`·cos(2πz/Λ) in the radius):
///
/// ```text
/// s = hoop + oval (x² − y²)/R² + wave cos(2πz/Λ),   ψ = shear (2xy/R²) cos(πz/Λ)
/// x* = Rot_z(ψ) (s x, s y),   z* = z (axial + warp (x² − y²)/R²)
/// ```
/// A polynomial-trigonometric map of space, so smooth on the caps too; it commutes with the
/// reflections in x = 0, y = 0 and z = 0, so it keeps the eighth model's symmetry planes.
/// (x² − y²)/R² and 2xy/R² are cos 2θ and sin 2θ on the cylinder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TubeField {
    pub radius: f64,
    pub hoop: f64,
    pub axial: f64,
    pub oval: f64,
    pub shear: f64,
    pub warp: f64,
    pub wave: f64,
    /// Λ, the wavelength of the axial wave (twice that of the shear)
    pub wavelength: f64,
}

impl TubeField {
    /// The standard field: inflated (λs = 1.3, λz = 1.15), ovalized 5 %, sheared 0.05 rad,
    /// warped 2 %, waved 3 %, on a tube of radius `radius` whose wavelength Λ is `wavelength`.
    pub fn standard(radius: f64, wavelength: f64) -> Self {
        TubeField {
            radius,
            hoop: 1.3,
            axial: 1.15,
            oval: 0.05,
            shear: 0.05,
            warp: 0.02,
            wave: 0.03,
            wavelength,
        }
    }
}

impl Field for TubeField {
    fn name(&self) -> String {
        format!(
            "inflation (λs = {}, λz = {}) with ovalization {}, shear {}, warping {} and an axial wave {} (Λ = {})",
            self.hoop, self.axial, self.oval, self.shear, self.warp, self.wave, self.wavelength
        )
    }
    fn map<T: Real>(&self, p: [T; 3]) -> [T; 3] {
        let [x, y, z] = p;
        let r2 = self.radius * self.radius;
        let k = std::f64::consts::PI / self.wavelength;
        let c2 = (x * x - y * y) / r2;
        let s2 = x * y * 2.0 / r2;
        let s = c2 * self.oval + (z * (2.0 * k)).cos() * self.wave + self.hoop;
        let psi = s2 * (z * k).cos() * self.shear;
        let (u, v) = (x * s, y * s);
        let (sn, cs) = (psi.sin(), psi.cos());
        [
            u * cs - v * sn,
            u * sn + v * cs,
            z * (c2 * self.warp + self.axial),
        ]
    }
}

/// A uniform stretch of the cylinder, x* = (λs x, λs y, λz z): the GPS inflation, for which
/// the body force on the cylinder vanishes at the GPS pressure (a test of [`super::body`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniform {
    pub hoop: f64,
    pub axial: f64,
}

impl Field for Uniform {
    fn name(&self) -> String {
        format!("uniform stretch (λs = {}, λz = {})", self.hoop, self.axial)
    }
    fn map<T: Real>(&self, p: [T; 3]) -> [T; 3] {
        [p[0] * self.hoop, p[1] * self.hoop, p[2] * self.axial]
    }
}
