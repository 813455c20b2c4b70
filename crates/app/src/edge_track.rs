//! `[mesh] track_contact_edge = true`: the generated tube's hoop node lines kept on the
//! contact edges at every step of each squeeze and confine stage, not only at the last one's
//! end ([`crate::edge_fit`]).
//!
//! At each step ([`tubemem_fem::stepping::Refit`]) the edges are the GPS section's under the
//! FE's own mid-span pressure at the step's plates or walls: on the secant prediction before
//! the solve and on the converged state after it. When an edge has moved by more than
//! [`TRACK_TOLERANCE`] of an element since the mesh was fitted, the mesh is fitted again
//! ([`tubemem_mesh::hoop::HoopMap::fitted`]), the state carried over
//! ([`tubemem_mesh::hoop::Transfer`]: a hyperelastic membrane has no history, so the state is
//! the map from reference to current surface, evaluated at the moved nodes) and solved again.
//! The edges come from the state itself (its pressure, with its mid-span stretches as the
//! closed form's starting guess), so a resumed run fits the same meshes bit for bit.

use crate::case::PlaneSpec;
use crate::edge_fit::{plate_section_edges, wall_section_edges};
use std::cell::RefCell;
use std::rc::Rc;
use tubemem_fem::model::{Model, State};
use tubemem_fem::FemError;
use tubemem_gps::{inflate, Hypothesis};
use tubemem_material::MembraneLaw;
use tubemem_mesh::hoop::HoopMap;
use tubemem_mesh::tube::capped_tube_fitted_of;
use tubemem_mesh::{ElementKind, Symmetry};

/// An edge moved by more than this fraction of an element's hoop width refits the mesh:
/// 0.005. A node line off the edge by 0.036 of an element raised the 9-node squeeze's χ error
/// at 64 around from 3e-6 to 1.7e-5 (the `edge_fit` locator study), about linearly, so 0.005
/// of an element costs at most about 2e-6.
pub const TRACK_TOLERANCE: f64 = 0.005;

/// The generated tube the tracker refits (the case's `[mesh]` and `[geometry]`, R = 1).
#[derive(Clone, Copy, Debug)]
pub struct TubeSpec {
    pub kind: ElementKind,
    /// L/R
    pub length: f64,
    pub around: usize,
    /// the tube whose node lines the edges take (`[mesh] edge_fit_around`, else `around`)
    pub fit_around: usize,
    pub along: usize,
    pub cap_rows: usize,
    pub symmetry: Symmetry,
}

impl TubeSpec {
    /// The reference nodes with the hoop lines fitted to `edges` (none: uniform).
    pub fn nodes(&self, edges: &[f64]) -> Result<Vec<[f64; 3]>, tubemem_mesh::MeshError> {
        let map = if edges.is_empty() {
            None
        } else {
            Some(HoopMap::fitted(self.fit_around, edges)?)
        };
        capped_tube_fitted_of(
            self.kind,
            1.0,
            self.length,
            self.around,
            self.along,
            self.cap_rows,
            self.symmetry,
            map.as_ref(),
        )
        .map(|m| m.nodes)
    }
}

/// What presses the tube in a tracked stage.
#[derive(Clone, Debug)]
pub enum Pressing {
    /// plates y = ±h, h the load value
    Plates,
    /// plates y = ±h held at this h whatever the load value (an inflation between them)
    HeldPlates(f64),
    /// the stage's planes at the load value t of their path
    Walls(Vec<PlaneSpec>),
}

/// The edges the mesh is fitted to now, shared with the run's step records and checkpoints.
pub type Edges = Rc<RefCell<Vec<f64>>>;

/// The node lines following the contact edges through one stage.
pub struct Tracker<'a> {
    pub tube: TubeSpec,
    pub law: &'a dyn MembraneLaw,
    pub pressing: Pressing,
    /// the edges the model is fitted to (reference angles from the x axis; empty: uniform)
    pub edges: Edges,
}

impl Tracker<'_> {
    /// The contact edges of the GPS section under pressure `w` at load value `value`, from the
    /// state's mid-span stretches `guess`; empty where the section does not touch.
    pub(crate) fn edges_at(&self, value: f64, w: f64, guess: [f64; 2]) -> Result<Vec<f64>, String> {
        if !(w.is_finite() && w > 0.0) {
            return Ok(vec![]);
        }
        match &self.pressing {
            Pressing::Plates | Pressing::HeldPlates(_) => {
                let rho = match self.pressing {
                    Pressing::HeldPlates(h) => h,
                    _ => value,
                };
                // the free circle at ϖ reaches the plates: below ρ = 1 always, above it once
                // ϖ passes the inflation's pressure at λs = ρ
                let touches = rho < 1.0
                    || inflate(self.law, Hypothesis::Gps, rho)
                        .map(|s| s.w < w)
                        .map_err(|e| e.to_string())?;
                if !touches {
                    return Ok(vec![]);
                }
                plate_section_edges(self.law, rho, w, guess).map_err(|e| {
                    format!("the GPS section between the plates at ρ = {rho}, ϖ = {w}: {e}")
                })
            }
            Pressing::Walls(planes) => {
                let walls = planes
                    .iter()
                    .map(|p| p.wall_at(value))
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(|e| e.to_string())?;
                wall_section_edges(self.law, &walls, w).map_err(|e| {
                    format!("the GPS section in the walls at t = {value}, ϖ = {w}: {e}")
                })
            }
        }
    }

    /// Whether `edges` are where the mesh is fitted, within [`TRACK_TOLERANCE`] of an element.
    fn fitted_to(&self, edges: &[f64]) -> bool {
        let h = 2.0 * std::f64::consts::PI / self.tube.around as f64;
        let now = self.edges.borrow();
        now.len() == edges.len()
            && now
                .iter()
                .zip(edges)
                .all(|(a, b)| (a - b).abs() <= TRACK_TOLERANCE * h)
    }
}

impl tubemem_fem::stepping::Refit for Tracker<'_> {
    fn nodes(
        &mut self,
        model: &Model,
        state: &State,
        value: f64,
    ) -> Result<Option<Vec<[f64; 3]>>, FemError> {
        let ms = tubemem_fem::post::midspan(model, state)?;
        let edges = self
            .edges_at(value, ms.w, [ms.lambda_s, ms.lambda_z])
            .map_err(|reason| FemError::Refit {
                reason: format!("[mesh] `track_contact_edge`: {reason}"),
            })?;
        if self.fitted_to(&edges) {
            return Ok(None);
        }
        let nodes = self.tube.nodes(&edges)?;
        *self.edges.borrow_mut() = edges;
        Ok(Some(nodes))
    }

    fn snapshot(&self) -> Vec<f64> {
        self.edges.borrow().clone()
    }

    fn restore(&mut self, snapshot: &[f64]) {
        *self.edges.borrow_mut() = snapshot.to_vec();
    }
}

impl TubeSpec {
    /// The tube a case's tracker refits (`[mesh] track_contact_edge` on a generated tube), if
    /// any.
    pub fn of(case: &crate::case::Case) -> Option<TubeSpec> {
        match (
            case.mesh.track_contact_edge,
            case.mesh.around,
            case.mesh.along,
        ) {
            (true, Some(around), Some(along)) => Some(TubeSpec {
                kind: case.mesh.element,
                length: case.geometry.length / case.geometry.radius,
                around,
                fit_around: case.mesh.fit_grid().unwrap_or(around),
                along,
                cap_rows: case.mesh.cap_rows.unwrap_or(around / 8),
                symmetry: case.mesh.symmetry,
            }),
            _ => None,
        }
    }
}
