//! The hereditary state of a viscoelastic membrane: one [`History`] per Gauss point, and the
//! time step the model is solving.
//!
//! A quasi-linear viscoelastic (Prony) law ([`tubemem_material::viscoelastic`]) turns each time
//! step into a hyperelastic problem: at every Gauss point the stress at the end of a step of
//! length Δt is
//!
//! ```text
//! S = α S⁰(C) + B,   α = g∞ + Σᵢ gᵢ γᵢ,   B = Σᵢ (eᵢ hᵢⁿ − gᵢ γᵢ S⁰ⁿ)
//! eᵢ = exp(−Δt/τᵢ),  γᵢ = (1 − eᵢ)/(Δt/τᵢ)
//! ```
//!
//! with B frozen over the step (it depends on the last converged state only), so the point has
//! the energy α W(C) + ½ B:(C − I) ([`crate::element::Hereditary`]) and Newton, its line
//! search and the stability count work as for an elastic law. Once a step has converged,
//! [`Memory::commit`] advances every point's history with the base law's stress at the
//! converged positions ([`History::advanced`]); a step that fails leaves the histories as they
//! were, so it can be retried with a shorter Δt.
//!
//! The output ([`crate::post`]) reports the committed state: S = g∞ S⁰(C) + Σᵢ hᵢ at the
//! positions of the last committed step ([`Memory::committed_at`]), so a driver commits a
//! converged step before it writes it.
//!
//! A step of Δt = 0 is a jump (α = 1, B = Σ hᵢ − (1 − g∞) S⁰ⁿ): the instantaneous response.
//! Jumps compose exactly (the update is linear in the increments of S⁰), so a pressure jump can
//! be taken in several load steps of zero length, as an elastic inflation is.

use crate::geometry::{RefElement, Vec3};
use crate::FemError;
use rayon::prelude::*;
use tubemem_material::viscoelastic::{History, Prony, Step};
use tubemem_material::MembraneLaw;

/// The histories of every Gauss point of a model (element major) and the current step.
#[derive(Clone, Debug)]
pub struct Memory {
    prony: Prony,
    /// the first Gauss point of each element, and the total at the end
    first: Vec<usize>,
    histories: Vec<History>,
    /// the current step's length and factors
    dt: f64,
    step: Step,
    /// B of the current step at every Gauss point
    offsets: Vec<[f64; 3]>,
    /// Σᵢ hᵢ of the committed histories at every Gauss point
    held: Vec<[f64; 3]>,
}

impl Memory {
    /// Every Gauss point of `elements` unloaded, and a jump (Δt = 0) as the current step.
    pub fn new<const N: usize>(prony: Prony, elements: &[RefElement<N>]) -> Self {
        let mut first = Vec::with_capacity(elements.len() + 1);
        let mut total = 0;
        for re in elements {
            first.push(total);
            total += re.gauss.len();
        }
        first.push(total);
        let terms = prony.terms().len();
        let step = prony.step(0.0);
        Self {
            histories: vec![History::unloaded(terms); total],
            offsets: vec![[0.0; 3]; total],
            held: vec![[0.0; 3]; total],
            prony,
            first,
            dt: 0.0,
            step,
        }
    }

    pub fn prony(&self) -> &Prony {
        &self.prony
    }

    /// The number of Gauss points (the histories).
    pub fn len(&self) -> usize {
        self.histories.len()
    }

    pub fn is_empty(&self) -> bool {
        self.histories.is_empty()
    }

    /// Every Gauss point's history, element major.
    pub fn histories(&self) -> &[History] {
        &self.histories
    }

    /// The histories of element `e`'s Gauss points.
    pub fn element_histories(&self, e: usize) -> &[History] {
        &self.histories[self.first[e]..self.first[e + 1]]
    }

    /// Replace every history (a checkpoint's), keeping the current step.
    pub fn set_histories(&mut self, histories: Vec<History>) -> Result<(), FemError> {
        let terms = self.prony.terms().len();
        if histories.len() != self.histories.len() {
            return Err(FemError::Setup {
                reason: format!(
                    "{} material histories given for {} Gauss points",
                    histories.len(),
                    self.histories.len()
                ),
            });
        }
        if let Some(k) = histories.iter().position(|h| {
            h.h.len() != terms || !(h.s0.iter().chain(h.h.iter().flatten())).all(|v| v.is_finite())
        }) {
            return Err(FemError::Setup {
                reason: format!(
                    "the material history of Gauss point {k} has not {terms} Prony terms of finite values"
                ),
            });
        }
        self.histories = histories;
        self.histories_changed()
    }

    /// The length of the step being solved.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Solve the next step over `dt` ≥ 0 (0: a jump) from the committed histories.
    pub fn set_step(&mut self, dt: f64) -> Result<(), FemError> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(FemError::InvalidParameter {
                name: "time step",
                value: dt,
                requirement: "must be finite and ≥ 0",
            });
        }
        self.dt = dt;
        self.step = self.prony.step(dt);
        let step = &self.step;
        self.histories
            .par_iter()
            .map(|h| h.offset(step))
            .collect_into_vec(&mut self.offsets);
        Ok(())
    }

    /// The histories were replaced: the committed Σᵢ hᵢ and the current step's offsets follow.
    fn histories_changed(&mut self) -> Result<(), FemError> {
        self.histories
            .par_iter()
            .map(|h| std::array::from_fn(|k| h.h.iter().map(|hi| hi[k]).sum::<f64>()))
            .collect_into_vec(&mut self.held);
        self.set_step(self.dt)
    }

    /// The current step at element `e`'s Gauss points.
    pub fn at(&self, e: usize) -> crate::element::Hereditary<'_> {
        crate::element::Hereditary {
            alpha: self.step.alpha,
            offsets: &self.offsets[self.first[e]..self.first[e + 1]],
        }
    }

    /// The committed state at element `e`'s Gauss points, as a step: S = g∞ S⁰(C) + Σᵢ hᵢ
    /// (what the output reports, after [`Memory::commit`]).
    pub fn committed_at(&self, e: usize) -> crate::element::Hereditary<'_> {
        crate::element::Hereditary {
            alpha: self.prony.g_infinity(),
            offsets: &self.held[self.first[e]..self.first[e + 1]],
        }
    }

    /// The converged end of the current step: every point's history advanced with the base
    /// law's stress at the positions `x` (`elements` the model's, whose points these
    /// histories are); the next step is again of the same length.
    pub fn commit<const N: usize>(
        &mut self,
        law: &dyn MembraneLaw,
        elements: &[RefElement<N>],
        x: &[[f64; 3]],
    ) -> Result<(), FemError> {
        let base = base_stresses(law, elements, x)?;
        let step = &self.step;
        self.histories = self
            .histories
            .par_iter()
            .zip(base.par_iter())
            .map(|(h, &s0)| h.advanced(step, s0))
            .collect();
        self.histories_changed()
    }
}

/// The base law's stress S⁰(C) at every Gauss point (element major) at the positions `x`.
fn base_stresses<const N: usize>(
    law: &dyn MembraneLaw,
    elements: &[RefElement<N>],
    x: &[[f64; 3]],
) -> Result<Vec<[f64; 3]>, FemError> {
    let per_element = elements
        .par_iter()
        .enumerate()
        .map(|(e, re)| {
            let xe: [Vec3; N] = re.gather(x);
            (0..re.gauss.len())
                .map(|g| {
                    let c = crate::element::cauchy_green(&re.gradient(g, &xe));
                    law.stress_tangent(c)
                        .map(|st| st.s)
                        .map_err(|source| FemError::Material {
                            element: e,
                            gauss_point: g,
                            source,
                        })
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(per_element.into_iter().flatten().collect())
}

/// (cos φ, sin φ) of the reference hoop direction t = (−Y, X, 0)/|·| in a Gauss point's frame
/// (e1, e2): t = cos φ e1 + sin φ e2 (on a surface of revolution t is tangent). At the axis
/// (a cap's pole), where t is undefined, e1.
fn hoop_in_frame(frame: &[Vec3; 2], x_ref: &Vec3) -> (f64, f64) {
    let t = Vec3::new(-x_ref[1], x_ref[0], 0.0);
    if t.norm_squared() < 1e-20 {
        return (1.0, 0.0);
    }
    let (c, s) = (t.dot(&frame[0]), t.dot(&frame[1]));
    let n = c.hypot(s);
    (c / n, s / n)
}

/// Voigt (11, 22, 12) components in the frame (e1, e2) to the (hoop, meridian) basis
/// t = c e1 + s e2, m = −s e1 + c e2, and back.
fn to_hoop([a, b, d]: [f64; 3], (c, s): (f64, f64)) -> [f64; 3] {
    [
        c * c * a + s * s * b + 2.0 * c * s * d,
        s * s * a + c * c * b - 2.0 * c * s * d,
        c * s * (b - a) + (c * c - s * s) * d,
    ]
}

fn from_hoop([tt, mm, tm]: [f64; 3], (c, s): (f64, f64)) -> [f64; 3] {
    [
        c * c * tt + s * s * mm - 2.0 * c * s * tm,
        s * s * tt + c * c * mm + 2.0 * c * s * tm,
        c * s * (tt - mm) + (c * c - s * s) * tm,
    ]
}

/// Every Gauss point's history as (hoop, meridian) components, each tensor of the history
/// (S⁰, then h₁ …) in turn: `(1 + terms)` tensors per point, element major.
fn hoop_components<const N: usize>(
    elements: &[RefElement<N>],
    nodes: &[[f64; 3]],
    histories: &[History],
) -> Vec<Vec<[f64; 3]>> {
    let mut k = 0;
    let mut out = Vec::with_capacity(histories.len());
    for re in elements {
        let x0: [Vec3; N] = re.gather(nodes);
        for gp in re.gauss.iter() {
            let basis = hoop_in_frame(&gp.frame, &gp.position(&x0));
            let h = &histories[k];
            out.push(
                std::iter::once(h.s0)
                    .chain(h.h.iter().copied())
                    .map(|v| to_hoop(v, basis))
                    .collect(),
            );
            k += 1;
        }
    }
    out
}

/// The lumped projection of Gauss-point values to the nodes: node a takes
/// Σ w_g N_a(g) v_g / Σ w_g N_a(g) over the Gauss points of its elements (a uniform field is
/// kept exactly).
fn to_nodes<const N: usize>(
    elements: &[RefElement<N>],
    count: usize,
    values: &[Vec<[f64; 3]>],
) -> Vec<Vec<[f64; 3]>> {
    let width = values.first().map_or(0, Vec::len);
    let mut num = vec![vec![[0.0; 3]; width]; count];
    let mut den = vec![0.0; count];
    let mut k = 0;
    for re in elements {
        for gp in re.gauss.iter() {
            for (a, &n) in re.nodes.iter().enumerate() {
                let c = gp.w * gp.n[a];
                den[n] += c;
                for (acc, v) in num[n].iter_mut().zip(&values[k]) {
                    for i in 0..3 {
                        acc[i] += c * v[i];
                    }
                }
            }
            k += 1;
        }
    }
    for (v, d) in num.iter_mut().zip(&den) {
        if *d != 0.0 {
            v.iter_mut().flatten().for_each(|x| *x /= d);
        }
    }
    num
}

/// The nodal values `nodal` at the Gauss points of `elements`, back in each point's frame as
/// histories.
fn from_nodes<const N: usize>(
    elements: &[RefElement<N>],
    nodes: &[[f64; 3]],
    nodal: &[Vec<[f64; 3]>],
) -> Vec<History> {
    let width = nodal.first().map_or(0, Vec::len);
    let mut out = Vec::new();
    for re in elements {
        let x0: [Vec3; N] = re.gather(nodes);
        for gp in re.gauss.iter() {
            let basis = hoop_in_frame(&gp.frame, &gp.position(&x0));
            let mut v = vec![[0.0; 3]; width];
            for (a, &n) in re.nodes.iter().enumerate() {
                for (acc, x) in v.iter_mut().zip(&nodal[n]) {
                    for i in 0..3 {
                        acc[i] += gp.n[a] * x[i];
                    }
                }
            }
            let mut tensors = v.into_iter().map(|t| from_hoop(t, basis));
            let s0 = tensors.next().unwrap_or([0.0; 3]);
            out.push(History {
                s0,
                h: tensors.collect(),
            });
        }
    }
    out
}

impl Memory {
    /// Carry the histories to the same mesh with its reference nodes moved (`old_nodes` to
    /// `new_nodes`, `transfer` giving each new node's old neighbours, as the positions are
    /// carried: [`crate::model::Model::move_reference`]). Each tensor of a history is taken in
    /// the (hoop, meridian) basis of its point, projected to the nodes (lumped), carried by
    /// the transfer's weights, interpolated at the new Gauss points and turned into their
    /// frames. Where the history is the same at every point of a ring in that basis — the
    /// whole section of a GPS state, free or between frictionless planes, whose points all
    /// share one stretch history — this is exact to rounding; near the caps it is the
    /// interpolation's error of a smooth field, far from the mid-span.
    pub fn carry<const N: usize>(
        &mut self,
        old: &[RefElement<N>],
        old_nodes: &[[f64; 3]],
        new: &[RefElement<N>],
        new_nodes: &[[f64; 3]],
        transfer: &tubemem_mesh::hoop::Transfer,
    ) -> Result<(), FemError> {
        let count = old_nodes.len();
        let values = hoop_components(old, old_nodes, &self.histories);
        let nodal = to_nodes(old, count, &values);
        let moved: Vec<Vec<[f64; 3]>> = (0..count)
            .map(|n| {
                let mut acc = vec![[0.0; 3]; nodal[n].len()];
                for &(b, c) in transfer.weights(n) {
                    for (a, x) in acc.iter_mut().zip(&nodal[b]) {
                        for i in 0..3 {
                            a[i] += c * x[i];
                        }
                    }
                }
                acc
            })
            .collect();
        self.set_histories(from_nodes(new, new_nodes, &moved))
    }
}
