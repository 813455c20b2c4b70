//! Sliding a bulge along the whole tube: the tool behind the stability of the whole tube's
//! bulge (README, "The whole tube and branch switching").
//!
//! On a whole capped tube (no symmetry plane) the bulge that forms past the pressure maximum
//! can sit anywhere along the cylinder: far from the caps its translation is a neutral mode of
//! the stiffness (eigenvalue at round-off on a fine mesh). Which way it goes is decided by the
//! caps alone, through an interaction that decays like the profile's own tails. A continuation
//! cannot follow that family (its tangent is noise along the mode), and moving along the mode
//! linearly fails beyond a tiny step (a moving front is not linear in the nodal positions).
//!
//! What works exactly is a *shift by whole rows of elements*: on a uniform cylinder mesh the
//! rings are translates of one another, so a state whose bulge is moved by k rows — each ring
//! between two splices taking the deformation of the ring k rows behind it, shifted by the
//! current length of k rows of the uniform part it moves into — is again an equilibrium up to
//! the cap interaction. The splices sit in the uniform parts halfway between each front and
//! its cap, where the ring-to-ring step is uniform to the tails' size there. The caps and the
//! rings beyond the splices keep their positions; the whole body is then translated along z so
//! that the node whose z is pinned keeps it.
//!
//! [`Model::solve_held`](crate::model::Model::solve_held) relaxes such a state at the same
//! volume with the bulge held where it was put: its reaction is the cap's push on the bulge.

use crate::model::{Model, State};
use crate::FemError;
use tubemem_mesh::Symmetry;

/// The rings of a whole tube's cylinder: node ids ring by ring (ascending reference Z), each
/// ring in the order of its reference angle.
#[derive(Clone, Debug)]
pub struct Rings {
    pub rings: Vec<Vec<usize>>,
}

impl Rings {
    /// The rings of `model`'s cylinder: the nodes at the largest reference distance from the
    /// axis with |Z| within the cylinder, grouped by Z. Only a whole 4-node tube has rings that
    /// are translates of one another by one row.
    pub fn new(model: &Model) -> Result<Self, FemError> {
        let mesh = model.mesh();
        if mesh.symmetry != Symmetry::None || !mesh.mid.is_empty() || !mesh.plugs.is_empty() {
            return Err(FemError::Slide {
                what: "it needs the whole capped tube (symmetry = \"none\") of 4-node elements"
                    .into(),
            });
        }
        let rings = mesh.rings();
        let around = rings.first().map_or(0, Vec::len);
        if rings.len() < 3 || rings.iter().any(|r| r.len() != around) {
            return Err(FemError::Slide {
                what: format!(
                    "the cylinder's nodes do not form rings of equal size ({} rings)",
                    rings.len()
                ),
            });
        }
        Ok(Rings { rings })
    }

    /// The mean distance from the axis of each ring at `state`.
    pub fn radii(&self, state: &State) -> Vec<f64> {
        self.rings
            .iter()
            .map(|r| {
                r.iter()
                    .map(|&i| state.x[i][0].hypot(state.x[i][1]))
                    .sum::<f64>()
                    / r.len() as f64
            })
            .collect()
    }

    /// The first and last ring of the bulge at `state`: the rings wider than halfway between
    /// the narrowest and the widest; `None` without a bulge (all rings within 1 % of one
    /// another).
    pub fn bulge(&self, state: &State) -> Option<(usize, usize)> {
        let r = self.radii(state);
        let level = bulge_level(&r)?;
        let first = r.iter().position(|&v| v > level)?;
        let last = r.iter().rposition(|&v| v > level)?;
        Some((first, last))
    }

    /// The fronts of the bulge at `state`: the reference heights (rings' Z in `mesh`,
    /// interpolated) where the ring radius crosses halfway between the narrowest and the
    /// widest; empty without a bulge.
    pub fn fronts(&self, mesh: &tubemem_mesh::Mesh, state: &State) -> Vec<f64> {
        let r = self.radii(state);
        let Some(level) = bulge_level(&r) else {
            return vec![];
        };
        let z = |l: usize| mesh.nodes[self.rings[l][0]][2];
        (1..r.len())
            .filter_map(|i| {
                let (a, b) = (r[i - 1] - level, r[i] - level);
                (a * b < 0.0).then(|| z(i - 1) + (z(i) - z(i - 1)) * a / (a - b))
            })
            .collect()
    }
}

/// Halfway between the narrowest and the widest of the ring radii `r`, when the widest is more
/// than 1 % wider (a bulge).
fn bulge_level(r: &[f64]) -> Option<f64> {
    let lo = r.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = r.iter().copied().fold(0.0, f64::max);
    (hi > 1.01 * lo).then_some(0.5 * (lo + hi))
}

/// A bulge moved along the tube ([`translate_bulge`]).
#[derive(Clone, Debug)]
pub struct Translated {
    /// the state with the bulge moved (same pressure)
    pub state: State,
    /// the unit direction of the move on the free dofs: the direction to hold while relaxing
    pub direction: Vec<f64>,
    /// the splice rings (between them the rings were rewritten)
    pub splices: (usize, usize),
}

/// Move the bulge of `state` by `rows` rows of elements toward +Z (`rows` > 0) or −Z: see the
/// module header. Refused without a bulge, or when the bulge (with as many rows again of its
/// tail) would reach the splice on the side it moves to.
pub fn translate_bulge(
    model: &Model,
    rings: &Rings,
    state: &State,
    rows: isize,
) -> Result<Translated, FemError> {
    let n = rings.rings.len();
    let (first, last) = rings.bulge(state).ok_or(FemError::Slide {
        what: "there is none (the rings' radii are within 1 % of one another)".into(),
    })?;
    let (a, b) = (first / 2, (last + n - 1) / 2);
    let k = rows.unsigned_abs();
    let room = if rows > 0 { b - last } else { first - a };
    if rows == 0 || k >= room {
        return Err(FemError::Slide {
            what: format!(
                "a move of {rows} rows: it must be non-zero and shorter than the {room} rows of uniform tube between the bulge and the splice halfway to the cap"
            ),
        });
    }
    let x = &state.x;
    let z = |l: usize| x[rings.rings[l][0]][2];
    // the length of k rows of the uniform part the bulge moves into
    let c = if rows > 0 {
        z(b) - z(b - k)
    } else {
        z(a) - z(a + k)
    };
    let mut y = x.clone();
    for l in a..=b {
        let src = l as isize - rows;
        if src < a as isize || src > b as isize {
            // the uniform part the bulge leaves keeps its rings (k rows of it, continuous with
            // the shifted part: both uniform parts have the same axial stretch)
            continue;
        }
        for (&to, &from) in rings.rings[l].iter().zip(&rings.rings[src as usize]) {
            y[to] = [x[from][0], x[from][1], x[from][2] + c];
        }
    }
    // the pinned z: translate the whole body so that every node whose z is fixed keeps it
    if let Some(pin) = (0..x.len()).find(|&i| model.dofs().eq(i, 2).is_none()) {
        let dz = y[pin][2] - x[pin][2];
        y.iter_mut().for_each(|p| p[2] -= dz);
    }
    let mut direction = model.free_difference(&y, x);
    let nd = direction.iter().map(|v| v * v).sum::<f64>().sqrt();
    direction.iter_mut().for_each(|v| *v /= nd.max(1e-300));
    Ok(Translated {
        state: State {
            x: y,
            p: state.p,
            planes: state.planes,
            multipliers: Vec::new(),
        },
        direction,
        splices: (a, b),
    })
}
