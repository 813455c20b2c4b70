//! Gauss-point geometry of the membrane elements (4-node bilinear, 9-node biquadratic; N the
//! node count, a const parameter so that each element's arrays are sized at compile time): the one owner of shape-function values, reference
//! derivatives, area weights, the local reference frame, and of the current position, in-plane
//! deformation gradient and area ratio at a Gauss point.
//!
//! ```text
//! Reference frame at a Gauss point: e1 = G1/|G1|, e3 = G1×G2/|G1×G2|, e2 = e3 × e1,
//! J_iα = e_i·G_α (2×2), ∂N_a/∂X_i = Σ_α ∂N_a/∂ξ_α (J⁻¹)_αi, dA0 = det J dξdη.
//! position       x(ξ) = Σ_a N_a x_a
//! gradient       f_i = Σ_a x_a ∂N_a/∂X_i          (3-vectors, i = 1, 2)
//! area ratio     J = da/dA0 = |f_1 × f_2|
//! ```
//! Node numbering of a quad (counter-clockwise seen from outside, so that G1 × G2 points out):
//! ```text
//!  3 ───── 2
//!  │       │
//!  0 ───── 1
//! ```

use crate::FemError;
use nalgebra::{Matrix2, Vector3};
use tubemem_mesh::shape::{full_rule, shape_n};

/// A 3-vector.
pub type Vec3 = Vector3<f64>;

/// Reference data at one Gauss point.
#[derive(Clone, Debug)]
pub struct GaussPoint<const N: usize> {
    /// shape-function values N_a
    pub n: [f64; N],
    /// ∂N_a/∂X_i in the local orthonormal reference frame
    pub dn: [[f64; 2]; N],
    /// reference area weight dA0 (the rule's weight times det J)
    pub w: f64,
    /// the local orthonormal reference frame (e1, e2)
    pub frame: [Vec3; 2],
}

impl<const N: usize> GaussPoint<N> {
    /// x at the point.
    pub fn position(&self, xe: &[Vec3; N]) -> Vec3 {
        let mut p = Vec3::zeros();
        for a in 0..N {
            p += xe[a] * self.n[a];
        }
        p
    }

    /// The in-plane deformation gradient columns f_1, f_2 at the point.
    pub fn gradient(&self, xe: &[Vec3; N]) -> [Vec3; 2] {
        let mut f = [Vec3::zeros(); 2];
        for a in 0..N {
            for i in 0..2 {
                f[i] += xe[a] * self.dn[a][i];
            }
        }
        f
    }

    /// The area ratio J = da/dA0 = |f_1 × f_2| at the point.
    pub fn area_ratio(&self, xe: &[Vec3; N]) -> f64 {
        let f = self.gradient(xe);
        f[0].cross(&f[1]).norm()
    }
}

/// Reference data of one element at its Gauss points.
#[derive(Clone, Debug)]
pub struct RefElement<const N: usize = 4> {
    pub nodes: [usize; N],
    pub gauss: Box<[GaussPoint<N>]>,
    /// the element's nodes as points (N_b = δ_ab there), each with the reference area
    /// ∫N_a dA0 as its weight: the contact's nodal quadrature
    pub nodal: Box<[GaussPoint<N>]>,
}

/// The reference coordinates (ξ, η) of an element's nodes, in node order.
fn node_coordinates<const N: usize>() -> &'static [(f64, f64)] {
    const CORNERS: [(f64, f64); 4] = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    const NINE: [(f64, f64); 9] = [
        (-1.0, -1.0),
        (1.0, -1.0),
        (1.0, 1.0),
        (-1.0, 1.0),
        (0.0, -1.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (-1.0, 0.0),
        (0.0, 0.0),
    ];
    if N == 9 {
        &NINE
    } else {
        &CORNERS
    }
}

/// The reference data at a point with shape values `n` and reference derivatives `d` of an
/// element with nodes at `xv`, and `weight` times det J as its weight; `None` where the
/// element is degenerate.
fn point_at<const N: usize>(
    xv: &[Vec3; N],
    n: [f64; N],
    d: &[[f64; 2]; N],
    weight: f64,
) -> Option<GaussPoint<N>> {
    let mut g1 = Vec3::zeros();
    let mut g2 = Vec3::zeros();
    for a in 0..N {
        g1 += xv[a] * d[a][0];
        g2 += xv[a] * d[a][1];
    }
    let n3 = g1.cross(&g2);
    let area = n3.norm();
    if !(area > 1e-14 * g1.norm() * g2.norm()) {
        return None;
    }
    let e1 = g1 / g1.norm();
    let e3 = n3 / area;
    let e2 = e3.cross(&e1);
    let j = Matrix2::new(e1.dot(&g1), e1.dot(&g2), e2.dot(&g1), e2.dot(&g2));
    let det = j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)];
    let inv = Matrix2::new(
        j[(1, 1)] / det,
        -j[(0, 1)] / det,
        -j[(1, 0)] / det,
        j[(0, 0)] / det,
    );
    let mut dn = [[0.0; 2]; N];
    for a in 0..N {
        for i in 0..2 {
            dn[a][i] = d[a][0] * inv[(0, i)] + d[a][1] * inv[(1, i)];
        }
    }
    Some(GaussPoint {
        n,
        dn,
        // the 2 × 2 rule's weights are 1: det * 1 is det, bit for bit
        w: det * weight,
        frame: [e1, e2],
    })
}

impl<const N: usize> RefElement<N> {
    /// The reference geometry of element `id` with nodes `nodes` at reference positions `x`,
    /// with the element's full rule (2 × 2 for N = 4, 3 × 3 for N = 9).
    pub fn new(id: usize, nodes: [usize; N], x: &[[f64; 3]; N]) -> Result<Self, FemError> {
        Self::with_rule(id, nodes, x, full_rule::<N>())
    }

    /// [`RefElement::new`] with the quadrature rule `rule` of (ξ, η, weight) points.
    pub fn with_rule(
        id: usize,
        nodes: [usize; N],
        x: &[[f64; 3]; N],
        rule: &[(f64, f64, f64)],
    ) -> Result<Self, FemError> {
        let xv = x.map(Vec3::from);
        let mut gauss = Vec::with_capacity(rule.len());
        for (g, &(xi, eta, weight)) in rule.iter().enumerate() {
            let (n, d) = shape_n::<N>(xi, eta);
            let point = point_at(&xv, n, &d, weight).ok_or(FemError::DegenerateElement {
                element: id,
                gauss_point: g,
            })?;
            gauss.push(point);
        }
        // the nodes as points, each weighted by ∫N_a dA0 over the element (by its rule: the
        // row sums of the consistent mass, all positive for both elements: 1/4 of the area
        // each on a 4-node parallelogram, Simpson's 1/36, 4/36, 16/36 on a 9-node one)
        let mut nodal = Vec::with_capacity(N);
        for (a, &(xi, eta)) in node_coordinates::<N>().iter().enumerate() {
            let (_, d) = shape_n::<N>(xi, eta);
            let mut n = [0.0; N];
            n[a] = 1.0;
            let lumped: f64 = gauss.iter().map(|gp| gp.w * gp.n[a]).sum();
            let mut point = point_at(&xv, n, &d, 1.0).ok_or(FemError::DegenerateNode {
                element: id,
                node: a,
            })?;
            point.w = lumped;
            nodal.push(point);
        }
        Ok(Self {
            nodes,
            gauss: gauss.into_boxed_slice(),
            nodal: nodal.into_boxed_slice(),
        })
    }

    /// The element's nodal positions taken from the global array `x`.
    #[inline]
    pub fn gather(&self, x: &[[f64; 3]]) -> [Vec3; N] {
        self.nodes.map(|i| Vec3::from(x[i]))
    }

    /// x at Gauss point `g`.
    pub fn position(&self, g: usize, xe: &[Vec3; N]) -> Vec3 {
        self.gauss[g].position(xe)
    }

    /// The in-plane deformation gradient columns f_1, f_2 at Gauss point `g`.
    pub fn gradient(&self, g: usize, xe: &[Vec3; N]) -> [Vec3; 2] {
        self.gauss[g].gradient(xe)
    }

    /// The area ratio J = da/dA0 = |f_1 × f_2| at Gauss point `g`.
    pub fn area_ratio(&self, g: usize, xe: &[Vec3; N]) -> f64 {
        self.gauss[g].area_ratio(xe)
    }

    /// The image F v of a vector v of the reference tangent plane at Gauss point `g`.
    pub fn push_forward(&self, g: usize, f: &[Vec3; 2], v: &Vec3) -> Vec3 {
        let [e1, e2] = &self.gauss[g].frame;
        f[0] * e1.dot(v) + f[1] * e2.dot(v)
    }
}
