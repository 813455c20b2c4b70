//! Principal-stretch (Valanis–Landel) laws, W = w(λ1) + w(λ2) + w(λ3) with λ3 = 1/(λ1 λ2):
//! Ogden's law and the principal-stretch energies written in a case file, as [`MembraneLaw`]s
//! in the invariants (a, b) = (tr C, det C) like every other law.
//!
//! With x = λ² and g(x) = w(√x), the in-plane part is G = g(x1) + g(x2), where x1,2 = s ± d
//! are the eigenvalues of C: s = a/2, d² = D = s² − b. G is symmetric in x1, x2, so it is a
//! smooth function of (s, D) even where the stretches are equal (D = 0: the reference state,
//! equibiaxial states), although d = √D is not. Two evaluations, both exact to round-off:
//!
//! ```text
//! d ≥ 0.05 s (direct)   G_s = g'1 + g'2, G_D = (g'1 − g'2)/(2d),
//!                       G_ss = g''1 + g''2, G_sD = (g''1 − g''2)/(2d),
//!                       G_DD = ((g''1 + g''2) d − (g'1 − g'2)) / (4 d³)
//! d < 0.05 s (series)   G = g(s + d) + g(s − d) = 2 Σ_k t_{2k} D^k,  t_n = g⁽ⁿ⁾(s)/n!
//!                       G_s = 2 Σ (2k+1) t_{2k+1} D^k,  G_ss = 2 Σ (2k+1)(2k+2) t_{2k+2} D^k,
//!                       G_D = 2 Σ k t_{2k} D^{k−1},  G_sD = 2 Σ k (2k+1) t_{2k+1} D^{k−1},
//!                       G_DD = 2 Σ k (k−1) t_{2k} D^{k−2},   k ≤ K = 6
//! then  G_a = G_s/2 + s G_D,  G_b = −G_D,  G_aa = G_ss/4 + s G_sD + s² G_DD + G_D/2,
//!       G_ab = −G_sD/2 − s G_DD,  G_bb = G_DD
//! ```
//!
//! The series' first neglected term is of relative size (d/s)^(2K+2) in G and (d/s)^(2K−2) ≈
//! 0.05¹⁰ ≈ 1e-13 in G_DD at the switch; the direct formulas lose about ε/(d/s)² ≈ 1e-13 to
//! cancellation there. The out-of-plane part is g(1/b) (λ3² = 1/b). W = G + g(1/b) − 3 g(1),
//! so that W = 0 at the reference state.

use crate::{EnergyDerivatives, MaterialError, MembraneLaw};

/// The series' order: G to D^K ([`SERIES_TERMS`] Taylor coefficients of g).
const K: usize = 6;
/// The Taylor coefficients the series needs: t_0 … t_{2K+2}.
pub const SERIES_TERMS: usize = 2 * K + 3;
/// Below this d/s the series is used, at or above it the direct formulas.
pub const SERIES_SWITCH: f64 = 0.05;

/// w(λ) of a separable law, given as the Taylor coefficients of g(x) = w(√x).
pub trait StretchEnergy: Send + Sync + std::fmt::Debug {
    fn name(&self) -> String;
    /// t_k = g⁽ᵏ⁾(x)/k! for k < `t.len()` (at most [`SERIES_TERMS`]), x > 0; an error where
    /// the law does not admit the stretch √x.
    fn taylor(&self, x: f64, t: &mut [f64]) -> Result<(), MaterialError>;
}

/// A [`MembraneLaw`] from a separable principal-stretch energy.
#[derive(Clone, Debug, PartialEq)]
pub struct Separable<S> {
    pub energy: S,
    pub shear_modulus: f64,
    /// 3 g(1), subtracted so that W = 0 at the reference state (computed once)
    offset: f64,
}

impl<S: StretchEnergy> Separable<S> {
    pub fn new(energy: S, shear_modulus: f64) -> Result<Self, MaterialError> {
        let mut t = [0.0; 1];
        energy.taylor(1.0, &mut t)?;
        Ok(Self {
            energy,
            shear_modulus,
            offset: 3.0 * t[0],
        })
    }

    /// G(a, b) and its derivatives: (G, G_a, G_b, G_aa, G_ab, G_bb).
    fn in_plane(&self, a: f64, b: f64) -> Result<[f64; 6], MaterialError> {
        let s = 0.5 * a;
        let dd = (s * s - b).max(0.0);
        let d = dd.sqrt();
        let (g, gs, gd_, gss, gsd_, gdd_) = if d < SERIES_SWITCH * s {
            let mut t = [0.0; SERIES_TERMS];
            self.energy.taylor(s, &mut t)?;
            let (mut g, mut gs, mut gss, mut gd, mut gsd, mut gdd) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            // Horner-free sums: D^k with k ≤ 6 is well within range
            let mut pk = 1.0; // D^k
            for k in 0..=K {
                let kf = k as f64;
                g += 2.0 * t[2 * k] * pk;
                gs += 2.0 * (2.0 * kf + 1.0) * t[2 * k + 1] * pk;
                gss += 2.0 * (2.0 * kf + 1.0) * (2.0 * kf + 2.0) * t[2 * k + 2] * pk;
                pk *= dd;
            }
            let mut pk1 = 1.0; // D^(k−1)
            for k in 1..=K {
                let kf = k as f64;
                gd += 2.0 * kf * t[2 * k] * pk1;
                gsd += 2.0 * kf * (2.0 * kf + 1.0) * t[2 * k + 1] * pk1;
                pk1 *= dd;
            }
            let mut pk2 = 1.0; // D^(k−2)
            for k in 2..=K {
                let kf = k as f64;
                gdd += 2.0 * kf * (kf - 1.0) * t[2 * k] * pk2;
                pk2 *= dd;
            }
            (g, gs, gd, gss, gsd, gdd)
        } else {
            let (mut t1, mut t2) = ([0.0; 3], [0.0; 3]);
            self.energy.taylor(s + d, &mut t1)?;
            self.energy.taylor(s - d, &mut t2)?;
            let (g1, g1p, g1pp) = (t1[0], t1[1], 2.0 * t1[2]);
            let (g2, g2p, g2pp) = (t2[0], t2[1], 2.0 * t2[2]);
            let gd = g1p - g2p;
            (
                g1 + g2,
                g1p + g2p,
                gd / (2.0 * d),
                g1pp + g2pp,
                (g1pp - g2pp) / (2.0 * d),
                ((g1pp + g2pp) * d - gd) / (4.0 * d * dd),
            )
        };
        Ok([
            g,
            0.5 * gs + s * gd_,
            -gd_,
            0.25 * gss + s * gsd_ + s * s * gdd_ + 0.5 * gd_,
            -0.5 * gsd_ - s * gdd_,
            gdd_,
        ])
    }
}

impl<S: StretchEnergy> MembraneLaw for Separable<S> {
    fn name(&self) -> String {
        self.energy.name()
    }
    fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    fn derivatives_ab(&self, a: f64, b: f64) -> Result<EnergyDerivatives, MaterialError> {
        let [g, ga, gb, gaa, gab, gbb] = self.in_plane(a, b)?;
        // the out-of-plane stretch: h(b) = g(y), y = 1/b
        let y = 1.0 / b;
        let mut t = [0.0; 3];
        self.energy.taylor(y, &mut t)?;
        let (h0, h1, h2) = (t[0], t[1], 2.0 * t[2]);
        let (b2, b3) = (b * b, b * b * b);
        Ok(EnergyDerivatives {
            w: g + h0 - self.offset,
            w_a: ga,
            w_b: gb - h1 / b2,
            w_aa: gaa,
            w_ab: gab,
            w_bb: gbb + h2 / (b2 * b2) + 2.0 * h1 / b3,
        })
    }
}
