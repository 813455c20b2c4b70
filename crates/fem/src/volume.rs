//! Exact enclosed volume of a closed bilinear-quad surface, with gradient and Hessian.
//!
//! ```text
//! V = Σ_e (1/3) ∫ x·(g1 × g2) dξdη            (2×2 Gauss is exact: degree 2 in ξ and in η)
//! ∂v/∂x_a = (1/3)[ N_a (g1×g2) + N_a,ξ (g2×x) + N_a,η (x×g1) ]
//! ∂²v/∂x_a∂x_b = (1/3)[ N_a(N_b,η [g1]× − N_b,ξ [g2]×) + N_a,ξ(N_b [g2]× − N_b,η [x]×)
//!                      + N_a,η(N_b,ξ [x]× − N_b [g1]×) ]      ([a]× v = a × v)
//! ```
//! The Hessian is symmetric (it is the Hessian of a scalar), so the pressure load stiffness
//! −p ∂²V/∂x² is symmetric as well.

use tubemem_mesh::{cross, dot, shape, tangents, GAUSS2};

fn skew(a: [f64; 3]) -> [[f64; 3]; 3] {
    [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]]
}

/// Volume contribution of one quad; fills its gradient (12) and, if asked, Hessian (144).
pub fn volume_kernel(
    x: &[[f64; 3]; 4],
    grad: &mut [f64; 12],
    mut hess: Option<&mut [f64; 144]>,
) -> f64 {
    grad.fill(0.0);
    if let Some(h) = hess.as_deref_mut() {
        h.fill(0.0);
    }
    let third = 1.0 / 3.0;
    let mut v = 0.0;
    for &(xi, eta) in &GAUSS2 {
        let (n, d) = shape(xi, eta);
        let (p, g1, g2) = tangents(x, xi, eta);
        let g12 = cross(g1, g2);
        v += third * dot(p, g12);
        let (g2x, xg1) = (cross(g2, p), cross(p, g1));
        for a in 0..4 {
            for k in 0..3 {
                grad[3 * a + k] += third * (n[a] * g12[k] + d[a][0] * g2x[k] + d[a][1] * xg1[k]);
            }
        }
        if let Some(h) = hess.as_deref_mut() {
            let (s1, s2, sx) = (skew(g1), skew(g2), skew(p));
            for a in 0..4 {
                for b in 0..4 {
                    for i in 0..3 {
                        for j in 0..3 {
                            let val = n[a] * (d[b][1] * s1[i][j] - d[b][0] * s2[i][j])
                                + d[a][0] * (n[b] * s2[i][j] - d[b][1] * sx[i][j])
                                + d[a][1] * (d[b][0] * sx[i][j] - n[b] * s1[i][j]);
                            h[(3 * a + i) * 12 + 3 * b + j] += third * val;
                        }
                    }
                }
            }
        }
    }
    v
}
