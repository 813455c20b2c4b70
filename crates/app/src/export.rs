//! `tubemem export CASE.toml --format abaqus`: the same model as an Abaqus/CalculiX input deck,
//! so that users of those codes can run the identical model and compare.
//!
//! What is written (physical units: lengths × R, the shear modulus μ, pressure p = ϖ μH/R):
//! * the mesh of the run (`build_mesh`), nodes numbered from 1 in tubemem's order;
//! * elements: 4-node as `S4` shells of the case's thickness H (the default; `--element m3d4`
//!   for membranes), 9-node as Abaqus `M3D9` membranes (CalculiX has no 9-node shell or
//!   membrane: such a deck is for Abaqus);
//! * the material: neo-Hookean `C10 = μ/2`, Mooney–Rivlin `C10 = μ/2, C01 = αμ/2` (tubemem's
//!   eq. 83: W = (μ/2)[(I1 − 3) + α(I2 − 3)]), with `D1 = 2/K`, K = `bulk_ratio` × μ(1 + α)
//!   (default 1000: nearly incompressible; CalculiX expands shells into solids, which need a bulk
//!   modulus, and the thickness stretch then differs from 1/(λ1λ2) by about μ/K of the strain.
//!   Measured with CalculiX 2.20 on the 64-around neo-Hookean tube of scripts/bench-vs-calculix.sh:
//!   K/μ = 1e3 gives mid-span errors λs +1.3e-4, λz +2.3e-4 against the exact tube in 10.6 s,
//!   1e5 gives −3.4e-4, −6.9e-5 in 28 s, and 1e4 stops at 96 % of the load: the choice moves
//!   CalculiX's errors by more than its mesh does);
//!   the Anssari-Benam–Bucchi law is not in those codes and is refused;
//! * the symmetry conditions of the reduced model: on the plane x_a = 0 the displacement u_a
//!   and (shells) the rotations about the two other axes, plus tubemem's own pins of rigid
//!   modes (every dof that tubemem fixes is fixed);
//! * one `*STEP, NLGEOM` per inflation stage with the follower pressure (`*DLOAD … P`, negative:
//!   Abaqus's positive shell pressure acts against the element normal, and tubemem's normals
//!   point out), ramped over the stage's number of increments; a stretch target becomes the
//!   GPS pressure of that stretch (eq. 66), as pressure control;
//! * node sets MIDSPAN (the ring at z = 0) and NEXT (the ring of the next element row above it),
//!   printed (`*NODE PRINT`) at the end of each step, for the mid-span λs and λz.
//!
//! Refused, with the reason: rigid-plug caps, squeeze and confine stages (closed gas and rigid
//! plates: CalculiX has no fluid cavity), volume-ratio targets and arc-length control (neither
//! code's pressure-controlled *STATIC follows them; Abaqus's *STATIC, RIKS is not exported).

use crate::case::{Caps, Case, Kind, Target};
use crate::run::build_mesh;
use std::fmt::Write as _;
use thiserror::Error;
use tubemem_material::MaterialSpec;
use tubemem_mesh::{ElementKind, Mesh};

/// Why a case cannot be exported.
#[derive(Debug, Error)]
pub enum ExportError {
    #[error("{0}")]
    Unsupported(String),
    #[error(transparent)]
    App(#[from] crate::AppError),
    #[error("the GPS pressure of stage {stage}'s target stretch")]
    Gps {
        stage: usize,
        #[source]
        source: tubemem_gps::GpsError,
    },
}

/// The element written for the 4-node element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShellChoice {
    /// S4 shells of thickness H (the default)
    S4,
    /// M3D4 membranes of thickness H
    M3d4,
}

/// The Abaqus/CalculiX input deck of `case` (`label` names it in the heading).
///
/// Its length: the deck is written in order, section after section (heading, nodes, elements,
/// sets, symmetry conditions, material, one step per stage), each a few lines.
pub fn abaqus_deck(
    case: &Case,
    label: &str,
    shell: ShellChoice,
    bulk_ratio: f64,
) -> Result<String, ExportError> {
    if !(bulk_ratio.is_finite() && bulk_ratio > 0.0) {
        return Err(ExportError::Unsupported(format!(
            "the bulk modulus ratio K/μ = {bulk_ratio} must be finite and > 0"
        )));
    }
    let unsupported = |s: String| Err(ExportError::Unsupported(s));
    let g = &case.geometry;
    if g.caps == Caps::RigidPlug {
        return unsupported(
            "rigid-plug caps are not exported (they are a tied rigid disc with an axial degree of freedom; use caps = \"hemisphere\")".into(),
        );
    }
    // μ the case's shear modulus (ϖ = pR/(μH)), μ(1 + α) the small-strain one
    let (mu, c10, c01, mu_small) = match &case.material {
        &MaterialSpec::NeoHookean { shear_modulus } => {
            (shear_modulus, 0.5 * shear_modulus, 0.0, shear_modulus)
        }
        &MaterialSpec::MooneyRivlin {
            shear_modulus,
            alpha,
        } => (
            shear_modulus,
            0.5 * shear_modulus,
            0.5 * alpha * shear_modulus,
            shear_modulus * (1.0 + alpha),
        ),
        MaterialSpec::Abb { .. } => {
            return unsupported(
                "the Anssari-Benam–Bucchi law is not a material of Abaqus or CalculiX: export a neo-Hookean or Mooney–Rivlin case (or write it as a user material, *USER MATERIAL / UMAT, yourself)".into(),
            )
        }
        other => {
            return unsupported(format!(
                "the {} law is not exported yet: export writes neo-Hookean and Mooney–Rivlin materials",
                other.model()
            ))
        }
    };
    let law = case
        .material
        .build()
        .map_err(|e| crate::AppError::from(crate::case::CaseError::Material(e)))?;
    let mut pressures = Vec::new();
    for (i, plan) in case.plan().iter().enumerate() {
        let stage = i + 1;
        let kind = match case.stages[i].kind {
            Kind::Inflate => None,
            Kind::Squeeze => Some("squeeze"),
            Kind::Confine => Some("confine"),
        };
        if let Some(kind) = kind {
            return unsupported(format!(
                "stage {stage} ({kind}): closed gas and rigid planes are not exported (CalculiX has no fluid cavity); export the inflation stages alone"
            ));
        }
        if plan.arc_length {
            return unsupported(format!(
                "stage {stage}: arc-length control is not exported (CalculiX's *STATIC cannot follow it; Abaqus would need *STATIC, RIKS)"
            ));
        }
        let w = match plan.target {
            Target::Pressure(w) => w,
            Target::Stretch(ls) => {
                tubemem_gps::inflate(law.as_ref(), tubemem_gps::Hypothesis::Gps, ls)
                    .map_err(|source| ExportError::Gps { stage, source })?
                    .w
            }
            Target::VolumeRatio(_) => {
                return unsupported(format!(
                    "stage {stage}: a volume-ratio target is not exported (neither code's pressure-controlled *STATIC can hold a volume); give target_pressure or target_stretch"
                ))
            }
            Target::Rho(_) | Target::Confine(_) => {
                return unsupported(format!(
                    "stage {stage}: only inflation targets are exported"
                ))
            }
        };
        pressures.push((w, plan.steps));
    }
    let mesh = build_mesh(case)?;
    let r = g.radius;
    // without [units] the deck is dimensionless like the run: H = 1 (ϖ = pR/(μH) and the
    // forces over πμH do not depend on it)
    let h = g.thickness.unwrap_or(1.0);
    let p_scale = mu * h / r;
    let mut s = String::new();
    let _ = writeln!(s, "*HEADING");
    let _ = writeln!(
        s,
        "tubemem export of {label}: {} elements ({}), symmetry {:?}, L/R = {}",
        mesh.quads.len(),
        mesh.element().name(),
        mesh.symmetry,
        g.length / g.radius
    );
    let _ = writeln!(s, "** units: lengths in the case's unit (R = {r}), stress μ = {mu}, pressure p = ϖ μH/R = ϖ × {p_scale:e}");
    s.push_str("*NODE, NSET=NALL\n");
    for (i, p) in mesh.nodes.iter().enumerate() {
        let _ = writeln!(
            s,
            "{}, {:.12e}, {:.12e}, {:.12e}",
            i + 1,
            p[0] * r,
            p[1] * r,
            p[2] * r
        );
    }
    let (etype, shell_dofs) = match (mesh.element(), shell) {
        (ElementKind::Quad4, ShellChoice::S4) => ("S4", true),
        (ElementKind::Quad4, ShellChoice::M3d4) => ("M3D4", false),
        (ElementKind::Quad9, _) => ("M3D9", false),
    };
    if mesh.element() == ElementKind::Quad9 {
        s.push_str("** M3D9 is an Abaqus element; CalculiX has no 9-node shell or membrane\n");
    }
    let _ = writeln!(s, "*ELEMENT, TYPE={etype}, ELSET=EALL");
    for e in 0..mesh.quads.len() {
        let nodes: Vec<String> = mesh
            .element_nodes(e)
            .iter()
            .map(|i| (i + 1).to_string())
            .collect();
        let _ = writeln!(s, "{}, {}", e + 1, nodes.join(", "));
    }
    for (name, z) in [("MIDSPAN", 0.0), ("NEXT", next_ring_height(&mesh))] {
        let ring: Vec<usize> = (0..mesh.nodes.len())
            .filter(|&i| {
                (mesh.nodes[i][2] - z).abs() <= 1e-9 * mesh.scale()
                    && (mesh.nodes[i][0].hypot(mesh.nodes[i][1]) - 1.0).abs() <= 1e-9
            })
            .collect();
        let _ = writeln!(s, "*NSET, NSET={name}");
        for chunk in ring.chunks(16) {
            let ids: Vec<String> = chunk.iter().map(|i| (i + 1).to_string()).collect();
            let _ = writeln!(s, "{}", ids.join(", "));
        }
    }
    s.push_str("*MATERIAL, NAME=RUBBER\n*HYPERELASTIC, MOONEY-RIVLIN\n");
    let d1 = 2.0 / (bulk_ratio * mu_small);
    let _ = writeln!(s, "{c10:e}, {c01:e}, {d1:e}");
    let _ = writeln!(
        s,
        "*{} SECTION, ELSET=EALL, MATERIAL=RUBBER\n{h:e}",
        if shell_dofs { "SHELL" } else { "MEMBRANE" }
    );
    // every dof tubemem fixes (symmetry planes and the pins of rigid modes), and for shells the
    // rotations that a symmetry plane forbids (about the two axes in the plane)
    let dofs = tubemem_fem::dofs::DofMap::new(&mesh);
    let on: Vec<Vec<bool>> = (0..3).map(|ax| mesh.on_plane(ax)).collect();
    s.push_str("*BOUNDARY\n");
    for (i, _) in mesh.nodes.iter().enumerate() {
        for k in 0..3 {
            if dofs.eq(i, k).is_none() {
                let _ = writeln!(s, "{}, {}, {}", i + 1, k + 1, k + 1);
            }
        }
        if shell_dofs {
            for &ax in mesh.symmetry.planes() {
                if on[ax][i] {
                    for rot in (0..3).filter(|&b| b != ax) {
                        let _ = writeln!(s, "{}, {}, {}", i + 1, rot + 4, rot + 4);
                    }
                }
            }
        }
    }
    for (k, (w, steps)) in pressures.iter().enumerate() {
        let inc = 1.0 / *steps as f64;
        let _ = writeln!(s, "** stage {}: ϖ = {w:.12}", k + 1);
        let _ = writeln!(
            s,
            "*STEP, NLGEOM, INC=1000\n*STATIC\n{inc:e}, 1.0, {:e}, {inc:e}",
            inc * 1e-4
        );
        // the total load of the step (Abaqus ramps it over the step)
        let _ = writeln!(s, "*DLOAD\nEALL, P, {:.12e}", w * p_scale);
        s.push_str("*NODE PRINT, NSET=MIDSPAN\nU\n*NODE PRINT, NSET=NEXT\nU\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n");
    }
    Ok(s)
}

/// The reference height of the first ring of element corners above z = 0 on the cylinder.
fn next_ring_height(mesh: &Mesh) -> f64 {
    let tol = 1e-9 * mesh.scale();
    mesh.quads
        .iter()
        .flatten()
        .map(|&i| mesh.nodes[i])
        .filter(|p| p[2] > tol && (p[0].hypot(p[1]) - 1.0).abs() <= 1e-9)
        .map(|p| p[2])
        .fold(f64::INFINITY, f64::min)
}
