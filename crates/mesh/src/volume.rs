//! Exact enclosed volume of a closed surface of bilinear (or biquadratic) quads, with gradient and Hessian: the one
//! implementation, used by the mesh checks, the FE loading and the output.
//!
//! ```text
//! V = Σ_e (1/3) ∫ x·(g1 × g2) dξdη            (2×2 Gauss is exact: degree 2 in ξ and in η;
//!                                              3×3 for the 9-node element: degree 5)
//! ∂v/∂x_a = (1/3)[ N_a (g1×g2) + N_a,ξ (g2×x) + N_a,η (x×g1) ]
//! ∂²v/∂x_a∂x_b = (1/3)[ N_a(N_b,η [g1]× − N_b,ξ [g2]×) + N_a,ξ(N_b [g2]× − N_b,η [x]×)
//!                      + N_a,η(N_b,ξ [x]× − N_b [g1]×) ]      ([a]× v = a × v)
//!              = (1/3)[ c1 g1 + c2 g2 + c3 x ]×,  c1 = N_a N_b,η − N_a,η N_b,
//!                c2 = N_a,ξ N_b − N_a N_b,ξ,  c3 = N_a,η N_b,ξ − N_a,ξ N_b,η
//! ```
//! The Hessian is symmetric (it is the Hessian of a scalar), so the pressure load stiffness
//! −p ∂²V/∂x² is symmetric as well. For a symmetry-reduced mesh the formula gives the volume of
//! the reduced part: the missing closing faces lie on planes through the origin, where x·n = 0.

use crate::shape;
use crate::shape::{full_rule, shape_n};
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

/// Position and tangent vectors of the N-node element at (ξ, η).
pub fn tangents_n<const N: usize>(x: &[Vector3<f64>; N], xi: f64, eta: f64) -> [Vector3<f64>; 3] {
    let (n, d) = shape_n::<N>(xi, eta);
    tangents_with(x, &n, &d)
}

/// [`tangents`] from shape-function values and derivatives already at hand.
#[inline]
fn tangents_with<const N: usize>(
    x: &[Vector3<f64>; N],
    n: &[f64; N],
    d: &[[f64; 2]; N],
) -> [Vector3<f64>; 3] {
    let mut out = [Vector3::zeros(); 3];
    for a in 0..N {
        out[0] += x[a] * n[a];
        out[1] += x[a] * d[a][0];
        out[2] += x[a] * d[a][1];
    }
    out
}

/// Volume contribution of one bilinear quad, (1/3) ∫ x·(g1 × g2) dξdη; adds its gradient and
/// Hessian into `grad` and `hess` when asked (the caller zeroes them).
pub fn volume_kernel(
    x: &[Vector3<f64>; 4],
    grad: Option<&mut Vector12>,
    hess: Option<&mut Matrix12>,
) -> f64 {
    volume_kernel_n::<4, 12>(x, grad, hess)
}

/// [`volume_kernel`] for the N-node element with D = 3N dofs, with its full rule (exact: the
/// integrand is of degree 2 (N = 4) or 5 (N = 9) in each of ξ, η).
pub fn volume_kernel_n<const N: usize, const D: usize>(
    x: &[Vector3<f64>; N],
    mut grad: Option<&mut SVector<f64, D>>,
    mut hess: Option<&mut SMatrix<f64, D, D>>,
) -> f64 {
    const { assert!(D == 3 * N) };
    let third = 1.0 / 3.0;
    let mut v = 0.0;
    for &(xi, eta, w) in full_rule::<N>() {
        // w = 1 for the 2 × 2 rule: third * w is third, bit for bit
        let tw = third * w;
        let (n, d) = shape_n::<N>(xi, eta);
        let [p, g1, g2] = tangents_with(x, &n, &d);
        let g12 = g1.cross(&g2);
        v += tw * p.dot(&g12);
        if let Some(grad) = grad.as_deref_mut() {
            let (g2x, xg1) = (g2.cross(&p), p.cross(&g1));
            for a in 0..N {
                let ga = g12 * n[a] + g2x * d[a][0] + xg1 * d[a][1];
                let mut block = grad.fixed_rows_mut::<3>(3 * a);
                block += ga * tw;
            }
        }
        if let Some(h) = hess.as_deref_mut() {
            // Each block is a cross-product matrix: collecting the three skew terms,
            // ∂²v/∂x_a∂x_b = (1/3) [c1 g1 + c2 g2 + c3 x]×, with
            // c1 = N_a N_b,η − N_a,η N_b, c2 = N_a,ξ N_b − N_a N_b,ξ, c3 = N_a,η N_b,ξ − N_a,ξ N_b,η.
            for a in 0..N {
                for b in 0..N {
                    let c1 = n[a] * d[b][1] - d[a][1] * n[b];
                    let c2 = d[a][0] * n[b] - n[a] * d[b][0];
                    let c3 = d[a][1] * d[b][0] - d[a][0] * d[b][1];
                    let v = (g1 * c1 + g2 * c2 + p * c3) * tw;
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

/// The volume contribution of one 9-node element given as plain coordinates.
pub fn quad9_volume(x: &[[f64; 3]; 9]) -> f64 {
    volume_kernel_n::<9, 27>(&x.map(Vector3::from), None, None)
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
