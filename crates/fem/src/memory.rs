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
use crate::model::Elements;
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
    pub fn new(prony: Prony, elements: &Elements) -> Self {
        let mut first = Vec::with_capacity(elements.len() + 1);
        let mut total = 0;
        for e in 0..elements.len() {
            first.push(total);
            total += crate::with_elements!(elements, v => v[e].gauss.len());
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
        self.set_step(self.dt)
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
        self.histories
            .par_iter()
            .map(|h| std::array::from_fn(|k| h.h.iter().map(|hi| hi[k]).sum::<f64>()))
            .collect_into_vec(&mut self.held);
        Ok(())
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
    /// law's stress at the positions `x`; the next step is again of the same length.
    pub fn commit(
        &mut self,
        law: &dyn MembraneLaw,
        elements: &Elements,
        x: &[[f64; 3]],
    ) -> Result<(), FemError> {
        let base = crate::with_elements!(elements, v => base_stresses(law, v, x))?;
        let step = &self.step;
        self.histories = self
            .histories
            .par_iter()
            .zip(base.par_iter())
            .map(|(h, &s0)| h.advanced(step, s0))
            .collect();
        self.set_step(self.dt)
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
