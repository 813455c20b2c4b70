//! The manufactured deformations: smooth maps of space x*(X), written once for any [`Real`]
//! scalar (plain numbers, dual numbers).

use crate::contact::Plane;
use tubemem_material::dual::Real;

/// A smooth map x*(X) of space, and the rigid planes it lies on where it is pressed against
/// them (none by default).
pub trait Field: Send + Sync {
    fn name(&self) -> String;
    fn map<T: Real>(&self, p: [T; 3]) -> [T; 3];
    /// The rigid planes x* touches.
    fn planes(&self) -> Vec<Plane> {
        vec![]
    }
    /// The pressure each plane of [`Field::planes`] exerts at X (per reference area, along
    /// its normal): zero where x*(X) lies off it.
    fn contact_pressures(&self, _p: [f64; 3]) -> Vec<f64> {
        vec![]
    }
    /// The traction the planes supply at X (per reference area): Σ q_k n_k.
    fn contact_traction(&self, p: [f64; 3]) -> [f64; 3] {
        let mut t = [0.0; 3];
        for (q, plane) in self.contact_pressures(p).iter().zip(self.planes()) {
            for i in 0..3 {
                t[i] += q * plane.normal[i];
            }
        }
        t
    }
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

/// A field squeezed between the plates y = ±`height` (the paper's Sec. 4 squeeze; normals ∓e_y):
/// the inner field's points beyond a plate are brought onto it, and those inside keep a gap
/// that leaves the plate smoothly over a band of width δ:
///
/// ```text
/// y* = y + r(h − y) − r(h + y),   r(t) = t for t ≤ 0,  t (1 − β(t/δ)) for 0 < t < δ,  0 for t ≥ δ
/// ```
/// with β the C⁴ smoothstep 126u⁵ − 420u⁶ + 540u⁷ − 315u⁸ + 70u⁹ (0 at u = 0, 1 at u = 1, its
/// first four derivatives zero at both ends). The gap h − y* = t β(t/δ) is C⁵ where the
/// membrane leaves the plate and C⁴ where the band ends: x* is in H⁵, enough for the 9-node
/// element's order 3. For δ < h the two plates' bands do not meet, so y* is odd in y and the
/// eighth model's symmetry plane y = 0 holds (as do x = 0 and z = 0, from the inner field).
/// Where x* lies on a plate (y beyond ±h) the plate pushes with the manufactured pressure
/// q = `traction` ((|y| − h)/`depth`)³ per reference area along its normal, which vanishes at
/// the contact edge with two derivatives; the body force is made with it ([`super::body`]), so
/// x* is an equilibrium with the plates' contact force q. The FE must find the contact zone
/// and carry q through its contact algorithm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pressed<F: Field> {
    pub inner: F,
    /// h, the plates' half gap
    pub height: f64,
    /// δ, the width of the gap's band (< h)
    pub blend: f64,
    /// the depth of the inner field beyond a plate at which q = `traction`
    pub depth: f64,
    /// the manufactured contact pressure's scale (per μH/R)
    pub traction: f64,
}

impl Pressed<TubeField> {
    /// The standard field squeezed by the plates y = ±1.15 R: the inflated tube's crest (the
    /// inner field reaches about y = 1.28 R) is flattened over about ±25° around it, along the whole
    /// cylinder and onto the caps; δ = 0.8 R, q = ((|y| − h)/0.1 R)³ (up to ((1.28 − 1.15)/0.1)³
    /// ≈ 2.2 μH/R at the crest, where the standard pressure is 0.4). A wide band and a gentle
    /// squeeze: with δ = 0.2 R or h = 1.1 R the 9-node element's errors were still
    /// pre-asymptotic at 256 around (orders 3.4–4.4), and with h = 1.1 R, δ = R the squeezed
    /// state has hoop compression (N2 < 0) that the relaxed law wrinkles; this one stays taut
    /// (smallest N2 0.16 μH) and both elements reach their orders between 64 and 256 around
    /// (crates/fem/tests/manufactured.rs).
    pub fn standard(radius: f64, wavelength: f64) -> Self {
        Pressed {
            inner: TubeField::standard(radius, wavelength),
            height: 1.15 * radius,
            blend: 0.8 * radius,
            depth: 0.1 * radius,
            traction: 1.0,
        }
    }

    /// r(t) of the gap's band.
    fn excess<T: Real>(&self, t: T) -> T {
        let u = t.value() / self.blend;
        if u <= 0.0 {
            t
        } else if u >= 1.0 {
            t * 0.0
        } else {
            let u = t / self.blend;
            let beta = u.powi(5) * (((u * 70.0 - 315.0) * u + 540.0) * u * u - u * 420.0 + 126.0);
            t - t * beta
        }
    }
}

impl Field for Pressed<TubeField> {
    fn name(&self) -> String {
        format!(
            "{}, squeezed between the plates y = ±{} (band {}, contact pressure {} ((|y| − h)/{})³)",
            self.inner.name(),
            self.height,
            self.blend,
            self.traction,
            self.depth
        )
    }
    fn map<T: Real>(&self, p: [T; 3]) -> [T; 3] {
        let [x, y, z] = self.inner.map(p);
        let h = self.height;
        [x, y + self.excess(-y + h) - self.excess(y + h), z]
    }
    fn planes(&self) -> Vec<Plane> {
        crate::contact::Contact::plates(self.height, 0.0).planes
    }
    fn contact_pressures(&self, p: [f64; 3]) -> Vec<f64> {
        // the planes of Contact::plates: y = h (normal −e_y), then y = −h (normal +e_y)
        let y = self.inner.map(p)[1];
        let q = |over: f64| {
            if over > 0.0 {
                self.traction * (over / self.depth).powi(3)
            } else {
                0.0
            }
        };
        vec![q(y - self.height), q(-y - self.height)]
    }
}
