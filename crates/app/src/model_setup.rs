//! The mesh and the model a case asks for, and the memory guard that runs before anything
//! large is built.

use crate::case::{Caps, Case};
use crate::{AppError, Result};
use tubemem_mesh::hoop::HoopMap;
use tubemem_mesh::tube::{capped_tube_fitted_of, plugged_tube_of};
use tubemem_mesh::Mesh;

/// The mesh a case asks for, with where its node lines were fitted to the contact edges
/// (`[mesh] fit_contact_edge`); `solve` runs [`crate::edge_fit`]'s locating case (the caller's
/// run, which uses this function to build its own mesh). Most callers want
/// [`crate::run::build_mesh`].
pub(crate) fn mesh_of(
    case: &Case,
    solve: &mut dyn FnMut(&Case) -> crate::report::RunOutcome,
) -> Result<(Mesh, Option<crate::report::ContactEdgeFit>)> {
    let g = &case.geometry;
    let ll = g.length / g.radius;
    match (&case.mesh.file, case.mesh.around, case.mesh.along) {
        (Some(file), ..) => {
            let path = case.base_dir.join(file);
            tubemem_mesh::io::read_json(&path, g.radius)
                .and_then(|m| {
                    // the mesh's own faults first (plugs, unused nodes, orientation), then
                    // whether it is the case's tube at all
                    m.check()?;
                    m.check_tube(0.5 * ll, g.caps == Caps::Hemisphere)?;
                    Ok((m, None))
                })
                .map_err(|source| AppError::MeshFile {
                    file: file.clone(),
                    source,
                })
        }
        (None, Some(around), Some(along)) => {
            let cap_rows = case.mesh.cap_rows.unwrap_or(around / 8);
            let (kind, sym) = (case.mesh.element, case.mesh.symmetry);
            let fit = crate::edge_fit::contact_edges(case, solve)?;
            let map = match &fit {
                Some(f) => Some(
                    HoopMap::fitted(case.mesh.fit_grid().unwrap_or(around), &f.edges)
                        .map_err(AppError::Mesh)?,
                ),
                None => None,
            };
            match g.caps {
                Caps::Hemisphere => {
                    capped_tube_fitted_of(kind, 1.0, ll, around, along, cap_rows, sym, map.as_ref())
                }
                Caps::RigidPlug => plugged_tube_of(kind, 1.0, ll, around, along, sym),
            }
            .map(|m| (m, fit))
            .map_err(AppError::Mesh)
        }
        _ => Err(crate::case::CaseError::Invalid(
            "[mesh] needs `around` and `along`, or `file`".into(),
        )
        .into()),
    }
}

/// The estimated peak memory of a model with `equations` equations: 8 MiB + 240 B·n·log2 n.
/// Fitted to the measured peak RSS of pressure-controlled runs (release, this 2-core machine):
/// 19.7, 56.9, 167 and 414 MiB at 4,520, 16,280, 47,904 and 104,448 equations (the fit is
/// within 10 % there); at 978,432 equations it gives 4.7 GiB against the 4.2–4.6 GiB peak
/// measured with the split factorization (`bash scripts/bench-million.sh`, `ORDERING=auto
/// THREADS=2`; it was 5.6 GiB before the factorization's transients were kept from one
/// factorization to the next and the global pattern pairs dropped), so it errs on the safe side
/// as the factor's fill grows more slowly than n log n.
pub(crate) fn memory_estimate(equations: usize) -> u64 {
    let n = equations.max(2) as f64;
    (8.0 * (1u64 << 20) as f64 + 240.0 * n * n.log2()) as u64
}

/// The equations of the case's generated tube, counted before it is built: the full tube has
/// about around·along cylinder cells plus 2·(around²/16 + around·cap_rows) in the two
/// cube-sphere caps, a node per cell (four for the 9-node element), three unknowns each,
/// divided by the symmetry multiplicity (within 3 % of the built shipped cases).
pub fn equations_estimate(case: &Case) -> Option<usize> {
    let (around, along) = (case.mesh.around? as f64, case.mesh.along? as f64);
    // each cap: a top face of (around/4)² cells and four side faces of around/4 × cap_rows
    let rows = case.mesh.cap_rows.map_or(around / 8.0, |r| r as f64);
    let cells = around * along + 2.0 * (around * around / 16.0 + around * rows);
    // a 9-node element has about four nodes per cell (the lattice of twice the resolution)
    let per_cell = match case.mesh.element {
        tubemem_mesh::ElementKind::Quad4 => 1.0,
        tubemem_mesh::ElementKind::Quad9 => 4.0,
    };
    let equations = 3.0 * per_cell * cells / case.mesh.symmetry.multiplicity();
    // saturating: a key of 2⁶³ − 1 elements is an estimate of usize::MAX, not an overflow
    Some(if equations < usize::MAX as f64 {
        equations as usize
    } else {
        usize::MAX
    })
}

/// The memory this machine has available (`MemAvailable` of /proc/meminfo), if it says.
pub(crate) fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

pub(crate) fn check_memory(equations: usize, force: bool) -> Result<()> {
    if force {
        return Ok(());
    }
    let estimate = memory_estimate(equations);
    match available_memory() {
        Some(available) if estimate > available => Err(AppError::TooLarge {
            equations,
            estimate_bytes: estimate,
            available_bytes: available,
        }),
        _ => Ok(()),
    }
}

/// Whether some confine stage of `case` has planes that are not symmetric about x = 0
/// (`[0]`) or y = 0 (`[1]`): such planes push the tube sideways, which the rigid-mode pins on
/// the axis x = y = 0 (the caps' poles) must not resist (`Model::soften_rigid_pins`).
pub fn sideways_planes(case: &Case) -> [bool; 2] {
    let mut out = [false, false];
    for stage in &case.stages {
        for (axis, flag) in out.iter_mut().enumerate() {
            *flag |= !stage
                .plane
                .iter()
                .all(|p| p.mirrored_in(&stage.plane, axis));
        }
    }
    out
}

/// The model of `mesh` with the case's law (with its tension-field relaxation if the case asks),
/// its rigid-mode pins (springs where planes move the tube sideways), the solver's settings and
/// the run's interrupt flag.
pub(crate) fn model_of(
    case: &Case,
    mesh: Mesh,
    interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
) -> Result<tubemem_fem::model::Model> {
    let law = case.material.build_with(case.solver.wrinkling)?;
    let mut model = tubemem_fem::model::Model::with_ordering(mesh, law, case.solver.ordering)
        .map_err(AppError::Model)?;
    // planes that move the tube sideways: the rigid-mode pins on the axis would hold the caps'
    // poles against them, so springs hold those modes instead
    let soft = sideways_planes(case);
    if soft.iter().any(|s| *s) {
        model
            .soften_rigid_pins(soft, tubemem_fem::dofs::SOFT_PIN_STIFFNESS)
            .map_err(AppError::Model)?;
    }
    model.set_interrupt(interrupt);
    model.set_settings(tubemem_fem::NewtonSettings {
        rtol: case.solver.rtol,
        max_iterations: case.solver.max_iterations,
        ..tubemem_fem::NewtonSettings::default()
    });
    model.set_factor_threads(case.solver.factor_threads);
    model.set_refactorization(case.solver.refactorize);
    model.set_iteration_log(case.output.iterations);
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tubemem_fem::linsolve::{Layout, SparseLdlt, SPLIT_MIN_UNKNOWNS};
    use tubemem_fem::ordering::Ordering;

    /// Our own numeric layer (the tree split's halves, each a multifrontal LDLᵀ over faer's
    /// symbolic analysis and dense kernels) against faer's own factorization of the whole, on
    /// the pattern of every shipped case (cases/*.toml, edge fits left out: a fit moves nodes,
    /// not the pattern). The values: a regular matrix of known inertia on the pattern — ±2 on
    /// the diagonal (every 7th negative), off-diagonal entries of at most 0.01 in magnitude
    /// (at most 74 a row on the 9-node tube: Gershgorin puts every eigenvalue within 0.74 of
    /// ±2, so the condition number is below 2.2 and the negative count is the negative
    /// diagonals'). Both factors must find that count, and their solutions of one right-hand
    /// side must agree, and satisfy the matrix, to 1e-12 (a condition of 2.2 times round-off,
    /// with three orders of margin).
    #[test]
    fn the_tree_split_agrees_with_faers_factor_on_every_shipped_pattern() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases");
        let mut paths: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        paths.sort();
        assert!(paths.len() >= 19, "{} shipped cases", paths.len());
        for path in &paths {
            let name = path.file_name().unwrap().to_string_lossy();
            let mut case = Case::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
            case.mesh.fit_contact_edge = false;
            let (mesh, _) = mesh_of(&case, &mut |_| {
                unreachable!("no locating run without a fit")
            })
            .unwrap();
            let model = model_of(&case, mesh, None).unwrap();
            let pairs = model.pattern_pairs();
            let n = model.dofs().len();
            let d = |i: usize| if i % 7 == 3 { -2.0 } else { 2.0 };
            let mut seen = std::collections::HashSet::new();
            let values: Vec<f64> = pairs
                .iter()
                .map(|&(r, c)| match (seen.insert((r, c)), r == c) {
                    (false, _) => 0.0,
                    (true, true) => d(r),
                    (true, false) => 0.01 * (((r * 31 + c * 17) % 11) as f64 / 5.0 - 1.0),
                })
                .collect();
            let negative = (0..n).filter(|&i| d(i) < 0.0).count();
            let mut whole =
                SparseLdlt::with_options(n, &pairs, Layout::Auto, Ordering::NestedDissection)
                    .unwrap();
            if n < SPLIT_MIN_UNKNOWNS {
                assert_eq!(whole.split_separator(), None, "{name}: faer's whole factor");
            }
            let mut split = SparseLdlt::split_of(n, &pairs)
                .unwrap()
                .unwrap_or_else(|| panic!("{name}: METIS found no split"));
            assert_eq!(whole.factorize(&values).unwrap(), negative, "{name}");
            assert_eq!(split.factorize(&values).unwrap(), negative, "{name}");
            let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
            let (mut x, mut y) = (b.clone(), b.clone());
            whole.solve(&mut x);
            split.solve(&mut y);
            let mut ax = vec![0.0; n];
            for (&(r, c), v) in pairs.iter().zip(&values) {
                ax[r] += v * y[c];
                if r != c {
                    ax[c] += v * y[r];
                }
            }
            let apart = x
                .iter()
                .zip(&y)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let residual = ax
                .iter()
                .zip(&b)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            eprintln!(
                "{name}: {n} unknowns, separator {}; split − whole {apart:.1e}, residual {residual:.1e}",
                split.split_separator().unwrap_or(0)
            );
            assert!(
                apart < 1e-12 && residual < 1e-12,
                "{name}: {apart:e} {residual:e}"
            );
        }
    }
}
