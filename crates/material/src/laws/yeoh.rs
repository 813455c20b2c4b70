//! Yeoh's law (Yeoh 1993, *Rubber Chem. Technol.* 66): W = C10 (I1 − 3) + C20 (I1 − 3)² +
//! C30 (I1 − 3)³, as Abaqus and FEBio write it. μ = 2 C10 is the small-strain shear modulus.

use crate::{EnergyDerivatives, MaterialError, MembraneLaw};

/// Yeoh's three-term law, with its coefficients in stress units.
#[derive(Clone, Debug, PartialEq)]
pub struct Yeoh {
    c: [f64; 3],
    /// the largest I1 − 3 at which the law is stable (None: stable at every stretch)
    limit: Option<f64>,
}

/// The largest I1 that [`Yeoh::new`] scans for a loss of stability: 3 + 1e4 (equibiaxial
/// stretch 10): beyond what any membrane reaches before it tears.
const SCANNED_I1: f64 = 3.0 + 1e4;

impl Yeoh {
    /// C10 > 0 and finite C20, C30. Negative coefficients are accepted (fitted silicone laws
    /// have them: Ecoflex's C30 < 0): such a law is stable only up to the I1 where its membrane
    /// tangent stops being positive definite ([`Yeoh::stable_limit`], found by
    /// [`stability_limit`]), and refuses states beyond it. A law unstable already at the
    /// reference state is refused.
    pub fn new(c10: f64, c20: f64, c30: f64) -> Result<Self, MaterialError> {
        super::check_positive("c10", c10)?;
        for (name, v) in [("c20", c20), ("c30", c30)] {
            if !v.is_finite() {
                return Err(MaterialError::InvalidParameter {
                    name,
                    value: v,
                    requirement: "must be a finite number",
                });
            }
        }
        let mu = 2.0 * c10;
        let w = [c10 / mu, c20 / mu, c30 / mu];
        let limit = stability_limit(|x| {
            (
                w[0] + x * (2.0 * w[1] + 3.0 * w[2] * x),
                2.0 * w[1] + 6.0 * w[2] * x,
            )
        });
        if limit.is_some_and(|x| x <= 1e-6) {
            return Err(MaterialError::InvalidParameter {
                name: if c30 < 0.0 { "c30" } else { "c20" },
                value: if c30 < 0.0 { c30 } else { c20 },
                requirement: "the law is unstable already at small stretch (its membrane tangent is not positive definite near I1 = 3)",
            });
        }
        Ok(Self {
            c: [c10, c20, c30],
            limit,
        })
    }
}

/// The I1 − 3 where an energy of I1 alone, with W′(x) and W″(x) (x = I1 − 3) given by `w`,
/// first loses stability: W′ ≤ 0 (the membrane no longer pulls), or its membrane tangent
/// ∂²W/∂λα∂λβ = W″ ∇I1 ∇I1ᵀ + W′ ∇²I1 stops being positive definite at some state
/// (λ1, λ2) with that I1. States are scanned on rays λ2 = λ1^t, t from −½ (uniaxial) to 1
/// (equibiaxial), λ1 growing geometrically to I1 = [`SCANNED_I1`]; the first failure on each
/// ray is bisected to 1e-12 in ln λ1. `None`: stable everywhere scanned.
pub fn stability_limit(w: impl Fn(f64) -> (f64, f64)) -> Option<f64> {
    let stable = |l1: f64, t: f64| -> (bool, f64) {
        let l2 = l1.powf(t);
        let j2 = 1.0 / (l1 * l1 * l2 * l2);
        let i1 = l1 * l1 + l2 * l2 + j2;
        let (w1, w2) = w(i1 - 3.0);
        // ∇I1 and ∇²I1 in (λ1, λ2)
        let g = [2.0 * l1 - 2.0 * j2 / l1, 2.0 * l2 - 2.0 * j2 / l2];
        let k = [
            [2.0 + 6.0 * j2 / (l1 * l1), 4.0 * j2 / (l1 * l2)],
            [4.0 * j2 / (l1 * l2), 2.0 + 6.0 * j2 / (l2 * l2)],
        ];
        let h = |i: usize, j: usize| w2 * g[i] * g[j] + w1 * k[i][j];
        let ok = w1 > 0.0 && h(0, 0) > 0.0 && h(0, 0) * h(1, 1) - h(0, 1) * h(1, 0) > 0.0;
        (ok, i1 - 3.0)
    };
    let top = (SCANNED_I1 / 2.0).sqrt().ln();
    let n = 2000;
    let mut limit: Option<f64> = None;
    for r in 0..=30 {
        let t = -0.5 + 1.5 * r as f64 / 30.0;
        let mut prev = 0.0f64;
        for k in 1..=n {
            let s = top * k as f64 / n as f64;
            if stable(s.exp(), t).0 {
                prev = s;
                continue;
            }
            let (mut lo, mut hi) = (prev, s);
            while hi - lo > 1e-12 {
                let mid = 0.5 * (lo + hi);
                if stable(mid.exp(), t).0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let x = stable(lo.exp(), t).1;
            limit = Some(limit.map_or(x, |m: f64| m.min(x)));
            break;
        }
    }
    limit
}

impl Yeoh {
    /// The equibiaxial stretch λ with I1(λ, λ) = 3 + `x` (2λ² + λ⁻⁴ = 3 + x), by Newton.
    fn equibiaxial(x: f64) -> f64 {
        let mut l = (1.0 + 0.5 * x).sqrt().max(1.0);
        for _ in 0..100 {
            let f = 2.0 * l * l + l.powi(-4) - 3.0 - x;
            let d = 4.0 * l - 4.0 * l.powi(-5);
            if d.abs() < 1e-300 {
                break;
            }
            let next = l - f / d;
            if (next - l).abs() <= 1e-15 * l {
                return next;
            }
            l = next.max(1.0);
        }
        l
    }
}

impl MembraneLaw for Yeoh {
    fn name(&self) -> String {
        let [c10, c20, c30] = self.c;
        format!(
            "Yeoh (C10 = {}, C20 = {}, C30 = {})",
            crate::Num(c10),
            crate::Num(c20),
            crate::Num(c30)
        )
    }
    fn shear_modulus(&self) -> f64 {
        2.0 * self.c[0]
    }
    fn stable_limit(&self) -> Option<f64> {
        self.limit.map(|x| 3.0 + x)
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        let mu = 2.0 * self.c[0];
        let [c10, c20, c30] = self.c.map(|c| c / mu);
        let x = a + 1.0 / b - 3.0;
        if let Some(limit) = self.limit.filter(|l| x >= *l) {
            return Err(MaterialError::Unstable {
                law: self.name(),
                i1: 3.0 + x,
                limit: 3.0 + limit,
                stretch: Self::equibiaxial(limit),
            });
        }
        Ok(super::from_i1(
            [
                x * (c10 + x * (c20 + x * c30)),
                c10 + x * (2.0 * c20 + 3.0 * c30 * x),
                2.0 * c20 + 6.0 * c30 * x,
            ],
            a,
            b,
        ))
    }
}
