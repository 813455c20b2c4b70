//! Contour lines of a gridded field (marching squares), for the atlas's maps.

/// The segments where the bilinear interpolant of `z` on the grid (`xs` × `ys`, `z[i][j]` at
/// (`xs[i]`, `ys[j]`)) crosses `level` (marching squares; a cell with a missing corner has none),
/// as one polyline broken by NaN points between segments.
pub fn contour(xs: &[f64], ys: &[f64], z: &[Vec<f64>], level: f64) -> Vec<(f64, f64)> {
    let mut out = vec![];
    for i in 0..xs.len().saturating_sub(1) {
        for j in 0..ys.len().saturating_sub(1) {
            // corners counter-clockwise: (i,j), (i+1,j), (i+1,j+1), (i,j+1)
            let c = [
                (xs[i], ys[j], z[i][j]),
                (xs[i + 1], ys[j], z[i + 1][j]),
                (xs[i + 1], ys[j + 1], z[i + 1][j + 1]),
                (xs[i], ys[j + 1], z[i][j + 1]),
            ];
            if c.iter().any(|p| !p.2.is_finite()) {
                continue;
            }
            let mut cross = vec![];
            for k in 0..4 {
                let (a, b) = (c[k], c[(k + 1) % 4]);
                let (da, db) = (a.2 - level, b.2 - level);
                if (da < 0.0) != (db < 0.0) {
                    let t = da / (da - db);
                    cross.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
                }
            }
            // two crossings: one segment; four (a saddle): pair them by the centre's side
            let centre = c.iter().map(|p| p.2).sum::<f64>() / 4.0;
            let pairs: Vec<[usize; 2]> = match cross.len() {
                2 => vec![[0, 1]],
                4 if (centre < level) == (c[0].2 < level) => vec![[0, 3], [1, 2]],
                4 => vec![[0, 1], [2, 3]],
                _ => vec![],
            };
            for [a, b] in pairs {
                out.push(cross[a]);
                out.push(cross[b]);
                out.push((f64::NAN, f64::NAN));
            }
        }
    }
    out
}
