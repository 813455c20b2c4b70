//! The Langevin function L(β) = coth β − 1/β and its inverse, with the derivatives the
//! Arruda–Boyce law needs.
//!
//! **Inverse evaluation (exact, not an approximant).** β = L⁻¹(y), 0 ≤ y < 1, is the root of
//! L(β) − y, found by Newton's method from Cohen's Padé approximant β₀ = y (3 − y²)/(1 − y²)
//! (Cohen 1991, *Rheol. Acta* 30), kept inside the bracket [3y, 3y/(1 − y²)]-type bounds by
//! bisection when a step leaves the current bracket, and stopped when the step is below
//! 4 ε β. L is concave and increasing on β > 0, so Newton converges monotonically from either
//! side; in practice 3–5 steps. For |β| < 1 the Langevin function and its derivatives are
//! evaluated from their Taylor series (18 terms, truncation below 1e-17 relative), avoiding
//! the cancellation of coth β − 1/β.

/// The Taylor coefficients of L: L(x) = Σ_{n≥1} c_n x^{2n−1}, c_n = 2^{2n} B_{2n}/(2n)! (B the
/// Bernoulli numbers; from x coth x = Σ 2^{2n} B_{2n} x^{2n}/(2n)!, radius π). 18 terms reach
/// |c_18| ≈ 2.5e-18: below 1e-17 relative for |x| < 1.
const SERIES: [f64; 18] = [
    0.3333333333333333,
    -0.022222222222222223,
    0.0021164021164021165,
    -0.00021164021164021165,
    2.1377799155576935e-05,
    -2.1644042808063972e-06,
    2.1925947851873778e-07,
    -2.2214608789979678e-08,
    2.2507846516808994e-09,
    -2.2805151204592183e-10,
    2.3106432599002624e-11,
    -2.3411706819824882e-12,
    2.3721017400233653e-13,
    -2.4034415333307705e-14,
    2.4351954029183367e-15,
    -2.4673688045172075e-16,
    2.499967277122081e-17,
    -2.532996435740635e-18,
];

/// L(β), L'(β), L''(β): the series for |β| < 1 (no cancellation), coth β − 1/β and its
/// derivatives beyond (their cancellation costs at most about 3ε/β² ≤ 3ε there).
pub fn langevin(beta: f64) -> [f64; 3] {
    let x = beta;
    if x.abs() < 1.0 {
        let x2 = x * x;
        let (mut l, mut l1, mut l2) = (0.0, 0.0, 0.0);
        for (k, c) in SERIES.iter().enumerate().rev() {
            let p = (2 * k + 1) as f64; // the power of x in L's term
            l = l * x2 + c;
            l1 = l1 * x2 + c * p;
            l2 = l2 * x2 + c * p * (p - 1.0);
        }
        // L = x Σ c x^{2k}, L' = Σ c p x^{2k}, L'' = Σ c p (p − 1) x^{2k−1} (k ≥ 1)
        return [x * l, l1, l2 / x.max(f64::MIN_POSITIVE).copysign(x)];
    }
    // coth and csch² from t = e^{−2|x|}, which neither overflows nor cancels for |x| ≥ 1
    let t = (-2.0 * x.abs()).exp();
    let coth = ((1.0 + t) / (1.0 - t)).copysign(x);
    let csch2 = 4.0 * t / ((1.0 - t) * (1.0 - t));
    [
        coth - 1.0 / x,
        1.0 / (x * x) - csch2,
        -2.0 / (x * x * x) + 2.0 * coth * csch2,
    ]
}

/// β = L⁻¹(y) for 0 ≤ y < 1 (None outside), with dβ/dy and d²β/dy².
pub fn inverse_langevin(y: f64) -> Option<[f64; 3]> {
    if !(0.0..1.0).contains(&y) {
        return None;
    }
    if y == 0.0 {
        return Some([0.0, 3.0, 0.0]);
    }
    // bracket: L(β) < y below the root, > y above it; L(β) ≥ 1 − 1/β gives β ≤ 1/(1 − y)
    let (mut lo, mut hi): (f64, f64) = (0.0, 1.0 / (1.0 - y) + 1.0);
    let mut b = y * (3.0 - y * y) / (1.0 - y * y);
    for _ in 0..100 {
        let [l, l1, _] = langevin(b);
        let f = l - y;
        if f > 0.0 {
            hi = hi.min(b);
        } else {
            lo = lo.max(b);
        }
        let mut next = b - f / l1;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let done = (next - b).abs() <= 4.0 * f64::EPSILON * b;
        b = next;
        if done {
            break;
        }
    }
    let [_, l1, l2] = langevin(b);
    let d1 = 1.0 / l1;
    Some([b, d1, -l2 * d1 * d1 * d1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_langevin_inverts_and_its_derivatives_match_differences() {
        for &y in &[1e-6, 0.01, 0.05, 0.2, 0.5, 0.8, 0.95, 0.999] {
            let [b, d1, d2] = inverse_langevin(y).unwrap();
            let [l, _, _] = langevin(b);
            assert!(
                (l - y).abs() <= 4.0 * f64::EPSILON * y.max(1e-300) + 1e-300,
                "{y}"
            );
            // against coth − 1/β evaluated directly where it has no cancellation
            if b > 1.0 {
                assert!(((1.0 / b.tanh() - 1.0 / b) - y).abs() < 1e-14);
            }
            let h = 1e-6 * y.max(1e-3).min(1.0 - y);
            let f = |y: f64| inverse_langevin(y).unwrap()[0];
            let fd1 = (f(y + h) - f(y - h)) / (2.0 * h);
            assert!((d1 - fd1).abs() < 1e-6 * d1.abs(), "{y}: {d1} vs {fd1}");
            if y < 0.01 {
                // the FD of β' loses its digits here: the series β = 3y + 9y³/5 + 297y⁵/175
                // (Cohen 1991) gives β'' = 54y/5 + 1188y³/35
                let want = 54.0 * y / 5.0 + 1188.0 * y.powi(3) / 35.0;
                assert!((d2 - want).abs() < 1e-6 * want, "{y}: {d2} vs {want}");
            } else {
                let g = |y: f64| inverse_langevin(y).unwrap()[1];
                let fd2 = (g(y + h) - g(y - h)) / (2.0 * h);
                assert!((d2 - fd2).abs() < 1e-5 * d2.abs(), "{y}: {d2} vs {fd2}");
            }
        }
        // the series and the closed form agree where they meet
        let (a, b) = (langevin(0.9999999), langevin(1.0000001));
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-6, "{k}");
        }
        assert!(inverse_langevin(1.0).is_none() && inverse_langevin(-0.1).is_none());
    }
}
