//! Lagrange shape functions of the two membrane elements and their quadrature rules: the one
//! owner of the reference element.
//!
//! ```text
//! quad4 (bilinear)       N_a = ¼(1 ± ξ)(1 ± η)                       2 × 2 Gauss
//! quad9 (biquadratic)    N_a = L_i(ξ) L_j(η),  L_−(s) = s(s−1)/2,      3 × 3 Gauss
//!                        L_0(s) = 1 − s²,  L_+(s) = s(s+1)/2
//! ```
//! Node order of the 9-node element (VTK_BIQUADRATIC_QUAD = 28, meshio `quad9`): the corners as
//! in the 4-node element, then the mid-side nodes of edges 0–1, 1–2, 2–3, 3–0, then the centre:
//! ```text
//!  3 ── 6 ── 2
//!  │         │
//!  7    8    5
//!  │         │
//!  0 ── 4 ── 1
//! ```
//! **Quadrature.** With the node positions on the exact surface, the 9-node geometry is
//! biquadratic, so x·(g1 × g2) is of degree 5 in ξ and in η: 3 × 3 Gauss (exact to degree 5)
//! integrates the enclosed volume exactly, as 2 × 2 does for the bilinear element. For the
//! membrane energy (a rational function of the gradients at finite strain) no rule is exact;
//! 3 × 3 is the full rule of the biquadratic element (the stiffness of an affine patch in an
//! undistorted element is integrated exactly), and the test
//! `a_reduced_rule_on_the_quad9_element_has_spurious_zero_energy_modes` shows what one order
//! less (2 × 2) does: the stiffness of a single element then has zero-energy modes beyond the
//! rigid motions — hourglassing.

/// 2×2 Gauss points on [−1, 1]², counter-clockwise (the 4-node element's order).
pub const GAUSS2: [(f64, f64); 4] = {
    const G: f64 = 0.577_350_269_189_625_8;
    [(-G, -G), (G, -G), (G, G), (-G, G)]
};

/// 2×2 Gauss points with their weights (all 1), in [`GAUSS2`]'s order.
pub const GAUSS2_RULE: [(f64, f64, f64); 4] = {
    const G: f64 = 0.577_350_269_189_625_8;
    [(-G, -G, 1.0), (G, -G, 1.0), (G, G, 1.0), (-G, G, 1.0)]
};

/// 3×3 Gauss points with their weights (η outer): ±√(3/5), 0 with weights 5/9, 8/9.
pub const GAUSS3_RULE: [(f64, f64, f64); 9] = {
    const G: f64 = 0.774_596_669_241_483_4;
    const A: f64 = 5.0 / 9.0;
    const B: f64 = 8.0 / 9.0;
    [
        (-G, -G, A * A),
        (0.0, -G, B * A),
        (G, -G, A * A),
        (-G, 0.0, A * B),
        (0.0, 0.0, B * B),
        (G, 0.0, A * B),
        (-G, G, A * A),
        (0.0, G, B * A),
        (G, G, A * A),
    ]
};

/// The kind of membrane element of a mesh.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum ElementKind {
    /// bilinear, flat-faceted (the default)
    #[default]
    Quad4,
    /// biquadratic Lagrange, isoparametric curved geometry
    Quad9,
}

impl ElementKind {
    /// Gauss points per direction of the full rule.
    pub fn gauss_per_direction(self) -> usize {
        match self {
            ElementKind::Quad4 => 2,
            ElementKind::Quad9 => 3,
        }
    }
    /// The name in case files, VTU/meshio (`quad`, `quad9`) aside.
    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Quad4 => "quad4",
            ElementKind::Quad9 => "quad9",
        }
    }
}

/// Bilinear shape functions and their (ξ, η) derivatives.
pub fn shape(xi: f64, eta: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    let n = [
        0.25 * (1.0 - xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 + eta),
        0.25 * (1.0 - xi) * (1.0 + eta),
    ];
    let d = [
        [-0.25 * (1.0 - eta), -0.25 * (1.0 - xi)],
        [0.25 * (1.0 - eta), -0.25 * (1.0 + xi)],
        [0.25 * (1.0 + eta), 0.25 * (1.0 + xi)],
        [-0.25 * (1.0 + eta), 0.25 * (1.0 - xi)],
    ];
    (n, d)
}

/// The three 1D quadratic Lagrange polynomials at s (nodes −1, 0, +1) and their derivatives.
fn lagrange2(s: f64) -> ([f64; 3], [f64; 3]) {
    (
        [0.5 * s * (s - 1.0), 1.0 - s * s, 0.5 * s * (s + 1.0)],
        [s - 0.5, -2.0 * s, s + 0.5],
    )
}

/// (i, j) = the 1D node (0 = −1, 1 = 0, 2 = +1) of each 9-node shape function in ξ and η.
pub const QUAD9_LATTICE: [(usize, usize); 9] = [
    (0, 0),
    (2, 0),
    (2, 2),
    (0, 2),
    (1, 0),
    (2, 1),
    (1, 2),
    (0, 1),
    (1, 1),
];

/// Biquadratic shape functions and their (ξ, η) derivatives, in the node order of the module
/// header.
pub fn shape9(xi: f64, eta: f64) -> ([f64; 9], [[f64; 2]; 9]) {
    let (lx, dx) = lagrange2(xi);
    let (ly, dy) = lagrange2(eta);
    let mut n = [0.0; 9];
    let mut d = [[0.0; 2]; 9];
    for (a, &(i, j)) in QUAD9_LATTICE.iter().enumerate() {
        n[a] = lx[i] * ly[j];
        d[a] = [dx[i] * ly[j], lx[i] * dy[j]];
    }
    (n, d)
}

/// The shape functions of the N-node element (N = 4 or 9).
#[inline]
pub fn shape_n<const N: usize>(xi: f64, eta: f64) -> ([f64; N], [[f64; 2]; N]) {
    const { assert!(N == 4 || N == 9, "membrane elements have 4 or 9 nodes") };
    let mut n = [0.0; N];
    let mut d = [[0.0; 2]; N];
    if N == 4 {
        let (a, b) = shape(xi, eta);
        n.copy_from_slice(&a);
        d.copy_from_slice(&b);
    } else {
        let (a, b) = shape9(xi, eta);
        n.copy_from_slice(&a);
        d.copy_from_slice(&b);
    }
    (n, d)
}

/// Gauss–Legendre points and weights on [−1, 1] with `n` = 1 … 4 points.
pub fn gauss_1d(n: usize) -> Option<Vec<(f64, f64)>> {
    let s35 = (3.0f64 / 5.0).sqrt();
    let pts = match n {
        1 => vec![(0.0, 2.0)],
        2 => {
            let g = 1.0 / 3.0f64.sqrt();
            vec![(-g, 1.0), (g, 1.0)]
        }
        3 => vec![(-s35, 5.0 / 9.0), (0.0, 8.0 / 9.0), (s35, 5.0 / 9.0)],
        4 => {
            let r = (6.0f64 / 5.0).sqrt();
            let (a, b) = (
                ((3.0 - 2.0 * r) / 7.0).sqrt(),
                ((3.0 + 2.0 * r) / 7.0).sqrt(),
            );
            let (wa, wb) = (
                (18.0 + 30.0f64.sqrt()) / 36.0,
                (18.0 - 30.0f64.sqrt()) / 36.0,
            );
            vec![(-b, wb), (-a, wa), (a, wa), (b, wb)]
        }
        _ => return None,
    };
    Some(pts)
}

/// A tensor-product rule of `n` × `n` points (ξ, η, weight), η outer. For n = 2 the points are
/// [`GAUSS2`] in its counter-clockwise order (the 4-node element's historical order, which keeps
/// its sums bit for bit).
pub fn rule(n: usize) -> Option<Vec<(f64, f64, f64)>> {
    if n == 2 {
        return Some(GAUSS2.iter().map(|&(x, e)| (x, e, 1.0)).collect());
    }
    let g = gauss_1d(n)?;
    let mut out = Vec::with_capacity(n * n);
    for &(eta, we) in &g {
        for &(xi, wx) in &g {
            out.push((xi, eta, wx * we));
        }
    }
    Some(out)
}

/// The full rule of the N-node element: 2 × 2 for N = 4, 3 × 3 for N = 9.
pub fn full_rule<const N: usize>() -> &'static [(f64, f64, f64)] {
    if N == 4 {
        &GAUSS2_RULE
    } else {
        &GAUSS3_RULE
    }
}
