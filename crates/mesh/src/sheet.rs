//! Flat sheets: the quarter annulus R_in ≤ r ≤ R_out, 0 ≤ θ ≤ π/2 in the plane z = 0, for the
//! tension-field problems of flat membranes. An open mesh ([`Mesh::open`]) with the eighth
//! model's planes: x = 0 and y = 0 are its symmetry planes, and z = 0, on which every node
//! lies, keeps it flat (an in-plane problem). Elements are oriented with +z normals; the
//! 9-node element takes its mid-side and centre nodes at the mid-radius and mid-angle, so its
//! curved edges lie on the circles.

use crate::{ElementKind, Mesh, MeshError, Symmetry};

/// The quarter annulus with `around` elements over the whole circle (a multiple of 4: around/4
/// in the quarter) and `radial` elements from `r_in` to `r_out`, equally spaced.
pub fn quarter_annulus(
    kind: ElementKind,
    r_in: f64,
    r_out: f64,
    around: usize,
    radial: usize,
) -> Result<Mesh, MeshError> {
    if !(r_in.is_finite() && r_out.is_finite() && r_in > 0.0 && r_out > r_in) {
        return Err(MeshError::InvalidParameter {
            name: "radius",
            value: r_in,
            requirement: "an annulus needs 0 < r_in < r_out",
        });
    }
    if around < 4 || !around.is_multiple_of(4) || radial < 1 {
        return Err(MeshError::InvalidParameter {
            name: "around",
            value: around as f64,
            requirement:
                "an annulus needs a multiple of 4 elements around and at least one radially",
        });
    }
    // the lattice: corners only (step 1) or with mid-nodes (step 2)
    let s = if kind == ElementKind::Quad9 { 2 } else { 1 };
    let (ni, nj) = (s * radial + 1, s * (around / 4) + 1);
    let mut nodes = Vec::with_capacity(ni * nj);
    for i in 0..ni {
        let r = r_in + (r_out - r_in) * i as f64 / (ni - 1) as f64;
        for j in 0..nj {
            let th = std::f64::consts::FRAC_PI_2 * j as f64 / (nj - 1) as f64;
            // exact zeros on the planes x = 0 and y = 0
            let (x, y) = match j {
                0 => (r, 0.0),
                _ if j == nj - 1 => (0.0, r),
                _ => (r * th.cos(), r * th.sin()),
            };
            nodes.push([x, y, 0.0]);
        }
    }
    let id = |i: usize, j: usize| i * nj + j;
    let mut quads = vec![];
    let mut mid = vec![];
    for i in 0..radial {
        for j in 0..around / 4 {
            let (a, b) = (s * i, s * j);
            // counter-clockwise in (r, θ): +r then +θ, normal +z
            quads.push([id(a, b), id(a + s, b), id(a + s, b + s), id(a, b + s)]);
            if s == 2 {
                mid.push([
                    id(a + 1, b),
                    id(a + 2, b + 1),
                    id(a + 1, b + 2),
                    id(a, b + 1),
                    id(a + 1, b + 1),
                ]);
            }
        }
    }
    let used: Vec<bool> = {
        let mut u = vec![false; nodes.len()];
        for q in &quads {
            q.iter().for_each(|&i| u[i] = true);
        }
        for m in &mid {
            m.iter().for_each(|&i| u[i] = true);
        }
        u
    };
    debug_assert!(used.iter().all(|&u| u));
    let mesh = Mesh {
        nodes,
        quads,
        symmetry: Symmetry::Eighth,
        plugs: vec![],
        mid,
        open: true,
    };
    mesh.check()?;
    Ok(mesh)
}
