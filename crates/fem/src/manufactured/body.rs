//! The manufactured body force b (per reference area) and the exact state at a point of the
//! reference surface; the body force as a force term of the model.
//!
//! At a surface point, the chart X(ξ) and x*(X(ξ)) are evaluated on second-order dual numbers
//! in (ξ1, ξ2) ([`HyperDual2`]): their values, first and second derivatives. Every quantity of
//! the divergence is then carried with its first derivatives in ξ (a small dual type): the metrics G_{αβ},
//! C_{αβ}, the invariants a = G^{αβ} C_{αβ}, b = det C_{αβ}/det G_{αβ}, the law's W_a, W_b
//! (whose ξ-derivatives are W_aa a' + W_ab b' and W_ab a' + W_bb b', from the law's own second
//! derivatives), S^{αβ}, and Q^β = √G S^{αβ} x_{,α}; then b = −(1/√G) Σ_β ∂_β Q^β − p n_A with
//! n_A = (x_{,1} × x_{,2})/√G. A field pressed against planes ([`Field::contact_traction`])
//! has the planes' traction t_c removed too (b − t_c: the body force and the planes together
//! hold x*).

use super::field::Field;
use super::surface::CappedTube;
use crate::term::{ElementAt, ElementTerm};
use crate::FemError;
use nalgebra::{SMatrix, SVector};
use std::ops::{Add, Div, Mul, Sub};
use std::sync::atomic::{AtomicU64, Ordering};
use tubemem_material::dual::HyperDual2;
use tubemem_material::{MaterialError, MembraneLaw};

/// A value with its derivatives in (ξ1, ξ2).
#[derive(Clone, Copy, Debug)]
struct D {
    v: f64,
    d: [f64; 2],
}

impl D {
    fn c(v: f64) -> Self {
        D { v, d: [0.0; 2] }
    }
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        D {
            v: s,
            d: [0.5 * self.d[0] / s, 0.5 * self.d[1] / s],
        }
    }
}
impl Add for D {
    type Output = D;
    fn add(self, o: D) -> D {
        D {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1]],
        }
    }
}
impl Sub for D {
    type Output = D;
    fn sub(self, o: D) -> D {
        D {
            v: self.v - o.v,
            d: [self.d[0] - o.d[0], self.d[1] - o.d[1]],
        }
    }
}
impl Mul for D {
    type Output = D;
    fn mul(self, o: D) -> D {
        D {
            v: self.v * o.v,
            d: [
                self.v * o.d[0] + self.d[0] * o.v,
                self.v * o.d[1] + self.d[1] * o.v,
            ],
        }
    }
}
impl Div for D {
    type Output = D;
    fn div(self, o: D) -> D {
        let inv = 1.0 / o.v;
        D {
            v: self.v * inv,
            d: [
                (self.d[0] - self.v * inv * o.d[0]) * inv,
                (self.d[1] - self.v * inv * o.d[1]) * inv,
            ],
        }
    }
}
impl Mul<f64> for D {
    type Output = D;
    fn mul(self, c: f64) -> D {
        D {
            v: self.v * c,
            d: [self.d[0] * c, self.d[1] * c],
        }
    }
}

/// A surface map's value, tangents X_{,α} and second derivatives X_{,αβ} (00, 01, 11) at ξ = 0.
#[derive(Clone, Copy, Debug)]
pub struct Jet2 {
    pub x: [f64; 3],
    pub t: [[f64; 3]; 2],
    pub h: [[f64; 3]; 3],
}

impl Jet2 {
    fn of(v: [HyperDual2; 3]) -> Self {
        Jet2 {
            x: v.map(|c| c.re),
            t: [v.map(|c| c.g[0]), v.map(|c| c.g[1])],
            h: [v.map(|c| c.h[0]), v.map(|c| c.h[1]), v.map(|c| c.h[2])],
        }
    }
    /// X_{,αβ}
    fn second(&self, a: usize, b: usize) -> [f64; 3] {
        self.h[a + b]
    }
    /// The tangent X_{,α} with its ξ-derivatives.
    fn tangent(&self, a: usize) -> [D; 3] {
        std::array::from_fn(|i| D {
            v: self.t[a][i],
            d: [self.second(a, 0)[i], self.second(a, 1)[i]],
        })
    }
}

fn dot(a: &[D; 3], b: &[D; 3]) -> D {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The exact state at a point of the reference surface.
#[derive(Clone, Copy, Debug)]
pub struct Exact {
    /// x*(X)
    pub x: [f64; 3],
    /// the principal Cauchy resultants N1 ≥ N2 (per μH)
    pub resultants: [f64; 2],
    /// the body force per reference area (with the pressure's and the planes' shares removed)
    pub body_force: [f64; 3],
    /// the traction the planes supply per reference area
    pub contact: [f64; 3],
}

/// The manufactured problem: a field on the exact capped tube, a law and a pressure.
pub struct Manufactured<'a, F: Field> {
    pub field: &'a F,
    pub surface: CappedTube,
    pub law: &'a dyn MembraneLaw,
    pub pressure: f64,
}

/// The principal stretches² of a 2D right Cauchy–Green tensor with invariants (a, b).
fn principal(a: f64, b: f64) -> (f64, f64) {
    let d = (0.25 * a * a - b).max(0.0).sqrt();
    (0.5 * a + d, (0.5 * a - d).max(0.0))
}

impl<F: Field> Manufactured<'_, F> {
    /// The chart and the field at the surface point `at`, with derivatives.
    pub fn jets(&self, at: [f64; 3]) -> (Jet2, Jet2) {
        let xi = [HyperDual2::variable(0.0, 0), HyperDual2::variable(0.0, 1)];
        let big = self.surface.chart(at, xi);
        let small = self.field.map(big);
        (Jet2::of(big), Jet2::of(small))
    }

    /// The exact state at the surface point `at`.
    pub fn exact(&self, at: [f64; 3]) -> Result<Exact, MaterialError> {
        let (gx, fx) = self.jets(at);
        let (gt, xt) = (
            [gx.tangent(0), gx.tangent(1)],
            [fx.tangent(0), fx.tangent(1)],
        );
        // metrics with their ξ-derivatives
        let g = [
            [dot(&gt[0], &gt[0]), dot(&gt[0], &gt[1])],
            [dot(&gt[1], &gt[0]), dot(&gt[1], &gt[1])],
        ];
        let c = [
            [dot(&xt[0], &xt[0]), dot(&xt[0], &xt[1])],
            [dot(&xt[1], &xt[0]), dot(&xt[1], &xt[1])],
        ];
        let det_g = g[0][0] * g[1][1] - g[0][1] * g[1][0];
        let det_c = c[0][0] * c[1][1] - c[0][1] * c[1][0];
        let ginv = [
            [g[1][1] / det_g, D::c(0.0) - g[0][1] / det_g],
            [D::c(0.0) - g[1][0] / det_g, g[0][0] / det_g],
        ];
        let cinv = [
            [c[1][1] / det_c, D::c(0.0) - c[0][1] / det_c],
            [D::c(0.0) - c[1][0] / det_c, c[0][0] / det_c],
        ];
        let mut a = D::c(0.0);
        for al in 0..2 {
            for be in 0..2 {
                a = a + ginv[al][be] * c[al][be];
            }
        }
        let b = det_c / det_g;
        let w = self.law.derivatives(a.v, b.v)?;
        let wa = D {
            v: w.w_a,
            d: [
                w.w_aa * a.d[0] + w.w_ab * b.d[0],
                w.w_aa * a.d[1] + w.w_ab * b.d[1],
            ],
        };
        let wb = D {
            v: w.w_b,
            d: [
                w.w_ab * a.d[0] + w.w_bb * b.d[0],
                w.w_ab * a.d[1] + w.w_bb * b.d[1],
            ],
        };
        let sg = det_g.sqrt();
        let mut div = [0.0; 3];
        for be in 0..2 {
            // Q^β = √G S^{αβ} x_{,α}, and its ∂_β
            for al in 0..2 {
                let s = (wa * ginv[al][be] + wb * b * cinv[al][be]) * 2.0;
                for i in 0..3 {
                    div[i] += (sg * s * xt[al][i]).d[be];
                }
            }
        }
        let n = cross(fx.t[0], fx.t[1]);
        let contact = self.field.contact_traction(gx.x);
        let body_force: [f64; 3] =
            std::array::from_fn(|i| -div[i] / sg.v - self.pressure * n[i] / sg.v - contact[i]);
        let (l1, l2) = principal(a.v, b.v);
        let r = self.law.resultants(l1.sqrt(), l2.sqrt())?;
        Ok(Exact {
            x: fx.x,
            resultants: [r[0].max(r[1]), r[0].min(r[1])],
            body_force,
            contact,
        })
    }
}

/// The body force as a force term: per element and Gauss point, the exact b at the Gauss
/// point's projection onto the exact surface, integrated with the element's reference area
/// weight; scaled by a factor the load stepping ramps (the term's energy is −scale ∫ b·x dA0,
/// so its force is −scale ∫ b N_a dA0 and its tangent zero).
pub struct BodyForce {
    /// b at every Gauss point of every element
    loads: Vec<Vec<[f64; 3]>>,
    /// the scale, as the bits of an f64 (set between solves)
    scale: AtomicU64,
}

impl BodyForce {
    /// The loads of every element's Gauss points: `points[e][g]` the reference positions.
    pub fn new<F: Field>(
        problem: &Manufactured<'_, F>,
        points: &[Vec<[f64; 3]>],
    ) -> Result<Self, MaterialError> {
        let loads = points
            .iter()
            .map(|gps| {
                gps.iter()
                    .map(|&p| {
                        problem
                            .exact(problem.surface.project(p))
                            .map(|e| e.body_force)
                    })
                    .collect::<Result<Vec<_>, _>>()
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            loads,
            scale: AtomicU64::new(0f64.to_bits()),
        })
    }
    /// ‖f_b‖ over all of the model's degrees of freedom (constrained ones included): the
    /// load's size, for Newton's residual scale ([`crate::model::Model::set_load_scale`]).
    pub fn load_norm(&self, model: &crate::model::Model) -> f64 {
        let mut f = vec![[0.0f64; 3]; model.mesh().nodes.len()];
        crate::with_elements!(model.elements(), els => {
            for (e, el) in els.iter().enumerate() {
                for (gp, b) in el.gauss.iter().zip(&self.loads[e]) {
                    for (a, &node) in el.nodes.iter().enumerate() {
                        for i in 0..3 {
                            f[node][i] += gp.w * gp.n[a] * b[i];
                        }
                    }
                }
            }
        });
        f.iter().flatten().map(|v| v * v).sum::<f64>().sqrt()
    }
    pub fn set_scale(&self, s: f64) {
        self.scale.store(s.to_bits(), Ordering::Relaxed);
    }
    fn scale(&self) -> f64 {
        f64::from_bits(self.scale.load(Ordering::Relaxed))
    }
}

impl ElementTerm for BodyForce {
    fn name(&self) -> &str {
        "manufactured body force"
    }
    fn add<const N: usize, const DOF: usize>(
        &self,
        el: &ElementAt<'_, N>,
        r: &mut SVector<f64, DOF>,
        _k: Option<&mut SMatrix<f64, DOF, DOF>>,
    ) -> Result<f64, FemError> {
        let s = self.scale();
        let loads = &self.loads[el.index];
        let mut energy = 0.0;
        for (gp, b) in el.reference.gauss.iter().zip(loads) {
            let x = gp.position(el.x);
            let w = s * gp.w;
            energy -= w * (b[0] * x[0] + b[1] * x[1] + b[2] * x[2]);
            for a in 0..N {
                for i in 0..3 {
                    r[3 * a + i] -= w * gp.n[a] * b[i];
                }
            }
        }
        Ok(energy)
    }
}
