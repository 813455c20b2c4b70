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
        self.assemble_terms(x, tangent, contact, multipliers, None)
    }

    /// [`Model::assemble_with_multipliers`] with the contact on the branch of the positions
    /// `branch` (see [`Contact::kernel_on_branch`]).
    pub(super) fn assemble_terms(
        &self,
        x: &[[f64; 3]],
        tangent: bool,
        contact: Option<&Contact>,
        multipliers: &[f64],
        branch: Option<&[[f64; 3]]>,
    ) -> Result<Assembled, FemError> {
        let membrane = MembraneTerm {
            law: self.law.as_ref(),
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
                self.assemble_with(els, x, tangent, &terms)
            }
            Elements::Quad9(els) => {
                let terms = Terms::<9, 27> {
                    membrane,
                    contact,
                    added,
                    dispatch: |t, el, r, k| t.add_quad9(el, r, k),
                    mesh_nodes,
                };
                self.assemble_with(els, x, tangent, &terms)
            }
        }
    }

    /// [`Model::assemble`] for elements of N nodes (D = 3N dofs).
    pub(super) fn assemble_with<const N: usize, const D: usize>(
        &self,
        elements: &[RefElement<N>],
        x: &[[f64; 3]],
        tangent: bool,
        terms: &Terms<'_, N, D>,
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
