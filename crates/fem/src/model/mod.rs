//! The finite element model of one mesh and one law: dofs, pattern, reference elements, the
//! assembly as a sum of terms, and the membrane problem that the Newton driver solves.
//!
//! | module | what it owns |
//! |---|---|
//! | `mod.rs` | [`Model`]: construction, numbering, accessors |
//! | `load` | [`Load`], [`Loading`], [`State`] |
//! | `elements` | [`Elements`] (4- or 9-node reference elements) |
//! | `assembly` | [`Model::assemble`]: the terms ([`crate::term`]) summed element by element, plug faces, soft pins; residuals and tangent products |
//! | `solve` | the shifted LDLᵀ, the bordered and gas solves, the solve drivers ([`Model::solve`], [`Model::solve_held`], [`Model::solve_arc`]) |
//! | `stability` | the pressure tangent, the softest mode ([`Model::smallest_mode`], [`ModeReport`]) |
//! | `problem` | the membrane equilibrium as a [`newton::Problem`], [`ArcConstraint`] |
//! | `diagnostics` | [`LockingProximity`], [`IterationTiming`] |
//! | `remap` | [`Model::move_reference`]: states carried to a refitted mesh |
//! | `reuse` | factorizing less often: the last factor preconditions GMRES ([`Refactorization`]) |
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

use crate::contact::{Contact, Enforcement, MovingPlanes, UpdateSize};
use crate::dofs::DofMap;
use crate::geometry::{RefElement, Vec3};
use crate::linsolve::SparseLdlt;
use crate::newton::{
    self, Augmentation, Evaluation, Inertia, Linearization, NewtonError, NewtonSettings,
};
use crate::pattern::Pattern;
use crate::term::{ContactTerm, ElementAt, ElementTerm, MembraneTerm, Term};
use crate::FemError;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use tubemem_material::MembraneLaw;
use tubemem_mesh::volume::volume_kernel_n;
use tubemem_mesh::{ElementKind, Mesh};

mod assembly;
mod diagnostics;
mod elements;
mod load;
mod problem;
mod prolong;
mod remap;
mod reuse;
mod solve;
mod stability;

pub use assembly::Assembled;
pub use diagnostics::{IterationTiming, LockingProximity, NEAR_LOCKING};
pub use elements::Elements;
pub use load::{Load, Loading, State};
pub use problem::{ArcConstraint, PRESSURE_FLOOR};
pub use prolong::{Prolongation, MAX_OFF_SURFACE};
pub use reuse::{
    Refactorization, AUTO_FLOP_RATIO, CONTRACTION, MAX_FORCING, MAX_KRYLOV, MAX_STATUS_CHANGES,
};
pub use solve::{Held, MAX_UPDATE_HALVINGS};
pub use stability::{ModeReport, NEUTRAL};

/// The finite element model of one mesh and one law.
pub struct Model {
    /// set from outside (a signal handler) to stop the solve at the next Newton iteration
    interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    mesh: Mesh,
    law: Box<dyn MembraneLaw>,
    /// the Gauss points' histories of a viscoelastic law and the time step solved
    /// ([`crate::memory`]; `None`: the law is elastic)
    memory: Option<crate::memory::Memory>,
    /// force terms added to the membrane and the contact ([`Model::add_term`])
    terms: Vec<Box<dyn Term>>,
    /// a load magnitude applied by the added terms ([`Model::set_load_scale`]; 0: none)
    pub(super) load_scale: f64,
    elements: Elements,
    dofs: DofMap,
    pattern: Pattern,
    ldlt: SparseLdlt,
    /// the fill-reducing ordering of `ldlt`'s symbolic analysis
    ordering: crate::ordering::Ordering,
    settings: NewtonSettings,
    /// when the linearizations factorize, and the factor's state across them
    reuse: reuse::FactorReuse,
    /// per-Newton-iteration timings, when asked for ([`Model::set_iteration_log`])
    iteration_log: Option<std::sync::Mutex<Vec<IterationRecord>>>,
}

/// Where one Newton iteration's time went (wall-clock seconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationRecord {
    /// the assembly with the tangent at the iterate (done for the accepted line-search trial
    /// that led here, or here)
    pub assembly: f64,
    /// the assemblies of rejected line-search trials before this iterate
    pub line_search: f64,
    /// the numeric factorization (and its shifted retries); 0 where the factor was reused
    pub factorization: f64,
    /// whether this linearization factorized its tangent (false: it reused an earlier factor)
    pub factorized: bool,
    /// the GMRES iterations of its solves with a reused factor (0 when it factorized)
    pub krylov: usize,
    /// the triangular solves of the correction (and of the bordered or gas term), or the GMRES
    /// solves with a reused factor
    pub solve: f64,
    /// the scaled residual at the iterate
    pub residual: f64,
    pub negative_pivots: usize,
}

impl Model {
    /// Check the mesh, number the dofs ([`DofMap`]), build the reference elements, the pattern
    /// and its symbolic factorization.
    pub fn new(mesh: Mesh, law: Box<dyn MembraneLaw>) -> Result<Self, FemError> {
        Self::with_ordering(mesh, law, crate::ordering::Ordering::default())
    }

    /// As [`Model::new`], with the factorization's fill-reducing ordering
    /// ([`crate::ordering`]) chosen.
    pub fn with_ordering(
        mesh: Mesh,
        law: Box<dyn MembraneLaw>,
        ordering: crate::ordering::Ordering,
    ) -> Result<Self, FemError> {
        mesh.check()?;
        let dofs = DofMap::new(&mesh);
        let elements = Self::reference_elements(&mesh)?;
        let (pattern, ldlt) = Self::numbering(&mesh, &elements, &dofs, ordering)?;
        Ok(Self {
            interrupt: None,
            mesh,
            law,
            memory: None,
            terms: Vec::new(),
            load_scale: 0.0,
            elements,
            dofs,
            pattern,
            ldlt,
            ordering,
            settings: NewtonSettings::default(),
            reuse: Default::default(),
            iteration_log: None,
        })
    }

    /// Hold the rigid-mode pins of component x (`soft[0]`) and y (`soft[1]`) by springs of
    /// stiffness `stiffness` instead ([`DofMap::with_soft_pins`]; runs use
    /// [`crate::dofs::SOFT_PIN_STIFFNESS`]), for problems whose planes move the tube sideways
    /// (not symmetric about x = 0 or y = 0): renumbers the dofs and rebuilds the pattern and
    /// the symbolic factorization. Call it before solving.
    pub fn soften_rigid_pins(&mut self, soft: [bool; 2], stiffness: f64) -> Result<(), FemError> {
        let dofs = DofMap::with_soft_pins(&self.mesh, soft, stiffness);
        let (pattern, ldlt) = Self::numbering(&self.mesh, &self.elements, &dofs, self.ordering)?;
        let par = self.ldlt.threads();
        self.dofs = dofs;
        self.pattern = pattern;
        self.ldlt = ldlt;
        self.ldlt.set_threads(par);
        Ok(())
    }

    /// The (row, col) of every value the assembly gives the factorization, row ≥ col, in the
    /// order the values come (duplicates included): the pattern's pairs, built again (runs do
    /// not keep them: 16 bytes a value).
    pub fn pattern_pairs(&self) -> Vec<(usize, usize)> {
        Pattern::new(
            &self.dofs,
            (0..self.elements.len()).map(|e| self.elements.nodes(e)),
        )
        .1
    }

    /// The fill-reducing ordering asked for ([`Model::with_ordering`]).
    pub fn ordering(&self) -> crate::ordering::Ordering {
        self.ordering
    }

    /// The ordering the factorization uses: what `Auto` chose, or the one asked for.
    pub fn factor_ordering(&self) -> crate::ordering::Ordering {
        self.ldlt.ordering()
    }

    /// The unknowns of the top separator when the factorization is split there
    /// ([`crate::linsolve::SparseLdlt::split_separator`]); `None` for a whole factor.
    pub fn factor_split_separator(&self) -> Option<usize> {
        self.ldlt.split_separator()
    }

    /// The reference elements of `mesh`.
    fn reference_elements(mesh: &Mesh) -> Result<Elements, FemError> {
        Ok(match mesh.element() {
            ElementKind::Quad4 => Elements::Quad4(
                mesh.quads
                    .iter()
                    .enumerate()
                    .map(|(e, q)| RefElement::new(e, *q, &q.map(|i| mesh.nodes[i])))
                    .collect::<Result<Vec<_>, _>>()?,
            ),
            ElementKind::Quad9 => Elements::Quad9(
                (0..mesh.quads.len())
                    .map(|e| {
                        let q = mesh.nodes9(e);
                        RefElement::new(e, q, &q.map(|i| mesh.nodes[i]))
                    })
                    .collect::<Result<Vec<_>, _>>()?,
            ),
        })
    }

    /// The sparsity pattern of `dofs` over `elements` and its symbolic factorization; a node
    /// that no element uses is an error.
    fn numbering(
        mesh: &Mesh,
        elements: &Elements,
        dofs: &DofMap,
        ordering: crate::ordering::Ordering,
    ) -> Result<(Pattern, SparseLdlt), FemError> {
        let (pattern, pairs) = Pattern::new(dofs, (0..elements.len()).map(|e| elements.nodes(e)));
        if let Some(k) = pattern.diagonal().iter().position(|&d| d == usize::MAX) {
            let node = (0..mesh.nodes.len())
                .find(|&i| (0..3).any(|c| dofs.eq(i, c) == Some(k)))
                .unwrap_or(usize::MAX);
            return Err(FemError::UnusedNode { node });
        }
        let ldlt =
            SparseLdlt::with_options(dofs.len(), &pairs, crate::linsolve::Layout::Auto, ordering)?;
        Ok((pattern, ldlt))
    }

    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// A flag that, once set, makes the next Newton iteration fail with
    /// [`FemError::Interrupted`] (the stepping then stops at once, keeping every converged step).
    pub fn set_interrupt(&mut self, flag: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>) {
        self.interrupt = flag;
    }

    /// Whether the interrupt flag is set.
    pub fn interrupted(&self) -> bool {
        self.interrupt
            .as_ref()
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
    }

    pub fn law(&self) -> &dyn MembraneLaw {
        self.law.as_ref()
    }

    /// Make the law viscoelastic with the relaxation `prony` ([`crate::memory`]): the law
    /// given at construction becomes the base law (its μ the instantaneous modulus), every
    /// Gauss point starts unloaded and the current step is a jump (Δt = 0).
    pub fn set_viscoelastic(&mut self, prony: tubemem_material::viscoelastic::Prony) {
        self.memory = Some(crate::with_elements!(&self.elements, v => {
            crate::memory::Memory::new(prony, v)
        }));
    }

    /// The Gauss points' histories of a viscoelastic law (`None`: elastic).
    pub fn memory(&self) -> Option<&crate::memory::Memory> {
        self.memory.as_ref()
    }

    /// Solve the next time step over `dt` ≥ 0 (0: a jump) from the committed histories; an
    /// elastic model ignores time (Ok).
    pub fn set_time_step(&mut self, dt: f64) -> Result<(), FemError> {
        match &mut self.memory {
            Some(m) => m.set_step(dt),
            None => Ok(()),
        }
    }

    /// Accept `state` as the converged end of the current time step: every Gauss point's
    /// history advances ([`crate::memory::Memory::commit`]). Nothing to do for an elastic
    /// model.
    pub fn commit_time_step(&mut self, state: &State) -> Result<(), FemError> {
        match &mut self.memory {
            Some(m) => {
                let law = self.law.as_ref();
                crate::with_elements!(&self.elements, v => m.commit(law, v, &state.x))
            }
            None => Ok(()),
        }
    }

    /// Put back a viscoelastic law's memory taken earlier ([`Model::memory`], cloned): a
    /// time step that failed after some of its substeps were committed starts again from
    /// there. It must be this model's (the same Gauss points).
    pub fn restore_memory(&mut self, memory: crate::memory::Memory) -> Result<(), FemError> {
        match &self.memory {
            Some(m) if m.len() == memory.len() => {
                self.memory = Some(memory);
                Ok(())
            }
            _ => Err(FemError::Setup {
                reason: "the memory restored is not this model's".into(),
            }),
        }
    }

    /// Replace the Gauss points' histories (a checkpoint's; [`crate::memory::Memory::set_histories`]).
    pub fn set_histories(
        &mut self,
        histories: Vec<tubemem_material::viscoelastic::History>,
    ) -> Result<(), FemError> {
        match &mut self.memory {
            Some(m) => m.set_histories(histories),
            None => Err(FemError::Setup {
                reason: "material histories given to an elastic model".into(),
            }),
        }
    }

    /// Add a force term ([`crate::term`]): every assembly from now on sums it, element by
    /// element, after the membrane and the contact.
    pub fn add_term(&mut self, term: Box<dyn Term>) {
        self.terms.push(term);
    }

    /// The magnitude (a force norm on the free dofs, per μH) of a load an added term applies,
    /// such as a body force: Newton measures its residual against the largest of the internal
    /// force, the pressure load and this (0, the default, adds nothing). Without it, a load
    /// carried by a term alone is measured against the net internal force, which vanishes at
    /// equilibrium.
    pub fn set_load_scale(&mut self, scale: f64) {
        self.load_scale = scale;
    }

    /// The names of the added terms, in the order they are summed.
    pub fn term_names(&self) -> Vec<&str> {
        self.terms.iter().map(|t| t.name()).collect()
    }

    pub fn elements(&self) -> &Elements {
        &self.elements
    }

    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }

    /// The number of equations.
    pub fn n_eq(&self) -> usize {
        self.dofs.len()
    }

    pub fn settings(&self) -> &NewtonSettings {
        &self.settings
    }

    pub fn set_settings(&mut self, settings: NewtonSettings) {
        self.settings = settings;
    }

    /// The number of nonzeros of the sparse factor.
    pub fn factor_nnz(&self) -> usize {
        self.ldlt.factor_nnz()
    }

    /// Record where each Newton iteration's time goes ([`IterationRecord`]), to be collected
    /// with [`Model::take_iteration_log`].
    pub fn set_iteration_log(&mut self, on: bool) {
        self.iteration_log = on.then(|| std::sync::Mutex::new(Vec::new()));
    }

    /// The iterations recorded since the last call (empty when not recording).
    pub fn take_iteration_log(&self) -> Vec<IterationRecord> {
        self.iteration_log
            .as_ref()
            .map(|m| std::mem::take(&mut *m.lock().unwrap_or_else(|e| e.into_inner())))
            .unwrap_or_default()
    }

    fn log_iteration(&self, r: IterationRecord) {
        if let Some(m) = &self.iteration_log {
            m.lock().unwrap_or_else(|e| e.into_inner()).push(r);
        }
    }

    /// The floating-point operations of one numeric factorization.
    pub fn factor_flops(&self) -> f64 {
        self.ldlt.factor_flops()
    }

    /// The threads of the numeric factorization (1: sequential, the default; 0: all of the
    /// current rayon pool). The factor is the same whatever the count
    /// ([`crate::linsolve::SparseLdlt::set_threads`]).
    pub fn set_factor_threads(&mut self, threads: usize) {
        self.ldlt.set_threads(threads);
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
            planes: 0.0,
            multipliers: Vec::new(),
        }
    }

    /// The total enclosed volume (all symmetry copies) at `x`.
    pub fn total_volume(&self, x: &[[f64; 3]]) -> f64 {
        self.multiplicity() * self.mesh.volume_at(x)
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// v − (φᵀv) φ for a unit φ.
fn project_out(v: &mut [f64], phi: &[f64]) {
    let c = dot(v, phi);
    v.iter_mut().zip(phi).for_each(|(x, p)| *x -= c * p);
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The node of the mesh closest to `p` (reference configuration).
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
