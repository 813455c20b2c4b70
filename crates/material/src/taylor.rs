//! Truncated Taylor series in one variable (Taylor-mode automatic differentiation): the
//! coefficients t_k = f⁽ᵏ⁾(x₀)/k!, k < N, of a function evaluated on them.
//!
//! Separable principal-stretch laws ([`crate::separable`]) need the derivatives of
//! g(x) = w(√x) to high order at one point, where the two in-plane stretches are nearly equal;
//! [`Jet`] gives them for any energy written once for [`Real`], a user's expression included.
//! The recurrences are the standard ones (Griewank & Walther, *Evaluating Derivatives*, 2nd ed.,
//! 2008, Table 13.2):
//!
//! ```text
//! c = a·b      c_k = Σ_{i≤k} a_i b_{k−i}
//! c = a/b      c_k = (a_k − Σ_{i=1..k} b_i c_{k−i}) / b_0
//! c = exp(a)   c_0 = e^{a_0},  c_k = (1/k) Σ_{i=1..k} i a_i c_{k−i}
//! c = ln(a)    c_0 = ln a_0,   c_k = (a_k − (1/k) Σ_{i=1..k−1} i c_i a_{k−i}) / a_0
//! c = a^p      c_0 = a_0^p,    c_k = (1/(k a_0)) Σ_{i=1..k} ((p + 1) i − k) a_i c_{k−i}
//! ```

use crate::dual::Real;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The first `N` Taylor coefficients of a function of one variable at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jet<const N: usize> {
    pub t: [f64; N],
}

impl<const N: usize> Jet<N> {
    /// The variable x itself at x₀: coefficients (x₀, 1, 0, …).
    pub fn variable(x0: f64) -> Self {
        let mut t = [0.0; N];
        t[0] = x0;
        if N > 1 {
            t[1] = 1.0;
        }
        Self { t }
    }
    pub fn constant(c: f64) -> Self {
        let mut t = [0.0; N];
        t[0] = c;
        Self { t }
    }
}

impl<const N: usize> Add for Jet<N> {
    type Output = Self;
    fn add(mut self, o: Self) -> Self {
        for k in 0..N {
            self.t[k] += o.t[k];
        }
        self
    }
}
impl<const N: usize> Sub for Jet<N> {
    type Output = Self;
    fn sub(mut self, o: Self) -> Self {
        for k in 0..N {
            self.t[k] -= o.t[k];
        }
        self
    }
}
impl<const N: usize> Neg for Jet<N> {
    type Output = Self;
    fn neg(mut self) -> Self {
        for v in &mut self.t {
            *v = -*v;
        }
        self
    }
}
impl<const N: usize> Mul for Jet<N> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        let mut t = [0.0; N];
        for (k, c) in t.iter_mut().enumerate() {
            *c = (0..=k).map(|i| self.t[i] * o.t[k - i]).sum();
        }
        Self { t }
    }
}
impl<const N: usize> Div for Jet<N> {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let mut t = [0.0; N];
        for k in 0..N {
            let s: f64 = (1..=k).map(|i| o.t[i] * t[k - i]).sum();
            t[k] = (self.t[k] - s) / o.t[0];
        }
        Self { t }
    }
}
impl<const N: usize> Add<f64> for Jet<N> {
    type Output = Self;
    fn add(mut self, c: f64) -> Self {
        self.t[0] += c;
        self
    }
}
impl<const N: usize> Sub<f64> for Jet<N> {
    type Output = Self;
    fn sub(mut self, c: f64) -> Self {
        self.t[0] -= c;
        self
    }
}
impl<const N: usize> Mul<f64> for Jet<N> {
    type Output = Self;
    fn mul(mut self, c: f64) -> Self {
        for v in &mut self.t {
            *v *= c;
        }
        self
    }
}
impl<const N: usize> Div<f64> for Jet<N> {
    type Output = Self;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, c: f64) -> Self {
        self * (1.0 / c)
    }
}

impl<const N: usize> Real for Jet<N> {
    fn value(self) -> f64 {
        self.t[0]
    }
    fn exp(self) -> Self {
        let mut c = [0.0; N];
        c[0] = self.t[0].exp();
        for k in 1..N {
            let s: f64 = (1..=k).map(|i| i as f64 * self.t[i] * c[k - i]).sum();
            c[k] = s / k as f64;
        }
        Self { t: c }
    }
    fn ln(self) -> Self {
        let a = self.t;
        let mut c = [0.0; N];
        c[0] = a[0].ln();
        for k in 1..N {
            let s: f64 = (1..k).map(|i| i as f64 * c[i] * a[k - i]).sum();
            c[k] = (a[k] - s / k as f64) / a[0];
        }
        Self { t: c }
    }
    fn powf(self, p: f64) -> Self {
        let a = self.t;
        let mut c = [0.0; N];
        c[0] = a[0].powf(p);
        for k in 1..N {
            let s: f64 = (1..=k)
                .map(|i| ((p + 1.0) * i as f64 - k as f64) * a[i] * c[k - i])
                .sum();
            c[k] = s / (k as f64 * a[0]);
        }
        Self { t: c }
    }
    fn sqrt(self) -> Self {
        self.powf(0.5)
    }
    fn powi(self, n: i32) -> Self {
        match n {
            0 => Self::constant(1.0),
            n if n < 0 => self.powi(-n).recip(),
            n => {
                let mut r = self;
                for _ in 1..n {
                    r = r * self;
                }
                r
            }
        }
    }
    fn recip(self) -> Self {
        Self::constant(1.0) / self
    }
    fn lift(self, c: f64) -> Self {
        Self::constant(c)
    }
    fn sin(self) -> Self {
        self.sin_cos().0
    }
    fn cos(self) -> Self {
        self.sin_cos().1
    }
}

impl<const N: usize> Jet<N> {
    /// (sin, cos) together: s_k = (1/k) Σ i a_i c_{k−i}, c_k = −(1/k) Σ i a_i s_{k−i}.
    pub fn sin_cos(self) -> (Self, Self) {
        let a = self.t;
        let (mut s, mut c) = ([0.0; N], [0.0; N]);
        (s[0], c[0]) = a[0].sin_cos();
        for k in 1..N {
            let (mut ss, mut cc) = (0.0, 0.0);
            for i in 1..=k {
                ss += i as f64 * a[i] * c[k - i];
                cc += i as f64 * a[i] * s[k - i];
            }
            s[k] = ss / k as f64;
            c[k] = -cc / k as f64;
        }
        (Self { t: s }, Self { t: c })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each recurrence against the closed-form Taylor coefficients of the same function.
    #[test]
    fn jet_coefficients_match_closed_forms() {
        let x0: f64 = 1.7;
        let x = Jet::<8>::variable(x0);
        // exp(x): e^{x0}/k!
        let e = x.exp();
        let mut fact = 1.0;
        for k in 0..8 {
            if k > 0 {
                fact *= k as f64;
            }
            assert!((e.t[k] - x0.exp() / fact).abs() < 1e-14 * x0.exp());
        }
        // ln(x): (−1)^{k+1}/(k x0^k)
        let l = x.ln();
        for k in 1..8 {
            let want = (-1f64).powi(k as i32 + 1) / (k as f64 * x0.powi(k as i32));
            assert!(
                (l.t[k] - want).abs() < 1e-14,
                "ln {k}: {} vs {want}",
                l.t[k]
            );
        }
        // x^p: binom(p, k) x0^{p−k}
        let p = 2.6;
        let y = x.powf(p);
        let mut binom = 1.0;
        for k in 0..8 {
            if k > 0 {
                binom *= (p - (k as f64 - 1.0)) / k as f64;
            }
            let want = binom * x0.powf(p - k as f64);
            assert!(
                (y.t[k] - want).abs() < 1e-13 * want.abs().max(1.0),
                "pow {k}"
            );
        }
        // 1/x and x·x·x against powi
        let r = x.recip();
        let q = x.powi(-1);
        for k in 0..8 {
            assert!((r.t[k] - q.t[k]).abs() < 1e-15);
            let want = (-1f64).powi(k as i32) / x0.powi(k as i32 + 1);
            assert!((r.t[k] - want).abs() < 1e-14);
        }
        // sin²(x) + cos²(x) = 1, and the coefficients of sin at x0
        let (sn, cs) = x.sin_cos();
        let one = sn * sn + cs * cs;
        assert!((one.t[0] - 1.0).abs() < 1e-15);
        for k in 1..8 {
            assert!(one.t[k].abs() < 1e-14);
        }
        let mut fact = 1.0;
        for k in 0..8 {
            if k > 0 {
                fact *= k as f64;
            }
            let want = (x0 + k as f64 * std::f64::consts::FRAC_PI_2).sin() / fact;
            assert!((sn.t[k] - want).abs() < 1e-14, "sin {k}");
        }
        // sqrt(x)^2 = x
        let s = x.sqrt() * x.sqrt();
        assert!((s.t[0] - x0).abs() < 1e-15 && (s.t[1] - 1.0).abs() < 1e-15);
        for k in 2..8 {
            assert!(s.t[k].abs() < 1e-14);
        }
    }
}
