//! The capped tube's exact reference surface: a cylinder of radius R between z = ±h (h the
//! half-length L/2) closed by hemispheres of radius R centred at z = ±h. Points are projected
//! onto it, and a local chart ξ ↦ X(ξ) is given at each of its points, written for any
//! [`Real`] so that dual numbers give its derivatives:
//!
//! ```text
//! cylinder   X(ξ) = (R q/|q|, z0 + ξ2),  q = (x0, y0) + ξ1 t,  t = (−y0, x0)/R
//! cap        X(ξ) = c + R q/|q|,         q = n0 + ξ1 t1 + ξ2 t2,  t1 × t2 = n0 (outward)
//! ```
//! Both are exact (on the surface for every ξ) and oriented so that X_{,1} × X_{,2} points
//! outwards.

use tubemem_material::dual::Real;

/// The exact capped tube.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CappedTube {
    pub radius: f64,
    /// h = L/2
    pub half_length: f64,
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl CappedTube {
    /// The cap centre a point beyond the cylinder belongs to (None: on the cylinder).
    fn cap_centre(&self, z: f64) -> Option<[f64; 3]> {
        if z > self.half_length {
            Some([0.0, 0.0, self.half_length])
        } else if z < -self.half_length {
            Some([0.0, 0.0, -self.half_length])
        } else {
            None
        }
    }

    /// The point of the surface nearest `p` along the surface's normal: radially onto the
    /// cylinder, or towards the cap's centre.
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let r = self.radius;
        match self.cap_centre(p[2]) {
            None => {
                let rho = p[0].hypot(p[1]);
                [r * p[0] / rho, r * p[1] / rho, p[2]]
            }
            Some(c) => {
                let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                let n = norm(d);
                [
                    c[0] + r * d[0] / n,
                    c[1] + r * d[1] / n,
                    c[2] + r * d[2] / n,
                ]
            }
        }
    }

    /// X(ξ) of the local chart at the surface point `at` (X(0) = at).
    pub fn chart<T: Real>(&self, at: [f64; 3], xi: [T; 2]) -> [T; 3] {
        let r = self.radius;
        match self.cap_centre(at[2]) {
            None => {
                let t = [-at[1] / r, at[0] / r];
                let q = [xi[0] * t[0] + at[0], xi[0] * t[1] + at[1]];
                let len = (q[0] * q[0] + q[1] * q[1]).sqrt();
                [q[0] / len * r, q[1] / len * r, xi[1] + at[2]]
            }
            Some(c) => {
                let n0 = [(at[0] - c[0]) / r, (at[1] - c[1]) / r, (at[2] - c[2]) / r];
                let e = if n0[2].abs() < 0.9 {
                    [0.0, 0.0, 1.0]
                } else {
                    [1.0, 0.0, 0.0]
                };
                let t1 = cross(e, n0);
                let l1 = norm(t1);
                let t1 = [t1[0] / l1, t1[1] / l1, t1[2] / l1];
                let t2 = cross(n0, t1);
                let q: [T; 3] = std::array::from_fn(|i| xi[0] * t1[i] + xi[1] * t2[i] + n0[i]);
                let len = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                std::array::from_fn(|i| q[i] / len * r + c[i])
            }
        }
    }
}
