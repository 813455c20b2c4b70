//! Stability: the pressure tangent dx/dϖ (with a neutral mode deflated), inverse iteration for
//! the stiffness's softest mode, and its description ([`ModeReport`]).

use super::*;

/// The relative eigenvalue (|μ| over K's largest diagonal entry) below which a mode counts as
/// neutral: 1e-8. Measured on the whole tube's bulging path (L/R = 40, 16 around; `cargo run
/// --release -p tubemem-fem --example neutral_mode -- 40 PER_R 16 3`, 2026-11-30): the uniform
/// tube's softest mode is 3e-7 (8 per R along) to 2e-6 (2 per R) of the diagonal; once the bulge
/// has formed, its translation is 1e-10 to 1e-6 at 2 per R (the discretization's ripple, changing
/// sign), 3e-14 to 2e-10 at 4 per R and 1e-17 to 1e-14 (round-off) at 8 per R. The bound lies
/// below the physical modes and above the translation on the meshes where it stops the path.
pub const NEUTRAL: f64 = 1e-8;

/// The stiffness's mode of smallest |eigenvalue|, described ([`Model::mode_report`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeReport {
    /// μ over K's largest diagonal entry
    pub relative_eigenvalue: f64,
    /// the share of the unit mode's squared norm in axial (z) displacements
    pub axial_share: f64,
    /// gᵀφ/‖g‖: how much the mode changes the enclosed volume (0: not at all)
    pub volume_change: f64,
}

impl ModeReport {
    /// |μ| at most [`NEUTRAL`] of the stiffness.
    pub fn is_neutral(&self) -> bool {
        self.relative_eigenvalue.abs() <= NEUTRAL
    }
}

impl Model {
    /// The path tangent under pressure as the load parameter at the equilibrium `state`:
    /// b = K⁻¹ g (dx/dϖ on the free dofs, K = K_int − ϖ H the pressure-control stiffness), g
    /// (∂V_part/∂x) and the number of negative pivots of K. Factorizes K at `state`.
    pub fn pressure_tangent(
        &mut self,
        state: &State,
        load: &Load,
    ) -> Result<(Vec<f64>, Vec<f64>, usize), FemError> {
        let (a, b, neg) = self.pressure_tangent_with(state, load)?;
        Ok((b, a.g, neg))
    }

    /// [`Model::pressure_tangent`] with the assembly it factorized.
    pub(super) fn pressure_tangent_with(
        &mut self,
        state: &State,
        load: &Load,
    ) -> Result<(Assembled, Vec<f64>, usize), FemError> {
        let a = self.assemble_state(state, true, load.contact.as_ref())?;
        let (neg, _) = self.factorize(&a, state.p)?;
        let mut b = a.g.clone();
        self.ldlt.solve(&mut b);
        Ok((a, b, neg))
    }

    /// [`Model::pressure_tangent`] with the neutral mode `phi0` held out (see [`Model::deflate`]):
    /// b projected off the refreshed mode, the mode's pivot out of the count; returns the
    /// refreshed mode too, or `None` — and the plain tangent — once the mode is no longer
    /// neutral (|μ| above [`NEUTRAL`] of the diagonal: e.g. the bulge's fronts have reached
    /// the caps and nothing can slide any more).
    #[allow(clippy::type_complexity)]
    pub fn pressure_tangent_deflated(
        &mut self,
        state: &State,
        load: &Load,
        phi0: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>, usize, Option<Vec<f64>>), FemError> {
        let (a, mut b, neg) = self.pressure_tangent_with(state, load)?;
        let (phi, mu) = self.deflate(phi0, &a.g, &b);
        // held while it is neutral and the load does not drive it (a mode along the load is
        // the path itself)
        let driven = dot(&a.g, &phi).abs() > NEUTRAL * norm(&a.g);
        if driven || (mu / self.largest_diagonal(&a, state.p)).abs() > NEUTRAL {
            return Ok((b, a.g, neg, None));
        }
        project_out(&mut b, &phi);
        Ok((b, a.g, neg - usize::from(mu < 0.0 && neg > 0), Some(phi)))
    }

    /// One inverse iteration on the current factor of K from the stored neutral mode `phi0`,
    /// kept free of the load: the refreshed unit mode and its Rayleigh quotient
    /// μ = 1/(φᵀK⁻¹φ) (negative: K's negative-pivot count includes it).
    ///
    /// A neutral mode (eigenvalue at round-off, e.g. the translation of a bulge far from the
    /// caps of a whole tube) leaves K⁻¹ undefined along it: the continuation holds it out of
    /// the tangent and of the corrector (the state keeps its component along the mode, so the
    /// bulge stays where it is), and out of the pivot count, whose sign for it is noise. One
    /// solve converges it (the gap to the next eigenvalue is many orders) — except on a
    /// propagation plateau, where the fronts' advance (which changes the volume, the path
    /// itself) is nearly neutral too: K⁻¹φ0 and `b` = K⁻¹g then span the two, and the held mode
    /// is their combination that does not change the volume (gᵀφ = 0).
    pub fn deflate(&self, phi0: &[f64], g: &[f64], b: &[f64]) -> (Vec<f64>, f64) {
        let u = self.unit_solve(phi0);
        // the part of b = K⁻¹g off u: a second direction of the near-null space when it is
        // not negligible
        let nb = norm(b).max(1e-300);
        let mut q: Vec<f64> = b.iter().map(|v| v / nb).collect();
        project_out(&mut q, &u);
        let nq = norm(&q);
        let phi = if nq > 1e-3 {
            q.iter_mut().for_each(|v| *v /= nq);
            let (gu, gq) = (dot(g, &u), dot(g, &q));
            let mut phi: Vec<f64> = u.iter().zip(&q).map(|(a, c)| gq * a - gu * c).collect();
            let n = norm(&phi).max(1e-300);
            phi.iter_mut().for_each(|v| *v /= n);
            phi
        } else {
            u
        };
        let mu = self.rayleigh(&phi);
        (phi, mu)
    }

    /// One inverse iteration on the current factor of K from the unit vector `phi0`:
    /// φ = K⁻¹φ0/‖K⁻¹φ0‖ (so Kφ lies along φ0) and its Rayleigh quotient.
    pub(super) fn inverse_iteration(&self, phi0: &[f64]) -> (Vec<f64>, f64) {
        let phi = self.unit_solve(phi0);
        let mu = self.rayleigh(&phi);
        (phi, mu)
    }

    /// K⁻¹v/‖K⁻¹v‖ with the current factor.
    pub(super) fn unit_solve(&self, v: &[f64]) -> Vec<f64> {
        let mut u = v.to_vec();
        self.ldlt.solve(&mut u);
        let n = norm(&u).max(1e-300);
        u.iter_mut().for_each(|x| *x /= n);
        u
    }

    /// The Rayleigh quotient of K for the unit vector φ through its inverse: μ = 1/(φᵀK⁻¹φ).
    pub(super) fn rayleigh(&self, phi: &[f64]) -> f64 {
        let mut w = phi.to_vec();
        self.ldlt.solve(&mut w);
        1.0 / dot(phi, &w)
    }

    /// The largest |diagonal entry| of K = K_int − p H in `a` (the scale of the stiffness).
    pub(super) fn largest_diagonal(&self, a: &Assembled, p: f64) -> f64 {
        self.largest_diagonal_of(
            self.pattern
                .diagonal()
                .iter()
                .map(|&d| a.k_int[d] - p * a.k_vol[d]),
        )
    }

    /// The largest |diagonal entry| of the tangent whose values (one per pattern entry) are `k`.
    pub(super) fn largest_diagonal_in(&self, k: &[f64]) -> f64 {
        self.largest_diagonal_of(self.pattern.diagonal().iter().map(|&d| k[d]))
    }

    fn largest_diagonal_of(&self, diagonal: impl Iterator<Item = f64>) -> f64 {
        diagonal.map(f64::abs).fold(0.0, f64::max).max(1e-300)
    }

    /// Inverse iteration with the factor of K = K_int − ϖ H at `state` (with the load's planes;
    /// for closed gas, of K + (ϖ/V_part) g gᵀ): the eigenvector of smallest |eigenvalue| (unit
    /// Euclidean norm on the free dofs) and its Rayleigh quotient. `iterations` solves, from a
    /// start vector of ones.
    pub fn smallest_mode(
        &mut self,
        state: &State,
        load: &Load,
        iterations: usize,
    ) -> Result<(Vec<f64>, f64), FemError> {
        self.smallest_mode_with(state, load, iterations)
            .map(|(v, mu, _, _)| (v, mu))
    }

    /// [`Model::smallest_mode`] with the assembly it factorized and the pressure it used.
    pub(super) fn smallest_mode_with(
        &mut self,
        state: &State,
        load: &Load,
        iterations: usize,
    ) -> Result<(Vec<f64>, f64, Assembled, f64), FemError> {
        let a = self.assemble_state(state, true, load.contact.as_ref())?;
        // closed gas: the stiffness is K + (ϖ/V) g gᵀ, solved by Sherman–Morrison
        let gas = load.gas().map(|pv| pv / (self.multiplicity() * a.volume));
        self.factorize(&a, gas.unwrap_or(state.p))?;
        let n = self.n_eq();
        // a start vector with a component along every mode: ones plus a deterministic ramp
        let mut v: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 / n as f64)).collect();
        let mut mu = 0.0;
        for _ in 0..iterations.max(1) {
            let nv = norm(&v);
            v.iter_mut().for_each(|x| *x /= nv);
            let mut w = v.clone();
            match gas {
                Some(p) => {
                    self.solve_gas(&a, p, &mut w);
                }
                None => self.ldlt.solve(&mut w),
            }
            // Rayleigh quotient of K⁻¹: vᵀK⁻¹v, so μ(K) ≈ 1/(vᵀw)
            let vw = dot(&v, &w);
            mu = if vw != 0.0 { 1.0 / vw } else { 0.0 };
            v = w;
        }
        let nv = norm(&v);
        v.iter_mut().for_each(|x| *x /= nv);
        Ok((v, mu, a, gas.unwrap_or(state.p)))
    }

    /// The eigenvector of smallest |eigenvalue| of the stiffness at `state` under `load` (by
    /// `iterations` inverse iterations, [`Model::smallest_mode`]), described: μ relative to K's
    /// largest diagonal entry, the share of the mode's squared norm in axial (z) displacements,
    /// and gᵀφ/‖g‖ (0 for a mode that keeps the volume). [`ModeReport::is_neutral`] below
    /// [`NEUTRAL`]. Returned with the mode.
    pub fn mode_report(
        &mut self,
        state: &State,
        load: &Load,
        iterations: usize,
    ) -> Result<(ModeReport, Vec<f64>), FemError> {
        let (phi, mu, a, p) = self.smallest_mode_with(state, load, iterations)?;
        let diag = self.largest_diagonal(&a, p);
        let mut u = vec![[0.0; 3]; state.x.len()];
        self.dofs.apply(&mut u, &phi, 1.0);
        let report = ModeReport {
            relative_eigenvalue: mu / diag,
            axial_share: u.iter().map(|v| v[2] * v[2]).sum(),
            volume_change: dot(&a.g, &phi) / norm(&a.g).max(1e-300),
        };
        Ok((report, phi))
    }
}
