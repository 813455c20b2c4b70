//! Closed-form curves as CSV: the columns of `tubemem gps … --csv` and of the figures' data.

use crate::{AppError, Result};
use std::path::Path;
use tubemem_gps::{FlatteningState, InflationState};

pub const INFLATION_HEADER: &str = "w,lambda_s,lambda_z,n_s,n_z";
pub const FLATTENING_HEADER: &str = "w,lambda_s,lambda_z,n_s,n_z,rho,chi,force,displacement";

pub fn inflation_values(s: &InflationState) -> Vec<f64> {
    vec![s.w, s.lambda_s, s.lambda_z, s.n_s, s.n_z]
}

pub fn flattening_values(s: &FlatteningState) -> Vec<f64> {
    vec![
        s.w,
        s.lambda_s,
        s.lambda_z,
        s.n_s,
        s.n_z,
        s.rho,
        s.chi,
        s.force,
        s.displacement,
    ]
}

/// One CSV line of numbers (shortest round-trip form), an empty field where a value does not
/// apply (non-finite).
pub(crate) fn csv_line(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| {
            if v.is_finite() {
                v.to_string()
            } else {
                String::new()
            }
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// Rows of numbers as CSV text (shortest round-trip representation), for the file `path`. A
/// non-finite value is refused: it would be a silent wrong answer.
pub(crate) fn csv_text(
    path: &Path,
    header: &str,
    rows: impl Iterator<Item = Vec<f64>>,
) -> Result<String> {
    let mut out = String::with_capacity(1 << 16);
    out.push_str(header);
    out.push('\n');
    for row in rows {
        if !row.iter().all(|v| v.is_finite()) {
            return Err(AppError::Output {
                what: path.display().to_string(),
                source: format!("internal error: a non-finite value was computed ({row:?}); please report this input").into(),
            });
        }
        let line: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        out.push_str(&line.join(","));
        out.push('\n');
    }
    Ok(out)
}

/// Write rows of numbers as CSV (`csv_text`), whole.
pub fn write_csv(path: &Path, header: &str, rows: impl Iterator<Item = Vec<f64>>) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| AppError::io(dir, e))?;
    }
    let out = csv_text(path, header, rows)?;
    crate::output_file::write_whole(path, out.as_bytes())
}
