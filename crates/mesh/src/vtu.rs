//! VTK XML output: one `.vtu` (UnstructuredGrid, ASCII, full precision) per saved step and a
//! `.pvd` collection that ParaView opens as a time series. meshio reads the `.vtu` files too.

use crate::MeshError;
use std::fmt::Write as _;
use std::path::Path;

/// A named field with `components` values per point (or per cell).
pub struct Field<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: &'a [f64],
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> MeshError {
    MeshError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}

fn data_array(out: &mut String, f: &Field, count: usize) -> Result<(), String> {
    if f.values.len() != f.components * count {
        return Err(format!(
            "field `{}` has {} values, expected {} × {}",
            f.name,
            f.values.len(),
            f.components,
            count
        ));
    }
    if let Some(v) = f.values.iter().find(|v| !v.is_finite()) {
        return Err(format!("field `{}` holds a non-finite value ({v})", f.name));
    }
    let _ = writeln!(
        out,
        "        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">",
        f.name, f.components
    );
    for chunk in f.values.chunks(f.components.max(1)) {
        let line: Vec<String> = chunk.iter().map(|v| format!("{v:e}")).collect();
        let _ = writeln!(out, "          {}", line.join(" "));
    }
    out.push_str("        </DataArray>\n");
    Ok(())
}

/// Write a quadrilateral surface with point and cell fields.
pub fn write_vtu(
    path: &Path,
    points: &[[f64; 3]],
    quads: &[[usize; 4]],
    point_data: &[Field],
    cell_data: &[Field],
) -> Result<(), MeshError> {
    let mut s = String::with_capacity(64 * (points.len() + quads.len()));
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        points.len(),
        quads.len()
    );
    s.push_str("      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in points {
        if p.iter().any(|v| !v.is_finite()) {
            return Err(io_err(path, "a node coordinate is not finite"));
        }
        let _ = writeln!(s, "          {:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    s.push_str("        </DataArray>\n      </Points>\n      <Cells>\n");
    s.push_str("        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for q in quads {
        let _ = writeln!(s, "          {} {} {} {}", q[0], q[1], q[2], q[3]);
    }
    s.push_str("        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 0..quads.len() {
        let _ = writeln!(s, "          {}", 4 * (i + 1));
    }
    s.push_str("        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in quads {
        s.push_str("          9\n"); // VTK_QUAD
    }
    s.push_str("        </DataArray>\n      </Cells>\n      <PointData>\n");
    for f in point_data {
        data_array(&mut s, f, points.len()).map_err(|e| io_err(path, e))?;
    }
    s.push_str("      </PointData>\n      <CellData>\n");
    for f in cell_data {
        data_array(&mut s, f, quads.len()).map_err(|e| io_err(path, e))?;
    }
    s.push_str("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, s).map_err(|e| io_err(path, e))
}

/// Write a `.pvd` collection of (time, file name relative to the `.pvd`) entries.
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> Result<(), MeshError> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, f) in entries {
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{f}\"/>"
        );
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    std::fs::write(path, s).map_err(|e| io_err(path, e))
}
