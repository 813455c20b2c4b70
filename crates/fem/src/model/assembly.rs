//! Assembly: energy, internal force, enclosed volume and their derivatives, summed element by
//! element over the model's terms ([`crate::term`]: the membrane, the contact, and every term
//! added by [`Model::add_term`]), then the plug faces and the soft rigid-mode pins. Element
//! kernels run in parallel; every sum is taken in element order, so the result does not depend
//! on the number of threads.

use super::*;

/// How an assembly of N-node elements calls an added [`Term`] (its `add_quad4` or `add_quad9`).
pub(super) type Dispatch<const N: usize, const D: usize> = for<'x> fn(
    &dyn Term,
    &ElementAt<'x, N>,
    &mut SVector<f64, D>,
    Option<&mut SMatrix<f64, D, D>>,
) -> Result<f64, FemError>;

/// What one element contributes besides the enclosed volume: the hyperelastic membrane, the
/// contact with rigid planes if the load has any, and the terms added to the model, in this
/// order.
pub(super) struct Terms<'a, const N: usize, const D: usize> {
    pub(super) membrane: MembraneTerm<'a>,
    pub(super) contact: Option<ContactTerm<'a>>,
    pub(super) added: &'a [Box<dyn Term>],
    pub(super) dispatch: Dispatch<N, D>,
    pub(super) mesh_nodes: &'a [[f64; 3]],
}

impl<const N: usize, const D: usize> Terms<'_, N, D> {
    /// Add the energy (returned), residual and, if asked, the stiffness of element `e`.
    fn add(
        &self,
        e: usize,
        el: &RefElement<N>,
        xe: &[Vec3; N],
        r: &mut SVector<f64, D>,
        mut k: Option<&mut SMatrix<f64, D, D>>,
    ) -> Result<f64, FemError> {
        let at = ElementAt {
            index: e,
            reference: el,
            x: xe,
            mesh_nodes: self.mesh_nodes,
        };
        let mut energy = self.membrane.add(&at, r, k.as_deref_mut())?;
        if let Some(c) = &self.contact {
            energy += c.add(&at, r, k.as_deref_mut())?;
        }
        for t in self.added {
            energy += (self.dispatch)(t.as_ref(), &at, r, k.as_deref_mut()).map_err(|source| {
                FemError::Term {
                    term: t.name().to_string(),
                    element: e,
                    source: Box::new(source),
                }
            })?;
        }
        Ok(energy)
    }
}

/// One element's energy, residual, volume and volume gradient.
pub(super) struct Local<const D: usize> {
    pub(super) energy: f64,
    pub(super) r: SVector<f64, D>,
    pub(super) v: f64,
    pub(super) g: SVector<f64, D>,
}

/// The pressure ϖ at which an assembly forms K = K_int − ϖH ([`TangentForm::At`]).
#[derive(Clone, Copy, Debug)]
pub(super) enum Pressure {
    /// a pressure known before the assembly
    Given(f64),
    /// closed gas: ϖ = pv/(m V_part), from the volume of the configuration assembled
    Gas { pv: f64, multiplicity: f64 },
}

impl Pressure {
    /// The pressure under `load` on a model of multiplicity `multiplicity`: closed gas's, or
    /// `p`.
    pub(super) fn under(load: &Load, multiplicity: f64, p: f64) -> Pressure {
        match load.gas() {
            Some(pv) => Pressure::Gas { pv, multiplicity },
            None => Pressure::Given(p),
        }
    }

    /// The pressure at the volume of the modelled part `volume`.
    pub(super) fn at(self, volume: f64) -> f64 {
        match self {
            Pressure::Given(p) => p,
            Pressure::Gas { pv, multiplicity } => pv / (multiplicity * volume),
        }
    }

    /// Whether `self` and `other` give the same pressure at every volume, bit for bit.
    pub(super) fn same_as(self, other: Pressure) -> bool {
        match (self, other) {
            (Pressure::Given(a), Pressure::Given(b)) => a.to_bits() == b.to_bits(),
            (
                Pressure::Gas { pv, multiplicity },
                Pressure::Gas {
                    pv: pv2,
                    multiplicity: m2,
                },
            ) => pv.to_bits() == pv2.to_bits() && multiplicity.to_bits() == m2.to_bits(),
            _ => false,
        }
    }
}

/// What an assembly forms of the tangent.
#[derive(Clone, Copy, Debug)]
pub(super) enum TangentForm {
    /// no matrix
    None,
    /// K_int and H apart ([`Assembled::k_int`], [`Assembled::k_vol`])
    Parts,
    /// only K = K_int − ϖH ([`Assembled::k`]) at the pressure given, formed element by
    /// element, so that H never exists whole: at a million unknowns each array of values
    /// takes some 200 MB
    At(Pressure),
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
    /// values of K_int and of ∂²V/∂x² in pattern order (empty without the tangent, and where
    /// the assembly formed K instead)
    pub k_int: Vec<f64>,
    pub k_vol: Vec<f64>,
    /// values of K = K_int − ϖH in pattern order, where the assembly formed it at a pressure
    /// ϖ (empty otherwise); each is K_int's value, plus a soft pin's stiffness on its diagonal,
    /// minus ϖ times H's, the same bits as forming them from `k_int` and `k_vol`
    pub k: Vec<f64>,
}

impl Model {
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
        let form = if tangent {
            TangentForm::Parts
        } else {
            TangentForm::None
        };
        self.assemble_terms(x, form, contact, multipliers, None)
    }

    /// [`Model::assemble_with_multipliers`] with the contact on the branch of the positions
    /// `branch` (see [`Contact::kernel_on_branch`]).
    pub(super) fn assemble_terms(
        &self,
        x: &[[f64; 3]],
        form: TangentForm,
        contact: Option<&Contact>,
        multipliers: &[f64],
        branch: Option<&[[f64; 3]]>,
    ) -> Result<Assembled, FemError> {
        let membrane = MembraneTerm {
            law: self.law.as_ref(),
            memory: self.memory.as_ref(),
        };
        let contact = contact.map(|contact| ContactTerm {
            contact,
            multipliers,
            branch,
        });
        let (added, mesh_nodes) = (&self.terms[..], &self.mesh.nodes[..]);
        match &self.elements {
            Elements::Quad4(els) => {
                let terms = Terms::<4, 12> {
                    membrane,
                    contact,
                    added,
                    dispatch: |t, el, r, k| t.add_quad4(el, r, k),
                    mesh_nodes,
                };
                self.assemble_with(els, x, form, &terms)
            }
            Elements::Quad9(els) => {
                let terms = Terms::<9, 27> {
                    membrane,
                    contact,
                    added,
                    dispatch: |t, el, r, k| t.add_quad9(el, r, k),
                    mesh_nodes,
                };
                self.assemble_with(els, x, form, &terms)
            }
        }
    }

    /// [`Model::assemble`] for elements of N nodes (D = 3N dofs), the tangent formed as `form`
    /// says.
    pub(super) fn assemble_with<const N: usize, const D: usize>(
        &self,
        elements: &[RefElement<N>],
        x: &[[f64; 3]],
        form: TangentForm,
        terms: &Terms<'_, N, D>,
    ) -> Result<Assembled, FemError> {
        // Each element writes its D × D entries straight into its own contiguous range of
        // the value arrays (the pattern lists entries element by element); the vectors and
        // scalars come back per element and are summed in element order. No element matrix is
        // stored, and the result does not depend on the number of threads.
        let diagonal = self.pattern.diagonal();
        let len = self.pattern.len();
        let (mut k_int, mut k_vol, mut k) = match form {
            TangentForm::None => (Vec::new(), Vec::new(), Vec::new()),
            TangentForm::Parts => (vec![0.0; len], vec![0.0; len], Vec::new()),
            TangentForm::At(_) => (Vec::new(), Vec::new(), vec![0.0; len]),
        };
        // K's pressure, and its soft pins' (entry, stiffness) in entry order: a pin's
        // stiffness goes to K_int's diagonal value before ϖH is taken off, as in `Parts`
        let (p, pins) = match form {
            TangentForm::At(pressure) => {
                let volume = match pressure {
                    Pressure::Given(_) => 0.0,
                    Pressure::Gas { .. } => self.volume_with::<N, D>(elements, x),
                };
                let mut pins: Vec<(usize, f64)> = self
                    .dofs
                    .soft_pins()
                    .iter()
                    .map(|pin| (diagonal[pin.eq], pin.stiffness))
                    .collect();
                pins.sort_by_key(|&(entry, _)| entry);
                (pressure.at(volume), pins)
            }
            _ => (0.0, Vec::new()),
        };
        // each element's (first entry, K_int's or K's range, H's range)
        let mut slices: Vec<(usize, &mut [f64], &mut [f64])> = Vec::new();
        if !matches!(form, TangentForm::None) {
            slices.reserve(elements.len());
            let combined = matches!(form, TangentForm::At(_));
            let mut ki = if combined {
                k.as_mut_slice()
            } else {
                k_int.as_mut_slice()
            };
            let mut kv = k_vol.as_mut_slice();
            let mut first = 0;
            for e in 0..elements.len() {
                let n = self.pattern.element_entries(e).len();
                let (a, rest_i) = ki.split_at_mut(n);
                let (b, rest_v) = kv.split_at_mut(if combined { 0 } else { n });
                slices.push((first, a, b));
                ki = rest_i;
                kv = rest_v;
                first += n;
            }
        }
        let locals: Vec<Result<Local<D>, FemError>> = match form {
            TangentForm::None => elements
                .par_iter()
                .enumerate()
                .map(|(e, el)| Self::element(e, el, x, terms, None))
                .collect(),
            _ => elements
                .par_iter()
                .zip(slices.par_iter_mut())
                .enumerate()
                .map(|(e, (el, (first, ki, kv)))| {
                    let (mut km, mut h) = (SMatrix::<f64, D, D>::zeros(), SMatrix::zeros());
                    let l = Self::element(e, el, x, terms, Some((&mut km, &mut h)))?;
                    let entries = self.pattern.element_entries(e);
                    if kv.is_empty() {
                        // the pins in this element's range of entries
                        let from = pins.partition_point(|&(entry, _)| entry < *first);
                        let mut pins = pins[from..]
                            .iter()
                            .take_while(|&&(entry, _)| entry < *first + entries.len())
                            .peekable();
                        for (slot, &(i, j)) in entries.iter().enumerate() {
                            let (i, j) = (i as usize, j as usize);
                            let mut v = km[(i, j)];
                            while let Some(&(_, s)) = pins.next_if(|&&(e, _)| e == *first + slot) {
                                v += s;
                            }
                            ki[slot] = v - p * h[(i, j)];
                        }
                    } else {
                        for (slot, &(i, j)) in entries.iter().enumerate() {
                            let (i, j) = (i as usize, j as usize);
                            ki[slot] = km[(i, j)];
                            kv[slot] = h[(i, j)];
                        }
                    }
                    Ok(l)
                })
                .collect(),
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
            k,
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
        for (face, eq) in self.plug_faces(x).zip(self.dofs.plug_equations()) {
            out.volume += face.volume();
            if let Some(k) = eq {
                out.g[*k] += face.area * face.sign / 3.0;
            }
        }
        // soft rigid-mode pins: E = κ_s/2 (x − X)², r = κ_s (x − X), K += κ_s on the diagonal
        // (K's own values have it already)
        for pin in self.dofs.soft_pins() {
            let u = x[pin.node][pin.component] - self.mesh.nodes[pin.node][pin.component];
            out.energy += 0.5 * pin.stiffness * u * u;
            out.f_int[pin.eq] += pin.stiffness * u;
            if matches!(form, TangentForm::Parts) {
                out.k_int[diagonal[pin.eq]] += pin.stiffness;
            }
        }
        Ok(out)
    }

    /// The plug faces that close the surface at the positions `x`, plug by plug.
    fn plug_faces<'a>(
        &'a self,
        x: &'a [[f64; 3]],
    ) -> impl Iterator<Item = tubemem_mesh::PlugFace> + 'a {
        let closed = self.mesh.symmetry.rings_closed();
        let quad9 = self.mesh.element() == tubemem_mesh::ElementKind::Quad9;
        self.mesh
            .plugs
            .iter()
            .map(move |ring| tubemem_mesh::plug_face(x, ring, closed, quad9))
    }

    /// The volume of the modelled part at the positions `x`: the elements' in element order,
    /// then the plug faces', bit for bit the volume [`Model::assemble_with`] sums.
    fn volume_with<const N: usize, const D: usize>(
        &self,
        elements: &[RefElement<N>],
        x: &[[f64; 3]],
    ) -> f64 {
        let per_element: Vec<f64> = elements
            .par_iter()
            .map(|el| volume_kernel_n::<N, D>(&el.gather(x), None, None))
            .collect();
        let mut volume = 0.0;
        for v in per_element {
            volume += v;
        }
        for face in self.plug_faces(x) {
            volume += face.volume();
        }
        volume
    }

    /// One element: the terms' energy and residual (and stiffness into `mats.0`), the volume,
    /// its gradient (and Hessian into `mats.1`). The matrices must come in zeroed.
    pub(super) fn element<const N: usize, const D: usize>(
        e: usize,
        el: &RefElement<N>,
        x: &[[f64; 3]],
        terms: &Terms<'_, N, D>,
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

    /// The residual R = f_int − p ∂V/∂x on the free dofs, with p = `p` or, for closed gas,
    /// p = pv/(m V_part) (for tests and diagnostics).
    pub fn residual(&self, x: &[[f64; 3]], load: &Load, p: f64) -> Result<Vec<f64>, FemError> {
        let a = self.assemble(x, false, load.contact.as_ref())?;
        let p = Pressure::under(load, self.multiplicity(), p).at(a.volume);
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
        let p = Pressure::under(load, self.multiplicity(), p).at(a.volume);
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

    /// x − x0 on the free dofs.
    pub fn free_difference(&self, x: &[[f64; 3]], x0: &[[f64; 3]]) -> Vec<f64> {
        self.dofs.difference(x, x0)
    }

    /// x0 + t·dx on the free dofs (into `x`).
    pub fn free_update(&self, x: &mut [[f64; 3]], dx: &[f64], t: f64) {
        self.dofs.apply(x, dx, t)
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
    pub(super) fn plane_rate_with<const N: usize, const D: usize>(
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use tubemem_material::laws::AnssariBenamBucchi;
    use tubemem_mesh::tube::{capped_tube_of, plugged_tube_of};
    use tubemem_mesh::{ElementKind, Symmetry};

    /// K = K_int − ϖH formed element by element ([`TangentForm::At`]) is bit for bit the K
    /// formed from the parts ([`TangentForm::Parts`]: K_int with the soft pins' stiffness on its
    /// diagonal, minus ϖ times H), and every other output is the parts' own, at a given
    /// pressure and at closed gas's pv/(m V) (whose volume the assembly takes first). The
    /// models have every kind of entry: a soft pin on a quarter tube, plug faces (volume,
    /// no Hessian), 4- and 9-node elements, plates in contact.
    #[test]
    fn k_formed_element_by_element_is_the_parts_bit_for_bit() {
        let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
        for (kind, plugged) in [(ElementKind::Quad4, false), (ElementKind::Quad9, true)] {
            let mesh = if plugged {
                plugged_tube_of(kind, 1.0, 3.0, 8, 4, Symmetry::None).unwrap()
            } else {
                capped_tube_of(kind, 1.0, 3.0, 8, 6, Symmetry::Quarter).unwrap()
            };
            let mut model = Model::new(mesh, Box::new(law.clone())).unwrap();
            if !plugged {
                model.soften_rigid_pins([true, false], 10.0).unwrap();
                assert_eq!(model.dofs().soft_pins().len(), 1);
            }
            let mut st = model.reference_state();
            model.solve(&mut st, &Load::pressure(0.4)).unwrap();
            // off equilibrium, the pinned node moved too, so that its spring has a force
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            for p in st.x.iter_mut() {
                for c in p.iter_mut() {
                    *c += rng.random_range(-0.005..0.005);
                }
            }
            let ymax = st.x.iter().map(|p| p[1]).fold(0.0, f64::max);
            let contact = Contact::plates(0.8 * ymax, 50.0);
            let parts = model
                .assemble_terms(&st.x, TangentForm::Parts, Some(&contact), &[], None)
                .unwrap();
            assert!(parts.k.is_empty() && !parts.k_vol.is_empty());
            let pv = 0.4 * model.multiplicity() * parts.volume;
            for pressure in [
                Pressure::Given(0.37),
                Pressure::Gas {
                    pv,
                    multiplicity: model.multiplicity(),
                },
            ] {
                let at = model
                    .assemble_terms(&st.x, TangentForm::At(pressure), Some(&contact), &[], None)
                    .unwrap();
                assert!(at.k_int.is_empty() && at.k_vol.is_empty());
                let p = pressure.at(parts.volume);
                assert!(p > 0.3, "{p}");
                let same = |a: &[f64], b: &[f64]| {
                    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
                };
                assert_eq!(at.volume.to_bits(), parts.volume.to_bits());
                assert_eq!(at.energy.to_bits(), parts.energy.to_bits());
                assert!(same(&at.f_int, &parts.f_int) && same(&at.g, &parts.g));
                let k: Vec<f64> = parts
                    .k_int
                    .iter()
                    .zip(&parts.k_vol)
                    .map(|(k, h)| k - p * h)
                    .collect();
                assert!(same(&at.k, &k), "{kind:?}, {pressure:?}");
            }
        }
    }
}
