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
    /// `stability_limit` below), and refuses states beyond it (every Yeoh law with C10 > 0 is
    /// stable at the reference state, where ∇I1 = 0).
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
        // W′ > 0 and W″ ≥ 0 everywhere: stable at every stretch, nothing to scan
        let convex = c20 >= 0.0 && c30 >= 0.0;
        let limit = (!convex)
            .then(|| {
                stability_limit(|x| {
                    (
                        w[0] + x * (2.0 * w[1] + 3.0 * w[2] * x),
                        2.0 * w[1] + 6.0 * w[2] * x,
                    )
                })
            })
            .flatten();
        Ok(Self {
            c: [c10, c20, c30],
            limit,
        })
    }
}

/// The I1 − 3 where an energy of I1 alone, with W′(x) and W″(x) (x = I1 − 3) given by `w`,
/// first loses stability: W′ ≤ 0 (the membrane no longer pulls), or its membrane tangent
/// H = W″ ∇I1 ∇I1ᵀ + W′ ∇²I1 (in the principal stretches) stops being positive definite at
/// some state with that I1. ∇²I1 is positive definite at every state, so H is where W′ > 0
/// and W″ ≥ 0; where W″ < 0 it is iff W′ + W″ q > 0, q = ∇I1ᵀ(∇²I1)⁻¹∇I1, and the worst state
/// of an I1 is the one of largest q, [`q_max`]. `None`: stable up to I1 = [`SCANNED_I1`].
pub fn stability_limit(w: impl Fn(f64) -> (f64, f64)) -> Option<f64> {
    let table = q_table();
    // on each interval of the table, q at its worse end: the limit errs on the safe side
    let fails = |x: f64, q: f64| {
        let (w1, w2) = w(x);
        !(w1 > 0.0 && w1 + w2.min(0.0) * q > 0.0)
    };
    let mut prev = 0.0;
    for pair in table.windows(2) {
        let ((_, qa), (xb, qb)) = (pair[0], pair[1]);
        let q = qa.max(qb);
        if !fails(xb, q) {
            prev = xb;
            continue;
        }
        let (mut lo, mut hi) = (prev, xb);
        if fails(lo, q) {
            return Some(lo);
        }
        while hi - lo > 1e-12 * hi.max(1e-12) {
            let mid = 0.5 * (lo + hi);
            if fails(mid, q) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        return Some(lo);
    }
    None
}

/// q_max(x) on a grid of x = I1 − 3 from 0 to [`SCANNED_I1`] − 3: (x, the largest q =
/// ∇I1ᵀ(∇²I1)⁻¹∇I1 over the states with that I1, on rays λ2 = λ1^t, t from −½ (uniaxial) to 1
/// (equibiaxial)), computed once.
fn q_table() -> &'static [(f64, f64)] {
    static TABLE: std::sync::OnceLock<Vec<(f64, f64)>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let q_at = |l1: f64, t: f64| -> (f64, f64) {
            let l2 = l1.powf(t);
            let j2 = 1.0 / (l1 * l1 * l2 * l2);
            let g = [2.0 * l1 - 2.0 * j2 / l1, 2.0 * l2 - 2.0 * j2 / l2];
            let k = [
                [2.0 + 6.0 * j2 / (l1 * l1), 4.0 * j2 / (l1 * l2)],
                [4.0 * j2 / (l1 * l2), 2.0 + 6.0 * j2 / (l2 * l2)],
            ];
            let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
            let q =
                (k[1][1] * g[0] * g[0] - 2.0 * k[0][1] * g[0] * g[1] + k[0][0] * g[1] * g[1]) / det;
            (l1 * l1 + l2 * l2 + j2 - 3.0, q)
        };
        let n = 400;
        let xmax = SCANNED_I1 - 3.0;
        (0..=n)
            .map(|i| {
                // geometric in x from 1e-6, with x = 0 first
                let x = if i == 0 {
                    0.0
                } else {
                    1e-6 * (xmax / 1e-6).powf((i - 1) as f64 / (n - 1) as f64)
                };
                let mut q = 0.0f64;
                for r in 0..=30 {
                    let t = -0.5 + 1.5 * r as f64 / 30.0;
                    // λ1 ≥ 1 with I1 − 3 = x on this ray (I1 grows with λ1 there)
                    let (mut lo, mut hi) = (0.0f64, (SCANNED_I1).sqrt().ln() + 1.0);
                    for _ in 0..80 {
                        let mid = 0.5 * (lo + hi);
                        if q_at(mid.exp(), t).0 < x {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    q = q.max(q_at(hi.exp(), t).1);
                }
                (x, q)
            })
            .collect()
    })
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
