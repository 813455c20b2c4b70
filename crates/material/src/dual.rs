//! A second-order forward-mode dual number in two variables, for automatic differentiation of
//! membrane energies written once over a generic scalar type.
//!
//! ```text
//! x = re + g·ε + ½ εᵀ H ε      (ε ∈ ℝ², truncated after second order)
//! (f∘x).re = f(re),  (f∘x).g = f'(re) g,  (f∘x).H = f'(re) H + f''(re) g gᵀ
//! ```
//!
//! Why our own type rather than `num-dual` (the maintained library for exactly this): measured
//! side by side in `benches/laws.rs` (`cargo bench -p tubemem-material --bench laws`), the
//! derivatives of the ABB energy take 20.5 ns with this type and 33.7 ns with num-dual 0.15's
//! `Dual2SVec64<2>` (whose derivative parts are `Option`s, checked at every operation): 1.65×
//! slower, on the hot path of every Gauss point of a user law. num-dual is kept as the
//! independent reference: [`crate::AutoDiff::derivatives_ab_num_dual`] computes the same
//! derivatives through it, and a test holds the two together (and both against the analytic
//! derivatives of every built-in law).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The scalar operations a membrane energy may use. Implemented for `f64` and [`HyperDual2`].
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// The value (real part), used for validity checks such as a locking limit.
    fn value(self) -> f64;
    fn ln(self) -> Self;
    fn exp(self) -> Self;
    fn sqrt(self) -> Self;
    fn powi(self, n: i32) -> Self;
    fn recip(self) -> Self;
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    /// self^p for a constant p (self > 0 where p is not an integer).
    fn powf(self, p: f64) -> Self {
        (self.ln() * p).exp()
    }
    /// self^e for a variable exponent: exp(e ln self), self > 0.
    fn pow(self, e: Self) -> Self {
        (self.ln() * e).exp()
    }
    /// The constant `c` as a scalar of this kind (no derivatives).
    fn lift(self, c: f64) -> Self {
        self * 0.0 + c
    }
}

impl Real for f64 {
    fn value(self) -> f64 {
        self
    }
    fn ln(self) -> Self {
        f64::ln(self)
    }
    fn exp(self) -> Self {
        f64::exp(self)
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn powi(self, n: i32) -> Self {
        f64::powi(self, n)
    }
    fn recip(self) -> Self {
        f64::recip(self)
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn powf(self, p: f64) -> Self {
        f64::powf(self, p)
    }
    fn pow(self, e: Self) -> Self {
        f64::powf(self, e)
    }
    fn lift(self, c: f64) -> Self {
        c
    }
}

/// Value, gradient and (symmetric) Hessian with respect to two independent variables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HyperDual2 {
    pub re: f64,
    pub g: [f64; 2],
    /// Hessian entries (00, 01, 11).
    pub h: [f64; 3],
}

impl HyperDual2 {
    /// The independent variable number `k` (0 or 1) with value `x`.
    pub fn variable(x: f64, k: usize) -> Self {
        let mut g = [0.0; 2];
        g[k] = 1.0;
        Self {
            re: x,
            g,
            h: [0.0; 3],
        }
    }
    pub fn constant(x: f64) -> Self {
        Self {
            re: x,
            g: [0.0; 2],
            h: [0.0; 3],
        }
    }
    /// Chain rule for a scalar function with value f0 and derivatives f1, f2 at `self.re`.
    #[inline]
    fn chain(self, f0: f64, f1: f64, f2: f64) -> Self {
        let [g0, g1] = self.g;
        Self {
            re: f0,
            g: [f1 * g0, f1 * g1],
            h: [
                f1 * self.h[0] + f2 * g0 * g0,
                f1 * self.h[1] + f2 * g0 * g1,
                f1 * self.h[2] + f2 * g1 * g1,
            ],
        }
    }
}

impl Add for HyperDual2 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            re: self.re + o.re,
            g: [self.g[0] + o.g[0], self.g[1] + o.g[1]],
            h: [self.h[0] + o.h[0], self.h[1] + o.h[1], self.h[2] + o.h[2]],
        }
    }
}
impl Sub for HyperDual2 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}
impl Neg for HyperDual2 {
    type Output = Self;
    fn neg(self) -> Self {
        self * -1.0
    }
}
impl Mul for HyperDual2 {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        let (a, b) = (self, o);
        Self {
            re: a.re * b.re,
            g: [a.re * b.g[0] + a.g[0] * b.re, a.re * b.g[1] + a.g[1] * b.re],
            h: [
                a.re * b.h[0] + b.re * a.h[0] + 2.0 * a.g[0] * b.g[0],
                a.re * b.h[1] + b.re * a.h[1] + a.g[0] * b.g[1] + a.g[1] * b.g[0],
                a.re * b.h[2] + b.re * a.h[2] + 2.0 * a.g[1] * b.g[1],
            ],
        }
    }
}
impl Div for HyperDual2 {
    type Output = Self;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Self) -> Self {
        self * o.recip()
    }
}
impl Add<f64> for HyperDual2 {
    type Output = Self;
    fn add(mut self, c: f64) -> Self {
        self.re += c;
        self
    }
}
impl Sub<f64> for HyperDual2 {
    type Output = Self;
    fn sub(mut self, c: f64) -> Self {
        self.re -= c;
        self
    }
}
impl Mul<f64> for HyperDual2 {
    type Output = Self;
    fn mul(self, c: f64) -> Self {
        Self {
            re: self.re * c,
            g: [self.g[0] * c, self.g[1] * c],
            h: [self.h[0] * c, self.h[1] * c, self.h[2] * c],
        }
    }
}
impl Div<f64> for HyperDual2 {
    type Output = Self;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, c: f64) -> Self {
        self * (1.0 / c)
    }
}

impl Real for HyperDual2 {
    fn value(self) -> f64 {
        self.re
    }
    fn ln(self) -> Self {
        let x = self.re;
        self.chain(x.ln(), 1.0 / x, -1.0 / (x * x))
    }
    fn exp(self) -> Self {
        let e = self.re.exp();
        self.chain(e, e, e)
    }
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (s * self.re))
    }
    fn powi(self, n: i32) -> Self {
        let x = self.re;
        let nf = f64::from(n);
        self.chain(
            x.powi(n),
            nf * x.powi(n - 1),
            nf * (nf - 1.0) * x.powi(n - 2),
        )
    }
    fn recip(self) -> Self {
        let x = self.re;
        self.chain(1.0 / x, -1.0 / (x * x), 2.0 / (x * x * x))
    }
    fn lift(self, c: f64) -> Self {
        Self::constant(c)
    }
    fn sin(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(s, c, -s)
    }
    fn cos(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(c, -s, -c)
    }
    fn powf(self, p: f64) -> Self {
        let x = self.re;
        let xp = x.powf(p);
        self.chain(xp, p * xp / x, p * (p - 1.0) * xp / (x * x))
    }
}

impl Real for num_dual::Dual2SVec64<2> {
    fn value(self) -> f64 {
        self.re
    }
    fn ln(self) -> Self {
        num_dual::DualNum::ln(&self)
    }
    fn exp(self) -> Self {
        num_dual::DualNum::exp(&self)
    }
    fn sqrt(self) -> Self {
        num_dual::DualNum::sqrt(&self)
    }
    fn powi(self, n: i32) -> Self {
        num_dual::DualNum::powi(&self, n)
    }
    fn recip(self) -> Self {
        num_dual::DualNum::recip(&self)
    }
    fn sin(self) -> Self {
        num_dual::DualNum::sin(&self)
    }
    fn cos(self) -> Self {
        num_dual::DualNum::cos(&self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hyperdual_matches_hand_derivatives() {
        // f(x, y) = ln(x y²) + sqrt(x)/y + exp(x - y)
        let (x0, y0) = (1.7, 0.6);
        let x = HyperDual2::variable(x0, 0);
        let y = HyperDual2::variable(y0, 1);
        let f = (x * y.powi(2)).ln() + x.sqrt() / y + (x - y).exp();
        let e = (x0 - y0).exp();
        let fx = 1.0 / x0 + 0.5 / (x0.sqrt() * y0) + e;
        let fy = 2.0 / y0 - x0.sqrt() / (y0 * y0) - e;
        let fxx = -1.0 / (x0 * x0) - 0.25 / (x0.powf(1.5) * y0) + e;
        let fxy = -0.5 / (x0.sqrt() * y0 * y0) - e;
        let fyy = -2.0 / (y0 * y0) + 2.0 * x0.sqrt() / y0.powi(3) + e;
        let tol = 1e-13;
        assert!((f.g[0] - fx).abs() < tol * fx.abs().max(1.0));
        assert!((f.g[1] - fy).abs() < tol * fy.abs().max(1.0));
        assert!((f.h[0] - fxx).abs() < tol * fxx.abs().max(1.0));
        assert!((f.h[1] - fxy).abs() < tol * fxy.abs().max(1.0));
        assert!((f.h[2] - fyy).abs() < tol * fyy.abs().max(1.0));
    }
}
