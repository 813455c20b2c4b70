//! One time step of the section in time: the GPS equations with the step's hereditary stress
//! S = α S⁰(λs, λz) + B ([`tubemem_material::viscoelastic`]), free or between plates, under a
//! given pressure, a closed gas, or a given hoop stretch or volume.
//!
//! ```text
//! N_s = α N⁰_s + B_s λs/λz      N_z = α N⁰_z + B_z λz/λs
//! free:          N_s = ϖ λs,   N_s = 2 N_z (GPS; PS: λz = 1),  gas: ϖ λs² λz = M
//! plates at ±ρ:  N_s = ϖ ρ,    N_s (2λs − ρ)/(2λs) = N_z (eq. 76₂),  gas: ϖ ρ (2λs − ρ) λz = M
//!                χ = λs − ρ, force ϖχ (eq. 80)
//! ```

use crate::{newton, resultants, GpsError, Hypothesis};
use tubemem_material::{MaterialError, MembraneLaw};

/// What fixes the pressure in a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Fix {
    /// ϖ given
    Pressure(f64),
    /// the gas closed: ϖ × (enclosed volume per unit reference length over πR²) = M
    Gas(f64),
    /// λs given (free only)
    Stretch(f64),
    /// v = λs² λz given (free only)
    Volume(f64),
}

/// What fixes the pressure between plates (the plates fix ρ, so never λs or v).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum PlateFix {
    /// ϖ given
    Pressure(f64),
    /// the gas closed: ϖ ρ (2λs − ρ) λz = M
    Gas(f64),
}

/// Where a step's section is: free under a [`Fix`], or between plates at ±ρ under a
/// [`PlateFix`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Section {
    Free(Fix),
    Plates(f64, PlateFix),
}

/// The solved step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Solved {
    pub ls: f64,
    pub lz: f64,
    pub ns: f64,
    pub nz: f64,
    pub w: f64,
}

const STAGE: &str = "viscoelastic section in time (eqs. 66, 76–77)";

/// One step's equations: the law, the hypothesis, α and the history's stress B.
pub(crate) struct StepEquations<'a> {
    pub law: &'a dyn MembraneLaw,
    pub hyp: Hypothesis,
    pub alpha: f64,
    pub b: [f64; 3],
}

type Jac = [[f64; 2]; 2];

impl StepEquations<'_> {
    /// N_s, N_z at (λs, λz) and their Jacobian [[∂N_s/∂λs, ∂N_s/∂λz], [∂N_z/∂λs, ∂N_z/∂λz]].
    fn resultants(&self, ls: f64, lz: f64) -> Result<(f64, f64, Jac), MaterialError> {
        let r = resultants::resultants(self.law, ls, lz)?;
        let (alpha, bs, bz) = (self.alpha, self.b[0], self.b[1]);
        let ns = alpha * r.ns + bs * ls / lz;
        let nz = alpha * r.nz + bz * lz / ls;
        let j = [
            [
                alpha * r.jac[0][0] + bs / lz,
                alpha * r.jac[0][1] - bs * ls / (lz * lz),
            ],
            [
                alpha * r.jac[1][0] - bz * lz / (ls * ls),
                alpha * r.jac[1][1] + bz / ls,
            ],
        ];
        Ok((ns, nz, j))
    }

    /// The free section's two equations in (λs, λz) and their Jacobian (GPS).
    fn free_gps(&self, fix: Fix, x: [f64; 2]) -> Result<([f64; 2], Jac), MaterialError> {
        let [ls, lz] = x;
        let (ns, nz, j) = self.resultants(ls, lz)?;
        let axial = [j[0][0] - 2.0 * j[1][0], j[0][1] - 2.0 * j[1][1]];
        let (f, d) = match fix {
            Fix::Pressure(w) => (ns - w * ls, [j[0][0] - w, j[0][1]]),
            // ϖ = N_s/λs: ϖ λs² λz = N_s λs λz
            Fix::Gas(m) => (
                ns * ls * lz / m - 1.0,
                [lz * (j[0][0] * ls + ns) / m, ls * (j[0][1] * lz + ns) / m],
            ),
            Fix::Stretch(v) => (ls - v, [1.0, 0.0]),
            Fix::Volume(v) => (ls * ls * lz - v, [2.0 * ls * lz, ls * ls]),
        };
        Ok(([f, ns - 2.0 * nz], [d, axial]))
    }

    /// Between plates at ±ρ: the two equations in (λs, λz) and their Jacobian (GPS).
    fn plates_gps(
        &self,
        rho: f64,
        fix: PlateFix,
        x: [f64; 2],
    ) -> Result<([f64; 2], Jac), MaterialError> {
        let [ls, lz] = x;
        let (ns, nz, j) = self.resultants(ls, lz)?;
        let q = 1.0 - rho / (2.0 * ls);
        let dq = rho / (2.0 * ls * ls);
        let t = 2.0 * ls - rho;
        let axial = (
            ns * q - nz,
            [j[0][0] * q + ns * dq - j[1][0], j[0][1] * q - j[1][1]],
        );
        let (f, d) = match fix {
            PlateFix::Pressure(w) => (ns - w * rho, [j[0][0], j[0][1]]),
            PlateFix::Gas(m) => (
                lz * ns * t / m - 1.0,
                [
                    lz * (j[0][0] * t + 2.0 * ns) / m,
                    (ns * t + lz * j[0][1] * t) / m,
                ],
            ),
        };
        Ok(([f, axial.0], [d, axial.1]))
    }

    /// Solve the step's `section` from the guess (λs, λz).
    pub fn solve(&self, section: Section, guess: [f64; 2], at: &str) -> Result<Solved, GpsError> {
        let rho = match section {
            Section::Free(_) => None,
            Section::Plates(rho, _) => Some(rho),
        };
        let ftol = 1e-13;
        let fail = |f: newton::Failure| f.into_error(STAGE, at);
        let (ls, lz) = match self.hyp {
            Hypothesis::Gps => {
                let x = match section {
                    Section::Free(fix) => newton::system2(|x| self.free_gps(fix, x), guess, ftol),
                    Section::Plates(rho, fix) => {
                        newton::system2(|x| self.plates_gps(rho, fix, x), guess, ftol)
                    }
                }
                .map_err(fail)?;
                (x[0], x[1])
            }
            // PS: λz = 1, the first equation alone in λs
            Hypothesis::Ps => {
                let ls = match section {
                    Section::Free(Fix::Stretch(v)) => v,
                    Section::Free(Fix::Volume(v)) => v.sqrt(),
                    _ => newton::scalar(
                        |ls| {
                            let (f, j) = match section {
                                Section::Free(fix) => self.free_gps(fix, [ls, 1.0])?,
                                Section::Plates(rho, fix) => {
                                    self.plates_gps(rho, fix, [ls, 1.0])?
                                }
                            };
                            Ok((f[0], j[0][0]))
                        },
                        guess[0],
                        ftol,
                    )
                    .map_err(fail)?,
                };
                (ls, 1.0)
            }
        };
        let (ns, nz, _) = self
            .resultants(ls, lz)
            .map_err(|source| GpsError::Material {
                stage: STAGE,
                at: at.to_string(),
                source,
            })?;
        if ns.is_nan() || ns <= 0.0 {
            return Err(GpsError::Compressive {
                stage: "viscoelastic section in time",
                at: at.to_string(),
                n_s: ns,
                w: ns / rho.unwrap_or(ls),
            });
        }
        Ok(Solved {
            ls,
            lz,
            ns,
            nz,
            w: ns / rho.unwrap_or(ls),
        })
    }
}
