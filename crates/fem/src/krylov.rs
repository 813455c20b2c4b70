//! Right-preconditioned GMRES (Saad & Schultz 1986; Saad, *Iterative Methods for Sparse Linear
//! Systems*, §9.3.2), without restarts, for reusing a factor of a nearby matrix.
//!
//! The tangent of a membrane under pressure is symmetric but may be indefinite, and so is its
//! LDLᵀ factor: MINRES needs a definite preconditioner and CG a definite operator, so neither
//! fits; GMRES takes any nonsingular pair. With the preconditioner on the right, the residual
//! it minimizes is the true residual ‖b − A x‖ of the unpreconditioned system, and that is
//! what the tolerance is judged on.
//!
//! Every operation is sequential and in a fixed order, so the result does not depend on the
//! number of threads.

/// What a GMRES solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KrylovReport {
    /// Krylov iterations (applications of the operator and of the preconditioner)
    pub iterations: usize,
    /// ‖b − A x‖ / ‖b‖ at return (the Arnoldi recurrence's value, which equals the true
    /// residual in exact arithmetic)
    pub relative_residual: f64,
    /// whether `relative_residual ≤ tolerance`
    pub converged: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solve A x = b from x = 0 by right-preconditioned GMRES with at most `max_iterations`
/// iterations, to ‖b − A x‖ ≤ `tolerance` ‖b‖. `apply(v, out)` sets out = A v;
/// `precondition(v)` replaces v by M⁻¹ v. On return `b` holds x (the best iterate found,
/// converged or not).
pub fn gmres(
    b: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
    mut apply: impl FnMut(&[f64], &mut [f64]),
    mut precondition: impl FnMut(&mut [f64]),
) -> KrylovReport {
    let n = b.len();
    let beta = dot(b, b).sqrt();
    if beta == 0.0 || max_iterations == 0 {
        let relative_residual = if beta == 0.0 { 0.0 } else { 1.0 };
        b.iter_mut().for_each(|v| *v = 0.0);
        return KrylovReport {
            iterations: 0,
            relative_residual,
            converged: beta == 0.0,
        };
    }
    // the Arnoldi basis V, the Hessenberg matrix H (column j has j + 2 entries) reduced by
    // Givens rotations (c, s) as it is built, and the rotated right-hand side g
    let mut basis: Vec<Vec<f64>> = vec![b.iter().map(|v| v / beta).collect()];
    let mut h: Vec<Vec<f64>> = Vec::new();
    let mut rotations: Vec<(f64, f64)> = Vec::new();
    let mut g = vec![beta];
    let mut z = vec![0.0; n];
    let mut w = vec![0.0; n];
    let mut relative_residual = 1.0;
    let mut iterations = 0;
    for j in 0..max_iterations {
        z.copy_from_slice(&basis[j]);
        precondition(&mut z);
        apply(&z, &mut w);
        // modified Gram–Schmidt
        let mut col = Vec::with_capacity(j + 2);
        for v in &basis {
            let hij = dot(&w, v);
            for (wk, vk) in w.iter_mut().zip(v) {
                *wk -= hij * vk;
            }
            col.push(hij);
        }
        let norm = dot(&w, &w).sqrt();
        col.push(norm);
        for (i, &(c, s)) in rotations.iter().enumerate() {
            let (a, b) = (col[i], col[i + 1]);
            col[i] = c * a + s * b;
            col[i + 1] = -s * a + c * b;
        }
        let (a, b) = (col[j], col[j + 1]);
        let r = a.hypot(b);
        let (c, s) = if r == 0.0 { (1.0, 0.0) } else { (a / r, b / r) };
        col[j] = r;
        col[j + 1] = 0.0;
        rotations.push((c, s));
        let gj = g[j];
        g[j] = c * gj;
        g.push(-s * gj);
        h.push(col);
        iterations = j + 1;
        relative_residual = g[j + 1].abs() / beta;
        if relative_residual <= tolerance || norm == 0.0 || !relative_residual.is_finite() {
            break;
        }
        basis.push(w.iter().map(|v| v / norm).collect());
    }
    // y = H⁻¹ g (upper triangular), x = M⁻¹ V y
    let k = iterations;
    let mut y = vec![0.0; k];
    for i in (0..k).rev() {
        let mut s = g[i];
        for (jj, yj) in y.iter().enumerate().skip(i + 1) {
            s -= h[jj][i] * yj;
        }
        y[i] = if h[i][i] == 0.0 { 0.0 } else { s / h[i][i] };
    }
    z.iter_mut().for_each(|v| *v = 0.0);
    for (v, yj) in basis.iter().zip(&y) {
        for (zk, vk) in z.iter_mut().zip(v) {
            *zk += yj * vk;
        }
    }
    precondition(&mut z);
    b.copy_from_slice(&z);
    KrylovReport {
        iterations,
        relative_residual,
        converged: relative_residual <= tolerance,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The indefinite tridiagonal A = tridiag(−1, d_i, −1) with d
    /// alternating in sign, preconditioned by the exact inverse of a nearby matrix (its
    /// diagonal): GMRES reaches 1e-12 of ‖b‖ and the solution of a dense elimination.
    #[test]
    fn gmres_solves_an_indefinite_system_to_its_tolerance() {
        let n = 40;
        let d: Vec<f64> = (0..n)
            .map(|i| {
                if i % 3 == 0 {
                    -4.0
                } else {
                    3.0 + i as f64 * 0.1
                }
            })
            .collect();
        let apply = |v: &[f64], out: &mut [f64]| {
            for i in 0..n {
                let mut s = d[i] * v[i];
                if i > 0 {
                    s -= v[i - 1];
                }
                if i + 1 < n {
                    s -= v[i + 1];
                }
                out[i] = s;
            }
        };
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        // the reference: dense Gaussian elimination with partial pivoting
        let mut a = vec![vec![0.0; n + 1]; n];
        for i in 0..n {
            let mut e = vec![0.0; n];
            e[i] = 1.0;
            let mut col = vec![0.0; n];
            apply(&e, &mut col);
            for r in 0..n {
                a[r][i] = col[r];
            }
            a[i][n] = b[i];
        }
        for k in 0..n {
            let p = (k..n)
                .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
                .unwrap();
            a.swap(k, p);
            for i in k + 1..n {
                let f = a[i][k] / a[k][k];
                for j in k..=n {
                    a[i][j] -= f * a[k][j];
                }
            }
        }
        let mut exact = vec![0.0; n];
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|j| a[i][j] * exact[j]).sum();
            exact[i] = (a[i][n] - s) / a[i][i];
        }
        let mut x = b.clone();
        let report = gmres(&mut x, 1e-12, n, apply, |v| {
            for (vi, di) in v.iter_mut().zip(&d) {
                *vi /= di;
            }
        });
        assert!(report.converged, "{report:?}");
        assert!(report.iterations < n, "{report:?}");
        // the true residual, not the recurrence's: equal in exact arithmetic, so within 10× of
        // the tolerance (rounding of 40-term products)
        let mut ax = vec![0.0; n];
        apply(&x, &mut ax);
        let r: f64 = ax
            .iter()
            .zip(&b)
            .map(|(p, q)| (p - q) * (p - q))
            .sum::<f64>();
        let bn: f64 = b.iter().map(|v| v * v).sum::<f64>();
        assert!(
            (r / bn).sqrt() <= 1e-11,
            "true residual {}",
            (r / bn).sqrt()
        );
        // ‖x − x*‖ ≤ cond(A) ‖b − Ax‖/‖b‖ ‖x*‖, and Gershgorin puts every eigenvalue of the
        // symmetric A within 2 of a d_i, so |λ| ∈ [1, 8.8] and cond(A) ≤ 8.8; 1e-14 more for
        // the rounding of the elimination that gives x*
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let err: Vec<f64> = x.iter().zip(&exact).map(|(p, q)| p - q).collect();
        let bound = 8.8 * (r / bn).sqrt() * norm(&exact) + 1e-14;
        assert!(
            norm(&err) <= bound,
            "error {:e} above {bound:e}",
            norm(&err)
        );
    }

    /// With the exact inverse as preconditioner GMRES converges in one iteration; with an
    /// iteration limit below what the system needs it reports not converged, and what it
    /// returns is still its best iterate (the residual fell).
    #[test]
    fn gmres_with_the_exact_inverse_takes_one_iteration_and_reports_its_limit() {
        let n = 30;
        let apply = |v: &[f64], out: &mut [f64]| {
            for i in 0..n {
                out[i] = (i as f64 + 1.0) * v[i];
            }
        };
        let mut x: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let report = gmres(&mut x, 1e-14, 5, apply, |v| {
            for (i, vi) in v.iter_mut().enumerate() {
                *vi /= i as f64 + 1.0;
            }
        });
        assert_eq!(report.iterations, 1);
        // x = M⁻¹ V y: a division and a product per entry from the exact answer 1
        assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-14));
        // unpreconditioned, 30 distinct eigenvalues: 3 iterations do not reach 1e-14
        let b: Vec<f64> = vec![1.0; n];
        let mut x = b.clone();
        let report = gmres(&mut x, 1e-14, 3, apply, |_| {});
        assert!(!report.converged);
        assert_eq!(report.iterations, 3);
        assert!(report.relative_residual < 1.0);
        let mut ax = vec![0.0; n];
        apply(&x, &mut ax);
        let r = ax
            .iter()
            .zip(&b)
            .map(|(p, q)| (p - q) * (p - q))
            .sum::<f64>()
            .sqrt()
            / (n as f64).sqrt();
        // the recurrence's residual is the true one up to the rounding of 30-term sums
        assert!(
            (r - report.relative_residual).abs() < 1e-12,
            "{r} vs {report:?}"
        );
    }
}
