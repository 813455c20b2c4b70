//! A critical mode along the tube.

use super::{Figure, Series, Stroke};
use plotters::style::RGBColor;

/// A critical mode along the tube: the means over each ring of nodes at the reference radius
/// (the cylinder and the caps' equators) of the mode's radial and axial components, against
/// the reference Z, scaled so that the largest is 1 (a mode's size is arbitrary).
pub fn mode_figure(
    mesh: &tubemem_mesh::Mesh,
    mode: &[[f64; 3]],
    title: &str,
    notes: Vec<String>,
) -> Figure {
    let radius = mesh
        .nodes
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, f64::max);
    // (Z, mean u_r, mean u_z) per ring (a mode of another mesh's length draws nothing)
    let rings: Vec<(f64, f64, f64)> = mesh
        .rings()
        .iter()
        .filter(|ring| !ring.is_empty() && ring.iter().all(|&i| i < mode.len()))
        .map(|ring| {
            let (mut ur, mut uz) = (0.0, 0.0);
            for &i in ring {
                let p = mesh.nodes[i];
                ur += (mode[i][0] * p[0] + mode[i][1] * p[1]) / radius;
                uz += mode[i][2];
            }
            let n = ring.len() as f64;
            (mesh.nodes[ring[0]][2], ur / n, uz / n)
        })
        .collect();
    let scale = rings
        .iter()
        .map(|r| r.1.abs().max(r.2.abs()))
        .fold(0.0, f64::max)
        .max(1e-300);
    let series = |label: &str, pick: fn(&(f64, f64, f64)) -> f64, color, stroke| Series {
        label: label.into(),
        points: rings.iter().map(|r| (r.0, pick(r) / scale)).collect(),
        color,
        stroke,
        width: 2,
    };
    let mut fig = Figure::new(
        title,
        "reference axial position Z / R",
        "mode (ring mean, largest = 1)",
        vec![
            series(
                "radial component u_r",
                |r| r.1,
                RGBColor(200, 30, 30),
                Stroke::Solid,
            ),
            series(
                "axial component u_z",
                |r| r.2,
                RGBColor(30, 60, 200),
                Stroke::Dashed,
            ),
        ],
    );
    fig.y_from_zero = false;
    fig.notes = notes;
    fig
}
