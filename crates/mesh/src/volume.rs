//! Exact enclosed volume of a closed bilinear-quad surface, with gradient and Hessian: the one
//! implementation, used by the mesh checks, the FE loading and the output.
//!
//! ```text
//! V = Σ_e (1/3) ∫ x·(g1 × g2) dξdη            (2×2 Gauss is exact: degree 2 in ξ and in η)
//! ∂v/∂x_a = (1/3)[ N_a (g1×g2) + N_a,ξ (g2×x) + N_a,η (x×g1) ]
//! ∂²v/∂x_a∂x_b = (1/3)[ N_a(N_b,η [g1]× − N_b,ξ [g2]×) + N_a,ξ(N_b [g2]× − N_b,η [x]×)
//!                      + N_a,η(N_b,ξ [x]× − N_b [g1]×) ]      ([a]× v = a × v)
//!              = (1/3)[ c1 g1 + c2 g2 + c3 x ]×,  c1 = N_a N_b,η − N_a,η N_b,
//!                c2 = N_a,ξ N_b − N_a N_b,ξ,  c3 = N_a,η N_b,ξ − N_a,ξ N_b,η
//! ```
//! The Hessian is symmetric (it is the Hessian of a scalar), so the pressure load stiffness
//! −p ∂²V/∂x² is symmetric as well. For a symmetry-reduced mesh the formula gives the volume of
//! the reduced part: the missing closing faces lie on planes through the origin, where x·n = 0.

use crate::{shape, GAUSS2};
use nalgebra::{SMatrix, SVector, Vector3};

/// 12 element dofs (4 nodes × 3 components, node-major).
pub type Vector12 = SVector<f64, 12>;
/// 12 × 12 element matrix.
pub type Matrix12 = SMatrix<f64, 12, 12>;

/// Position and tangent vectors g1 = ∂x/∂ξ, g2 = ∂x/∂η of a bilinear quad at (ξ, η).
pub fn tangents(x: &[Vector3<f64>; 4], xi: f64, eta: f64) -> [Vector3<f64>; 3] {
    let (n, d) = shape(xi, eta);
    tangents_with(x, &n, &d)
}

/// [`tangents`] from shape-function values and derivatives already at hand.
#[inline]
fn tangents_with(x: &[Vector3<f64>; 4], n: &[f64; 4], d: &[[f64; 2]; 4]) -> [Vector3<f64>; 3] {
    let mut out = [Vector3::zeros(); 3];
    for a in 0..4 {
        out[0] += x[a] * n[a];
        out[1] += x[a] * d[a][0];
        out[2] += x[a] * d[a][1];
    }
    out
}

/// Volume contribution of one quad, (1/3) ∫ x·(g1 × g2) dξdη; adds its gradient and Hessian
/// into `grad` and `hess` when asked (the caller zeroes them).
pub fn volume_kernel(
    x: &[Vector3<f64>; 4],
    mut grad: Option<&mut Vector12>,
    mut hess: Option<&mut Matrix12>,
) -> f64 {
    let third = 1.0 / 3.0;
    let mut v = 0.0;
    for &(xi, eta) in &GAUSS2 {
        let (n, d) = shape(xi, eta);
        let [p, g1, g2] = tangents_with(x, &n, &d);
        let g12 = g1.cross(&g2);
        v += third * p.dot(&g12);
        if let Some(grad) = grad.as_deref_mut() {
            let (g2x, xg1) = (g2.cross(&p), p.cross(&g1));
            for a in 0..4 {
                let ga = g12 * n[a] + g2x * d[a][0] + xg1 * d[a][1];
                let mut block = grad.fixed_rows_mut::<3>(3 * a);
                block += ga * third;
            }
        }
        if let Some(h) = hess.as_deref_mut() {
            // Each block is a cross-product matrix: collecting the three skew terms,
            // ∂²v/∂x_a∂x_b = (1/3) [c1 g1 + c2 g2 + c3 x]×, with
            // c1 = N_a N_b,η − N_a,η N_b, c2 = N_a,ξ N_b − N_a N_b,ξ, c3 = N_a,η N_b,ξ − N_a,ξ N_b,η.
            for a in 0..4 {
                for b in 0..4 {
                    let c1 = n[a] * d[b][1] - d[a][1] * n[b];
                    let c2 = d[a][0] * n[b] - n[a] * d[b][0];
                    let c3 = d[a][1] * d[b][0] - d[a][0] * d[b][1];
                    let v = (g1 * c1 + g2 * c2 + p * c3) * third;
                    let (r, c) = (3 * a, 3 * b);
                    h[(r, c + 1)] -= v[2];
                    h[(r, c + 2)] += v[1];
                    h[(r + 1, c)] += v[2];
                    h[(r + 1, c + 2)] -= v[0];
                    h[(r + 2, c)] -= v[1];
                    h[(r + 2, c + 1)] += v[0];
                }
            }
        }
    }
    v
}

/// The volume contribution of one quad given as plain coordinates.
pub fn quad_volume(x: &[[f64; 3]; 4]) -> f64 {
    let xv = [
        Vector3::from(x[0]),
        Vector3::from(x[1]),
        Vector3::from(x[2]),
        Vector3::from(x[3]),
    ];
    volume_kernel(&xv, None, None)
}
