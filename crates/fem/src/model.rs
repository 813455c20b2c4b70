//! Global model: constraints, parallel assembly, Newton with loading control, continuation.
//!
//! Loading (all per unit μH, lengths in R; p is the reduced pressure ϖ):
//! ```text
//! pressure control  R(x) = f_int(x) − p ∂V/∂x,        K = K_int − p ∂²V/∂x²
//! bordered control  p is a Lagrange multiplier of a constraint c(x) = 0 with gradient h:
//!                   [K  −g][Δx]   [−R]      K a = −R,  K b = g
//!                   [hᵀ  0][Δp] = [−c]      Δp = (−c − hᵀa)/(hᵀb),  Δx = a + Δp b
//!                   volume control: c = m V_part − V_target, h = m g (m = symmetry multiplicity)
//!                   node control:   c = x_k − target,      h = e_k
//! closed gas        p = M/(m V_part) (Boyle, eq. 60), tangent K + (p/V_part) g gᵀ: the dense
//!                   rank-one term is never assembled; Sherman–Morrison with the sparse factor:
//!                   A⁻¹r = K⁻¹r − c K⁻¹g (gᵀK⁻¹r)/(1 + c gᵀK⁻¹g),  c = p/V_part
//! ```
//! Stability indicator: the number of negative eigenvalues of the operator actually solved,
//! from the LDLᵀ pivots of K and the sign rules of a rank-one (or bordered) update:
//! #neg(K + c ggᵀ) = #neg(K) − [1 + c gᵀK⁻¹g < 0], and on the constraint subspace
//! #neg = #neg(K) − [hᵀK⁻¹g < 0].

use crate::contact::{contact_kernel, Plane};
use crate::element::{membrane_kernel, RefElement};
use crate::linsolve::SparseLdlt;
use crate::volume::volume_kernel;
use crate::FemError;
use rayon::prelude::*;
use tubemem_material::MembraneLaw;
use tubemem_mesh::Mesh;

/// How the load is controlled during a stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// prescribed reduced pressure ϖ
    Pressure(f64),
    /// prescribed total enclosed volume (whole tube, all symmetry copies)
    Volume(f64),
    /// prescribed coordinate of one degree of freedom (node, component), pressure as multiplier
    Node {
        node: usize,
        component: usize,
        target: f64,
    },
    /// closed isothermal gas: p · V_total = `pv` (Boyle's constant)
    Gas { pv: f64 },
    /// closed gas and two rigid plates y = ±`half_gap` (normal ∓e_y), displacement controlled
    Squeeze { pv: f64, half_gap: f64 },
}

impl Control {
    /// Boyle's constant, for the closed-gas controls.
    pub fn gas(&self) -> Option<f64> {
        match *self {
            Control::Gas { pv } | Control::Squeeze { pv, .. } => Some(pv),
            _ => None,
        }
    }

    /// The rigid plates this control places.
    pub fn plates(&self) -> Vec<Plane> {
        match *self {
            Control::Squeeze { half_gap, .. } => vec![
                Plane {
                    normal: [0.0, -1.0, 0.0],
                    offset: -half_gap,
                },
                Plane {
                    normal: [0.0, 1.0, 0.0],
                    offset: -half_gap,
                },
            ],
            _ => vec![],
        }
    }
}

/// A converged (or trial) configuration.
#[derive(Clone, Debug)]
pub struct State {
    pub x: Vec<[f64; 3]>,
    /// reduced pressure ϖ
    pub p: f64,
}

/// What one Newton solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonInfo {
    pub iterations: usize,
    pub residual: f64,
    pub negative_pivots: usize,
    /// diagonal shift that had to be added to factorize (0 in regular states)
    pub shift: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// ‖R‖₂ ≤ rtol · max(‖f_int‖₂, ‖p g‖₂)
    pub rtol: f64,
    pub max_iterations: usize,
    /// the largest nodal displacement per iteration (in R); longer steps are scaled down
    pub max_step: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            rtol: 1e-9,
            max_iterations: 30,
            max_step: 0.25,
        }
    }
}

struct Local {
    energy: f64,
    r: [f64; 12],
    k: [f64; 144],
    v: f64,
    g: [f64; 12],
    h: [f64; 144],
}

/// Global quantities at a configuration.
pub struct Assembled {
    pub energy: f64,
    /// internal force on the free dofs
    pub f_int: Vec<f64>,
    /// volume of the modelled part
    pub volume: f64,
    /// ∂V_part/∂x on the free dofs
    pub g: Vec<f64>,
    k_int: Vec<f64>,
    k_vol: Vec<f64>,
}

/// The finite element model of one mesh and one law.
pub struct Model {
    pub mesh: Mesh,
    pub law: Box<dyn MembraneLaw>,
    pub elements: Vec<RefElement>,
    /// equation number of each dof (3 per node), `None` where fixed
    pub eq: Vec<Option<usize>>,
    pub n_eq: usize,
    /// per element: (local row, local col) of each matrix entry, in pattern order
    entries: Vec<Vec<(u8, u8)>>,
    diag: Vec<usize>,
    /// equation of each rigid plug's axial translation (None if fixed)
    plug_eq: Vec<Option<usize>>,
    ldlt: SparseLdlt,
    pub settings: NewtonSettings,
    /// rigid planes always present (any number, any orientation)
    pub planes: Vec<Plane>,
    /// contact penalty κ (per unit μH/R², see `contact::penalty_for`)
    pub penalty: f64,
}

impl Model {
    /// Build the model: check the mesh, fix the symmetry-plane normal displacements and pin the
    /// remaining rigid-body modes on nodes whose motion the symmetry of the problem already
    /// forbids (so the pins carry no load): u_x = u_y = 0 on the axis x = y = 0, u_x = 0 at the
    /// node of largest y on the line x = z = 0, u_z = 0 at one node on z = 0.
    pub fn new(mesh: Mesh, law: Box<dyn MembraneLaw>) -> Result<Self, FemError> {
        mesh.check()?;
        let nn = mesh.nodes.len();
        let mut fixed = vec![false; 3 * nn];
        let on: Vec<Vec<bool>> = (0..3).map(|ax| mesh.on_plane(ax)).collect();
        for &ax in mesh.symmetry.planes() {
            for i in 0..nn {
                if on[ax][i] {
                    fixed[3 * i + ax] = true;
                }
            }
        }
        let planes = mesh.symmetry.planes();
        // translations x, y and rotations about x, y
        if !planes.contains(&0) || !planes.contains(&1) {
            for i in 0..nn {
                if on[0][i] && on[1][i] {
                    fixed[3 * i] = true;
                    fixed[3 * i + 1] = true;
                }
            }
        }
        // rotation about z
        if !planes.contains(&0) && !planes.contains(&1) {
            if let Some(i) = (0..nn)
                .filter(|&i| on[0][i] && on[2][i])
                .max_by(|&a, &b| mesh.nodes[a][1].total_cmp(&mesh.nodes[b][1]))
            {
                fixed[3 * i] = true;
            }
        }
        // translation z
        if !planes.contains(&2) {
            if let Some(i) = (0..nn).find(|&i| on[2][i]) {
                fixed[3 * i + 2] = true;
            }
        }
        // Rigid plugs: the ring nodes keep x and y (tied to the disc) and share one axial dof,
        // the disc's translation.
        let mut plug_of = vec![usize::MAX; nn];
        for (k, ring) in mesh.plugs.iter().enumerate() {
            for &i in ring {
                fixed[3 * i] = true;
                fixed[3 * i + 1] = true;
                plug_of[i] = k;
            }
        }
        let mut eq = vec![None; 3 * nn];
        let mut plug_eq = vec![None; mesh.plugs.len()];
        let mut n_eq = 0;
        for (d, f) in fixed.iter().enumerate() {
            if *f {
                continue;
            }
            let node = d / 3;
            if d % 3 == 2 && plug_of[node] != usize::MAX {
                let k = plug_of[node];
                eq[d] = Some(*plug_eq[k].get_or_insert_with(|| {
                    n_eq += 1;
                    n_eq - 1
                }));
            } else {
                eq[d] = Some(n_eq);
                n_eq += 1;
            }
        }
        let mut elements = Vec::with_capacity(mesh.quads.len());
        for (e, q) in mesh.quads.iter().enumerate() {
            elements.push(RefElement::new(e, *q, &q.map(|i| mesh.nodes[i]))?);
        }
        let mut entries = Vec::with_capacity(elements.len());
        let mut pairs = Vec::new();
        let mut diag = vec![usize::MAX; n_eq];
        for el in &elements {
            let mut list = Vec::new();
            for i in 0..12 {
                for j in 0..12 {
                    if let (Some(a), Some(b)) = (
                        eq[3 * el.nodes[i / 3] + i % 3],
                        eq[3 * el.nodes[j / 3] + j % 3],
                    ) {
                        if a >= b {
                            if a == b && diag[a] == usize::MAX {
                                diag[a] = pairs.len();
                            }
                            pairs.push((a, b));
                            list.push((i as u8, j as u8));
                        }
                    }
                }
            }
            entries.push(list);
        }
        let ldlt = SparseLdlt::new(n_eq, &pairs)?;
        Ok(Self {
            mesh,
            law,
            elements,
            eq,
            n_eq,
            entries,
            diag,
            plug_eq,
            ldlt,
            settings: NewtonSettings::default(),
            planes: vec![],
            penalty: 0.0,
        })
    }

    /// The symmetry multiplicity (copies of the model in the whole tube).
    pub fn multiplicity(&self) -> f64 {
        self.mesh.symmetry.multiplicity()
    }

    /// The reference configuration with zero pressure.
    pub fn reference_state(&self) -> State {
        State {
            x: self.mesh.nodes.clone(),
            p: 0.0,
        }
    }

    /// Assemble energy, internal force, volume and its gradient, and (if `tangent`) the matrix
    /// values. Element kernels run in parallel; every sum is taken in element order, so the result
    /// does not depend on the number of threads.
    pub fn assemble(&self, x: &[[f64; 3]], tangent: bool) -> Result<Assembled, FemError> {
        self.assemble_with(x, tangent, &[])
    }

    /// All contact planes for a control: the model's own and the control's plates.
    pub fn contact_planes(&self, control: Control) -> Vec<Plane> {
        let mut p = self.planes.clone();
        p.extend(control.plates());
        p
    }

    /// [`Model::assemble`] with contact against `extra` planes (added to the model's own).
    pub fn assemble_with(
        &self,
        x: &[[f64; 3]],
        tangent: bool,
        extra: &[Plane],
    ) -> Result<Assembled, FemError> {
        let law = self.law.as_ref();
        let planes: Vec<Plane> = self.planes.iter().chain(extra).copied().collect();
        let kappa = self.penalty;
        let locals: Vec<Result<Local, FemError>> = self
            .elements
            .par_iter()
            .enumerate()
            .map(|(e, el)| {
                let xe = el.nodes.map(|i| x[i]);
                let mut l = Local {
                    energy: 0.0,
                    r: [0.0; 12],
                    k: [0.0; 144],
                    v: 0.0,
                    g: [0.0; 12],
                    h: [0.0; 144],
                };
                l.energy = membrane_kernel(law, el, &xe, &mut l.r, tangent.then_some(&mut l.k))
                    .map_err(|(gp, source)| FemError::Material {
                        element: e,
                        gauss_point: gp,
                        source,
                    })?;
                if !planes.is_empty() {
                    l.energy += contact_kernel(
                        el,
                        &xe,
                        &planes,
                        kappa,
                        &mut l.r,
                        tangent.then_some(&mut l.k),
                    );
                }
                l.v = volume_kernel(&xe, &mut l.g, tangent.then_some(&mut l.h));
                Ok(l)
            })
            .collect();
        let mut out = Assembled {
            energy: 0.0,
            f_int: vec![0.0; self.n_eq],
            volume: 0.0,
            g: vec![0.0; self.n_eq],
            k_int: Vec::new(),
            k_vol: Vec::new(),
        };
        if tangent {
            let n: usize = self.entries.iter().map(|l| l.len()).sum();
            out.k_int.reserve(n);
            out.k_vol.reserve(n);
        }
        for (e, l) in locals.into_iter().enumerate() {
            let l = l?;
            out.energy += l.energy;
            out.volume += l.v;
            let el = &self.elements[e];
            for i in 0..12 {
                if let Some(a) = self.eq[3 * el.nodes[i / 3] + i % 3] {
                    out.f_int[a] += l.r[i];
                    out.g[a] += l.g[i];
                }
            }
            if tangent {
                for &(i, j) in &self.entries[e] {
                    let idx = i as usize * 12 + j as usize;
                    out.k_int.push(l.k[idx]);
                    out.k_vol.push(l.h[idx]);
                }
            }
        }
        // Rigid plug faces close the surface: V_face = (1/3) z_d A sign, linear in the disc
        // translation z_d (A is fixed, the ring being tied to the disc), so no Hessian term.
        for (ring, eq) in self.mesh.plugs.iter().zip(&self.plug_eq) {
            let face = tubemem_mesh::plug_face(x, ring);
            out.volume += face.volume();
            if let Some(k) = eq {
                out.g[*k] += face.area * face.sign / 3.0;
            }
        }
        Ok(out)
    }

    /// Factorize K = K_int − p H (+ a diagonal shift if K is singular); returns (#neg, shift).
    fn factorize(&mut self, a: &Assembled, p: f64) -> Result<(usize, f64), FemError> {
        let mut vals: Vec<f64> = a
            .k_int
            .iter()
            .zip(&a.k_vol)
            .map(|(k, h)| k - p * h)
            .collect();
        match self.ldlt.factorize(&vals) {
            Ok(neg) => Ok((neg, 0.0)),
            Err(first) => {
                let scale = self
                    .diag
                    .iter()
                    .map(|&d| vals[d].abs())
                    .fold(0.0, f64::max)
                    .max(1e-300);
                let mut applied = 0.0;
                for rel in [1e-10, 1e-8, 1e-6, 1e-4] {
                    let s = rel * scale;
                    for &d in &self.diag {
                        vals[d] += s - applied;
                    }
                    applied = s;
                    if let Ok(neg) = self.ldlt.factorize(&vals) {
                        return Ok((neg, s));
                    }
                }
                Err(first)
            }
        }
    }

    fn apply(&self, x: &mut [[f64; 3]], dx: &[f64], t: f64) {
        for (d, e) in self.eq.iter().enumerate() {
            if let Some(k) = e {
                x[d / 3][d % 3] += t * dx[*k];
            }
        }
    }

    /// Newton iterations at fixed control; `state` is the initial guess and, on success, the
    /// converged state.
    pub fn solve(
        &mut self,
        state: &mut State,
        control: Control,
    ) -> Result<NewtonInfo, (usize, f64)> {
        let m = self.multiplicity();
        let settings = self.settings;
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if let Control::Pressure(p) = control {
            state.p = p;
        }
        let plates = control.plates();
        let mut last = f64::INFINITY;
        for it in 0..=settings.max_iterations {
            let a = match self.assemble_with(&state.x, true, &plates) {
                Ok(a) => a,
                Err(_) => return Err((it, f64::INFINITY)),
            };
            if let Some(pv) = control.gas() {
                state.p = pv / (m * a.volume);
            }
            let p = state.p;
            let r: Vec<f64> = a.f_int.iter().zip(&a.g).map(|(f, g)| f - p * g).collect();
            let (c, h): (f64, Option<Vec<f64>>) = match control {
                Control::Volume(v) => (m * a.volume - v, Some(a.g.iter().map(|g| m * g).collect())),
                Control::Node {
                    node,
                    component,
                    target,
                } => {
                    let k = self.eq[3 * node + component].ok_or((it, f64::INFINITY))?;
                    let mut e = vec![0.0; self.n_eq];
                    e[k] = 1.0;
                    (state.x[node][component] - target, Some(e))
                }
                _ => (0.0, None),
            };
            let reference = norm(&a.f_int).max(p.abs() * norm(&a.g)).max(1e-12);
            let res = norm(&r) / reference;
            let cscale = match control {
                Control::Volume(v) => v.abs().max(1e-300),
                _ => 1.0,
            };
            last = res + c.abs() / cscale;
            let (neg, shift) = match self.factorize(&a, p) {
                Ok(v) => v,
                Err(_) => return Err((it, last)),
            };
            let converged = res <= settings.rtol && c.abs() <= 1e-12 * cscale;
            // the Newton correction
            let mut dx: Vec<f64> = r.iter().map(|v| -v).collect();
            self.ldlt.solve(&mut dx);
            let mut dp = 0.0;
            let mut negative = neg;
            match (control, &h) {
                (c, _) if c.gas().is_some() => {
                    let cc = p / a.volume;
                    let mut b = a.g.clone();
                    self.ldlt.solve(&mut b);
                    let gb: f64 = a.g.iter().zip(&b).map(|(x, y)| x * y).sum();
                    let gdx: f64 = a.g.iter().zip(&dx).map(|(x, y)| x * y).sum();
                    let denom = 1.0 + cc * gb;
                    if denom < 0.0 {
                        negative = negative.saturating_sub(1);
                    }
                    for (d, bb) in dx.iter_mut().zip(&b) {
                        *d -= cc * bb * gdx / denom;
                    }
                }
                (_, Some(h)) => {
                    let mut b = a.g.clone();
                    self.ldlt.solve(&mut b);
                    let hb: f64 = h.iter().zip(&b).map(|(x, y)| x * y).sum();
                    let ha: f64 = h.iter().zip(&dx).map(|(x, y)| x * y).sum();
                    if hb < 0.0 {
                        negative = negative.saturating_sub(1);
                    }
                    dp = (-c - ha) / hb;
                    for (d, bb) in dx.iter_mut().zip(&b) {
                        *d += dp * bb;
                    }
                }
                _ => {}
            }
            if converged {
                return Ok(NewtonInfo {
                    iterations: it,
                    residual: res,
                    negative_pivots: negative,
                    shift,
                });
            }
            if it == settings.max_iterations {
                break;
            }
            // limit the step, then backtrack on the residual
            let maxd = (0..self.mesh.nodes.len())
                .map(|i| {
                    (0..3)
                        .map(|k| self.eq[3 * i + k].map_or(0.0, |e| dx[e] * dx[e]))
                        .sum::<f64>()
                        .sqrt()
                })
                .fold(0.0, f64::max);
            let mut t = if maxd > settings.max_step {
                settings.max_step / maxd
            } else {
                1.0
            };
            if !dx.iter().all(|v| v.is_finite()) || !dp.is_finite() {
                return Err((it, last));
            }
            let x0 = state.x.clone();
            let p0 = state.p;
            // potential and its slope along dx (∂Π/∂x = R)
            let pi0 = potential(control, a.energy, a.volume, p);
            let slope: f64 = r.iter().zip(&dx).map(|(ri, di)| ri * di).sum();
            let mut accepted = false;
            for _ in 0..8 {
                state.x.clone_from(&x0);
                self.apply(&mut state.x, &dx, t);
                state.p = p0 + t * dp;
                if let Ok(trial) = self.assemble_with(&state.x, false, &plates) {
                    let pt = match control {
                        c if c.gas().is_some() => c.gas().unwrap_or(0.0) / (m * trial.volume),
                        _ => state.p,
                    };
                    let rt: Vec<f64> = trial
                        .f_int
                        .iter()
                        .zip(&trial.g)
                        .map(|(f, g)| f - pt * g)
                        .collect();
                    let reft = norm(&trial.f_int).max(pt.abs() * norm(&trial.g)).max(1e-12);
                    // Bordered controls: accept full steps (the merit mixes R and c). Potential
                    // controls (pressure, gas, squeeze): accept a decrease of the residual or of
                    // the total potential Π (Armijo on the directional derivative −Rᵀdx·t).
                    let pi_t = potential(control, trial.energy, trial.volume, pt);
                    let armijo = pi0 + 1e-4 * t * slope;
                    if h.is_some() || norm(&rt) / reft < res || pi_t < armijo || t < 1e-3 {
                        accepted = true;
                        break;
                    }
                }
                t *= 0.5;
            }
            if !accepted {
                state.x = x0;
                state.p = p0;
                return Err((it, last));
            }
        }
        Err((settings.max_iterations, last))
    }
}

impl Model {
    /// The residual R = f_int − p ∂V/∂x on the free dofs, with p = `p` or, for closed gas,
    /// p = pv/(m V_part) (for tests and diagnostics).
    pub fn residual(&self, x: &[[f64; 3]], control: Control, p: f64) -> Result<Vec<f64>, FemError> {
        let a = self.assemble_with(x, false, &control.plates())?;
        let p = match control.gas() {
            Some(pv) => pv / (self.multiplicity() * a.volume),
            _ => p,
        };
        Ok(a.f_int.iter().zip(&a.g).map(|(f, g)| f - p * g).collect())
    }

    /// The product of the consistent tangent with `v` (free dofs), computed from the element
    /// matrices without factorizing: (K_int − p H) v, plus (p/V_part) g (gᵀv) for closed gas.
    pub fn tangent_times(
        &self,
        x: &[[f64; 3]],
        control: Control,
        p: f64,
        v: &[f64],
    ) -> Result<Vec<f64>, FemError> {
        let a = self.assemble_with(x, true, &control.plates())?;
        let p = match control.gas() {
            Some(pv) => pv / (self.multiplicity() * a.volume),
            _ => p,
        };
        let mut out = vec![0.0; self.n_eq];
        let mut k = 0;
        for (e, list) in self.entries.iter().enumerate() {
            let el = &self.elements[e];
            for &(i, j) in list {
                let (i, j) = (i as usize, j as usize);
                let ra = self.eq[3 * el.nodes[i / 3] + i % 3].expect("entries hold free dofs");
                let cb = self.eq[3 * el.nodes[j / 3] + j % 3].expect("entries hold free dofs");
                let val = a.k_int[k] - p * a.k_vol[k];
                out[ra] += val * v[cb];
                if i != j && ra == cb {
                    // both (i, j) and (j, i) are stored when they share an equation
                } else if ra != cb {
                    out[cb] += val * v[ra];
                }
                k += 1;
            }
        }
        if control.gas().is_some() {
            let gv: f64 = a.g.iter().zip(v).map(|(g, v)| g * v).sum();
            for (o, g) in out.iter_mut().zip(&a.g) {
                *o += p / a.volume * g * gv;
            }
        }
        Ok(out)
    }
}

/// Wall-clock seconds of the three parts of one Newton iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationTiming {
    pub assembly: f64,
    pub factorization: f64,
    pub solve: f64,
    pub negative_pivots: usize,
    pub factor_nnz: usize,
}

impl Model {
    /// Time one Newton iteration at `state` under pressure control (for benchmarks).
    pub fn time_iteration(&mut self, state: &State) -> Result<IterationTiming, FemError> {
        let t0 = std::time::Instant::now();
        let a = self.assemble(&state.x, true)?;
        let t1 = std::time::Instant::now();
        let (neg, _) = self.factorize(&a, state.p)?;
        let t2 = std::time::Instant::now();
        let mut dx: Vec<f64> = a
            .f_int
            .iter()
            .zip(&a.g)
            .map(|(f, g)| state.p * g - f)
            .collect();
        self.ldlt.solve(&mut dx);
        let t3 = std::time::Instant::now();
        Ok(IterationTiming {
            assembly: (t1 - t0).as_secs_f64(),
            factorization: (t2 - t1).as_secs_f64(),
            solve: (t3 - t2).as_secs_f64(),
            negative_pivots: neg,
            factor_nnz: self.ldlt.factor_nnz(),
        })
    }
}

/// The total potential of the modelled part for the potential-based controls:
/// Π = W_int + E_contact − p V_part (pressure) or − (pv/m) ln V_part (closed gas, squeeze; by
/// Boyle's law pv/m = p V_part at every state).
fn potential(control: Control, energy: f64, v_part: f64, p: f64) -> f64 {
    match control {
        Control::Gas { .. } | Control::Squeeze { .. } => energy - p * v_part * v_part.ln(),
        _ => energy - p * v_part,
    }
}

/// One stage of a run: its number (for messages), the control value at its start and end, and
/// how to step between them.
pub struct Stage {
    pub index: usize,
    pub from: f64,
    pub to: f64,
    pub initial_steps: usize,
    pub max_cuts: usize,
}

/// Run one stage: the control moves linearly from `stage.from` to `stage.to` (built by
/// `control(value)`), with step cut-back on failure and growth after easy steps.
/// `on_step(model, step, value, state, info)` is called for every converged step, so results can be
/// written as the run goes; an error names the stage, the step, the iterations and the residual.
pub fn run_stage(
    model: &mut Model,
    state: &mut State,
    stage: &Stage,
    control: impl Fn(f64) -> Control,
    mut on_step: impl FnMut(&Model, usize, f64, &State, &NewtonInfo) -> Result<(), String>,
) -> Result<(), FemError> {
    let (from, to) = (stage.from, stage.to);
    // A stress-free membrane has no stiffness against inextensional modes, and a bordered
    // control (volume, node) amplifies them: from an unloaded state, first take a small
    // pressure-controlled step (ϖ = 0.01, a hoop strain of about 0.25 %), which converges from
    // the reference and gives the membrane its geometric stiffness.
    if state.p == 0.0 && !matches!(control(from), Control::Pressure(_)) {
        let mut p0 = 0.01;
        loop {
            let mut trial = state.clone();
            if model.solve(&mut trial, Control::Pressure(p0)).is_ok() {
                *state = trial;
                break;
            }
            p0 *= 0.5;
            if p0 < 1e-6 {
                return Err(FemError::NoConvergence {
                    stage: stage.index,
                    step: 0,
                    iterations: model.settings.max_iterations,
                    residual: f64::NAN,
                    tolerance: model.settings.rtol,
                    cuts: 14,
                });
            }
        }
    }
    let mut lambda = 0.0;
    let mut dl = 1.0 / stage.initial_steps.max(1) as f64;
    let mut step = 0;
    let mut cuts = 0;
    while lambda < 1.0 {
        // snap to the end when within rounding of it (no zero-length last step)
        let next = if lambda + dl >= 1.0 - 1e-9 {
            1.0
        } else {
            lambda + dl
        };
        let value = from + (to - from) * next;
        let mut trial = state.clone();
        match model.solve(&mut trial, control(value)) {
            Ok(info) => {
                step += 1;
                lambda = next;
                *state = trial;
                on_step(model, step, value, state, &info).map_err(|reason| FemError::Output {
                    stage: stage.index,
                    step,
                    reason,
                })?;
                if info.iterations <= 5 {
                    dl = (dl * 1.5).min(0.25);
                }
            }
            Err((iterations, residual)) => {
                cuts += 1;
                dl *= 0.5;
                if cuts > stage.max_cuts {
                    return Err(FemError::NoConvergence {
                        stage: stage.index,
                        step: step + 1,
                        iterations,
                        residual,
                        tolerance: model.settings.rtol,
                        cuts: cuts - 1,
                    });
                }
            }
        }
    }
    Ok(())
}

/// The node of the model closest to `p` (reference configuration).
pub fn nearest_node(mesh: &Mesh, p: [f64; 3]) -> usize {
    (0..mesh.nodes.len())
        .min_by(|&a, &b| {
            let d = |i: usize| {
                (0..3)
                    .map(|k| (mesh.nodes[i][k] - p[k]).powi(2))
                    .sum::<f64>()
            };
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(0)
}
