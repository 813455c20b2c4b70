//! Uniform refinement of a bilinear (4-node) mesh: every quad split in four, the new nodes (the
//! edges' midpoints and the quads' centres) placed by a projection onto the surface the mesh
//! approximates. A family of meshes from a user's mesh, for a convergence study on it.

use crate::{Mesh, MeshError};
use std::collections::HashMap;

/// `mesh` with every quad split in four (corners a, b, c, d: the children a-ab-o-da,
/// ab-b-bc-o, o-bc-c-cd, da-o-cd-d, o the centre), the new nodes at `project`(the bilinear
/// midpoint). Only 4-node meshes without plugs; node numbering: the old nodes first, then the
/// new ones in the order they are met.
pub fn split(mesh: &Mesh, project: impl Fn([f64; 3]) -> [f64; 3]) -> Result<Mesh, MeshError> {
    if !mesh.mid.is_empty() {
        return Err(MeshError::InvalidParameter {
            name: "element",
            value: 9.0,
            requirement: "uniform refinement splits 4-node meshes; refine a 9-node mesh by generating it finer",
        });
    }
    if !mesh.plugs.is_empty() {
        return Err(MeshError::InvalidParameter {
            name: "plugs",
            value: mesh.plugs.len() as f64,
            requirement: "uniform refinement does not split plug rings",
        });
    }
    let mut nodes = mesh.nodes.clone();
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    let add = |nodes: &mut Vec<[f64; 3]>, p: [f64; 3]| {
        nodes.push(project(p));
        nodes.len() - 1
    };
    let mid = |a: [f64; 3], b: [f64; 3]| {
        [
            0.5 * (a[0] + b[0]),
            0.5 * (a[1] + b[1]),
            0.5 * (a[2] + b[2]),
        ]
    };
    let mut quads = Vec::with_capacity(4 * mesh.quads.len());
    for q in &mesh.quads {
        let mut e = [0usize; 4];
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            let key = (a.min(b), a.max(b));
            e[k] = match edges.get(&key) {
                Some(&i) => i,
                None => {
                    let i = add(&mut nodes, mid(mesh.nodes[a], mesh.nodes[b]));
                    edges.insert(key, i);
                    i
                }
            };
        }
        let c = q.map(|i| mesh.nodes[i]);
        let o = add(
            &mut nodes,
            [0, 1, 2].map(|i| 0.25 * (c[0][i] + c[1][i] + c[2][i] + c[3][i])),
        );
        let [a, b, cc, d] = *q;
        let [ab, bc, cd, da] = e;
        quads.extend([
            [a, ab, o, da],
            [ab, b, bc, o],
            [o, bc, cc, cd],
            [da, o, cd, d],
        ]);
    }
    let out = Mesh {
        nodes,
        quads,
        symmetry: mesh.symmetry,
        plugs: vec![],
        mid: vec![],
        open: mesh.open,
    };
    out.check()?;
    Ok(out)
}
