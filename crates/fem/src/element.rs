//! The membrane kernel of the 4- and 9-node elements (finite strain, any law; N nodes, D = 3N
//! element dofs, both compile-time constants).
//!
//! ```text
//! C_ij = f_i·f_j,  (W, S, ℂ) = law(C)  (per unit μH; f_i from [`crate::geometry`])
//! r_a  = Σ_gp dA0 Σ_ij S_ij ∂N_a/∂X_i f_j
//! K_ba = Σ_gp dA0 [ B_bᵀ ℂ B_a + (Σ_ij S_ij ∂N_b/∂X_i ∂N_a/∂X_j) I₃ ]
//! B_a  = [ ∂N_a/∂X_1 f_1ᵀ ; ∂N_a/∂X_2 f_2ᵀ ; ∂N_a/∂X_1 f_2ᵀ + ∂N_a/∂X_2 f_1ᵀ ]  (Voigt 11, 22, 2·12)
//! ```

use crate::geometry::{RefElement, Vec3};
use nalgebra::{Matrix2, Matrix3, SMatrix, SVector};
use tubemem_material::{MaterialError, MembraneLaw, StressTangent};
pub use tubemem_mesh::volume::{Matrix12, Vector12};

/// The right Cauchy–Green components (C11, C22, C12) of the gradient columns f_1, f_2.
pub fn cauchy_green(f: &[Vec3; 2]) -> [f64; 3] {
    [f[0].dot(&f[0]), f[1].dot(&f[1]), f[0].dot(&f[1])]
}

/// One time step of a hereditary law at an element's Gauss points
/// ([`crate::memory`]): the base law's stress and tangent scaled by `alpha`, plus a stress
/// `offsets[g]` (Voigt 11, 22, 12) frozen over the step. Within the step the point is
/// hyperelastic with the energy α W(C) + ½ B:(C − I), so the residual is its gradient and the
/// tangent its Hessian.
#[derive(Clone, Copy, Debug)]
pub struct Hereditary<'a> {
    pub alpha: f64,
    pub offsets: &'a [[f64; 3]],
}

impl Hereditary<'_> {
    /// The step's stress, tangent and energy at Gauss point `g` from the base law's at `c`.
    pub fn apply(&self, g: usize, c: [f64; 3], base: StressTangent) -> StressTangent {
        let b = self.offsets[g];
        StressTangent {
            w: self.alpha * base.w
                + 0.5 * (b[0] * (c[0] - 1.0) + b[1] * (c[1] - 1.0) + 2.0 * b[2] * c[2]),
            s: std::array::from_fn(|k| self.alpha * base.s[k] + b[k]),
            tangent: base.tangent.map(|row| row.map(|v| self.alpha * v)),
        }
    }
}

/// Add the energy (per μH), residual r and, if asked, stiffness K of one element.
/// On failure returns the Gauss point and the material error.
pub fn membrane_kernel<const N: usize, const D: usize>(
    law: &dyn MembraneLaw,
    re: &RefElement<N>,
    xe: &[Vec3; N],
    r: &mut SVector<f64, D>,
    k: Option<&mut SMatrix<f64, D, D>>,
) -> Result<f64, (usize, MaterialError)> {
    membrane_kernel_in_step(law, None, re, xe, r, k)
}

/// [`membrane_kernel`] within a time step of a hereditary law (`hereditary`; `None`: the law
/// alone).
pub fn membrane_kernel_in_step<const N: usize, const D: usize>(
    law: &dyn MembraneLaw,
    hereditary: Option<Hereditary<'_>>,
    re: &RefElement<N>,
    xe: &[Vec3; N],
    r: &mut SVector<f64, D>,
    mut k: Option<&mut SMatrix<f64, D, D>>,
) -> Result<f64, (usize, MaterialError)> {
    const { assert!(D == 3 * N) };
    let mut energy = 0.0;
    for (g, gp) in re.gauss.iter().enumerate() {
        let f = re.gradient(g, xe);
        let c = cauchy_green(&f);
        let st = law.stress_tangent(c).map_err(|e| (g, e))?;
        let st = match hereditary {
            Some(h) => h.apply(g, c, st),
            None => st,
        };
        let w = gp.w;
        energy += w * st.w;
        let s = Matrix2::new(st.s[0], st.s[2], st.s[2], st.s[1]);
        let dn = &gp.dn;
        for a in 0..N {
            for i in 0..2 {
                for j in 0..2 {
                    let coef = w * s[(i, j)] * dn[a][i];
                    let mut ra = r.fixed_rows_mut::<3>(3 * a);
                    ra += f[j] * coef;
                }
            }
        }
        // a finite stress on a huge deformation can still overflow the forces
        if !(energy.is_finite() && r.iter().all(|v| v.is_finite())) {
            let c = cauchy_green(&f);
            return Err((
                g,
                MaterialError::non_finite(
                    law.name(),
                    "energy or internal force",
                    c[0] + c[1],
                    c[0] * c[1] - c[2] * c[2],
                ),
            ));
        }
        if let Some(k) = k.as_deref_mut() {
            let b: [Matrix3<f64>; N] = std::array::from_fn(|a| {
                Matrix3::from_rows(&[
                    (f[0] * dn[a][0]).transpose(),
                    (f[1] * dn[a][1]).transpose(),
                    (f[1] * dn[a][0] + f[0] * dn[a][1]).transpose(),
                ])
            });
            let d = Matrix3::from_fn(|p, q| st.tangent[p][q]);
            for a in 0..N {
                let db = d * b[a];
                for bb in 0..N {
                    let mut geo = 0.0;
                    for i in 0..2 {
                        let mut row = 0.0;
                        for j in 0..2 {
                            row += s[(i, j)] * dn[a][i] * dn[bb][j];
                        }
                        geo += row;
                    }
                    let mut block = b[bb].transpose() * db;
                    for ii in 0..3 {
                        block[(ii, ii)] += geo;
                    }
                    let mut kb = k.fixed_view_mut::<3, 3>(3 * bb, 3 * a);
                    kb += block * w;
                }
            }
        }
    }
    Ok(energy)
}

/// Principal stretches and principal Cauchy resultants (per μH) at a Gauss point, with the
/// full Cauchy resultant tensor N = J⁻¹ Σ_ij S_ij f_i ⊗ f_j (3×3, in the current tangent plane).
pub struct PointState {
    pub stretches: [f64; 2],
    pub cauchy: Matrix3<f64>,
    pub principal: [f64; 2],
}

pub fn point_state<const N: usize>(
    law: &dyn MembraneLaw,
    re: &RefElement<N>,
    g: usize,
    xe: &[Vec3; N],
) -> Result<PointState, MaterialError> {
    point_state_of(law, &re.gradient(g, xe))
}

/// [`point_state`] from the gradient columns f_1, f_2.
pub fn point_state_of(law: &dyn MembraneLaw, f: &[Vec3; 2]) -> Result<PointState, MaterialError> {
    point_state_in_step(law, None, f)
}

/// [`point_state_of`] at Gauss point `g` of a time step of a hereditary law (`hereditary`:
/// the step and the point; `None`: the law alone).
pub fn point_state_in_step(
    law: &dyn MembraneLaw,
    hereditary: Option<(Hereditary<'_>, usize)>,
    f: &[Vec3; 2],
) -> Result<PointState, MaterialError> {
    let c = cauchy_green(f);
    let st = law.stress_tangent(c)?;
    let st = match hereditary {
        Some((h, g)) => h.apply(g, c, st),
        None => st,
    };
    let (tr, det) = (c[0] + c[1], c[0] * c[1] - c[2] * c[2]);
    let disc = (0.25 * tr * tr - det).max(0.0).sqrt();
    let (l1, l2) = ((0.5 * tr + disc).sqrt(), (0.5 * tr - disc).max(0.0).sqrt());
    let j = det.sqrt();
    let s = Matrix2::new(st.s[0], st.s[2], st.s[2], st.s[1]);
    let mut n = Matrix3::zeros();
    for i in 0..2 {
        for jj in 0..2 {
            n += f[i] * f[jj].transpose() * (s[(i, jj)] / j);
        }
    }
    // Principal values of N in the tangent plane: N = (1/J) F S Fᵀ has the eigenvalues of
    // (1/J) S C (mixed form).
    // scaled by its largest entry, so that squares of large resultants cannot overflow
    let sc = s * Matrix2::new(c[0], c[2], c[2], c[1]);
    // (only where they are large: an ordinary state is computed as it always was)
    let scale = if sc.amax() > 1e150 { sc.amax() } else { 1.0 };
    let sc = sc / scale;
    let (t2, d2) = (sc.trace(), sc.determinant());
    let disc2 = (0.25 * t2 * t2 - d2).max(0.0).sqrt();
    let principal = [
        (0.5 * t2 + disc2) * scale / j,
        (0.5 * t2 - disc2) * scale / j,
    ];
    if !(n.iter().all(|v| v.is_finite()) && principal.iter().all(|v| v.is_finite())) {
        return Err(MaterialError::non_finite(law.name(), "resultant", tr, det));
    }
    Ok(PointState {
        stretches: [l1, l2],
        cauchy: n,
        principal,
    })
}
