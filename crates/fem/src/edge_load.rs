//! A dead radial traction on the edges of a sheet that lie on a circle about the z axis: a
//! force term ([`crate::term`]) for the free edges of an open mesh (a flat annulus pulled at
//! its rims). Per reference length, t = T e_r(X), e_r the reference radial unit vector in
//! the xy-plane (T > 0 pulls outwards); its consistent nodal forces are
//!
//! ```text
//! f_a = ∫_edge N_a(s) T e_r(X(s)) |X'(s)| ds      (5-point Gauss–Legendre in s ∈ [−1, 1])
//! ```
//! with the edge's own interpolation: linear (4-node elements) or quadratic through its
//! mid-side node (9-node), so a curved edge carries its arc's load. The energy is −Σ f_a·x_a;
//! the tangent is zero (a dead load).

use crate::term::{ElementAt, ElementTerm};
use crate::FemError;
use nalgebra::{SMatrix, SVector};

/// Gauss–Legendre, 5 points on [−1, 1].
const GL5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// A radial traction `traction` on the element edges whose end nodes lie at distance `radius`
/// from the z axis (within 1e-9 of it), times a scale the load stepping sets.
pub struct RadialTraction {
    pub radius: f64,
    pub traction: f64,
    scale: std::sync::atomic::AtomicU64,
}

impl RadialTraction {
    pub fn new(radius: f64, traction: f64) -> Self {
        Self {
            radius,
            traction,
            scale: std::sync::atomic::AtomicU64::new(1f64.to_bits()),
        }
    }
    /// Scale the traction by `s` from the next assembly on.
    pub fn set_scale(&self, s: f64) {
        self.scale
            .store(s.to_bits(), std::sync::atomic::Ordering::Relaxed);
    }
    fn scale(&self) -> f64 {
        f64::from_bits(self.scale.load(std::sync::atomic::Ordering::Relaxed))
    }
    /// The consistent nodal forces of element `el`: (local node, force).
    fn forces<const N: usize>(&self, el: &ElementAt<'_, N>) -> Vec<(usize, [f64; 3])> {
        let x0 = el.x0();
        let on = |a: usize| (x0[a][0].hypot(x0[a][1]) - self.radius).abs() <= 1e-9 * self.radius;
        let mut out = vec![];
        for k in 0..4 {
            let (a, b) = (k, (k + 1) % 4);
            if !(on(a) && on(b)) {
                continue;
            }
            // the edge's nodes and 1D shape functions in s: (a, b) or (a, mid, b)
            let ends: Vec<usize> = if N == 9 {
                vec![a, 4 + k, b]
            } else {
                vec![a, b]
            };
            let shape = |s: f64| -> Vec<(f64, f64)> {
                // (N, dN/ds)
                if N == 9 {
                    vec![
                        (0.5 * s * (s - 1.0), s - 0.5),
                        (1.0 - s * s, -2.0 * s),
                        (0.5 * s * (s + 1.0), s + 0.5),
                    ]
                } else {
                    vec![(0.5 * (1.0 - s), -0.5), (0.5 * (1.0 + s), 0.5)]
                }
            };
            let mut f = vec![[0.0f64; 3]; ends.len()];
            for (s, w) in GL5 {
                let sh = shape(s);
                let (mut p, mut dp) = ([0.0; 3], [0.0; 3]);
                for (&node, (n, dn)) in ends.iter().zip(&sh) {
                    for i in 0..3 {
                        p[i] += n * x0[node][i];
                        dp[i] += dn * x0[node][i];
                    }
                }
                let ds = (dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2]).sqrt();
                let r = p[0].hypot(p[1]);
                let t = self.traction * self.scale();
                let t = [t * p[0] / r, t * p[1] / r, 0.0];
                for (fa, (n, _)) in f.iter_mut().zip(&sh) {
                    for i in 0..3 {
                        fa[i] += w * n * t[i] * ds;
                    }
                }
            }
            out.extend(ends.into_iter().zip(f));
        }
        out
    }
}

impl ElementTerm for RadialTraction {
    fn name(&self) -> &str {
        "radial edge traction"
    }
    fn add<const N: usize, const D: usize>(
        &self,
        el: &ElementAt<'_, N>,
        r: &mut SVector<f64, D>,
        _k: Option<&mut SMatrix<f64, D, D>>,
    ) -> Result<f64, FemError> {
        let mut energy = 0.0;
        for (a, f) in self.forces(el) {
            for i in 0..3 {
                r[3 * a + i] -= f[i];
                energy -= f[i] * el.x[a][i];
            }
        }
        Ok(energy)
    }
}
