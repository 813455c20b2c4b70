//! User meshes: a small JSON format that `tubemem run` reads through `[mesh] file = "…"`, and
//! that `python_ref` writes from any meshio-readable quadrilateral surface mesh.
//!
//! ```json
//! {
//!   "nodes": [[x, y, z], ...],          // reference positions, in units of R
//!   "quads": [[a, b, c, d], ...],       // 0-based, counter-clockwise seen from outside
//!   "symmetry": "none",                 // optional: "none" | "half" | "quarter" | "eighth"
//!   "plugs": [[i, j, ...], ...]         // optional: rings tied to rigid end discs
//! }
//! ```
//! The tube axis is z, the mid-span cross-section is z = 0, and the reference radius is 1.
//! The mesh is checked ([`Mesh::check`]): a malformed file, an index out of range, a degenerate
//! or inverted element, a non-manifold edge or an opening off the symmetry planes and plugs is
//! reported with the element or edge (and, for JSON syntax, the line and column).

use crate::{Mesh, MeshError, Symmetry};
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshFile {
    pub nodes: Vec<[f64; 3]>,
    pub quads: Vec<[usize; 4]>,
    #[serde(default)]
    pub symmetry: Symmetry,
    #[serde(default)]
    pub plugs: Vec<Vec<usize>>,
}

/// Read and check a JSON mesh; coordinates are divided by `radius` (to units of R).
pub fn read_json(path: &Path, radius: f64) -> Result<Mesh, MeshError> {
    let err = |reason: String| MeshError::Io {
        path: path.display().to_string(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
    let f: MeshFile =
        serde_json::from_str(&text).map_err(|e| err(format!("not a tubemem mesh file: {e}")))?;
    if f.nodes.is_empty() || f.quads.is_empty() {
        return Err(err("the mesh has no nodes or no quads".into()));
    }
    if let Some((i, p)) = f
        .nodes
        .iter()
        .enumerate()
        .find(|(_, p)| p.iter().any(|v| !v.is_finite()))
    {
        return Err(err(format!("node {i} has a non-finite coordinate {p:?}")));
    }
    for (k, ring) in f.plugs.iter().enumerate() {
        if let Some(&i) = ring.iter().find(|&&i| i >= f.nodes.len()) {
            return Err(err(format!(
                "plug {k} refers to node {i}, but the mesh has {} nodes",
                f.nodes.len()
            )));
        }
    }
    let mesh = Mesh {
        nodes: f.nodes.iter().map(|p| p.map(|v| v / radius)).collect(),
        quads: f.quads,
        symmetry: f.symmetry,
        plugs: f.plugs,
    };
    mesh.check()?;
    Ok(mesh)
}

/// Write a mesh in the same format (pretty-printed).
pub fn write_json(path: &Path, mesh: &Mesh) -> Result<(), MeshError> {
    let f = MeshFile {
        nodes: mesh.nodes.clone(),
        quads: mesh.quads.clone(),
        symmetry: mesh.symmetry,
        plugs: mesh.plugs.clone(),
    };
    let text = serde_json::to_string(&f).map_err(|e| MeshError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    std::fs::write(path, text).map_err(|e| MeshError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })
}
