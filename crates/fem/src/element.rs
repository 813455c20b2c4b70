//! The 4-node membrane element (bilinear, 2×2 Gauss, finite strain, any law).
//!
//! ```text
//! Reference frame at a Gauss point: e1 = G1/|G1|, e3 = G1×G2/|G1×G2|, e2 = e3 × e1,
//! J_iα = e_i·G_α (2×2), ∂N_a/∂X_i = Σ_α ∂N_a/∂ξ_α (J⁻¹)_αi, dA0 = det J dξdη.
//! In-plane deformation gradient columns f_i = Σ_a x_a ∂N_a/∂X_i (3-vectors),
//! C_ij = f_i·f_j, (S, ℂ) = law(C)  (per unit μH).
//! r_a  = Σ_gp dA0 Σ_ij S_ij ∂N_a/∂X_i f_j
//! K_ab = Σ_gp dA0 [ B_aᵀ ℂ B_b + (Σ_ij S_ij ∂N_a/∂X_i ∂N_b/∂X_j) I₃ ]
//! B_a  = [ ∂N_a/∂X_1 f_1ᵀ ; ∂N_a/∂X_2 f_2ᵀ ; ∂N_a/∂X_1 f_2ᵀ + ∂N_a/∂X_2 f_1ᵀ ]  (Voigt 11, 22, 2·12)
//! ```

use crate::FemError;
use tubemem_material::{MaterialError, MembraneLaw};
use tubemem_mesh::{cross, dot, shape, GAUSS2};

/// Reference data of one element at its four Gauss points.
#[derive(Clone, Debug)]
pub struct RefElement {
    pub nodes: [usize; 4],
    /// ∂N_a/∂X_i in the local orthonormal reference frame, per Gauss point
    pub dn: [[[f64; 2]; 4]; 4],
    /// shape function values per Gauss point
    pub n: [[f64; 4]; 4],
    /// reference area weight dA0 per Gauss point
    pub w: [f64; 4],
    /// the local orthonormal reference frame (e1, e2) per Gauss point
    pub frame: [[[f64; 3]; 2]; 4],
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl RefElement {
    pub fn new(id: usize, nodes: [usize; 4], x: &[[f64; 3]; 4]) -> Result<Self, FemError> {
        let mut dn = [[[0.0; 2]; 4]; 4];
        let mut nv = [[0.0; 4]; 4];
        let mut w = [0.0; 4];
        let mut frame = [[[0.0; 3]; 2]; 4];
        for (g, &(xi, eta)) in GAUSS2.iter().enumerate() {
            let (n, d) = shape(xi, eta);
            let mut g1 = [0.0; 3];
            let mut g2 = [0.0; 3];
            for a in 0..4 {
                for k in 0..3 {
                    g1[k] += d[a][0] * x[a][k];
                    g2[k] += d[a][1] * x[a][k];
                }
            }
            let n3 = cross(g1, g2);
            let area = norm(n3);
            if !(area > 1e-14 * norm(g1) * norm(g2)) {
                return Err(FemError::DegenerateElement {
                    element: id,
                    gauss_point: g,
                });
            }
            let e1 = g1.map(|v| v / norm(g1));
            let e3 = n3.map(|v| v / area);
            let e2 = cross(e3, e1);
            // J = [[e1·G1, e1·G2], [e2·G1, e2·G2]]
            let j = [[dot(e1, g1), dot(e1, g2)], [dot(e2, g1), dot(e2, g2)]];
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            let inv = [
                [j[1][1] / det, -j[0][1] / det],
                [-j[1][0] / det, j[0][0] / det],
            ];
            for a in 0..4 {
                for i in 0..2 {
                    dn[g][a][i] = d[a][0] * inv[0][i] + d[a][1] * inv[1][i];
                }
            }
            nv[g] = n;
            w[g] = det;
            frame[g] = [e1, e2];
        }
        Ok(Self {
            nodes,
            frame,
            dn,
            n: nv,
            w,
        })
    }

    /// f_1, f_2 at Gauss point `g`.
    pub fn gradient(&self, g: usize, x: &[[f64; 3]; 4]) -> [[f64; 3]; 2] {
        let mut f = [[0.0; 3]; 2];
        for a in 0..4 {
            for i in 0..2 {
                for k in 0..3 {
                    f[i][k] += self.dn[g][a][i] * x[a][k];
                }
            }
        }
        f
    }
}

/// Energy (per μH), residual r (12) and, if asked, stiffness K (12×12 row-major) of one element.
/// On failure returns the Gauss point and the material error.
pub fn membrane_kernel(
    law: &dyn MembraneLaw,
    re: &RefElement,
    x: &[[f64; 3]; 4],
    r: &mut [f64; 12],
    mut k: Option<&mut [f64; 144]>,
) -> Result<f64, (usize, MaterialError)> {
    r.fill(0.0);
    if let Some(k) = k.as_deref_mut() {
        k.fill(0.0);
    }
    let mut energy = 0.0;
    for g in 0..4 {
        let f = re.gradient(g, x);
        let c = [dot(f[0], f[0]), dot(f[1], f[1]), dot(f[0], f[1])];
        let st = law.stress_tangent(c).map_err(|e| (g, e))?;
        let w = re.w[g];
        energy += w * st.w;
        let s = [[st.s[0], st.s[2]], [st.s[2], st.s[1]]];
        let dn = &re.dn[g];
        for a in 0..4 {
            for i in 0..2 {
                for j in 0..2 {
                    let coef = w * s[i][j] * dn[a][i];
                    for kk in 0..3 {
                        r[3 * a + kk] += coef * f[j][kk];
                    }
                }
            }
        }
        if let Some(k) = k.as_deref_mut() {
            let b = |a: usize| -> [[f64; 3]; 3] {
                let mut m = [[0.0; 3]; 3];
                for kk in 0..3 {
                    m[0][kk] = dn[a][0] * f[0][kk];
                    m[1][kk] = dn[a][1] * f[1][kk];
                    m[2][kk] = dn[a][0] * f[1][kk] + dn[a][1] * f[0][kk];
                }
                m
            };
            let bs: Vec<[[f64; 3]; 3]> = (0..4).map(b).collect();
            let d = st.tangent;
            for a in 0..4 {
                // DB_a = ℂ B_a (3×3)
                let mut db = [[0.0; 3]; 3];
                for p in 0..3 {
                    for kk in 0..3 {
                        db[p][kk] = (0..3).map(|q| d[p][q] * bs[a][q][kk]).sum();
                    }
                }
                for bb in 0..4 {
                    let geo: f64 = (0..2)
                        .map(|i| (0..2).map(|j| s[i][j] * dn[a][i] * dn[bb][j]).sum::<f64>())
                        .sum();
                    for ii in 0..3 {
                        for jj in 0..3 {
                            let mat: f64 = (0..3).map(|p| bs[bb][p][ii] * db[p][jj]).sum();
                            // K_(b,ii),(a,jj) = B_bᵀ ℂ B_a
                            let mut v = mat;
                            if ii == jj {
                                v += geo;
                            }
                            k[(3 * bb + ii) * 12 + 3 * a + jj] += w * v;
                        }
                    }
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
    pub cauchy: [[f64; 3]; 3],
    pub principal: [f64; 2],
}

pub fn point_state(
    law: &dyn MembraneLaw,
    re: &RefElement,
    g: usize,
    x: &[[f64; 3]; 4],
) -> Result<PointState, MaterialError> {
    let f = re.gradient(g, x);
    let c = [dot(f[0], f[0]), dot(f[1], f[1]), dot(f[0], f[1])];
    let st = law.stress_tangent(c)?;
    let (tr, det) = (c[0] + c[1], c[0] * c[1] - c[2] * c[2]);
    let disc = (0.25 * tr * tr - det).max(0.0).sqrt();
    let (l1, l2) = ((0.5 * tr + disc).sqrt(), (0.5 * tr - disc).max(0.0).sqrt());
    let j = det.sqrt();
    let s = [[st.s[0], st.s[2]], [st.s[2], st.s[1]]];
    let mut n = [[0.0; 3]; 3];
    for i in 0..2 {
        for jj in 0..2 {
            for p in 0..3 {
                for q in 0..3 {
                    n[p][q] += s[i][jj] * f[i][p] * f[jj][q] / j;
                }
            }
        }
    }
    // Principal values of N in the tangent plane: N = (1/J) F S Fᵀ has the eigenvalues of
    // (1/J) S C (mixed form).
    let sc = [
        [
            s[0][0] * c[0] + s[0][1] * c[2],
            s[0][0] * c[2] + s[0][1] * c[1],
        ],
        [
            s[1][0] * c[0] + s[1][1] * c[2],
            s[1][0] * c[2] + s[1][1] * c[1],
        ],
    ];
    let (t2, d2) = (
        sc[0][0] + sc[1][1],
        sc[0][0] * sc[1][1] - sc[0][1] * sc[1][0],
    );
    let disc2 = (0.25 * t2 * t2 - d2).max(0.0).sqrt();
    Ok(PointState {
        stretches: [l1, l2],
        cauchy: n,
        principal: [(0.5 * t2 + disc2) / j, (0.5 * t2 - disc2) / j],
    })
}
