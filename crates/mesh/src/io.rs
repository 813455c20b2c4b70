//! User meshes: a small JSON format that `tubemem run` reads through `[mesh] file = "…"`, and
//! that `python_ref` writes from any meshio-readable quadrilateral surface mesh.
//!
//! ```json
//! {
//!   "nodes": [[x, y, z], ...],          // reference positions, in units of R
//!   "quads": [[a, b, c, d], ...],       // 0-based, counter-clockwise seen from outside; or
//!                                       // 9 nodes each (corners, mid-sides of 01 12 23 30,
//!                                       // centre: meshio's quad9 order) for the 9-node element
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
    pub quads: Vec<Vec<usize>>,
    #[serde(default)]
    pub symmetry: Symmetry,
    #[serde(default)]
    pub plugs: Vec<Vec<usize>>,
}

/// The largest mesh file read: 256 MiB, about 3 million nodes with their quads in this JSON
/// form (some 80 bytes a node): already beyond what the memory guard admits for a full model.
pub const MAX_MESH_FILE_BYTES: u64 = 256 << 20;

/// The largest text input other than a case or a mesh (test data, rings, atlas and suite
/// files): 64 MiB.
pub const MAX_TEXT_INPUT_BYTES: u64 = 64 << 20;

/// Read at most `limit` bytes of a regular text file; a longer file is refused with its limit
/// named, and anything but a regular file (a FIFO, /dev/zero) before it is opened.
pub fn read_text_limited(path: &Path, limit: u64) -> std::io::Result<String> {
    use std::io::Read;
    // a FIFO would block the open until a writer comes (forever, if none does); a device or
    // socket is not a file to read
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a folder, a FIFO, a device or a socket): give a file",
        ));
    }
    let f = std::fs::File::open(path)?;
    let mut buf = Vec::new();
    f.take(limit + 1).read_to_end(&mut buf)?;
    if buf.len() as u64 > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "larger than the {} MiB this file may have",
                limit as f64 / (1u64 << 20) as f64
            ),
        ));
    }
    String::from_utf8(buf)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, NotUtf8(e)))
}

/// A file that is not UTF-8 text (the conversion's error as the source).
#[derive(Debug, thiserror::Error)]
#[error("not UTF-8 text")]
pub struct NotUtf8(#[source] pub std::string::FromUtf8Error);

/// Read and check a JSON mesh; coordinates are divided by `radius` (to units of R).
pub fn read_json(path: &Path, radius: f64) -> Result<Mesh, MeshError> {
    let err = |reason: String| MeshError::File {
        path: path.display().to_string(),
        reason,
    };
    let text = read_text_limited(path, MAX_MESH_FILE_BYTES).map_err(|e| MeshError::Io {
        path: path.display().to_string(),
        source: crate::Shared::new(e),
    })?;
    let f: MeshFile = serde_json::from_str(&text).map_err(|e| MeshError::Json {
        path: path.display().to_string(),
        source: crate::Shared::new(e),
    })?;
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
    if !(radius.is_finite() && radius > 0.0) {
        return Err(err(format!("radius {radius} must be finite and > 0")));
    }
    let nodes: Vec<[f64; 3]> = f.nodes.iter().map(|p| p.map(|v| v / radius)).collect();
    if let Some((i, p)) = nodes
        .iter()
        .enumerate()
        .find(|(_, p)| p.iter().any(|v| !v.is_finite()))
    {
        return Err(err(format!(
            "node {i} at {:?} divided by the radius {radius} is {p:?}: not a finite position",
            f.nodes[i]
        )));
    }
    let per = f.quads[0].len();
    if per != 4 && per != 9 {
        return Err(err(format!(
            "element 0 has {per} nodes: an element has 4 (bilinear) or 9 (biquadratic) nodes"
        )));
    }
    if let Some((e, q)) = f.quads.iter().enumerate().find(|(_, q)| q.len() != per) {
        return Err(err(format!(
            "element {e} has {} nodes but element 0 has {per}: one mesh has one kind of element",
            q.len()
        )));
    }
    let quads = f.quads.iter().map(|q| [q[0], q[1], q[2], q[3]]).collect();
    let mid = if per == 9 {
        f.quads
            .iter()
            .map(|q| [q[4], q[5], q[6], q[7], q[8]])
            .collect()
    } else {
        vec![]
    };
    let mesh = Mesh {
        nodes,
        quads,
        symmetry: f.symmetry,
        plugs: f.plugs,
        mid,
        open: false,
    };
    mesh.check()?;
    Ok(mesh)
}

/// Write a mesh in the same format (pretty-printed).
pub fn write_json(path: &Path, mesh: &Mesh) -> Result<(), MeshError> {
    let f = MeshFile {
        nodes: mesh.nodes.clone(),
        quads: (0..mesh.quads.len())
            .map(|e| mesh.element_nodes(e))
            .collect(),
        symmetry: mesh.symmetry,
        plugs: mesh.plugs.clone(),
    };
    let text = serde_json::to_string(&f).map_err(|e| MeshError::Json {
        path: path.display().to_string(),
        source: crate::Shared::new(e),
    })?;
    crate::file::write_whole(path, text.as_bytes()).map_err(|e| MeshError::Io {
        path: path.display().to_string(),
        source: crate::Shared::new(e),
    })
}
