//! Moving the reference mesh (a refitted hoop map) and carrying states over to it.

use super::*;

impl Model {
    /// Move the reference nodes to `nodes` (the same mesh with nodes moved along their hoops,
    /// a refitted [`tubemem_mesh::hoop::HoopMap`]) and carry each of `states` over by
    /// `transfer` ([`tubemem_mesh::hoop::Transfer::between`] the old nodes and `nodes`): the
    /// positions by the transfer, and the contact multipliers of nodal contact points as the
    /// planes' traction per reference area at each node (the elements' values at a shared node
    /// averaged with their weights ∫N_a dA0, then transferred), with no last gap. The dofs,
    /// the pattern and the symbolic factorization stay (the topology is the same). Gauss-point
    /// multipliers have no nodal field to transfer: an error. A viscoelastic law's Gauss-point
    /// histories are carried too ([`crate::memory::Memory::carry`]).
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
        // a viscoelastic law's histories follow ([`crate::memory::Memory::carry`])
        if let Some(m) = &mut self.memory {
            let (old_nodes, new_nodes) = (&self.mesh.nodes, &mesh.nodes);
            match (&self.elements, &new_elements) {
                (Elements::Quad4(a), Elements::Quad4(b)) => {
                    m.carry(a, old_nodes, b, new_nodes, transfer)?
                }
                (Elements::Quad9(a), Elements::Quad9(b)) => {
                    m.carry(a, old_nodes, b, new_nodes, transfer)?
                }
                _ => {
                    return Err(FemError::Remap {
                        reason: "the moved mesh has another element kind".into(),
                    })
                }
            }
        }
        self.mesh = mesh;
        self.elements = new_elements;
        Ok(())
    }
}

/// The positions `x` of the mesh with reference nodes `old` carried to the moved reference
/// nodes `new` by `transfer`: a node that did not move keeps its position; a moved one takes
/// the interpolated cylindrical displacement of its old neighbours, the current radius r, the
/// turn φ − Θ from its reference angle Θ and the axial displacement z − Z, placed at its own
/// reference angle Θ'. A uniform dilation, a rigid turn about the axis and an axial stretch,
/// the inflated tube's state, carry over exactly; interpolating the positions themselves
/// would leave the hoop's O(h³) chord error of the interpolation (a residual of 0.15 on the
/// 9-node inflation test at 16 around, `tests_remap`).
pub(super) fn carry_positions(
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
