//! Wrinkling against a closed form: the tension-field solution of a flat annulus pulled at both
//! rims (the Lamé problem of an annular sheet with opposed radial tractions; Davidovitch, Schroll,
//! Vella, Adda-Bedia & Cerda, *Prototypical model for tensional wrinkling in thin sheets*, PNAS
//! 108, 2011, and Taylor, Davidovitch, Qiu & Bertoldi, JMPS 79, 2015, who use it to compare
//! numerical approaches to wrinkled sheets).
//!
//! An annulus R_in ≤ r ≤ R_out carries a radial tension T_in at its inner rim and T_out at
//! its outer rim (forces per length). The linear elastic (Lamé) solution, the same for every
//! isotropic law under traction boundary conditions,
//!
//! ```text
//! N_rr = A' + B'/r²,  N_θθ = A' − B'/r²,  B' = (T_in − T_out)/(R_in⁻² − R_out⁻²),  A' = T_out − B'/R_out²
//! ```
//! puts the hoop resultant in compression near the hub once T_in/T_out is large enough: a
//! membrane cannot carry it and wrinkles. Tension-field theory replaces the wrinkled zone
//! R_in ≤ r ≤ L by a state of radial tension alone, N_θθ = 0, whose equilibrium
//! d(r N_rr)/dr = N_θθ gives N_rr = T_in R_in / r; the taut zone is a Lamé solution with
//! N_θθ(L) = 0 and N_rr continuous:
//!
//! ```text
//! r > L:  N_rr = A (1 + L²/r²),  N_θθ = A (1 − L²/r²),  A = T_in R_in/(2L)
//! N_rr(R_out) = T_out  ⇒  L = (T_out R_out²/(T_in R_in)) [1 − √(1 − (T_in R_in/(T_out R_out))²)]
//! ```
//! (for R_out → ∞, L = R_in T_in/(2 T_out), the PNAS paper's L_I). Small strains: the
//! solution is linear, so the FE is loaded with tractions far below the modulus.
//!
//! [`solve_annulus`] loads a quarter annulus ([`tubemem_mesh::sheet`]) with the tractions
//! ([`crate::edge_load`]) and measures the FE's radial and hoop resultants at its Gauss points
//! against the closed form, and its wrinkled radius: where the hoop resultant of its taut
//! rings extrapolates to zero.

use crate::edge_load::RadialTraction;
use crate::model::{Load, Loading, Model};
use crate::{with_elements, FemError};
use tubemem_material::MembraneLaw;

/// The annulus and its rim tractions.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Annulus {
    pub r_in: f64,
    pub r_out: f64,
    pub t_in: f64,
    pub t_out: f64,
}

impl Annulus {
    /// The linear (Lamé) resultants (N_rr, N_θθ) at r: the solution without wrinkling.
    pub fn lame(&self, r: f64) -> [f64; 2] {
        let b = (self.t_in - self.t_out) / (self.r_in.powi(-2) - self.r_out.powi(-2));
        let a = self.t_out - b / (self.r_out * self.r_out);
        [a + b / (r * r), a - b / (r * r)]
    }

    /// The wrinkled zone's outer radius L of tension-field theory, or None when the Lamé
    /// solution is nowhere compressive (no wrinkles) or the tractions admit no tension field
    /// (T_in R_in > T_out R_out: the outer rim cannot balance the hub).
    pub fn wrinkle_radius(&self) -> Option<f64> {
        if self.lame(self.r_in)[1] >= 0.0 {
            return None;
        }
        let q = self.t_in * self.r_in / (self.t_out * self.r_out);
        if q > 1.0 {
            return None;
        }
        Some(
            self.t_out * self.r_out * self.r_out / (self.t_in * self.r_in)
                * (1.0 - (1.0 - q * q).sqrt()),
        )
    }

    /// The tension-field resultants (N_rr, N_θθ) at r (the Lamé ones where there are no
    /// wrinkles).
    pub fn tension_field(&self, r: f64) -> [f64; 2] {
        match self.wrinkle_radius() {
            None => self.lame(r),
            Some(l) if r <= l => [self.t_in * self.r_in / r, 0.0],
            Some(l) => {
                let a = self.t_in * self.r_in / (2.0 * l);
                [a * (1.0 + l * l / (r * r)), a * (1.0 - l * l / (r * r))]
            }
        }
    }
}

/// One Gauss point's resultants.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct PointResultants {
    /// the reference radius
    pub r: f64,
    pub n_rr: f64,
    pub n_tt: f64,
    /// the reference area weight
    pub w: f64,
}

/// The FE solution of the annulus and its comparison with the closed forms.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct AnnulusSolution {
    pub equations: usize,
    /// every Gauss point's resultants, by increasing radius
    pub points: Vec<PointResultants>,
    /// the FE's wrinkled radius (None: its hoop resultant is nowhere zero)
    pub wrinkle_radius: Option<f64>,
    /// √(∫|N − N_TFT|² dA/∫dA)/T_out, N = (N_rr, N_θθ)
    pub error_tension_field: f64,
    /// the same against the Lamé solution
    pub error_lame: f64,
    /// the smallest hoop resultant over T_out (negative: compression)
    pub min_hoop: f64,
}

/// The Cauchy resultants (N_rr, N_θθ) at a Gauss point of the current state.
fn resultants<const N: usize>(
    law: &dyn MembraneLaw,
    g: &crate::geometry::GaussPoint<N>,
    x: &[crate::geometry::Vec3; N],
) -> Result<[f64; 2], tubemem_material::MaterialError> {
    let f = g.gradient(x);
    let c = [f[0].dot(&f[0]), f[1].dot(&f[1]), f[0].dot(&f[1])];
    let s = law.stress_tangent(c)?.s;
    let j = f[0].cross(&f[1]).norm();
    let p = g.position(x);
    let rho = p[0].hypot(p[1]);
    let er = nalgebra::Vector3::new(p[0] / rho, p[1] / rho, 0.0);
    let et = nalgebra::Vector3::new(-er[1], er[0], 0.0);
    // σ = (S11 f0 f0ᵀ + S22 f1 f1ᵀ + S12 (f0 f1ᵀ + f1 f0ᵀ)) / J
    let quad = |v: &nalgebra::Vector3<f64>| {
        let (a, b) = (f[0].dot(v), f[1].dot(v));
        (s[0] * a * a + s[1] * b * b + 2.0 * s[2] * a * b) / j
    };
    Ok([quad(&er), quad(&et)])
}

/// Solve the annulus on `model` (a quarter annulus mesh of `a`'s radii) under its rim
/// tractions from the stress-free state, and compare.
pub fn solve_annulus(
    mut model: Model,
    a: &Annulus,
    steps: usize,
) -> Result<AnnulusSolution, FemError> {
    let rims = [
        std::sync::Arc::new(RadialTraction::new(a.r_in, -a.t_in)),
        std::sync::Arc::new(RadialTraction::new(a.r_out, a.t_out)),
    ];
    for rim in &rims {
        model.add_term(Box::new(rim.clone()));
    }
    // the rims' load, for Newton's residual scale: T × the quarter rims' length
    let quarter = std::f64::consts::FRAC_PI_2;
    model.set_load_scale(quarter * (a.t_in * a.r_in + a.t_out * a.r_out));
    // Newton to 1e-8 of the rims' load: the stresses of these small strains are computed from
    // positions of order 1, so round-off leaves the residual near 3e-9 of the load (measured);
    // 1e-8 in the stresses is far below the discretization error
    let mut settings = *model.settings();
    settings.rtol = 1e-8;
    model.set_settings(settings);
    let mut state = model.reference_state();
    // the path: both rims at T_out first (a uniform pretension, taut everywhere), then the
    // hub's traction raised to T_in in `steps` equal steps: the wrinkles grow from the hub
    let steps = steps.max(1);
    let inner = |t: f64| (a.t_out + t * (a.t_in - a.t_out)) / a.t_in;
    for k in 0..=steps {
        let t = k as f64 / steps as f64;
        rims[0].set_scale(inner(t));
        model
            .solve(&mut state, &Load::new(Loading::Pressure(0.0)))
            .map_err(|e| FemError::Stage {
                stage: 1,
                step: k + 1,
                value: t,
                cuts: 0,
                material: None,
                near_locking: None,
                source: Box::new(e),
            })?;
    }
    let law = model.law();
    let nodes = &model.mesh().nodes;
    let mut points = vec![];
    let material = |source| FemError::Material {
        element: 0,
        gauss_point: 0,
        source,
    };
    with_elements!(model.elements(), els => {
        for el in els.iter() {
            let (x, x0) = (el.gather(&state.x), el.gather(nodes));
            for g in el.gauss.iter() {
                let p0 = g.position(&x0);
                let [n_rr, n_tt] = resultants(law, g, &x).map_err(material)?;
                points.push(PointResultants { r: p0[0].hypot(p0[1]), n_rr, n_tt, w: g.w });
            }
        }
    });
    points.sort_by(|p, q| p.r.total_cmp(&q.r));
    let l2 = |exact: &dyn Fn(f64) -> [f64; 2]| {
        let (mut e, mut area) = (0.0, 0.0);
        for p in &points {
            let n = exact(p.r);
            e += p.w * ((p.n_rr - n[0]).powi(2) + (p.n_tt - n[1]).powi(2));
            area += p.w;
        }
        (e / area).sqrt() / a.t_out
    };
    Ok(AnnulusSolution {
        equations: model.n_eq(),
        wrinkle_radius: fe_wrinkle_radius(&points, a.t_out),
        error_tension_field: l2(&|r| a.tension_field(r)),
        error_lame: l2(&|r| a.lame(r)),
        min_hoop: points.iter().map(|p| p.n_tt).fold(f64::INFINITY, f64::min) / a.t_out,
        points,
    })
}

/// Where the taut zone's hoop resultant vanishes: the rings (Gauss points grouped by radius,
/// their resultants averaged) whose hoop resultant is at least 5 % of T_out — clear of the
/// element that straddles the wrinkled zone's edge — are fitted by least squares with the
/// only form equilibrium and compatibility allow there, the Lamé form N_θθ = A − B/r², and
/// L = √(B/A) is its zero. None when no ring is wrinkled (a hoop resultant below 1 % of
/// T_out) or fewer than two are taut.
fn fe_wrinkle_radius(points: &[PointResultants], t_out: f64) -> Option<f64> {
    let mut rings: Vec<(f64, f64, usize)> = vec![];
    for p in points {
        match rings.last_mut() {
            Some(last) if (p.r - last.0).abs() <= 1e-9 * p.r => {
                last.1 += p.n_tt;
                last.2 += 1;
            }
            _ => rings.push((p.r, p.n_tt, 1)),
        }
    }
    let rings: Vec<(f64, f64)> = rings
        .into_iter()
        .map(|(r, s, n)| (r, s / n as f64))
        .collect();
    if !rings.iter().any(|&(_, n)| n < 0.01 * t_out) {
        return None;
    }
    let taut: Vec<(f64, f64)> = rings
        .into_iter()
        .filter(|&(_, n)| n >= 0.05 * t_out)
        .collect();
    if taut.len() < 2 {
        return None;
    }
    // least squares in (1, −1/r²): [[Σ1, −Σu], [−Σu, Σu²]] [A, B] = [Σn, −Σn u], u = 1/r²
    let (mut s1, mut su, mut suu, mut sn, mut snu) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(r, n) in &taut {
        let u = 1.0 / (r * r);
        s1 += 1.0;
        su += u;
        suu += u * u;
        sn += n;
        snu += n * u;
    }
    let det = s1 * suu - su * su;
    let a = (sn * suu - snu * su) / det;
    let b = (sn * su - s1 * snu) / det;
    (a > 0.0 && b > 0.0).then(|| (b / a).sqrt())
}
