//! VTK XML output: one `.vtu` (UnstructuredGrid) per saved step and a `.pvd` collection that
//! ParaView opens as a time series; meshio reads the `.vtu` files too (the python_ref test
//! `test_run_folder_reads_back` holds the two together).
//!
//! Arrays are written inline, either as ASCII text (`%e`, full precision) or binary: base64 of
//! a UInt64 byte count followed by the little-endian values (`header_type="UInt64"`), exact and
//! about a third of the size. Kept as a small writer of our own rather than a crate (vtkio):
//! it is one function, it writes exactly the arrays tubemem needs, and meshio checks it.

use crate::MeshError;
use std::fmt::Write as _;
use std::path::Path;

/// A named field with `components` values per point (or per cell).
pub struct Field<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: &'a [f64],
}

/// A value of the file's field data (VTK `FieldData`, one per file, not per point or cell):
/// numbers as Float64, text as the UInt8 array of its UTF-8 bytes (meshio reads both into
/// `field_data`; `bytes(m.field_data[name]).decode()` gives the text back).
pub enum FieldValue<'a> {
    Numbers(&'a [f64]),
    Text(&'a str),
}

/// What this writer cannot write (a non-finite value, a cell it does not know).
fn content_err(path: &Path, e: impl std::fmt::Display) -> MeshError {
    MeshError::File {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}

/// The file system's refusal.
fn io_err(path: &Path, e: std::io::Error) -> MeshError {
    MeshError::Io {
        path: path.display().to_string(),
        source: crate::Shared::new(e),
    }
}

/// How arrays are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Encoding {
    /// base64 of the little-endian bytes (exact, compact)
    #[default]
    Binary,
    /// text, one tuple a line
    Ascii,
}

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(B64[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// One DataArray: its XML head and the values, in `encoding`.
fn array<T: Copy>(
    out: &mut String,
    head: &str,
    values: &[T],
    per_line: usize,
    encoding: Encoding,
    text: impl Fn(T) -> String,
    bytes: impl Fn(T) -> Vec<u8>,
) {
    match encoding {
        Encoding::Ascii => {
            let _ = writeln!(out, "        <DataArray {head} format=\"ascii\">");
            for chunk in values.chunks(per_line.max(1)) {
                let line: Vec<String> = chunk.iter().map(|&v| text(v)).collect();
                let _ = writeln!(out, "          {}", line.join(" "));
            }
        }
        Encoding::Binary => {
            let _ = writeln!(out, "        <DataArray {head} format=\"binary\">");
            let mut raw: Vec<u8> = Vec::with_capacity(8 + values.len() * 8);
            let data: Vec<u8> = values.iter().flat_map(|&v| bytes(v)).collect();
            raw.extend_from_slice(&(data.len() as u64).to_le_bytes());
            raw.extend_from_slice(&data);
            let _ = writeln!(out, "          {}", base64(&raw));
        }
    }
    out.push_str("        </DataArray>\n");
}

fn data_array(out: &mut String, f: &Field, count: usize, encoding: Encoding) -> Result<(), String> {
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
    array(
        out,
        &format!(
            "type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\"",
            f.name, f.components
        ),
        f.values,
        f.components,
        encoding,
        |v| format!("{v:e}"),
        |v| v.to_le_bytes().to_vec(),
    );
    Ok(())
}

/// Write a quadrilateral surface with point and cell fields: 4-node cells as VTK_QUAD (9),
/// 9-node cells (corners, mid-sides, centre) as VTK_BIQUADRATIC_QUAD (28).
/// `field_data`: (name, value) pairs of the file as a whole (a run's version, case hash, step).
#[allow(clippy::too_many_arguments)]
pub fn write_vtu<C: AsRef<[usize]>>(
    path: &Path,
    points: &[[f64; 3]],
    quads: &[C],
    point_data: &[Field],
    cell_data: &[Field],
    field_data: &[(&str, FieldValue)],
    encoding: Encoding,
) -> Result<(), MeshError> {
    let mut s = String::with_capacity(64 * (points.len() + quads.len()));
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n");
    if !field_data.is_empty() {
        s.push_str("    <FieldData>\n");
        for (name, value) in field_data {
            match value {
                FieldValue::Numbers(v) => {
                    if v.iter().any(|x| !x.is_finite()) {
                        return Err(content_err(
                            path,
                            format!("field data `{name}` is not finite"),
                        ));
                    }
                    let text: Vec<String> = v.iter().map(|x| format!("{x:e}")).collect();
                    let _ = writeln!(
                        s,
                        "      <DataArray type=\"Float64\" Name=\"{name}\" NumberOfTuples=\"{}\" format=\"ascii\">{}</DataArray>",
                        v.len(),
                        text.join(" ")
                    );
                }
                FieldValue::Text(t) => {
                    let bytes: Vec<String> = t.bytes().map(|b| b.to_string()).collect();
                    let _ = writeln!(
                        s,
                        "      <DataArray type=\"UInt8\" Name=\"{name}\" NumberOfTuples=\"{}\" format=\"ascii\">{}</DataArray>",
                        bytes.len(),
                        bytes.join(" ")
                    );
                }
            }
        }
        s.push_str("    </FieldData>\n");
    }
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        points.len(),
        quads.len()
    );
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return Err(content_err(path, "a node coordinate is not finite"));
    }
    s.push_str("      <Points>\n");
    let coords: Vec<f64> = points.iter().flatten().copied().collect();
    array(
        &mut s,
        "type=\"Float64\" NumberOfComponents=\"3\"",
        &coords,
        3,
        encoding,
        |v| format!("{v:e}"),
        |v| v.to_le_bytes().to_vec(),
    );
    s.push_str("      </Points>\n      <Cells>\n");
    let conn: Vec<i64> = quads
        .iter()
        .flat_map(|q| q.as_ref().iter().map(|&i| i as i64))
        .collect();
    let mut offsets: Vec<i64> = Vec::with_capacity(quads.len());
    let mut types: Vec<u8> = Vec::with_capacity(quads.len());
    let mut end = 0i64;
    for (e, q) in quads.iter().enumerate() {
        let q = q.as_ref();
        end += q.len() as i64;
        offsets.push(end);
        types.push(match q.len() {
            4 => 9,  // VTK_QUAD
            9 => 28, // VTK_BIQUADRATIC_QUAD
            n => {
                return Err(content_err(
                    path,
                    format!("cell {e} has {n} nodes: only 4- and 9-node quads are written"),
                ))
            }
        });
        if let Some(&i) = q.iter().find(|&&i| i >= points.len()) {
            return Err(content_err(
                path,
                format!("cell {e} refers to node {i} of {}", points.len()),
            ));
        }
    }
    let int = |v: i64| v.to_string();
    let int_bytes = |v: i64| v.to_le_bytes().to_vec();
    array(
        &mut s,
        "type=\"Int64\" Name=\"connectivity\"",
        &conn,
        4,
        encoding,
        int,
        int_bytes,
    );
    array(
        &mut s,
        "type=\"Int64\" Name=\"offsets\"",
        &offsets,
        1,
        encoding,
        int,
        int_bytes,
    );
    array(
        &mut s,
        "type=\"UInt8\" Name=\"types\"",
        &types,
        1,
        encoding,
        |v| v.to_string(),
        |v| vec![v],
    );
    s.push_str("      </Cells>\n      <PointData>\n");
    for f in point_data {
        data_array(&mut s, f, points.len(), encoding).map_err(|e| content_err(path, e))?;
    }
    s.push_str("      </PointData>\n      <CellData>\n");
    for f in cell_data {
        data_array(&mut s, f, quads.len(), encoding).map_err(|e| content_err(path, e))?;
    }
    s.push_str("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    crate::file::write_whole(path, s.as_bytes()).map_err(|e| io_err(path, e))
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
    crate::file::write_whole(path, s.as_bytes()).map_err(|e| io_err(path, e))
}

#[cfg(test)]
mod tests {
    use super::base64;

    /// RFC 4648, section 10: the test vectors.
    #[test]
    fn base64_matches_rfc_4648() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }
}
