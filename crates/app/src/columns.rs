//! The column dictionary: every column of the CSV files a run writes, with its meaning, in one
//! place. The headers the writers use ([`STEPS_HEADER`], …) live here beside their meanings, and
//! a test holds each header to its dictionary name by name; `tubemem columns` prints the
//! dictionary (the book's reference page is generated from it).
//!
//! Quantities are dimensionless unless a column says otherwise: R = 1, μH = 1, ϖ = pR/(μH),
//! resultants N/(μH), force = plate force per unit length/(πμH) (the paper's eqs. 67 and 80).

/// One column: its name in the file's header and what it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column {
    pub name: &'static str,
    pub meaning: &'static str,
}

/// One file's columns.
#[derive(Clone, Copy, Debug)]
pub struct Table {
    /// the file, relative to the run folder
    pub file: &'static str,
    /// when it is written and what one row is
    pub about: &'static str,
    /// its header, as written
    pub header: &'static str,
    /// every column of the header, in order
    pub columns: &'static [Column],
}

const fn c(name: &'static str, meaning: &'static str) -> Column {
    Column { name, meaning }
}

/// The columns of steps.csv. New columns are only ever appended.
pub const STEPS_HEADER: &str = "stage,step,w,lambda_s,lambda_z,n_s,n_z,n_sz,volume,newton_iterations,negative_pivots,rho,chi,chi_geometric,force,displacement,contact_pressure,penetration,\
gps_w,gps_lambda_s,gps_lambda_z,gps_chi,gps_force,local_lambda_s,local_lambda_z,local_chi,local_force,\
arc_length,dw_ds,critical,nonuniformity,gps_applicable,negative_pivots_volume,\
augmentations,augmentation_iterations,contact_gap,multiplier_change,flat_pressure_deviation,\
mesh_refits,plate_force,stiffness,gps_stiffness,plate_stiffness";

/// The SI columns steps.csv adds after [`STEPS_HEADER`] with `[units] system = "SI"`: the
/// mid-span pressure p = ϖ μH/R, the resultants n μH, in a squeeze the plate force per
/// length force · πμH and the plates' half-gap ρR, then the total force on one plate, and
/// GPS's pressure and force per length at the step.
pub const SI_HEADER: &str = "pressure_pa,n_s_n_per_m,n_z_n_per_m,force_n_per_m,half_gap_m,plate_force_n,gps_pressure_pa,gps_force_n_per_m,stiffness_pa,gps_stiffness_pa,plate_stiffness_n_per_m";

/// The columns of critical_points.csv (`kind`: 1 pressure maximum, −1 pressure minimum, 2
/// bifurcation, as steps.csv's `critical`).
pub const CRITICAL_HEADER: &str = "stage,step,kind,arc_length,bracket,w,lambda_s,lambda_z,volume,negative_pivots_before,negative_pivots_after,reference_w,reference_lambda_s,polygon_factor,w_error_over_polygon,mode_eigenvalue";

/// The columns of iterations.csv (`[output] iterations = true`): one row per Newton
/// linearization; `row` is the steps.csv row of the step they led to.
pub const ITERATIONS_HEADER: &str =
    "row,stage,step,iteration,assembly_s,line_search_s,factorization_s,solve_s,residual,negative_pivots,factorized,krylov_iterations";

/// The columns of fronts.csv: one line per bulge front per step.
pub const FRONTS_HEADER: &str = "row,stage,step,w,volume,front,z_ref";

/// The columns of a stage-end profile (one row per ring).
pub const PROFILE_HEADER: &str =
    "z_ref,z,radius,lambda_s,lambda_z,n_s,n_z,n_sz,contact_width,contact_force";

/// The columns of profiles.csv: the step's row in steps.csv, its stage and step, then
/// [`PROFILE_HEADER`].
pub const PROFILES_HEADER: &str =
    "row,stage,step,z_ref,z,radius,lambda_s,lambda_z,n_s,n_z,n_sz,contact_width,contact_force";

/// The columns of walls.csv (confine stages).
pub const WALLS_HEADER: &str = "row,stage,step,wall,contact_length,force,penetration,gps_contact_length,gps_force,local_contact_length,local_force";

const ROW: Column = c(
    "row",
    "the step's row in steps.csv (1 = the first data row)",
);
const STAGE: Column = c("stage", "the stage, from 1 in the case file's order");
const STEP: Column = c("step", "the converged step within its stage, from 1");

const RING: [Column; 10] = [
    c("z_ref", "the ring's reference height Z (R), 0 at mid-span"),
    c("z", "its current mean height"),
    c("radius", "its current mean radius (R)"),
    c(
        "lambda_s",
        "hoop stretch: the ring polygon's current length over its reference length",
    ),
    c("lambda_z", "axial stretch: the mean stretch of the meridian edges leaving the ring"),
    c("n_s", "hoop resultant tᵀNt per μH, averaged over the Gauss points of the elements touching the ring"),
    c("n_z", "axial resultant aᵀNa per μH"),
    c("n_sz", "in-plane shear resultant tᵀNa per μH"),
    c(
        "contact_width",
        "the ring's geometric contact width against the plates, c/(πR), all symmetry copies (0 without plates)",
    ),
    c(
        "contact_force",
        "the plate force per unit length at the ring over πμH, as the mid-span `force` (0 without plates)",
    ),
];

const PROFILES_COLUMNS: [Column; 13] = [
    ROW, STAGE, STEP, RING[0], RING[1], RING[2], RING[3], RING[4], RING[5], RING[6], RING[7],
    RING[8], RING[9],
];

const STEPS_COLUMNS: [Column; 43] = [
    STAGE,
    STEP,
    c("w", "reduced mid-span pressure ϖ = pR/(μH) (eq. 67)"),
    c("lambda_s", "mid-span hoop stretch λs: the Z = 0 ring polygon's length over its reference length (eq. 57)"),
    c("lambda_z", "mid-span axial stretch λz: the mean stretch of the meridian edges leaving the Z = 0 ring"),
    c("n_s", "mid-span hoop resultant N_s/(μH)"),
    c("n_z", "mid-span axial resultant N_z/(μH)"),
    c("n_sz", "mid-span in-plane shear resultant N_sz/(μH) (0 for a uniform tube)"),
    c("volume", "the enclosed volume over the reference volume"),
    c("newton_iterations", "Newton iterations of the step (all augmentations' solves)"),
    c(
        "negative_pivots",
        "negative pivots of the stiffness's LDLᵀ at the converged state (under pressure control for arc-length stages): 0 means stable",
    ),
    c("rho", "squeeze: the plates' half-gap ρ over R (empty for inflation rows)"),
    c(
        "chi",
        "squeeze: contact width χ = c/(πR), c = ∫p_c ds/ϖ at mid-span, from the contact-pressure distribution",
    ),
    c("chi_geometric", "squeeze: the width of the ring's penetrated part over πR (only O(h) accurate)"),
    c("force", "squeeze: the plate force per unit length at mid-span over πμH, the FE counterpart of ϖχ (eq. 80)"),
    c("displacement", "squeeze: the plate displacement λs* − ρ (eq. 81)"),
    c(
        "contact_pressure",
        "squeeze: the mean contact pressure per current area at the contact points of the elements next to Z = 0 (GPS: ϖ on the flat zone)",
    ),
    c("penetration", "squeeze: the largest penetration of a plate anywhere (R)"),
    c("gps_w", "GPS at the step: ϖ (inflation rows: at the FE's λs; squeeze rows: at the FE's ρ)"),
    c("gps_lambda_s", "GPS at the step: λs"),
    c("gps_lambda_z", "GPS at the step: λz"),
    c("gps_chi", "GPS at the step: χ (squeeze rows)"),
    c("gps_force", "GPS at the step: the force per length over πμH (squeeze rows)"),
    c("local_lambda_s", "the GPS section under the FE's own mid-span pressure: λs (squeeze rows)"),
    c("local_lambda_z", "the GPS section under the FE's own pressure: λz"),
    c("local_chi", "the GPS section under the FE's own pressure: χ"),
    c("local_force", "the GPS section under the FE's own pressure: force per length over πμH"),
    c("arc_length", "arc-length stages: the path's arc length from the stage start (scaled norm)"),
    c(
        "dw_ds",
        "arc-length stages: dλ/ds of the unit tangent, λ the stage's load parameter (ϖ; the plates' half-gap; a confine stage's t)",
    ),
    c(
        "critical",
        "a critical point located between the previous step and this one: 1 maximum of λ, −1 minimum, 2 bifurcation, 3 neutral mode (empty: none)",
    ),
    c("nonuniformity", "the largest |λs(Z)/λs(0) − 1| over the central half of the cylinder"),
    c(
        "gps_applicable",
        "1 where the tube is uniform to 1 % over its central half (the closed-form columns describe it), else 0",
    ),
    c(
        "negative_pivots_volume",
        "arc-length stages: negative pivots under volume control (the closed tube's stability)",
    ),
    c("augmentations", "augmented contact: the multiplier updates of the step"),
    c("augmentation_iterations", "augmented contact: the Newton iterations of the updates after the first solve"),
    c("contact_gap", "augmented contact: the largest penetration left at the step's end (R)"),
    c("multiplier_change", "augmented contact: the last update's largest multiplier change"),
    c(
        "flat_pressure_deviation",
        "the largest |p_c/ϖ − 1| over the flat zone's interior next to Z = 0 (empty: no element wholly in contact)",
    ),
    c("mesh_refits", "edge-tracked contact: the mesh moves and re-solves of the step"),
    c(
        "plate_force",
        "squeeze: the total force on one plate (the whole tube, caps included, all symmetry copies) over μHR: the integral of the contact pressure over the plate",
    ),
    c(
        "stiffness",
        "squeeze rows after a stage's first: the plates' effective stiffness −Δforce/Δgap over the step, the gap 2ρ (R), force per length over πμH: in πμH/R",
    ),
    c(
        "gps_stiffness",
        "the same from GPS's force at the step and the one before (the same two plate positions)",
    ),
    c(
        "plate_stiffness",
        "squeeze rows after a stage's first: −Δplate_force/Δgap over the step, the whole tube's force on one plate: in μH",
    ),
];

const SI_COLUMNS: [Column; 11] = [
    c(
        "pressure_pa",
        "with [units] system = \"SI\": the mid-span pressure p = ϖμH/R (Pa)",
    ),
    c("n_s_n_per_m", "with SI units: N_s (N/m)"),
    c("n_z_n_per_m", "with SI units: N_z (N/m)"),
    c(
        "force_n_per_m",
        "with SI units, squeeze rows: the plate force per length, force·πμH (N/m)",
    ),
    c(
        "half_gap_m",
        "with SI units, squeeze rows: the plates' half-gap ρR (m)",
    ),
    c(
        "plate_force_n",
        "with SI units, squeeze rows: the total force on one plate, plate_force·μHR (N)",
    ),
    c(
        "gps_pressure_pa",
        "with SI units: GPS's pressure at the step, gps_w·μH/R (Pa)",
    ),
    c(
        "gps_force_n_per_m",
        "with SI units, squeeze rows: GPS's plate force per length, gps_force·πμH (N/m)",
    ),
    c(
        "stiffness_pa",
        "with SI units: stiffness·πμH/R, the force per length's −ΔF/Δgap (N/m per m of gap: Pa)",
    ),
    c(
        "gps_stiffness_pa",
        "with SI units: gps_stiffness·πμH/R (Pa)",
    ),
    c(
        "plate_stiffness_n_per_m",
        "with SI units: plate_stiffness·μH, the total plate force's −ΔF/Δgap (N/m)",
    ),
];

const CRITICAL_COLUMNS: [Column; 16] = [
    STAGE,
    c("step", "the point lies between the stage's converged steps step − 1 and step"),
    c("kind", "1 pressure maximum, −1 pressure minimum, 2 bifurcation, 3 neutral mode"),
    c("arc_length", "the point's arc length from the stage start"),
    c("bracket", "the final bracket on the arc length (≤ 1e-8 when located)"),
    c("w", "ϖ at the point"),
    c("lambda_s", "mid-span λs at the point"),
    c("lambda_z", "mid-span λz at the point"),
    c("volume", "the volume ratio at the point"),
    c("negative_pivots_before", "negative pivots under pressure control before the point"),
    c("negative_pivots_after", "negative pivots under pressure control after the point"),
    c(
        "reference_w",
        "the closed form the point is compared with: GPS's limit point, or Maxwell's pressure for a mid-span inside a bulge",
    ),
    c("reference_lambda_s", "the closed form's λs at that point"),
    c("polygon_factor", "the mesh's polygon factor 1/cos(π/n)"),
    c("w_error_over_polygon", "ϖ over the reference divided by the polygon factor, minus one"),
    c("mode_eigenvalue", "a bifurcation: the eigenvalue of K nearest zero at the point"),
];

const ITERATIONS_COLUMNS: [Column; 12] = [
    ROW,
    STAGE,
    STEP,
    c("iteration", "the Newton iteration within the step, from 1"),
    c("assembly_s", "seconds assembling the residual and tangent"),
    c("line_search_s", "seconds in the line search"),
    c(
        "factorization_s",
        "seconds in the sparse LDLᵀ factorization (0 where the factor was reused)",
    ),
    c("solve_s", "seconds in the triangular solves (or the GMRES solves with a reused factor)"),
    c("residual", "the relative residual after the iteration"),
    c(
        "negative_pivots",
        "negative pivots of the factorized tangent (where the factor was reused: of the tangent it was made from)",
    ),
    c(
        "factorized",
        "1 where the iteration factorized its tangent, 0 where it reused an earlier factor ([solver] refactorize)",
    ),
    c(
        "krylov_iterations",
        "GMRES iterations of the solves with a reused factor (0 where it factorized)",
    ),
];

const FRONTS_COLUMNS: [Column; 7] = [
    ROW,
    STAGE,
    STEP,
    c("w", "ϖ at the step"),
    c("volume", "the volume ratio at the step"),
    c("front", "the front's number, counted from the lowest Z"),
    c(
        "z_ref",
        "the front's reference height: where λs crosses halfway between its extremes and flattens on both sides",
    ),
];

const WALLS_COLUMNS: [Column; 11] = [
    ROW,
    STAGE,
    STEP,
    c("wall", "the wall, from 1 in the case's order"),
    c(
        "contact_length",
        "the FE's mid-span contact length on the wall (R)",
    ),
    c(
        "force",
        "the FE's force per unit length on the wall over πμH",
    ),
    c("penetration", "the wall's largest penetration anywhere (R)"),
    c(
        "gps_contact_length",
        "GPS for the same walls: the contact length",
    ),
    c(
        "gps_force",
        "GPS for the same walls: the force per length over πμH",
    ),
    c(
        "local_contact_length",
        "the GPS section under the FE's own pressure: the contact length",
    ),
    c(
        "local_force",
        "the GPS section under the FE's own pressure: the force per length over πμH",
    ),
];

/// Every CSV file a run writes, with its columns.
pub const TABLES: [Table; 7] = [
    Table {
        file: "steps.csv",
        about: "one row per converged step, flushed as the run goes; squeeze columns are empty for inflation rows; with `[units] system = \"SI\"` the SI columns follow",
        header: STEPS_HEADER,
        columns: &STEPS_COLUMNS,
    },
    Table {
        file: "steps.csv (SI columns)",
        about: "appended after the columns above with `[units] system = \"SI\"`",
        header: SI_HEADER,
        columns: &SI_COLUMNS,
    },
    Table {
        file: "profiles/stageN_final.csv",
        about: "the profile along the tube at each stage end, one row per ring (cylinder and cap equators)",
        header: PROFILE_HEADER,
        columns: &RING,
    },
    Table {
        file: "profiles/profiles.csv",
        about: "the profile at every converged step, in long form (`[output] profiles = \"stage-end\"` turns it off)",
        header: PROFILES_HEADER,
        columns: &PROFILES_COLUMNS,
    },
    Table {
        file: "walls.csv",
        about: "confine stages: each wall at every step",
        header: WALLS_HEADER,
        columns: &WALLS_COLUMNS,
    },
    Table {
        file: "critical_points.csv",
        about: "arc-length stages: every located critical point",
        header: CRITICAL_HEADER,
        columns: &CRITICAL_COLUMNS,
    },
    Table {
        file: "fronts.csv",
        about: "at every step with a bulge (λs varying by more than 10 % along the tube): its fronts, one row each",
        header: FRONTS_HEADER,
        columns: &FRONTS_COLUMNS,
    },
];

/// `[output] iterations = true`: iterations.csv's columns.
pub const ITERATIONS_TABLE: Table = Table {
    file: "iterations.csv",
    about: "with `[output] iterations = true`: one row per Newton linearization (a resumed run trims the rows past its checkpoint)",
    header: ITERATIONS_HEADER,
    columns: &ITERATIONS_COLUMNS,
};

/// Every table: [`TABLES`] and [`ITERATIONS_TABLE`].
pub fn all_tables() -> Vec<Table> {
    let mut v = TABLES.to_vec();
    v.push(ITERATIONS_TABLE);
    v
}

/// The dictionary as Markdown: a section per file, a table of its columns.
pub fn markdown() -> String {
    let mut s = String::new();
    for t in all_tables() {
        s.push_str(&format!("## `{}`\n\n{}.\n\n", t.file, capitalize(t.about)));
        s.push_str("| column | meaning |\n|---|---|\n");
        for col in t.columns {
            s.push_str(&format!(
                "| `{}` | {} |\n",
                col.name,
                col.meaning.replace('|', "\\|")
            ));
        }
        s.push('\n');
    }
    s
}

fn capitalize(s: &str) -> String {
    let mut ch = s.chars();
    match ch.next() {
        Some(f) => f.to_uppercase().chain(ch).collect(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_header_column_has_its_meaning_in_order() {
        for t in all_tables() {
            let names: Vec<&str> = t.columns.iter().map(|c| c.name).collect();
            let header: Vec<&str> = t.header.split(',').collect();
            assert_eq!(names, header, "{}", t.file);
            assert!(
                t.columns.iter().all(|c| !c.meaning.is_empty()),
                "{}",
                t.file
            );
        }
    }
}
