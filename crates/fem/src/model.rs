//! The finite element model of one mesh and one law: dofs, pattern, reference elements, the
//! assembly as a sum of terms, and the membrane problem that the Newton driver solves.
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
use crate::element::membrane_kernel;
use crate::geometry::{RefElement, Vec3};
use crate::linsolve::SparseLdlt;
use crate::newton::{
    self, Augmentation, Evaluation, Inertia, Linearization, NewtonError, NewtonSettings,
};
use crate::pattern::Pattern;
use crate::FemError;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use tubemem_material::MembraneLaw;
use tubemem_mesh::volume::volume_kernel_n;
use tubemem_mesh::{ElementKind, Mesh};

/// How the enclosed gas is loaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Loading {
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
}

/// Everything that loads the model at one step: the gas loading and the rigid planes.
#[derive(Clone, Debug, PartialEq)]
pub struct Load {
    pub loading: Loading,
    pub contact: Option<Contact>,
}

impl Load {
    pub fn new(loading: Loading) -> Self {
        Self {
            loading,
            contact: None,
        }
    }
    pub fn pressure(p: f64) -> Self {
        Self::new(Loading::Pressure(p))
    }
    pub fn with_contact(loading: Loading, contact: Contact) -> Self {
        Self {
            loading,
            contact: Some(contact),
        }
    }
    /// Boyle's constant, for closed gas.
    pub fn gas(&self) -> Option<f64> {
        match self.loading {
            Loading::Gas { pv } => Some(pv),
            _ => None,
        }
    }
}

/// A converged (or trial) configuration.
#[derive(Clone, Debug)]
pub struct State {
    pub x: Vec<[f64; 3]>,
    /// reduced pressure ϖ
    pub p: f64,
    /// the planes' load parameter λ of a closed-gas arc-length path ([`MovingPlanes`]);
    /// unused (0) elsewhere
    pub planes: f64,
    /// the contact multipliers of an augmented-Lagrangian contact
    /// ([`crate::contact::Enforcement::Augmented`]), element major, then Gauss point, then
    /// plane, [`crate::contact::HISTORY`] values each ([`Contact::point`],
    /// [`Contact::element_history`]); empty: none (the penalty alone)
    pub multipliers: Vec<f64>,
}

/// The reference elements of a model: all 4-node or all 9-node.
#[derive(Clone, Debug)]
pub enum Elements {
    Quad4(Vec<RefElement<4>>),
    Quad9(Vec<RefElement<9>>),
}

/// Run `$body` with `$v` bound to the element vector of either kind (the body is compiled once
/// per kind, so generic kernels are monomorphized for both).
#[macro_export]
macro_rules! with_elements {
    ($els:expr, $v:ident => $body:expr) => {
        match $els {
            $crate::model::Elements::Quad4($v) => $body,
            $crate::model::Elements::Quad9($v) => $body,
        }
    };
}

impl Elements {
    pub fn len(&self) -> usize {
        with_elements!(self, v => v.len())
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The nodes of element `e` (4 or 9).
    pub fn nodes(&self, e: usize) -> &[usize] {
        with_elements!(self, v => &v[e].nodes[..])
    }
    /// The corner nodes of element `e`.
    pub fn corners(&self, e: usize) -> [usize; 4] {
        let n = self.nodes(e);
        [n[0], n[1], n[2], n[3]]
    }
    /// The nodes of each element: 4 or 9.
    pub fn nodes_per_element(&self) -> usize {
        match self {
            Elements::Quad4(_) => 4,
            Elements::Quad9(_) => 9,
        }
    }
    /// Element `e`'s nodal weights ∫N_a dA0, in node order.
    pub fn nodal_weights(&self, e: usize) -> Vec<f64> {
        with_elements!(self, v => v[e].nodal.iter().map(|p| p.w).collect())
    }
    pub fn kind(&self) -> ElementKind {
        match self {
            Elements::Quad4(_) => ElementKind::Quad4,
            Elements::Quad9(_) => ElementKind::Quad9,
        }
    }
}

/// What one element contributes besides the enclosed volume: the hyperelastic membrane
/// ([`crate::element`]) and, if any, penalty contact with rigid planes ([`crate::contact`]).
#[derive(Clone, Copy)]
struct Terms<'a> {
    law: &'a dyn MembraneLaw,
    contact: Option<&'a Contact>,
    /// the contact multipliers of every element ([`State::multipliers`]; empty: none)
    multipliers: &'a [f64],
    /// positions whose contact status selects the contact's branch
    /// ([`Contact::kernel_on_branch`]; none: the positions assembled)
    branch: Option<&'a [[f64; 3]]>,
}

impl Terms<'_> {
    /// Add the energy (returned), residual and, if asked, the stiffness of element `e`.
    fn add<const N: usize, const D: usize>(
        &self,
        e: usize,
        el: &RefElement<N>,
        xe: &[Vec3; N],
        r: &mut SVector<f64, D>,
        mut k: Option<&mut SMatrix<f64, D, D>>,
    ) -> Result<f64, FemError> {
        let mut energy =
            membrane_kernel(self.law, el, xe, r, k.as_deref_mut()).map_err(|(gp, source)| {
                FemError::Material {
                    element: e,
                    gauss_point: gp,
                    source,
                }
            })?;
        if let Some(c) = self.contact {
            let lambda = c.element_history(self.multipliers, e, c.samples(el).len());
            let branch = self.branch.map(|b| el.gather(b));
            energy += c.kernel_on_branch(el, xe, branch.as_ref(), lambda, r, k);
        }
        Ok(energy)
    }
}

/// One element's energy, residual, volume and volume gradient.
struct Local<const D: usize> {
    energy: f64,
    r: SVector<f64, D>,
    v: f64,
    g: SVector<f64, D>,
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
    /// values of K_int and of ∂²V/∂x² in pattern order (empty without the tangent)
    pub k_int: Vec<f64>,
    pub k_vol: Vec<f64>,
}

/// The finite element model of one mesh and one law.
pub struct Model {
    /// set from outside (a signal handler) to stop the solve at the next Newton iteration
    interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    mesh: Mesh,
    law: Box<dyn MembraneLaw>,
    elements: Elements,
    dofs: DofMap,
    pattern: Pattern,
    ldlt: SparseLdlt,
    settings: NewtonSettings,
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
    /// the numeric factorization (and its shifted retries)
    pub factorization: f64,
    /// the triangular solves of the correction (and of the bordered or gas term)
    pub solve: f64,
    /// the scaled residual at the iterate
    pub residual: f64,
    pub negative_pivots: usize,
}

impl Model {
    /// Check the mesh, number the dofs ([`DofMap`]), build the reference elements, the pattern
    /// and its symbolic factorization.
    pub fn new(mesh: Mesh, law: Box<dyn MembraneLaw>) -> Result<Self, FemError> {
        mesh.check()?;
        let dofs = DofMap::new(&mesh);
        let elements = Self::reference_elements(&mesh)?;
        let (pattern, ldlt) = Self::numbering(&mesh, &elements, &dofs)?;
        Ok(Self {
            interrupt: None,
            mesh,
            law,
            elements,
            dofs,
            pattern,
            ldlt,
            settings: NewtonSettings::default(),
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
        let (pattern, ldlt) = Self::numbering(&self.mesh, &self.elements, &dofs)?;
        self.dofs = dofs;
        self.pattern = pattern;
        self.ldlt = ldlt;
        Ok(())
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

    /// Move the reference nodes to `nodes` (the same mesh with nodes moved along their hoops,
    /// a refitted [`tubemem_mesh::hoop::HoopMap`]) and carry each of `states` over by
    /// `transfer` ([`tubemem_mesh::hoop::Transfer::between`] the old nodes and `nodes`): the
    /// positions by the transfer, and the contact multipliers of nodal contact points as the
    /// planes' traction per reference area at each node (the elements' values at a shared node
    /// averaged with their weights ∫N_a dA0, then transferred), with no last gap. The dofs,
    /// the pattern and the symbolic factorization stay (the topology is the same). Gauss-point
    /// multipliers have no nodal field to transfer: an error.
    pub fn move_reference(
        &mut self,
        nodes: Vec<[f64; 3]>,
        transfer: &tubemem_mesh::hoop::Transfer,
        contact: Option<&Contact>,
        states: &mut [&mut State],
    ) -> Result<(), FemError> {
        let points = contact.map(|c| c.points);
        let count = self.mesh.nodes.len();
        if nodes.len() != count {
            return Err(tubemem_mesh::MeshError::InvalidParameter {
                name: "moved nodes",
                value: nodes.len() as f64,
                requirement: "a refitted mesh must have the old mesh's node count",
            }
            .into());
        }
        // the old nodal traction fields, per state: node major, plane minor
        let per_node = self.elements.nodes_per_element();
        let elements = self.elements.len();
        let mut fields: Vec<Option<(usize, Vec<f64>)>> = Vec::with_capacity(states.len());
        for st in states.iter() {
            if st.multipliers.is_empty() {
                fields.push(None);
                continue;
            }
            let per_element = st.multipliers.len() / elements.max(1);
            let planes = per_element / (crate::contact::HISTORY * per_node);
            if points != Some(crate::contact::ContactPoints::Nodal)
                || planes == 0
                || st.multipliers.len() != elements * planes * crate::contact::HISTORY * per_node
            {
                return Err(FemError::Remap {
                    reason: "the state's contact multipliers are not one per node of each element (Gauss-point multipliers cannot be carried to a moved mesh: use nodal contact points)".into(),
                });
            }
            let mut num = vec![0.0; count * planes];
            let mut den = vec![0.0; count];
            for e in 0..elements {
                let ns = self.elements.nodes(e);
                let w = self.elements.nodal_weights(e);
                let h = &st.multipliers[e * per_element..(e + 1) * per_element];
                for (a, &n) in ns.iter().enumerate() {
                    den[n] += w[a];
                    for k in 0..planes {
                        num[n * planes + k] += w[a] * h[crate::contact::HISTORY * (a * planes + k)];
                    }
                }
            }
            for (n, d) in den.iter().enumerate() {
                if *d > 0.0 {
                    for k in 0..planes {
                        num[n * planes + k] /= d;
                    }
                }
            }
            fields.push(Some((planes, num)));
        }
        let mut mesh = self.mesh.clone();
        mesh.nodes = nodes;
        mesh.check()?;
        let new_elements = Self::reference_elements(&mesh)?;
        let old_nodes = &self.mesh.nodes;
        for (st, field) in states.iter_mut().zip(fields) {
            let old_x = std::mem::take(&mut st.x);
            let mut new_x = carry_positions(old_nodes, &mesh.nodes, &old_x, transfer);
            if let (Some((planes, num)), Some(c)) = (&field, contact) {
                // a moved node in the contact zone (most of its old neighbours' weight
                // pressed), or that the interpolation
                // put inside a plane, takes its old neighbours' interpolated gap (on the plane
                // if they were, outside if they were): the interpolation's own gap
                // there (3.7e-4 R across a 9-node flat at 16 around, `tests_remap`), times the
                // regularization κ (from 1e-6 R), would be a traction error hundreds of times
                // the pressure
                for n in 0..new_x.len() {
                    let w = transfer.weights(n);
                    if matches!(w, [(b, _)] if *b == n) {
                        continue;
                    }
                    for (k, plane) in c.planes.iter().enumerate().take(*planes) {
                        // the weight of the old neighbours that pressed: most of it, and the
                        // node is in the contact zone
                        let share: f64 = w
                            .iter()
                            .filter(|&&(b, _)| num[b * planes + k] > 0.0)
                            .map(|&(_, c)| c)
                            .sum();
                        let pressing = share >= 0.5;
                        let now = plane.gap(new_x[n]);
                        if pressing || now < 0.0 {
                            // the gap of the neighbours that pressed, if it presses (the free
                            // ones' gaps grow quadratically off the edge: no interpolation for
                            // the flat); else of all
                            let on = |b: usize| pressing && num[b * planes + k] > 0.0;
                            let (sum, weight) = w
                                .iter()
                                .filter(|&&(b, _)| on(b) || !pressing)
                                .fold((0.0, 0.0), |(s, t), &(b, c)| {
                                    (s + c * plane.gap(old_x[b]), t + c)
                                });
                            let target = if weight.abs() > 1e-12 {
                                sum / weight
                            } else {
                                0.0
                            };
                            let g = now - target;

                            for i in 0..3 {
                                new_x[n][i] -= g * plane.normal[i];
                            }
                        }
                    }
                }
            }
            st.x = new_x;
            if let Some((planes, num)) = field {
                let per_element = st.multipliers.len() / elements;
                for e in 0..elements {
                    let ns = new_elements.nodes(e);
                    let h = &mut st.multipliers[e * per_element..(e + 1) * per_element];
                    for (a, &n) in ns.iter().enumerate() {
                        for k in 0..planes {
                            let i = crate::contact::HISTORY * (a * planes + k);
                            let v: f64 = transfer
                                .weights(n)
                                .iter()
                                .map(|&(b, c)| c * num[b * planes + k])
                                .sum();
                            // a multiplier is a pressing traction, ≥ 0
                            h[i] = v.max(0.0);
                            h[i + 2] = f64::NAN;
                        }
                    }
                }
            }
        }
        self.mesh = mesh;
        self.elements = new_elements;
        Ok(())
    }

    /// The sparsity pattern of `dofs` over `elements` and its symbolic factorization; a node
    /// that no element uses is an error.
    fn numbering(
        mesh: &Mesh,
        elements: &Elements,
        dofs: &DofMap,
    ) -> Result<(Pattern, SparseLdlt), FemError> {
        let pattern = Pattern::new(dofs, (0..elements.len()).map(|e| elements.nodes(e)));
        if let Some(k) = pattern.diagonal().iter().position(|&d| d == usize::MAX) {
            let node = (0..mesh.nodes.len())
                .find(|&i| (0..3).any(|c| dofs.eq(i, c) == Some(k)))
                .unwrap_or(usize::MAX);
            return Err(FemError::UnusedNode { node });
        }
        let ldlt = SparseLdlt::new(dofs.len(), pattern.pairs())?;
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

    /// Assemble energy, internal force, volume and its gradient, and (if `tangent`) the matrix
    /// values, from the membrane and the contact (if any). Element kernels run in parallel;
    /// every sum is taken in element order, so the result does not depend on the number of
    /// threads.
    pub fn assemble(
        &self,
        x: &[[f64; 3]],
        tangent: bool,
        contact: Option<&Contact>,
    ) -> Result<Assembled, FemError> {
        self.assemble_with_multipliers(x, tangent, contact, &[])
    }

    /// [`Model::assemble`] at the positions and contact multipliers of `state`.
    pub fn assemble_state(
        &self,
        state: &State,
        tangent: bool,
        contact: Option<&Contact>,
    ) -> Result<Assembled, FemError> {
        self.assemble_with_multipliers(&state.x, tangent, contact, &state.multipliers)
    }

    /// [`Model::assemble`] with the contact multipliers `multipliers` ([`State::multipliers`]).
    pub fn assemble_with_multipliers(
        &self,
        x: &[[f64; 3]],
        tangent: bool,
        contact: Option<&Contact>,
        multipliers: &[f64],
    ) -> Result<Assembled, FemError> {
        self.assemble_terms(x, tangent, contact, multipliers, None)
    }

    /// [`Model::assemble_with_multipliers`] with the contact on the branch of the positions
    /// `branch` (see [`Contact::kernel_on_branch`]).
    fn assemble_terms(
        &self,
        x: &[[f64; 3]],
        tangent: bool,
        contact: Option<&Contact>,
        multipliers: &[f64],
        branch: Option<&[[f64; 3]]>,
    ) -> Result<Assembled, FemError> {
        let terms = Terms {
            law: self.law.as_ref(),
            contact,
            multipliers,
            branch,
        };
        match &self.elements {
            Elements::Quad4(els) => self.assemble_with::<4, 12>(els, x, tangent, terms),
            Elements::Quad9(els) => self.assemble_with::<9, 27>(els, x, tangent, terms),
        }
    }

    /// [`Model::assemble`] for elements of N nodes (D = 3N dofs).
    fn assemble_with<const N: usize, const D: usize>(
        &self,
        elements: &[RefElement<N>],
        x: &[[f64; 3]],
        tangent: bool,
        terms: Terms<'_>,
    ) -> Result<Assembled, FemError> {
        // Each element writes its D × D entries straight into its own contiguous range of
        // the value arrays (the pattern lists entries element by element); the vectors and
        // scalars come back per element and are summed in element order. No element matrix is
        // stored, and the result does not depend on the number of threads.
        let (mut k_int, mut k_vol) = if tangent {
            (vec![0.0; self.pattern.len()], vec![0.0; self.pattern.len()])
        } else {
            (Vec::new(), Vec::new())
        };
        let mut slices: Vec<(&mut [f64], &mut [f64])> = Vec::with_capacity(elements.len());
        if tangent {
            let (mut ki, mut kv) = (k_int.as_mut_slice(), k_vol.as_mut_slice());
            for e in 0..elements.len() {
                let n = self.pattern.element_entries(e).len();
                let (a, rest_i) = ki.split_at_mut(n);
                let (b, rest_v) = kv.split_at_mut(n);
                slices.push((a, b));
                ki = rest_i;
                kv = rest_v;
            }
        }
        let locals: Vec<Result<Local<D>, FemError>> = if tangent {
            elements
                .par_iter()
                .zip(slices.par_iter_mut())
                .enumerate()
                .map(|(e, (el, (ki, kv)))| {
                    let (mut k, mut h) = (SMatrix::<f64, D, D>::zeros(), SMatrix::zeros());
                    let l = Self::element(e, el, x, terms, Some((&mut k, &mut h)))?;
                    for (slot, &(i, j)) in self.pattern.element_entries(e).iter().enumerate() {
                        let (i, j) = (i as usize, j as usize);
                        ki[slot] = k[(i, j)];
                        kv[slot] = h[(i, j)];
                    }
                    Ok(l)
                })
                .collect()
        } else {
            elements
                .par_iter()
                .enumerate()
                .map(|(e, el)| Self::element(e, el, x, terms, None))
                .collect()
        };
        drop(slices);
        let n_eq = self.n_eq();
        let mut out = Assembled {
            energy: 0.0,
            f_int: vec![0.0; n_eq],
            volume: 0.0,
            g: vec![0.0; n_eq],
            k_int,
            k_vol,
        };
        for (e, l) in locals.into_iter().enumerate() {
            let l = l?;
            out.energy += l.energy;
            out.volume += l.v;
            let el = &elements[e];
            for i in 0..D {
                if let Some(a) = self.dofs.eq(el.nodes[i / 3], i % 3) {
                    out.f_int[a] += l.r[i];
                    out.g[a] += l.g[i];
                }
            }
        }
        // Rigid plug faces close the surface: V_face = (1/3) z_d A sign, linear in the disc
        // translation z_d (A is fixed, the ring being tied to the disc), so no Hessian term.
        let closed = self.mesh.symmetry.rings_closed();
        for (ring, eq) in self.mesh.plugs.iter().zip(self.dofs.plug_equations()) {
            let face = tubemem_mesh::plug_face(
                x,
                ring,
                closed,
                self.mesh.element() == tubemem_mesh::ElementKind::Quad9,
            );
            out.volume += face.volume();
            if let Some(k) = eq {
                out.g[*k] += face.area * face.sign / 3.0;
            }
        }
        // soft rigid-mode pins: E = κ_s/2 (x − X)², r = κ_s (x − X), K += κ_s on the diagonal
        let diagonal = self.pattern.diagonal();
        for pin in self.dofs.soft_pins() {
            let u = x[pin.node][pin.component] - self.mesh.nodes[pin.node][pin.component];
            out.energy += 0.5 * pin.stiffness * u * u;
            out.f_int[pin.eq] += pin.stiffness * u;
            if tangent {
                out.k_int[diagonal[pin.eq]] += pin.stiffness;
            }
        }
        Ok(out)
    }

    /// One element: the terms' energy and residual (and stiffness into `mats.0`), the volume,
    /// its gradient (and Hessian into `mats.1`). The matrices must come in zeroed.
    fn element<const N: usize, const D: usize>(
        e: usize,
        el: &RefElement<N>,
        x: &[[f64; 3]],
        terms: Terms<'_>,
        mats: Option<(&mut SMatrix<f64, D, D>, &mut SMatrix<f64, D, D>)>,
    ) -> Result<Local<D>, FemError> {
        let xe = el.gather(x);
        let mut l = Local {
            energy: 0.0,
            r: SVector::zeros(),
            v: 0.0,
            g: SVector::zeros(),
        };
        let (k, h) = match mats {
            Some((k, h)) => (Some(k), Some(h)),
            None => (None, None),
        };
        l.energy += terms.add(e, el, &xe, &mut l.r, k)?;
        l.v = volume_kernel_n(&xe, Some(&mut l.g), h);
        Ok(l)
    }

    /// Factorize K = K_int − p H; if K is singular, retry with diagonal shifts of 1e-10 …
    /// 1e-4 of its largest diagonal entry. Returns (#neg, shift).
    fn factorize(&mut self, a: &Assembled, p: f64) -> Result<(usize, f64), FemError> {
        const SHIFTS: [f64; 4] = [1e-10, 1e-8, 1e-6, 1e-4];
        let mut vals: Vec<f64> = a
            .k_int
            .iter()
            .zip(&a.k_vol)
            .map(|(k, h)| k - p * h)
            .collect();
        match self.ldlt.factorize(&vals) {
            Ok(neg) => Ok((neg, 0.0)),
            Err(first) => {
                let diag = self.pattern.diagonal();
                let scale = diag
                    .iter()
                    .map(|&d| vals[d].abs())
                    .fold(0.0, f64::max)
                    .max(1e-300);
                let mut applied = 0.0;
                for rel in SHIFTS {
                    let s = rel * scale;
                    for &d in diag {
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

    /// Newton iterations under `load`; `state` is the initial guess and, on success, the
    /// converged state.
    pub fn solve(
        &mut self,
        state: &mut State,
        load: &Load,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        if let Loading::Pressure(p) = load.loading {
            state.p = p;
        }
        self.solve_load(state, load, None)
    }

    /// Newton under `load` (with the arc-length constraint `arc`, if any) inside the
    /// augmentation loop of the load's contact ([`Model::augmented`]).
    fn solve_load(
        &mut self,
        state: &mut State,
        load: &Load,
        arc: Option<&ArcConstraint<'_>>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        let settings = self.settings;
        let contact = load.contact.clone();
        self.augmented(
            state,
            |_| contact.clone(),
            |model, state| {
                newton::solve(
                    &mut MembraneProblem::new(model, load, arc),
                    state,
                    &settings,
                )
            },
        )
    }

    /// The Uzawa update of `state`'s contact history under `contact`
    /// ([`Contact::update_multipliers`] for every element). Returns the updated history and
    /// the update's maxima. Elements run in parallel; the maxima do not depend on the number of
    /// threads.
    fn augment(
        &self,
        state: &State,
        contact: &Contact,
        gap_tolerance: f64,
    ) -> (Vec<f64>, UpdateSize) {
        with_elements!(&self.elements, els => {
            let per = contact.multipliers_per_element(els.first().map_or(0, |e| contact.samples(e).len()));
            let mut out = vec![0.0; per * els.len()];
            let size = out
                .par_chunks_mut(per.max(1))
                .zip(els.par_iter())
                .enumerate()
                .map(|(e, (o, el))| {
                    let lambda = contact.element_history(&state.multipliers, e, contact.samples(el).len());
                    contact.update_multipliers(el, &el.gather(&state.x), lambda, gap_tolerance, o)
                })
                .reduce(UpdateSize::default, UpdateSize::max);
            (out, size)
        })
    }

    /// The contact points and planes whose status (pushed or free) differs between the
    /// positions `x` and `other`, with the multipliers `multipliers`.
    fn contact_status_changes(
        &self,
        x: &[[f64; 3]],
        other: &[[f64; 3]],
        contact: &Contact,
        multipliers: &[f64],
    ) -> usize {
        with_elements!(&self.elements, els => els
            .par_iter()
            .enumerate()
            .map(|(e, el)| {
                let lambda = contact.element_history(multipliers, e, contact.samples(el).len());
                contact.status_changes(el, &el.gather(x), &el.gather(other), lambda)
            })
            .sum())
    }

    /// Run `once` (one Newton solve of `state`) and, when the contact at the state
    /// (`contact_at`) is augmented ([`Enforcement::Augmented`]), the Uzawa loop around it:
    /// update the multipliers ([`Model::augment`]) and solve again until the largest gap where
    /// a plane pushes is within the gap tolerance. The state keeps the multipliers it is in
    /// equilibrium with (the last update, which found the gap within the tolerance, is not
    /// applied). A penalty contact (or none) drops the state's multipliers and solves once.
    fn augmented(
        &mut self,
        state: &mut State,
        contact_at: impl Fn(&State) -> Option<Contact>,
        mut once: impl FnMut(
            &mut Self,
            &mut State,
        ) -> Result<newton::NewtonReport, NewtonError<FemError>>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        let start = contact_at(state);
        let (Some(contact), Some((gap_tolerance, max_augmentations))) = (
            start.as_ref(),
            start.as_ref().and_then(|c| match c.enforcement {
                Enforcement::Augmented {
                    gap_tolerance,
                    max_augmentations,
                } => Some((gap_tolerance, max_augmentations)),
                Enforcement::Penalty => None,
            }),
        ) else {
            state.multipliers.clear();
            return once(self, state);
        };
        // a stage whose planes changed (or the first with multipliers) starts afresh; every
        // solve restarts the local penalties and keeps the multipliers
        let points = with_elements!(&self.elements, els => els.first().map_or(0, |e| contact.samples(e).len()));
        let per = contact.multipliers_per_element(points);
        if state.multipliers.len() == per * self.elements.len() {
            contact.restart_history(&mut state.multipliers);
        } else {
            state.multipliers = contact.fresh_history(points).repeat(self.elements.len());
        }
        let mut report = once(self, state)?;
        let mut aug = Augmentation::default();
        // the planes at the state (closed gas pressed by moving planes: at its parameter)
        while let Some(contact) = contact_at(state) {
            let (lambda, size) = self.augment(state, &contact, gap_tolerance);
            aug.gap = size.gap;
            aug.penetration = size.penetration;
            if !(size.gap.is_finite() && size.change.is_finite()) {
                return Err(NewtonError::Problem {
                    iteration: report.iterations,
                    source: FemError::NonFiniteResidual {
                        what: "contact multipliers",
                    },
                });
            }
            if size.gap <= gap_tolerance {
                break;
            }
            if aug.updates >= max_augmentations {
                return Err(NewtonError::Problem {
                    iteration: report.iterations,
                    source: FemError::Augmentation {
                        updates: aug.updates,
                        gap: size.gap,
                        penetration: size.penetration,
                        change: size.change,
                        tolerance: gap_tolerance,
                        penalty: contact.penalty,
                    },
                });
            }
            aug.updates += 1;
            aug.change = size.change;
            let again = self.solve_updated(state, lambda, &mut once)?;
            aug.iterations += again.iterations;
            report.iterations += again.iterations;
            report.history.extend(again.history);
            report.residual = again.residual;
            report.inertia = again.inertia;
        }
        report.augmentation = aug;
        Ok(report)
    }

    /// Solve `state` again after its multipliers' Uzawa update to `lambda` (from
    /// [`Model::augment`]). Where Newton finds no descent at its first iteration from the
    /// updated multipliers (a point at the contact edge whose gap and multiplier are both about
    /// zero can make the first direction one that no step length follows), the update is
    /// halved, up to [`MAX_UPDATE_HALVINGS`] times, from the state in equilibrium before it:
    /// the multipliers move part of the way, the local penalties stay. A solve that converges
    /// at once is unchanged.
    fn solve_updated(
        &mut self,
        state: &mut State,
        lambda: Vec<f64>,
        once: &mut impl FnMut(
            &mut Self,
            &mut State,
        ) -> Result<newton::NewtonReport, NewtonError<FemError>>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        let before = state.clone();
        state.multipliers = lambda.clone();
        let mut halvings = 0;
        loop {
            match once(self, state) {
                Ok(r) => return Ok(r),
                // the kink: no descent at the first iteration (cheap to detect); a solve that
                // fails later is not retried (each retry would cost up to a whole solve)
                Err(NewtonError::NoDescent { iteration: 0, .. })
                    if halvings < MAX_UPDATE_HALVINGS =>
                {
                    halvings += 1;
                    let w = 0.5f64.powi(halvings);
                    *state = before.clone();
                    // the history is [λ, κ, last gap] per point: λ part of the way, κ as it
                    // was, the gap of the update
                    let h = crate::contact::HISTORY;
                    for (m, full) in state
                        .multipliers
                        .chunks_exact_mut(h)
                        .zip(lambda.chunks_exact(h))
                    {
                        m[0] += w * (full[0] - m[0]);
                        m[2] = full[2];
                    }
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// Newton iterations at the prescribed total volume `volume` with the direction `phi0`
    /// (normalized here) held (a bulge held where it sits, `phi0` its translation): the correction and the volume
    /// column are projected off the mode φ = K⁻¹φ0/‖K⁻¹φ0‖ at every linearization (one inverse
    /// iteration, so Kφ lies along φ0); at the fixed point the residual R = f_int − ϖg lies along `phi0`,
    /// and convergence is on the residual off it. `state` is the initial guess and, on success,
    /// the converged state. Returns the Newton report and the [`Held`] values there: the
    /// refreshed mode, its eigenvalue and the reaction f = φ0ᵀR (f > 0: the energy at fixed
    /// volume grows along +φ0, so the state, let go, would move along −φ0).
    pub fn solve_held(
        &mut self,
        state: &mut State,
        volume: f64,
        phi0: &[f64],
    ) -> Result<(newton::NewtonReport, Held), NewtonError<FemError>> {
        let settings = self.settings;
        let load = Load::new(Loading::Volume(volume));
        // the hold's projections assume a unit direction
        let n = norm(phi0).max(1e-300);
        let phi0: Vec<f64> = phi0.iter().map(|v| v / n).collect();
        let mut problem = MembraneProblem::new(self, &load, None);
        problem.hold = Some(&phi0);
        let report = newton::solve(&mut problem, state, &settings)?;
        // set by the converged linearization (Newton returns only from one)
        let held = problem.held.take().ok_or(NewtonError::Problem {
            iteration: report.iterations,
            source: FemError::NonFiniteResidual {
                what: "the held mode (no converged linearization)",
            },
        })?;
        Ok((report, held))
    }

    /// Newton iterations on equilibrium under the pressure `state.p` (a free unknown) together
    /// with the arc-length constraint `arc` (see [`ArcConstraint`]); `state` is the predictor
    /// and, on success, the converged point. `load.loading` must be a pressure (its value is
    /// ignored: the pressure is the continuation parameter).
    pub fn solve_arc(
        &mut self,
        state: &mut State,
        load: &Load,
        arc: &ArcConstraint<'_>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        // the pressure is the continuation parameter: whatever the stage's own control, the
        // corrector solves equilibrium under ϖ (an unknown) with the stage's planes
        let load = &Load {
            loading: Loading::Pressure(state.p),
            contact: load.contact.clone(),
        };
        self.solve_load(state, load, Some(arc))
    }

    /// Newton iterations on equilibrium of the closed gas (Boyle's constant `pv`) pressed by
    /// `planes` at the parameter `state.planes` (a free unknown), together with the arc-length
    /// constraint `arc` in (x, λ); `state` is the predictor and, on success, the converged point
    /// (its `p` the gas pressure there).
    pub fn solve_arc_gas(
        &mut self,
        state: &mut State,
        pv: f64,
        planes: &MovingPlanes,
        arc: &ArcConstraint<'_>,
    ) -> Result<newton::NewtonReport, NewtonError<FemError>> {
        let settings = self.settings;
        let load = &Load::new(Loading::Gas { pv });
        self.augmented(
            state,
            |s| Some(planes.at(s.planes)),
            |model, state| {
                let mut problem = MembraneProblem::new(model, load, Some(arc));
                problem.planes = Some(planes);
                newton::solve(&mut problem, state, &settings)
            },
        )
    }

    /// ∂R/∂λ on the free dofs for the planes `planes` at λ, at the positions `x` (the load
    /// column of a closed-gas arc-length path).
    pub fn plane_rate(&self, state: &State, planes: &MovingPlanes, lambda: f64) -> Vec<f64> {
        let contact = planes.at(lambda);
        match &self.elements {
            Elements::Quad4(els) => {
                self.plane_rate_with::<4, 12>(els, state, &contact, &planes.rates)
            }
            Elements::Quad9(els) => {
                self.plane_rate_with::<9, 27>(els, state, &contact, &planes.rates)
            }
        }
    }

    /// [`Model::plane_rate`] for elements of N nodes (D = 3N dofs), summed in element order.
    fn plane_rate_with<const N: usize, const D: usize>(
        &self,
        elements: &[RefElement<N>],
        state: &State,
        contact: &Contact,
        rates: &[f64],
    ) -> Vec<f64> {
        let mut q = vec![0.0; self.n_eq()];
        for (e, el) in elements.iter().enumerate() {
            let mut qe = SVector::<f64, D>::zeros();
            let lambda = contact.element_history(&state.multipliers, e, contact.samples(el).len());
            contact.rate_kernel(el, &el.gather(&state.x), lambda, rates, &mut qe);
            for (i, v) in qe.iter().enumerate() {
                if let Some(a) = self.dofs.eq(el.nodes[i / 3], i % 3) {
                    q[a] += v;
                }
            }
        }
        q
    }

    /// The path tangent of a closed-gas arc-length path at the equilibrium `state`: b =
    /// K_gas⁻¹(−∂R/∂λ) (dx/dλ with the gas closed, K_gas = K_int − ϖH + K_c + (ϖ/V_part) g gᵀ),
    /// −∂R/∂λ, and the negative pivots of K_gas. Factorizes K at `state`.
    pub fn plane_tangent(
        &mut self,
        state: &State,
        pv: f64,
        planes: &MovingPlanes,
    ) -> Result<(Vec<f64>, Vec<f64>, usize), FemError> {
        let contact = planes.at(state.planes);
        let a = self.assemble_state(state, true, Some(&contact))?;
        let p = pv / (self.multiplicity() * a.volume);
        let (neg, _) = self.factorize(&a, p)?;
        let minus_q: Vec<f64> = self
            .plane_rate(state, planes, state.planes)
            .into_iter()
            .map(|v| -v)
            .collect();
        let mut b = minus_q.clone();
        let negative = self.solve_gas(&a, p, &mut b);
        Ok((b, minus_q, neg.saturating_sub(negative)))
    }

    /// Solve K_gas y = v in place with the factor of K = K_int − ϖH (+ K_c) by Sherman–Morrison
    /// for the closed gas's rank-one term (ϖ/V_part) g gᵀ; returns 1 when that term takes one
    /// negative pivot away from K's count (1 + (ϖ/V) gᵀK⁻¹g < 0), else 0.
    fn solve_gas(&self, a: &Assembled, p: f64, v: &mut [f64]) -> usize {
        let cc = p / a.volume;
        let mut b = a.g.clone();
        self.ldlt.solve(&mut b);
        self.ldlt.solve(v);
        let denom = 1.0 + cc * dot(&a.g, &b);
        let gv = dot(&a.g, v);
        for (y, bb) in v.iter_mut().zip(&b) {
            *y -= cc * bb * gv / denom;
        }
        usize::from(denom < 0.0)
    }

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
    fn pressure_tangent_with(
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
    fn inverse_iteration(&self, phi0: &[f64]) -> (Vec<f64>, f64) {
        let phi = self.unit_solve(phi0);
        let mu = self.rayleigh(&phi);
        (phi, mu)
    }

    /// K⁻¹v/‖K⁻¹v‖ with the current factor.
    fn unit_solve(&self, v: &[f64]) -> Vec<f64> {
        let mut u = v.to_vec();
        self.ldlt.solve(&mut u);
        let n = norm(&u).max(1e-300);
        u.iter_mut().for_each(|x| *x /= n);
        u
    }

    /// The Rayleigh quotient of K for the unit vector φ through its inverse: μ = 1/(φᵀK⁻¹φ).
    fn rayleigh(&self, phi: &[f64]) -> f64 {
        let mut w = phi.to_vec();
        self.ldlt.solve(&mut w);
        1.0 / dot(phi, &w)
    }

    /// The largest |diagonal entry| of K = K_int − p H in `a` (the scale of the stiffness).
    fn largest_diagonal(&self, a: &Assembled, p: f64) -> f64 {
        self.pattern
            .diagonal()
            .iter()
            .map(|&d| (a.k_int[d] - p * a.k_vol[d]).abs())
            .fold(0.0, f64::max)
            .max(1e-300)
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
    fn smallest_mode_with(
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

    /// x − x0 on the free dofs.
    pub fn free_difference(&self, x: &[[f64; 3]], x0: &[[f64; 3]]) -> Vec<f64> {
        self.dofs.difference(x, x0)
    }

    /// x0 + t·dx on the free dofs (into `x`).
    pub fn free_update(&self, x: &mut [[f64; 3]], dx: &[f64], t: f64) {
        self.dofs.apply(x, dx, t)
    }

    /// The residual R = f_int − p ∂V/∂x on the free dofs, with p = `p` or, for closed gas,
    /// p = pv/(m V_part) (for tests and diagnostics).
    pub fn residual(&self, x: &[[f64; 3]], load: &Load, p: f64) -> Result<Vec<f64>, FemError> {
        let a = self.assemble(x, false, load.contact.as_ref())?;
        let p = match load.gas() {
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
        load: &Load,
        p: f64,
        v: &[f64],
    ) -> Result<Vec<f64>, FemError> {
        let a = self.assemble(x, true, load.contact.as_ref())?;
        let p = match load.gas() {
            Some(pv) => pv / (self.multiplicity() * a.volume),
            _ => p,
        };
        let mut out = vec![0.0; self.n_eq()];
        let mut k = 0;
        for e in 0..self.elements.len() {
            let nodes = self.elements.nodes(e);
            for &(i, j) in self.pattern.element_entries(e) {
                let (i, j) = (i as usize, j as usize);
                let (Some(ra), Some(cb)) = (
                    self.dofs.eq(nodes[i / 3], i % 3),
                    self.dofs.eq(nodes[j / 3], j % 3),
                ) else {
                    continue;
                };
                let val = a.k_int[k] - p * a.k_vol[k];
                out[ra] += val * v[cb];
                // both (i, j) and (j, i) are stored when they share an equation
                if ra != cb {
                    out[cb] += val * v[ra];
                }
                k += 1;
            }
        }
        if load.gas().is_some() {
            let gv: f64 = a.g.iter().zip(v).map(|(g, v)| g * v).sum();
            for (o, g) in out.iter_mut().zip(&a.g) {
                *o += p / a.volume * g * gv;
            }
        }
        Ok(out)
    }
}

/// A held equilibrium's mode ([`Model::solve_held`]).
#[derive(Clone, Debug)]
pub struct Held {
    /// the refreshed unit mode (free dofs)
    pub mode: Vec<f64>,
    /// its eigenvalue over K's largest diagonal entry
    pub relative_eigenvalue: f64,
    /// the reaction φ0ᵀR of the hold (R = f_int − ϖ g on the free dofs, φ0 the held direction)
    pub force: f64,
    /// the membrane energy (over μH, whole model)
    pub energy: f64,
}

/// The relative eigenvalue (|μ| over K's largest diagonal entry) below which a mode counts as
/// neutral: 1e-8. Measured on the whole tube's bulging path (L/R = 40, 16 around; `cargo run
/// --release -p tubemem-fem --example neutral_mode -- 40 PER_R 16 3`, 2026-11-30): the uniform
/// tube's softest mode is 3e-7 (8 per R along) to 2e-6 (2 per R) of the diagonal; once the bulge
/// has formed, its translation is 1e-10 to 1e-6 at 2 per R (the discretization's ripple, changing
/// sign), 3e-14 to 2e-10 at 4 per R and 1e-17 to 1e-14 (round-off) at 8 per R. The bound lies
/// below the physical modes and above the translation on the meshes where it stops the path.
pub const NEUTRAL: f64 = 1e-8;

/// How many times the augmented solve halves a multiplier update whose solve failed: 3
/// (to 1/8 of the update; the channel's first contact steps at 32 and 64 around converge at
/// the first halving).
pub const MAX_UPDATE_HALVINGS: i32 = 3;

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

/// The pressure below which forces count as zero in the convergence test: ϖ = 1e-6 (six
/// orders below the pressures of the paper's examples). Near the stress-free state the internal
/// force vanishes, and a residual measured against it alone would never converge.
pub const PRESSURE_FLOOR: f64 = 1e-6;

/// The force scale the residual is measured against: the internal force, the pressure load, or
/// the load of [`PRESSURE_FLOOR`], whichever is largest.
fn force_scale(a: &Assembled, p: f64) -> f64 {
    let g = norm(&a.g);
    norm(&a.f_int)
        .max(p.abs() * g)
        .max(1e-12)
        .max(PRESSURE_FLOOR * g)
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

/// The total potential of the modelled part: Π = W_int + E_contact − p V_part (pressure) or
/// − (pv/m) ln V_part (closed gas; by Boyle's law pv/m = p V_part at every state).
fn potential(loading: Loading, energy: f64, v_part: f64, p: f64) -> f64 {
    match loading {
        Loading::Gas { .. } => energy - p * v_part * v_part.ln(),
        _ => energy - p * v_part,
    }
}

/// The arc-length (pseudo-arclength) constraint of one continuation step from the converged
/// point (x₀, ϖ₀) along the unit tangent (t_x, t_ϖ):
///
/// ```text
/// c(x, ϖ) = w t_xᵀ(x − x₀) + t_ϖ (ϖ − ϖ₀) − Δs = 0
/// ```
///
/// with x − x₀ on the free dofs and `w` the weight of the displacements in the arc-length norm
/// ‖(Δx, Δϖ)‖² = w ΔxᵀΔx + Δϖ².
#[derive(Clone, Copy, Debug)]
pub struct ArcConstraint<'a> {
    pub x0: &'a [[f64; 3]],
    pub p0: f64,
    pub tx: &'a [f64],
    pub tp: f64,
    pub w: f64,
    pub ds: f64,
    /// a neutral mode of K held out of the corrector (unit, free dofs; refreshed by one inverse
    /// iteration at every linearization): see [`Model::deflate`]
    pub neutral: Option<&'a [f64]>,
}

/// The membrane equilibrium under one load, as a [`newton::Problem`]: the state is (x, p), the
/// step (Δx on the free dofs, Δp). With `arc`, the pressure is an unknown and the arc-length
/// constraint closes the system.
/// A line-search trial's positions, its assembly (with the tangent) and the seconds it took.
type TrialAssembly = (State, Assembled, f64);

struct MembraneProblem<'a> {
    model: &'a mut Model,
    load: &'a Load,
    arc: Option<&'a ArcConstraint<'a>>,
    /// closed gas pressed by planes that move with `State::planes`, the arc's load parameter
    /// (then `load.contact` is unused)
    planes: Option<&'a MovingPlanes>,
    /// a direction φ0 held in a volume-control Newton (unit, free dofs): the correction is
    /// projected off φ = K⁻¹φ0/‖K⁻¹φ0‖ (one inverse iteration: the neutral mode near φ0), so the
    /// state keeps its coordinate along the mode, and the residual along φ0 — the generalized
    /// force that would move the state along the mode — is left as the hold's reaction (see
    /// [`Model::solve_held`])
    hold: Option<&'a [f64]>,
    /// with `hold`: the held mode, its eigenvalue, the reaction and the energy at the converged
    /// linearization
    held: Option<Held>,
    /// the assembly (with the tangent) of the last trial state the line search evaluated:
    /// when that trial is accepted, the next linearization is at the same state and takes it
    /// instead of assembling again
    trial: std::cell::RefCell<Option<TrialAssembly>>,
    /// seconds spent assembling line-search trials that were not taken since the last
    /// linearization
    rejected_seconds: std::cell::Cell<f64>,
    /// positions whose contact status the next linearization's contact takes
    /// ([`Contact::kernel_on_branch`]; set only by `relinearize`)
    branch: Option<Vec<[f64; 3]>>,
    /// the residual R = f_int − ϖg of the last linearization on its own branch
    residual: Vec<f64>,
}

impl MembraneProblem<'_> {
    fn new<'a>(
        model: &'a mut Model,
        load: &'a Load,
        arc: Option<&'a ArcConstraint<'a>>,
    ) -> MembraneProblem<'a> {
        MembraneProblem {
            model,
            load,
            arc,
            planes: None,
            hold: None,
            held: None,
            trial: std::cell::RefCell::new(None),
            rejected_seconds: std::cell::Cell::new(0.0),
            branch: None,
            residual: Vec::new(),
        }
    }

    /// The planes at `state`: the load's, or the moving planes at the state's parameter.
    fn contact(&self, state: &State) -> Option<std::borrow::Cow<'_, Contact>> {
        match self.planes {
            Some(m) => Some(std::borrow::Cow::Owned(m.at(state.planes))),
            None => self.load.contact.as_ref().map(std::borrow::Cow::Borrowed),
        }
    }

    /// The assembly with the tangent at `state` and the seconds it took: the cached trial's if
    /// it was made at exactly these positions and planes (bitwise), a fresh one otherwise.
    fn assemble_at(&self, state: &State) -> Result<(Assembled, f64), FemError> {
        let x = &state.x;
        if let Some(branch) = &self.branch {
            let t = std::time::Instant::now();
            let contact = self.contact(state);
            let a = self.model.assemble_terms(
                x,
                true,
                contact.as_deref(),
                &state.multipliers,
                Some(branch),
            )?;
            return Ok((a, t.elapsed().as_secs_f64()));
        }
        if let Some((xt, a, secs)) = self.trial.borrow_mut().take() {
            let same = xt.x.len() == x.len()
                && xt.planes.to_bits() == state.planes.to_bits()
                && xt
                    .x
                    .iter()
                    .zip(x)
                    .all(|(p, q)| (0..3).all(|k| p[k].to_bits() == q[k].to_bits()));
            if same {
                return Ok((a, secs));
            }
            self.rejected_seconds
                .set(self.rejected_seconds.get() + secs);
        }
        let t = std::time::Instant::now();
        let a = self
            .model
            .assemble_state(state, true, self.contact(state).as_deref())?;
        Ok((a, t.elapsed().as_secs_f64()))
    }

    fn pressure(&self, state_p: f64, volume: f64) -> f64 {
        match self.load.gas() {
            Some(pv) => pv / (self.model.multiplicity() * volume),
            None => state_p,
        }
    }

    /// Refuse states the loading cannot have: closed gas needs a positive volume, and the
    /// residual must be finite (so that no NaN reaches the convergence test or a message).
    fn admissible(&self, a: &Assembled, p: f64, res: f64) -> Result<(), FemError> {
        if self.load.gas().is_some() && !(a.volume > 0.0) {
            return Err(FemError::GasVolume { volume: a.volume });
        }
        if !p.is_finite() {
            return Err(FemError::NonFiniteResidual {
                what: "gas pressure",
            });
        }
        if !res.is_finite() {
            return Err(FemError::NonFiniteResidual {
                what: "internal or contact forces",
            });
        }
        Ok(())
    }
}

impl newton::Problem for MembraneProblem<'_> {
    type State = State;
    type Step = (Vec<f64>, f64);
    type Error = FemError;

    fn linearize(&mut self, state: &mut State) -> Result<Linearization<Self::Step>, FemError> {
        if self.model.interrupted() {
            return Err(FemError::Interrupted);
        }
        let m = self.model.multiplicity();
        let (a, assembly_seconds) = self.assemble_at(state)?;
        state.p = self.pressure(state.p, a.volume);
        let p = state.p;
        let r: Vec<f64> = a.f_int.iter().zip(&a.g).map(|(f, g)| f - p * g).collect();
        // the constraint c, its gradient h in x and its derivative cp in ϖ
        let mut cp = 0.0;
        let (c, h): (f64, Option<Vec<f64>>) = match (self.arc, self.load.loading) {
            (Some(arc), _) => {
                let d = self.model.dofs.difference(&state.x, arc.x0);
                cp = arc.tp;
                let lambda = if self.planes.is_some() {
                    state.planes
                } else {
                    p
                };
                (
                    arc.w * dot(arc.tx, &d) + arc.tp * (lambda - arc.p0) - arc.ds,
                    Some(arc.tx.iter().map(|t| arc.w * t).collect()),
                )
            }
            (None, Loading::Volume(v)) => {
                (m * a.volume - v, Some(a.g.iter().map(|g| m * g).collect()))
            }
            (
                None,
                Loading::Node {
                    node,
                    component,
                    target,
                },
            ) => {
                let k = self
                    .model
                    .dofs
                    .eq(node, component)
                    .ok_or(FemError::FixedControlDof { node, component })?;
                let mut e = vec![0.0; self.model.n_eq()];
                e[k] = 1.0;
                (state.x[node][component] - target, Some(e))
            }
            _ => (0.0, None),
        };
        let reference = force_scale(&a, p);
        let res = norm(&r) / reference;
        self.admissible(&a, p, res)?;
        let cscale = match (self.arc, self.load.loading) {
            // the constraint is an arc length (RMS displacement and ϖ, O(1) quantities): held to
            // 1e-12 of the step, but not below 1e-15 absolute — a locating step of σ ~ 1e-8
            // would otherwise ask for 1e-20, under the rounding of its own terms
            (Some(arc), _) => arc.ds.abs().max(1e-3),
            (None, Loading::Volume(v)) => v.abs().max(1e-300),
            _ => 1.0,
        };
        let merit = res + c.abs() / cscale;
        let t_factor = std::time::Instant::now();
        let (neg, shift) = self.model.factorize(&a, p)?;
        let factorization_seconds = t_factor.elapsed().as_secs_f64();
        let t_solve = std::time::Instant::now();
        let mut converged = res <= self.model.settings.rtol && c.abs() <= 1e-12 * cscale;
        // the Newton correction
        let ldlt = &self.model.ldlt;
        let mut dx: Vec<f64> = r.iter().map(|v| -v).collect();
        let moving = self.planes.zip(self.arc);
        // closed gas: K_gas = K + (ϖ/V) g gᵀ, applied by Sherman–Morrison (`solve_gas`)
        let gas_newton = self.load.gas().is_some() && self.arc.is_none();
        if moving.is_none() && !gas_newton {
            ldlt.solve(&mut dx);
        }
        let mut dp = 0.0;
        let mut negative = neg;
        if let Some((planes, arc)) = moving {
            // closed gas with moving planes: K_gas [dx; dλ] bordered by ∂R/∂λ and the arc
            // constraint, K_gas⁻¹ by Sherman–Morrison on the factor of K
            negative = negative.saturating_sub(self.model.solve_gas(&a, p, &mut dx));
            let mut bq: Vec<f64> = self
                .model
                .plane_rate(state, planes, state.planes)
                .into_iter()
                .map(|v| -v)
                .collect();
            self.model.solve_gas(&a, p, &mut bq);
            let h: Vec<f64> = arc.tx.iter().map(|t| arc.w * t).collect();
            let hb = dot(&h, &bq) + cp;
            dp = (-c - dot(&h, &dx)) / hb;
            for (d, bb) in dx.iter_mut().zip(&bq) {
                *d += dp * bb;
            }
        } else if gas_newton {
            negative = negative.saturating_sub(self.model.solve_gas(&a, p, &mut dx));
        } else if let Some(h) = &h {
            let mut b = a.g.clone();
            ldlt.solve(&mut b);
            if let Some(phi0) = self.hold {
                // the held mode out of the load column and the correction, and its force out of
                // the convergence test (it is the reaction of the hold)
                let (phi, mu) = self.model.inverse_iteration(phi0);
                project_out(&mut b, &phi);
                project_out(&mut dx, &phi);
                negative -= usize::from(mu < 0.0 && negative > 0);
                // deflating from φ0 makes Kφ lie along φ0 (one inverse iteration), so at the
                // fixed point R is along φ0: the reaction
                let mut r_off = r.clone();
                project_out(&mut r_off, phi0);
                converged = norm(&r_off) / reference <= self.model.settings.rtol
                    && c.abs() <= 1e-12 * cscale;
                if converged {
                    self.held = Some(Held {
                        force: dot(phi0, &r),
                        relative_eigenvalue: mu / self.model.largest_diagonal(&a, p),
                        energy: a.energy,
                        mode: phi,
                    });
                }
            } else if let Some(phi0) = self.arc.and_then(|arc| arc.neutral) {
                // the neutral mode out of the load column (not out of the correction: the
                // residual along it must still go); its pivot out of the count (its sign is
                // round-off)
                let (phi, mu) = self.model.deflate(phi0, &a.g, &b);
                project_out(&mut b, &phi);
                negative -= usize::from(mu < 0.0 && negative > 0);
            }
            let hb = dot(h, &b) + cp;
            let ha = dot(h, &dx);
            // the bordered operator's inertia (volume or stretch control); an arc-length step
            // reports the pressure-control stiffness K itself
            if hb < 0.0 && self.arc.is_none() {
                negative = negative.saturating_sub(1);
            }
            dp = (-c - ha) / hb;
            for (d, bb) in dx.iter_mut().zip(&b) {
                *d += dp * bb;
            }
        }
        let slope = dot(&r, &dx);
        if self.branch.is_none() {
            self.residual = r;
        }
        self.model.log_iteration(IterationRecord {
            assembly: assembly_seconds,
            line_search: self.rejected_seconds.replace(0.0),
            factorization: factorization_seconds,
            solve: t_solve.elapsed().as_secs_f64(),
            residual: res,
            negative_pivots: negative,
        });
        Ok(Linearization {
            residual: res,
            merit,
            converged,
            potential: potential(self.load.loading, a.energy, a.volume, p),
            slope,
            step: (dx, dp),
            bordered: h.is_some(),
            inertia: Inertia {
                negative_pivots: negative,
                shift,
            },
        })
    }

    /// Where the full step from `state` ends at `trial` with contact points on the other side
    /// of their kink (pushed at one end, free at the other), the semi-smooth Newton step: the
    /// linearization with each point's contact on the branch it has at `trial`
    /// ([`Contact::kernel_on_branch`]), its residual and potential (for the line search) the
    /// state's own. None where no point changes.
    fn relinearize(
        &mut self,
        state: &mut State,
        lin: &Linearization<Self::Step>,
        trial: &State,
    ) -> Result<Option<Linearization<Self::Step>>, FemError> {
        let Some(contact) = self.contact(state) else {
            return Ok(None);
        };
        let changes =
            self.model
                .contact_status_changes(&state.x, &trial.x, &contact, &state.multipliers);
        drop(contact);
        if changes == 0 {
            return Ok(None);
        }
        let own = std::mem::take(&mut self.residual);
        self.branch = Some(trial.x.clone());
        let branched = self.linearize(state);
        self.branch = None;
        let mut branched = branched?;
        branched.slope = dot(&own, &branched.step.0);
        self.residual = own;
        branched.residual = lin.residual;
        branched.merit = lin.merit;
        branched.potential = lin.potential;
        branched.converged = lin.converged;
        Ok(Some(branched))
    }

    fn evaluate(&self, state: &State) -> Result<Evaluation, FemError> {
        // with the tangent: an accepted trial is where the next iteration linearizes, and it
        // takes this assembly (`assemble_at`) instead of assembling the same state again
        let t = std::time::Instant::now();
        if let Some((_, _, secs)) = self.trial.borrow_mut().take() {
            // an earlier trial of this line search, not taken
            self.rejected_seconds
                .set(self.rejected_seconds.get() + secs);
        }
        let trial = self
            .model
            .assemble_state(state, true, self.contact(state).as_deref())?;
        let pt = self.pressure(state.p, trial.volume);
        let rt: Vec<f64> = trial
            .f_int
            .iter()
            .zip(&trial.g)
            .map(|(f, g)| f - pt * g)
            .collect();
        let reft = force_scale(&trial, pt);
        let residual = norm(&rt) / reft;
        self.admissible(&trial, pt, residual)?;
        let out = Evaluation {
            residual,
            potential: potential(self.load.loading, trial.energy, trial.volume, pt),
        };
        *self.trial.borrow_mut() = Some((state.clone(), trial, t.elapsed().as_secs_f64()));
        Ok(out)
    }

    fn update(&self, base: &State, step: &Self::Step, t: f64, state: &mut State) {
        state.x.clone_from(&base.x);
        self.model.dofs.apply(&mut state.x, &step.0, t);
        if self.planes.is_some() {
            // the planes move; the gas pressure follows the volume (set at evaluation)
            state.planes = base.planes + t * step.1;
            state.p = base.p;
        } else {
            state.p = base.p + t * step.1;
        }
    }

    fn step_size(&self, step: &Self::Step) -> f64 {
        self.model.dofs.max_nodal_norm(&step.0)
    }

    fn step_is_finite(&self, step: &Self::Step) -> bool {
        step.0.iter().all(|v| v.is_finite()) && step.1.is_finite()
    }
}

/// The fraction of a law's extensible range, (I1 − 3)/(I1,lim − 3), from which a failed solve is
/// attributed to locking: the ABB energy's stiffness grows as 1/(1 − fraction)², 400× its
/// small-strain value at 0.95, and Newton steps from such a state overshoot the limit or stall.
pub const NEAR_LOCKING: f64 = 0.95;

/// Where a state comes closest to the law's locking limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LockingProximity {
    pub element: usize,
    pub gauss_point: usize,
    /// I1 = tr C + 1/det C there
    pub i1: f64,
    /// the law's limit of I1
    pub limit: f64,
}

impl LockingProximity {
    /// (I1 − 3)/(I1,lim − 3): 0 unstretched, 1 locked.
    pub fn fraction(&self) -> f64 {
        (self.i1 - 3.0) / (self.limit - 3.0)
    }
}

impl std::fmt::Display for LockingProximity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the last converged state is at {:.1} % of the law's locking range (I1 = {:.4} of the locking limit {:.4}) at element {}, Gauss point {}: the membrane is locking",
            100.0 * self.fraction(),
            self.i1,
            self.limit,
            self.element,
            self.gauss_point
        )
    }
}

impl Model {
    /// The Gauss point of largest I1 at `x` against the law's locking limit (`None` for a law
    /// without one).
    pub fn locking_proximity(&self, x: &[[f64; 3]]) -> Option<LockingProximity> {
        let limit = self.law.locking_limit()?;
        let mut best: Option<LockingProximity> = None;
        with_elements!(&self.elements, els => for (e, el) in els.iter().enumerate() {
            let xe = el.gather(x);
            for g in 0..el.gauss.len() {
                let c = crate::element::cauchy_green(&el.gradient(g, &xe));
                let det = c[0] * c[1] - c[2] * c[2];
                let i1 = c[0] + c[1] + 1.0 / det;
                if i1.is_finite() && best.is_none_or(|b| i1 > b.i1) {
                    best = Some(LockingProximity {
                        element: e,
                        gauss_point: g,
                        i1,
                        limit,
                    });
                }
            }
        });
        best
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
    /// floating-point operations of the factorization
    pub factor_flops: f64,
}

impl Model {
    /// Time one Newton iteration at `state` under pressure control (for benchmarks).
    pub fn time_iteration(&mut self, state: &State) -> Result<IterationTiming, FemError> {
        let t0 = std::time::Instant::now();
        let a = self.assemble(&state.x, true, None)?;
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
            factor_flops: self.ldlt.factor_flops(),
        })
    }
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

/// The positions `x` of the mesh with reference nodes `old` carried to the moved reference
/// nodes `new` by `transfer`: a node that did not move keeps its position; a moved one takes
/// the interpolated cylindrical displacement of its old neighbours, the current radius r, the
/// turn φ − Θ from its reference angle Θ and the axial displacement z − Z, placed at its own
/// reference angle Θ'. A uniform dilation, a rigid turn about the axis and an axial stretch,
/// the inflated tube's state, carry over exactly; interpolating the positions themselves
/// would leave the hoop's O(h³) chord error of the interpolation (a residual of 0.15 on the
/// 9-node inflation test at 16 around, `tests_remap`).
fn carry_positions(
    old: &[[f64; 3]],
    new: &[[f64; 3]],
    x: &[[f64; 3]],
    transfer: &tubemem_mesh::hoop::Transfer,
) -> Vec<[f64; 3]> {
    let turn = |n: usize| {
        let t = old[n][1].atan2(old[n][0]);
        let f = x[n][1].atan2(x[n][0]);
        (f - t + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
    };
    (0..new.len())
        .map(|n| {
            let w = transfer.weights(n);
            if let [(b, c)] = w {
                if *b == n && *c == 1.0 {
                    return x[n];
                }
            }
            let (mut r, mut phi, mut uz) = (0.0, 0.0, 0.0);
            for &(b, c) in w {
                r += c * x[b][0].hypot(x[b][1]);
                phi += c * turn(b);
                uz += c * (x[b][2] - old[b][2]);
            }
            let a = new[n][1].atan2(new[n][0]) + phi;
            [r * a.cos(), r * a.sin(), new[n][2] + uz]
        })
        .collect()
}
