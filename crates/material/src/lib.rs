//! # tubemem-material — incompressible hyperelastic membrane laws
//!
//! One law object serves the closed form (`tubemem-gps`) and the finite elements. A law is an
//! isotropic, incompressible energy per unit reference volume μ W̄(I1, I2), reduced to the
//! membrane (λ3 = 1/(λ1 λ2), paper eq. 15). Every law is written in the two invariants of the
//! **2D** right Cauchy–Green tensor C (in the reference tangent plane):
//!
//! ```text
//! a = tr C  = λ1² + λ2²          b = det C = (λ1 λ2)²
//! I1 = a + 1/b                   I2 = a/b + b
//! ```
//!
//! and gives W(a, b) with its first and second partial derivatives ([`EnergyDerivatives`]).
//! Everything else is derived once, in this crate, from those six numbers:
//!
//! * principal-stretch derivatives ∂W/∂λα, ∂²W/∂λα∂λβ ([`MembraneLaw::principal`]);
//! * the Cauchy resultants of paper eq. (18), N_I/(μH) = (1/λ2) ∂W/∂λ1,
//!   N_II/(μH) = (1/λ1) ∂W/∂λ2 ([`MembraneLaw::resultants`]);
//! * for the finite elements, the second Piola–Kirchhoff resultant S = 2 ∂W/∂C and the tangent
//!   ℂ = 4 ∂²W/∂C∂C in an orthonormal frame of the reference tangent plane
//!   ([`MembraneLaw::stress_tangent`], Voigt order 11, 22, 12; both per unit μH).
//!
//! Built-in laws ([`laws`]): the generalized neo-Hookean law of Anssari-Benam & Bucchi (paper
//! eqs. 19–23), Mooney–Rivlin (Appendix B), neo-Hookean, Yeoh, Gent, Gent–Gent, Arruda–Boyce,
//! Ogden (principal stretches, through [`separable`]) and the compressible plane-stress
//! Saint-Venant–Kirchhoff law. A user's law needs only its energy: written as text in a case
//! file ([`laws::expression`], parsed by [`expr`]), or in Rust as an [`InvariantEnergy`] (one
//! generic function of I1, I2) wrapped in [`AutoDiff`]; the derivatives come from a
//! second-order dual number ([`dual::HyperDual2`]) or Taylor jets ([`taylor`]). The built-in
//! laws are also available that way, and tests hold the two routes against each other.
//! [`MaterialSpec`] is the typed description case files and the CLI name.
//!
//! ```
//! use tubemem_material::{laws::AnssariBenamBucchi, MembraneLaw};
//! let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
//! let [n1, n2] = law.resultants(1.3, 1.05).unwrap(); // N/(μH), eq. (22)
//! assert!(n1 > n2 && n2 > 0.0);
//! assert!(law.resultants(7.0, 7.0).is_err()); // I1 = 98 > 3𝒩 = 90: locking, a typed error
//! ```

pub mod dual;
mod error;
pub mod expr;
pub mod fit;
pub mod laws;
pub mod relaxed;
pub mod separable;
mod spec;
pub mod taylor;
pub mod viscoelastic;

pub use error::{
    shorten_lines, tidy_numbers, MaterialError, NonFiniteState, Num, MAX_MESSAGE_LINE,
};
pub use spec::{MaterialSpec, Wrinkling};

/// W(a, b) and its partial derivatives, a = tr C, b = det C (dimensionless, per μ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyDerivatives {
    pub w: f64,
    pub w_a: f64,
    pub w_b: f64,
    pub w_aa: f64,
    pub w_ab: f64,
    pub w_bb: f64,
}

/// W and its derivatives with respect to the principal stretches (λ1, λ2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipalDerivatives {
    pub w: f64,
    /// ∂W/∂λα
    pub grad: [f64; 2],
    /// ∂²W/∂λα∂λβ
    pub hess: [[f64; 2]; 2],
}

/// Energy, second Piola–Kirchhoff resultant and material tangent at a 2D right Cauchy–Green
/// tensor, all per unit μH, in an orthonormal frame of the reference tangent plane.
///
/// ```text
/// S  = 2 ∂W/∂C   = 2 (W_a I + W_b b C⁻¹)
/// ℂ  = 4 ∂²W/∂C∂C:
/// ℂ_ijkl = 4 [ W_aa δij δkl + b W_ab (δij C⁻¹kl + C⁻¹ij δkl)
///            + (b² W_bb + b W_b) C⁻¹ij C⁻¹kl − ½ b W_b (C⁻¹ik C⁻¹jl + C⁻¹il C⁻¹jk) ]
/// ```
/// Voigt order (11, 22, 12): `s = [S11, S22, S12]`, and `tangent` maps the Green–Lagrange
/// increment `[dE11, dE22, 2 dE12]` (dE = ½ dC) to `[dS11, dS22, dS12]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StressTangent {
    pub w: f64,
    pub s: [f64; 3],
    pub tangent: [[f64; 3]; 3],
}

fn check_stretch(what: &'static str, value: f64) -> Result<(), MaterialError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(MaterialError::InvalidState {
            what,
            value,
            requirement: "a stretch must be finite and > 0",
        })
    }
}

/// An isotropic incompressible membrane law. Implementors provide [`MembraneLaw::derivatives_ab`];
/// the rest is derived.
pub trait MembraneLaw: Send + Sync + std::fmt::Debug {
    /// A human-readable name with the parameters.
    fn name(&self) -> String;
    /// μ, the modulus that scales the dimensionless energy (μH scales the resultants).
    fn shear_modulus(&self) -> f64;
    /// The finite-extensibility limit of I1 = tr C + 1/det C, where the energy diverges
    /// (`None` for laws without one). Used to diagnose a solve that fails as it approaches it.
    fn locking_limit(&self) -> Option<f64> {
        None
    }
    /// The largest I1 = tr C + 1/det C below which the law is stable (its membrane tangent
    /// positive definite at every state), for laws that lose stability at large stretch (a
    /// Yeoh law with C30 < 0); `None` for laws stable at every stretch. Beyond it the law
    /// returns [`MaterialError::Unstable`].
    fn stable_limit(&self) -> Option<f64> {
        None
    }
    /// W(a, b) and its derivatives. Called with a > 0, b > 0 only; returns
    /// [`MaterialError::Locking`] beyond a finite-extensibility limit.
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError>;

    /// Checked version of [`MembraneLaw::derivatives_ab`]: rejects impossible invariants
    /// (a² < 4b means no real stretches) and non-finite results.
    fn derivatives(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        derivatives_checked(self, a, b)
    }

    /// The reduced energy W(λ1, λ2) (eq. 15).
    fn energy(&self, l1: f64, l2: f64) -> Result<f64, MaterialError> {
        Ok(self.principal(l1, l2)?.w)
    }

    /// W, ∂W/∂λα and ∂²W/∂λα∂λβ by the chain rule through a = λ1² + λ2², b = λ1²λ2².
    fn principal(&self, l1: f64, l2: f64) -> Result<PrincipalDerivatives, MaterialError> {
        check_stretch("λ1", l1)?;
        check_stretch("λ2", l2)?;
        let (a, b) = (l1 * l1 + l2 * l2, l1 * l1 * l2 * l2);
        let d = derivatives_checked(self, a, b)?;
        let da = [2.0 * l1, 2.0 * l2];
        let db = [2.0 * l1 * l2 * l2, 2.0 * l2 * l1 * l1];
        let dda = [[2.0, 0.0], [0.0, 2.0]];
        let ddb = [
            [2.0 * l2 * l2, 4.0 * l1 * l2],
            [4.0 * l1 * l2, 2.0 * l1 * l1],
        ];
        let mut hess = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                hess[i][j] = d.w_aa * da[i] * da[j]
                    + d.w_ab * (da[i] * db[j] + da[j] * db[i])
                    + d.w_bb * db[i] * db[j]
                    + d.w_a * dda[i][j]
                    + d.w_b * ddb[i][j];
            }
        }
        Ok(PrincipalDerivatives {
            w: d.w,
            grad: [d.w_a * da[0] + d.w_b * db[0], d.w_a * da[1] + d.w_b * db[1]],
            hess,
        })
    }

    /// Principal Cauchy resultants over μH, paper eq. (18):
    /// N1 = (1/λ2) ∂W/∂λ1, N2 = (1/λ1) ∂W/∂λ2.
    fn resultants(&self, l1: f64, l2: f64) -> Result<[f64; 2], MaterialError> {
        let p = self.principal(l1, l2)?;
        Ok([p.grad[0] / l2, p.grad[1] / l1])
    }

    /// S = 2∂W/∂C and ℂ = 4∂²W/∂C∂C at `c = [C11, C22, C12]` (orthonormal reference frame).
    fn stress_tangent(&self, c: [f64; 3]) -> Result<StressTangent, MaterialError> {
        let [c11, c22, c12] = c;
        let a = c11 + c22;
        let b = c11 * c22 - c12 * c12;
        if !(c11.is_finite() && c22.is_finite() && c12.is_finite())
            || c11 <= 0.0
            || c22 <= 0.0
            || b <= 0.0
        {
            return Err(MaterialError::InvalidState {
                what: "det C",
                value: b,
                requirement:
                    "C must be symmetric positive definite (an inverted or degenerate element?)",
            });
        }
        let d = derivatives_checked(self, a, b)?;
        // C⁻¹ as a full 2×2 matrix.
        let ci = [[c22 / b, -c12 / b], [-c12 / b, c11 / b]];
        let id = [[1.0, 0.0], [0.0, 1.0]];
        let s = |i: usize, j: usize| 2.0 * (d.w_a * id[i][j] + d.w_b * b * ci[i][j]);
        let k1 = b * b * d.w_bb + b * d.w_b;
        let cc = |i: usize, j: usize, k: usize, l: usize| {
            4.0 * (d.w_aa * id[i][j] * id[k][l]
                + b * d.w_ab * (id[i][j] * ci[k][l] + ci[i][j] * id[k][l])
                + k1 * ci[i][j] * ci[k][l]
                - 0.5 * b * d.w_b * (ci[i][k] * ci[j][l] + ci[i][l] * ci[j][k]))
        };
        const V: [(usize, usize); 3] = [(0, 0), (1, 1), (0, 1)];
        let mut tangent = [[0.0; 3]; 3];
        for (p, &(i, j)) in V.iter().enumerate() {
            for (q, &(k, l)) in V.iter().enumerate() {
                tangent[p][q] = cc(i, j, k, l);
            }
        }
        let stress = [s(0, 0), s(1, 1), s(0, 1)];
        if !stress.iter().all(|v| v.is_finite()) {
            return Err(non_finite(self.name(), "stress", a, b));
        }
        if !tangent.iter().flatten().all(|v| v.is_finite()) {
            return Err(non_finite(self.name(), "tangent", a, b));
        }
        Ok(StressTangent {
            w: d.w,
            s: stress,
            tangent,
        })
    }
}

fn derivatives_checked<L: MembraneLaw + ?Sized>(
    law: &L,
    a: f64,
    b: f64,
) -> Result<EnergyDerivatives, MaterialError> {
    if !(a.is_finite() && b.is_finite()) || b <= 0.0 || a <= 0.0 {
        return Err(MaterialError::InvalidState {
            what: "det C",
            value: b,
            requirement: "tr C and det C must be finite and > 0",
        });
    }
    // Real principal stretches need (λ1² − λ2²)² = a² − 4b ≥ 0 (allow rounding).
    if a * a - 4.0 * b < -1e-12 * a * a {
        return Err(MaterialError::InvalidState {
            what: "tr C² − 4 det C",
            value: a * a - 4.0 * b,
            requirement: "no real stretches have these invariants",
        });
    }
    let d = law.derivatives_ab(a, b)?;
    if [d.w, d.w_a, d.w_b, d.w_aa, d.w_ab, d.w_bb]
        .iter()
        .all(|x| x.is_finite())
    {
        Ok(d)
    } else {
        Err(non_finite(law.name(), "energy or its derivatives", a, b))
    }
}

fn non_finite(law: String, what: &'static str, a: f64, b: f64) -> MaterialError {
    MaterialError::non_finite(law, what, a, b)
}

/// A law given only by its energy W̄(I1, I2), written once for any [`dual::Real`] scalar.
///
/// ```
/// use tubemem_material::{dual::Real, AutoDiff, InvariantEnergy, MaterialError, MembraneLaw};
/// /// Gent: W̄ = −(Jm/2) ln(1 − (I1 − 3)/Jm)
/// #[derive(Debug)]
/// struct Gent { jm: f64 }
/// impl InvariantEnergy for Gent {
///     fn name(&self) -> String { format!("Gent (Jm = {})", self.jm) }
///     fn energy<T: Real>(&self, i1: T, _i2: T) -> Result<T, MaterialError> {
///         let x = (i1 - 3.0) / self.jm;
///         if x.value() >= 1.0 {
///             return Err(MaterialError::Locking { law: self.name(), i1: i1.value(), limit: 3.0 + self.jm });
///         }
///         Ok(-((-x + 1.0).ln()) * (self.jm / 2.0))
///     }
/// }
/// let law = AutoDiff::new(Gent { jm: 97.2 }, 1.0).unwrap();
/// let [n1, _] = law.resultants(1.2, 1.0).unwrap();
/// assert!(n1 > 0.0);
/// ```
pub trait InvariantEnergy: Send + Sync + std::fmt::Debug {
    fn name(&self) -> String;
    /// The dimensionless energy W̄(I1, I2) (per μ); an `Err` for states the law does not admit.
    fn energy<T: dual::Real>(&self, i1: T, i2: T) -> Result<T, MaterialError>;
}

/// A [`MembraneLaw`] whose derivatives come from automatic differentiation of an
/// [`InvariantEnergy`].
#[derive(Clone, Debug, PartialEq)]
pub struct AutoDiff<E> {
    energy: E,
    shear_modulus: f64,
}

impl<E: InvariantEnergy> AutoDiff<E> {
    pub fn new(energy: E, shear_modulus: f64) -> Result<Self, MaterialError> {
        if !(shear_modulus.is_finite() && shear_modulus > 0.0) {
            return Err(MaterialError::InvalidParameter {
                name: "shear_modulus",
                value: shear_modulus,
                requirement: "must be finite and > 0",
            });
        }
        Ok(Self {
            energy,
            shear_modulus,
        })
    }
}

impl<E: InvariantEnergy> MembraneLaw for AutoDiff<E> {
    fn name(&self) -> String {
        self.energy.name()
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        self.derivatives_ab_hand(a, b)
    }
}

impl<E: InvariantEnergy> AutoDiff<E> {
    /// W and its (a, b) derivatives through the hand-written [`dual::HyperDual2`] (what
    /// [`MembraneLaw::derivatives_ab`] uses).
    pub fn derivatives_ab_hand(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        use dual::{HyperDual2, Real};
        let a = HyperDual2::variable(a, 0);
        let b = HyperDual2::variable(b, 1);
        let binv = b.recip();
        let w = self.energy.energy(a + binv, a * binv + b)?;
        Ok(EnergyDerivatives {
            w: w.value(),
            w_a: w.g[0],
            w_b: w.g[1],
            w_aa: w.h[0],
            w_ab: w.h[1],
            w_bb: w.h[2],
        })
    }
}

impl<E: InvariantEnergy> AutoDiff<E> {
    /// The same derivatives through num-dual's `Dual2SVec64<2>`: the independent reference for
    /// the hand-written dual number (slower; see [`dual`]).
    pub fn derivatives_ab_num_dual(
        &self,
        a: f64,
        b: f64,
    ) -> Result<EnergyDerivatives, MaterialError> {
        use nalgebra::SVector;
        use num_dual::{Dual2SVec64, DualNum};
        let x = SVector::<f64, 2>::new(a, b);
        let mut v = x.map(Dual2SVec64::<2>::from_re);
        v[0].v1 = num_dual::Derivative::some(nalgebra::RowSVector::<f64, 2>::new(1.0, 0.0));
        v[1].v1 = num_dual::Derivative::some(nalgebra::RowSVector::<f64, 2>::new(0.0, 1.0));
        let (a, b) = (v[0], v[1]);
        let binv = b.recip();
        let w = self.energy.energy(a + binv, a * binv + b)?;
        let g = w.v1.unwrap_generic(nalgebra::U1, nalgebra::U2);
        let h = w.v2.unwrap_generic(nalgebra::U2, nalgebra::U2);
        Ok(EnergyDerivatives {
            w: w.re,
            w_a: g[0],
            w_b: g[1],
            w_aa: h[(0, 0)],
            w_ab: h[(0, 1)],
            w_bb: h[(1, 1)],
        })
    }
}

/// The built-in energies as [`InvariantEnergy`] too, so that automatic differentiation can be
/// checked against (and timed beside) the analytic derivatives.
pub mod energies {
    use super::{dual::Real, InvariantEnergy, MaterialError};

    /// Paper eq. (19).
    #[derive(Clone, Debug)]
    pub struct AbbEnergy {
        pub kuhn: f64,
    }
    impl InvariantEnergy for AbbEnergy {
        fn name(&self) -> String {
            format!(
                "Anssari-Benam–Bucchi (𝒩 = {}, automatic differentiation)",
                self.kuhn
            )
        }
        fn energy<T: Real>(&self, i1: T, _i2: T) -> Result<T, MaterialError> {
            let n = self.kuhn;
            if i1.value() >= 3.0 * n {
                return Err(MaterialError::Locking {
                    law: self.name(),
                    i1: i1.value(),
                    limit: 3.0 * n,
                });
            }
            let k = n * (3.0 - 3.0 * n) / (1.0 - 3.0 * n);
            Ok(((i1 - 3.0) / (6.0 * n) - ((i1 - 3.0 * n) / (3.0 - 3.0 * n)).ln()) * k)
        }
    }

    /// Paper eq. (83).
    #[derive(Clone, Debug)]
    pub struct MooneyRivlinEnergy {
        pub alpha: f64,
    }
    impl InvariantEnergy for MooneyRivlinEnergy {
        fn name(&self) -> String {
            format!(
                "Mooney–Rivlin (α = {}, automatic differentiation)",
                self.alpha
            )
        }
        fn energy<T: Real>(&self, i1: T, i2: T) -> Result<T, MaterialError> {
            Ok(((i1 - 3.0) + (i2 - 3.0) * self.alpha) * 0.5)
        }
    }
}

/// A boxed law is a law (so that the tension-field relaxation can wrap any of them).
impl MembraneLaw for Box<dyn MembraneLaw> {
    fn name(&self) -> String {
        (**self).name()
    }
    fn shear_modulus(&self) -> f64 {
        (**self).shear_modulus()
    }
    fn locking_limit(&self) -> Option<f64> {
        (**self).locking_limit()
    }
    fn stable_limit(&self) -> Option<f64> {
        (**self).stable_limit()
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        (**self).derivatives_ab(a, b)
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_fit;
#[cfg(test)]
mod tests_laws;
#[cfg(test)]
mod tests_visco;

/// An error and its sources, one line (for the tests).
#[cfg(test)]
fn error_chain_for_tests(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cur = c.source();
    }
    s
}
