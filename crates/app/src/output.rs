//! The run writer: an [`Observer`] that turns the report into files as the run goes.
//!
//! * `steps.csv`: one row per converged step, flushed at once ([`STEPS_HEADER`]);
//! * `vtu/step_NNNNN.vtu` + `tube.pvd`: a frame per step (frame 0 is the reference state); the
//!   PVD timestep is the load path: stage − 1 + the fraction of the stage done;
//! * `profiles/stageN_final.csv`: the profile along the tube at each stage end;
//! * `walls.csv`: confine stages, each wall at every step ([`WALLS_HEADER`]);
//! * `profiles/profiles.csv`: the profile at every converged step ([`PROFILES_HEADER`]; `row`
//!   is the step's row in steps.csv), unless `[output] profiles = "stage-end"`;
//! * `summary.json`: [`RunReport::summary`], rewritten (atomically: write, then rename) after
//!   every stage and on failure, so a run that fails midway loses nothing that had converged;
//! * `run.json`: the manifest — status `running`, `finished`, `failed` or `interrupted`, the
//!   process, the case's hash, start and end times, the error — written atomically at the start,
//!   after every stage and at the end.
//!
//! The folder is the run's alone: [`RunWriter::create`] takes an exclusive lock on
//! `.tubemem.lock` (a second run into it is refused and told which process holds it; the lock
//! dies with its process), and refuses a folder that already holds a run unless told to
//! overwrite it, so frames of an earlier run can never mix with a new one.

use crate::checkpoint::{read_checkpoint, write_checkpoint, Checkpoint};
pub use crate::columns::{
    CRITICAL_HEADER, FRONTS_HEADER, ITERATIONS_HEADER, PROFILES_HEADER, PROFILE_HEADER, SI_HEADER,
    STEPS_HEADER, WALLS_HEADER,
};
use crate::observer::{BoxError, Observer, StepView};
use crate::report::{RunReport, StepRecord};
use crate::{AppError, Result};
use std::path::{Path, PathBuf};
use tubemem_fem::model::{Model, State};
use tubemem_fem::post::{cell_contact_pressure, cell_values, regime_code, RingValues};
use tubemem_mesh::vtu::{write_pvd, write_vtu, Field, FieldValue};

/// The `critical` column of steps.csv: the kind of a critical point located between the
/// previous step and this one (empty: none).
pub(crate) fn critical_code(k: tubemem_fem::continuation::CriticalKind) -> f64 {
    use tubemem_fem::continuation::CriticalKind as K;
    match k {
        K::LimitMax => 1.0,
        K::LimitMin => -1.0,
        K::Bifurcation => 2.0,
        K::Neutral => 3.0,
    }
}

/// `rows` as CSV lines.
fn csv_rows<R: AsRef<[f64]>>(rows: &[R]) -> String {
    let mut text = String::new();
    for r in rows {
        text.push_str(&crate::curves::csv_line(r.as_ref()));
        text.push('\n');
    }
    text
}

/// The values of one critical_points.csv row ([`CRITICAL_HEADER`]; NaN where one does not apply).
pub fn critical_row(r: &crate::report::CriticalRecord) -> [f64; 16] {
    let g = r.reference.as_ref();
    [
        r.stage as f64,
        r.step as f64,
        critical_code(r.kind),
        r.arc_length,
        r.bracket,
        r.midspan.w,
        r.midspan.lambda_s,
        r.midspan.lambda_z,
        r.midspan.volume,
        r.negative_pivots_before as f64,
        r.negative_pivots_after as f64,
        g.map_or(f64::NAN, |g| g.w),
        g.map_or(f64::NAN, |g| g.lambda_s),
        r.polygon_factor.unwrap_or(f64::NAN),
        r.w_error_over_polygon.unwrap_or(f64::NAN),
        r.mode_eigenvalue.unwrap_or(f64::NAN),
    ]
}

/// The rows of fronts.csv for one step ([`FRONTS_HEADER`]), `row` its row in steps.csv.
pub fn front_rows(row: usize, r: &StepRecord) -> Vec<[f64; 7]> {
    r.fronts
        .iter()
        .enumerate()
        .map(|(k, z)| {
            [
                row as f64,
                r.stage as f64,
                r.step as f64,
                r.midspan.w,
                r.midspan.volume,
                (k + 1) as f64,
                *z,
            ]
        })
        .collect()
}

/// The values of one steps.csv row, `None` for an empty field.
pub fn step_row(r: &StepRecord) -> Vec<Option<f64>> {
    let m = &r.midspan;
    let mut v: Vec<Option<f64>> = vec![
        Some(r.stage as f64),
        Some(r.step as f64),
        Some(m.w),
        Some(m.lambda_s),
        Some(m.lambda_z),
        Some(m.n_s),
        Some(m.n_z),
        Some(m.n_sz),
        Some(m.volume),
        Some(r.newton_iterations as f64),
        Some(r.negative_pivots as f64),
    ];
    match &r.contact {
        Some(c) => {
            let c0 = &c.values;
            v.extend(
                [
                    c0.rho,
                    c0.chi,
                    c0.chi_geometric,
                    c0.force,
                    c.displacement,
                    c0.contact_pressure,
                    c0.penetration,
                ]
                .map(Some),
            );
        }
        None => v.extend([None; 7]),
    }
    let cf = &r.closed_form;
    match (&cf.gps_inflation, &cf.gps_flattening) {
        (Some(s), _) => v.extend([Some(s.w), Some(s.lambda_s), Some(s.lambda_z), None, None]),
        (None, Some(g)) => v.extend([g.w, g.lambda_s, g.lambda_z, g.chi, g.force].map(Some)),
        _ => v.extend([None; 5]),
    }
    match &cf.local {
        Some(Ok(l)) => v.extend([l.lambda_s, l.lambda_z, l.chi, l.force].map(Some)),
        _ => v.extend([None; 4]),
    }
    match &r.arc {
        Some(a) => v.extend([Some(a.arc_length), Some(a.dw_ds)]),
        None => v.extend([None; 2]),
    }
    v.push(r.critical.map(critical_code));
    v.push(r.nonuniformity);
    v.push(r.gps_applicable.map(|a| f64::from(u8::from(a))));
    v.push(r.negative_pivots_volume.map(|n| n as f64));
    match &r.augmentation {
        Some(a) => v.extend([
            Some(a.updates as f64),
            Some(a.iterations as f64),
            Some(a.gap),
            Some(a.change),
        ]),
        None => v.extend([None; 4]),
    }
    v.push(
        r.contact
            .as_ref()
            .and_then(|c| c.values.flat_pressure_deviation),
    );
    v.push(r.edge_tracking.as_ref().map(|t| t.refits as f64));
    v.push(r.contact.as_ref().map(|c| c.values.total_force));
    match &r.stiffness {
        Some(k) => v.extend([Some(k.force), k.gps_force, Some(k.plate_force)]),
        None => v.extend([None; 3]),
    }
    v
}

/// steps.csv's header: [`STEPS_HEADER`], and [`SI_HEADER`] with units.
pub(crate) fn steps_header(units: bool) -> String {
    if units {
        format!("{STEPS_HEADER},{SI_HEADER}")
    } else {
        STEPS_HEADER.to_string()
    }
}

/// The [`SI_HEADER`] values of a step (empty where the step has none).
pub fn si_values(s: &tubemem_gps::Scales, r: &StepRecord) -> [Option<f64>; 11] {
    let v = crate::report::SiValues::of(s, &r.midspan, r.contact.as_ref().map(|c| &c.values));
    let cf = &r.closed_form;
    let (gps_w, gps_force) = match (&cf.gps_inflation, &cf.gps_flattening) {
        (Some(g), _) => (Some(g.w), None),
        (None, Some(g)) => (Some(g.w), Some(g.force)),
        _ => (None, None),
    };
    [
        Some(v.pressure_pa),
        Some(v.n_s_n_per_m),
        Some(v.n_z_n_per_m),
        v.force_n_per_m,
        v.half_gap_m,
        v.plate_force_n,
        gps_w.map(|w| s.pressure(w)),
        gps_force.map(|f| s.force_per_length(f)),
        r.stiffness.map(|k| s.force_per_length(k.force) / s.radius),
        r.stiffness
            .and_then(|k| k.gps_force)
            .map(|k| s.force_per_length(k) / s.radius),
        r.stiffness.map(|k| s.resultant(k.plate_force)),
    ]
}

fn si_row(s: &tubemem_gps::Scales, r: &StepRecord) -> String {
    si_values(s, r)
        .iter()
        .map(|v| v.map_or(String::new(), |x| format!("{x}")))
        .collect::<Vec<_>>()
        .join(",")
}

pub(crate) fn format_row(r: &StepRecord) -> String {
    let fields: Vec<String> = step_row(r)
        .into_iter()
        .enumerate()
        .map(|(k, v)| match (k, v) {
            // integers as integers
            (0 | 1 | 9 | 10, Some(x)) => format!("{}", x as u64),
            (29 | 31 | 32 | 33 | 34, Some(x)) => format!("{}", x as i64),
            (_, Some(x)) => format!("{x}"),
            (_, None) => String::new(),
        })
        .collect();
    fields.join(",")
}

/// The VTU field data `units` of a case in SI: what its points and fields are in.
pub const VTU_UNITS_SI: &str = "SI: points and displacement in m, n_1 and n_2 in N/m, contact_pressure in Pa; lambda_s, lambda_z and wrinkled are ratios and codes";

/// The VTU field data `units` of a dimensionless case.
pub const VTU_UNITS_DIMENSIONLESS: &str = "dimensionless: points and displacement in R, n_1 and n_2 in μH, contact_pressure in μH/R (as ϖ); lambda_s, lambda_z and wrinkled are ratios and codes";

/// What to do with an output folder that already holds a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FolderMode {
    /// refuse it
    Fresh,
    /// remove the earlier run's files (only tubemem's own) and start afresh
    Overwrite,
}

/// The entries a run writes; what `Overwrite` removes and `Fresh` refuses to find.
pub const RUN_ENTRIES: [&str; 12] = [
    "checkpoints",
    "fronts.csv",
    "iterations.csv",
    "critical_points.csv",
    "steps.csv",
    "walls.csv",
    "summary.json",
    "run.json",
    "tube.pvd",
    "vtu",
    "profiles",
    RESERVE,
];

const LOCK: &str = ".tubemem.lock";

/// The space a run holds back for its closing files: a file of [`RESERVE_BYTES`] written when
/// the run takes its folder and removed when it ends, first thing on a failure, so that a run
/// stopped by a full disk can still write its manifest and summary (issue #25, class 3).
const RESERVE: &str = ".tubemem.reserve";

/// 1 MiB: the main job's run.json is 314 bytes and its summary.json 5.2 KiB, the shipped
/// bulge's (27 steps) 3.9 KiB (2026-12-02): the summary holds each stage's end, not each step.
const RESERVE_BYTES: usize = 1 << 20;

/// Whether `name` in the run's sub-folder `folder` (`vtu`, `profiles`, `checkpoints`) is a file
/// the run writes there: the frames `step_NNNNN.vtu` and `critical_stage…_step….vtu`, the
/// profiles `profiles.csv`, `stageN_final.csv` and `stageN_midspan_ring.csv`, the checkpoints
/// `ckpt-a.bin`, `ckpt-b.bin` and `.ckpt.tmp`.
fn own_file(folder: &str, name: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    match folder {
        "vtu" => {
            name.strip_prefix("step_")
                .and_then(|r| r.strip_suffix(".vtu"))
                .is_some_and(digits)
                || name
                    .strip_prefix("critical_stage")
                    .and_then(|r| r.strip_suffix(".vtu"))
                    .and_then(|r| r.split_once("_step"))
                    .is_some_and(|(a, b)| digits(a) && digits(b))
        }
        "profiles" => {
            name == "profiles.csv"
                || name
                    .strip_prefix("stage")
                    .and_then(|r| {
                        r.strip_suffix("_final.csv")
                            .or_else(|| r.strip_suffix("_midspan_ring.csv"))
                    })
                    .is_some_and(digits)
        }
        "checkpoints" => matches!(name, "ckpt-a.bin" | "ckpt-b.bin" | ".ckpt.tmp"),
        // the run folder itself
        "" => RUN_ENTRIES.contains(&name) && !matches!(name, "vtu" | "profiles" | "checkpoints"),
        _ => false,
    }
}

/// Whether `name` in `folder` is the temporary file of one of the run's whole-file writes
/// (`.NAME.PID.tmp`, [`tubemem_mesh::file`]), left by a kill between its write and its rename.
fn own_partial(folder: &str, name: &str) -> bool {
    tubemem_mesh::file::partial_of(name).is_some_and(|stem| own_file(folder, stem))
}

/// Refuse a run folder `dir` in which one of the run's `inputs` (the case file, a user mesh
/// file) has the name of a file the run writes, replaces or removes (`DIR/summary.json` as the
/// case file): tubemem never writes over its inputs (issue #25, class 4).
fn refuse_inputs(dir: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(root) = dir.canonicalize() else {
        // a folder that does not exist yet holds no input
        return Ok(());
    };
    for input in inputs {
        let Ok(path) = input.canonicalize() else {
            continue;
        };
        let (Some(parent), Some(name)) = (path.parent(), path.file_name().and_then(|n| n.to_str()))
        else {
            continue;
        };
        let folder = if parent == root {
            Some("")
        } else {
            ["vtu", "profiles", "checkpoints"]
                .into_iter()
                .find(|f| parent == root.join(f))
        };
        if let Some(folder) = folder {
            if own_file(folder, name) || own_partial(folder, name) || name == LOCK {
                return Err(AppError::Folder {
                    path: dir.to_path_buf(),
                    message: format!(
                        "the input {} has the name of a file the run writes there: tubemem never writes over its inputs; move it, or choose another --out",
                        input.display()
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Remove the temporary files of the run's whole-file writes in the run folder `dir` and its
/// sub-folders: a kill between a write and its rename leaves one (`--resume`, `--overwrite`).
fn remove_partial_files(dir: &Path) -> Result<()> {
    for folder in ["", "vtu", "profiles", "checkpoints"] {
        let d = dir.join(folder);
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            let p = entry.path();
            if entry
                .file_name()
                .to_str()
                .is_some_and(|n| own_partial(folder, n))
                && p.is_file()
            {
                std::fs::remove_file(&p).map_err(|e| AppError::io(&p, e))?;
            }
        }
    }
    Ok(())
}

/// `--overwrite` of the run's sub-folder `path` (`folder`): remove the files the run writes
/// there, and the folder if nothing else is left; files a user put there stay (issue #25,
/// class 4: the whole folder was removed).
fn remove_own_files(path: &Path, folder: &str) -> Result<()> {
    let entries = std::fs::read_dir(path).map_err(|e| AppError::io(path, e))?;
    let mut left = false;
    for entry in entries {
        let entry = entry.map_err(|e| AppError::io(path, e))?;
        let name = entry.file_name();
        let p = entry.path();
        match name.to_str() {
            Some(n) if (own_file(folder, n) || own_partial(folder, n)) && p.is_file() => {
                std::fs::remove_file(&p).map_err(|e| AppError::io(&p, e))?;
            }
            _ => left = true,
        }
    }
    if !left {
        std::fs::remove_dir(path).map_err(|e| AppError::io(path, e))?;
    }
    Ok(())
}

/// The most VTU output a run may write: 8 GiB (the L/R = 80 case writes 30 MB; a run that
/// would pass this is asked to write fewer or smaller frames rather than fill the disk).
pub const MAX_VTU_BYTES: u64 = 8 << 30;

/// The case text's hash (kept here for the writers; it belongs to the case).
pub use crate::case::case_hash;

fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// The manifest `run.json`.
#[derive(serde::Serialize)]
struct Manifest<'a> {
    status: &'a str,
    tubemem: &'a str,
    pid: u32,
    case: &'a str,
    case_hash: &'a str,
    started_unix: f64,
    finished_unix: Option<f64>,
    stages_finished: usize,
    steps_written: usize,
    error: Option<String>,
}

/// Writes a run folder.
pub struct RunWriter {
    dir: PathBuf,
    /// the files of the step being written, undone together if one write fails
    journal: crate::journal::Journal,
    /// whether profiles.csv is written (a folder of an earlier version may lack it)
    profiles: bool,
    pvd: Vec<(f64, String)>,
    frames: usize,
    rows: usize,
    /// held for the writer's life: the folder's exclusive lock
    _lock: crate::output_file::FolderLock,
    case_hash: String,
    started: f64,
    /// continuing a run: the files are there already
    resumed: bool,
    /// a checkpoint every this many steps (0: none)
    checkpoint_every: usize,
    /// bytes of VTU written so far
    vtu_bytes: u64,
    /// which steps get a frame
    vtu: crate::case::OutputSpec,
    /// the case's unit system: the VTU's points and fields are written in it
    units: crate::units::Units,
}

impl RunWriter {
    /// Take the folder `dir` for a run of the case whose text hashes to `case_hash`
    /// ([`case_hash`]): create it, lock it, and refuse (`Fresh`) or clear (`Overwrite`) an
    /// earlier run found in it.
    pub fn create(dir: &Path, mode: FolderMode, case_hash: &str, inputs: &[&Path]) -> Result<Self> {
        let folder = |message: String| AppError::Folder {
            path: dir.to_path_buf(),
            message,
        };
        refuse_inputs(dir, inputs)?;
        crate::output_file::create_folder(dir)?;
        let mut writer = Self::create_locked(dir, case_hash)?;
        let present: Vec<&str> = RUN_ENTRIES
            .iter()
            .copied()
            .filter(|e| dir.join(e).exists())
            .collect();
        if !present.is_empty() {
            match mode {
                FolderMode::Fresh => {
                    // we hold the lock, so a manifest still saying "running" is a killed run
                    let killed = std::fs::read_to_string(dir.join("run.json"))
                        .ok()
                        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
                        .is_some_and(|m| m["status"] == "running");
                    return Err(folder(if killed {
                        "it holds a run that was killed (its manifest says running, but no process holds the folder); use --resume to continue it from its last checkpoint, --overwrite to replace it, or choose another --out".to_string()
                    } else {
                        format!(
                            "it already holds a run ({}); use --overwrite to replace it, or choose another --out",
                            present.join(", ")
                        )
                    }));
                }
                FolderMode::Overwrite => {
                    for e in present {
                        let p = dir.join(e);
                        if p.is_dir() {
                            remove_own_files(&p, e)?;
                        } else {
                            std::fs::remove_file(&p).map_err(|err| AppError::io(&p, err))?;
                        }
                    }
                }
            }
        }
        remove_partial_files(dir)?;
        writer.reserve()?;
        Ok(writer)
    }

    /// Take the folder `dir` back to continue its run: lock it, read the newest checkpoint
    /// (`checkpoints/`, the last two are kept), check that the case is the one that ran, and cut
    /// steps.csv and the VTU series back to that checkpoint (a kill may have come between a
    /// step's files and its checkpoint). Returns the writer and the checkpoint to give to
    /// [`crate::run::RunOptions::resume`].
    pub fn resume(dir: &Path, case_hash: &str, inputs: &[&Path]) -> Result<(Self, Checkpoint)> {
        let folder = |message: String| AppError::Folder {
            path: dir.to_path_buf(),
            message,
        };
        refuse_inputs(dir, inputs)?;
        if !dir.join("checkpoints").is_dir() {
            return Err(folder(
                "it holds no checkpoint to resume from (the run stopped before its first checkpoint): start it afresh with --overwrite".into(),
            ));
        }
        let mut w = Self::create_locked(dir, case_hash)?;
        let ck = ["a", "b"]
            .iter()
            .filter_map(|k| read_checkpoint(&dir.join("checkpoints").join(format!("ckpt-{k}.bin"))))
            .max_by_key(|c| c.rows)
            .ok_or_else(|| {
                // checkpoints/ exists but holds no readable checkpoint: killed while the first
                // was being written, or the files were cut or changed since
                let present: Vec<String> = ["a", "b"]
                    .iter()
                    .map(|k| dir.join("checkpoints").join(format!("ckpt-{k}.bin")))
                    .filter_map(|p| {
                        let len = std::fs::metadata(&p).ok()?.len();
                        Some(format!("{} ({len} bytes)", p.display()))
                    })
                    .collect();
                folder(if present.is_empty() {
                    "it holds no whole checkpoint to resume from (the run was killed before its first checkpoint was complete): start it afresh with --overwrite".into()
                } else {
                    format!(
                        "its checkpoint files cannot be read (truncated or changed after the run: {}): start it afresh with --overwrite",
                        present.join(", ")
                    )
                })
            })?;
        if let Some(message) = ck.mismatch(case_hash, None) {
            return Err(folder(message));
        }
        // every frame the checkpoint lists must still be there (checked before anything is
        // cut back, so a refused resume leaves the folder as it was)
        let missing: Vec<&str> = ck
            .pvd
            .iter()
            .map(|(_, f)| f.as_str())
            .filter(|f| !dir.join(f).is_file())
            .collect();
        if !missing.is_empty() {
            return Err(folder(format!(
                "{} of the {} VTU frames its checkpoint lists are missing (first: {}): the folder was changed after the run, so its series cannot be continued; start it afresh with --overwrite",
                missing.len(),
                ck.pvd.len(),
                missing[0]
            )));
        }
        // steps.csv: the header and the checkpoint's rows
        let path = dir.join("steps.csv");
        let text = std::fs::read_to_string(&path).map_err(|e| AppError::io(&path, e))?;
        let kept: Vec<&str> = text.lines().take(1 + ck.rows).collect();
        if kept.len() != 1 + ck.rows {
            return Err(folder(format!(
                "steps.csv has {} rows but the checkpoint {}",
                kept.len().saturating_sub(1),
                ck.rows
            )));
        }
        atomic_write(&path, &format!("{}\n", kept.join("\n")))?;
        // frames past the checkpoint
        for k in ck.frames.. {
            let f = dir.join("vtu").join(format!("step_{k:05}.vtu"));
            if !f.exists() {
                break;
            }
            std::fs::remove_file(&f).map_err(|e| AppError::io(&f, e))?;
        }
        write_pvd(&dir.join("tube.pvd"), &ck.pvd).map_err(AppError::Mesh)?;
        // walls.csv: the rows of the kept steps (appended to from here on)
        trim_rows(&dir.join("walls.csv"), ck.rows)?;
        // profiles.csv: the rows of the kept steps
        w.profiles = trim_rows(&dir.join("profiles").join("profiles.csv"), ck.rows)?;
        // fronts.csv, iterations.csv: the rows of the kept steps; critical_points.csv: the
        // checkpoint's points
        trim_rows(&dir.join("fronts.csv"), ck.rows)?;
        trim_rows(&dir.join("iterations.csv"), ck.rows)?;
        let path = dir.join("critical_points.csv");
        let points: Vec<[f64; 16]> = ck
            .report
            .critical_points()
            .chain(&ck.critical_points)
            .map(critical_row)
            .collect();
        if !points.is_empty() {
            atomic_write(&path, &format!("{CRITICAL_HEADER}\n{}", csv_rows(&points)))?;
        } else if path.exists() {
            std::fs::remove_file(&path).map_err(|e| AppError::io(&path, e))?;
        }
        remove_partial_files(dir)?;
        w.reserve()?;
        w.pvd = ck.pvd.clone();
        w.frames = ck.frames;
        w.rows = ck.rows;
        w.resumed = true;
        Ok((w, ck))
    }

    fn create_locked(dir: &Path, case_hash: &str) -> Result<Self> {
        let lock = crate::output_file::lock_folder(dir, LOCK)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            journal: crate::journal::Journal::default(),
            profiles: true,
            pvd: vec![],
            frames: 0,
            rows: 0,
            _lock: lock,
            case_hash: case_hash.to_string(),
            started: unix_now(),
            resumed: false,
            checkpoint_every: 1,
            vtu_bytes: 0,
            units: crate::units::Units::dimensionless(),
            vtu: crate::case::OutputSpec::default(),
        })
    }

    /// Hold back [`RESERVE_BYTES`] of the disk for the closing files ([`RESERVE`]).
    fn reserve(&mut self) -> Result<()> {
        let path = self.dir.join(RESERVE);
        tubemem_mesh::file::write_whole(&path, &vec![0u8; RESERVE_BYTES]).map_err(|e| {
            AppError::Folder {
                path: self.dir.clone(),
                message: format!(
                    "cannot hold back {} KiB for the run's closing files ({}): {e}",
                    RESERVE_BYTES >> 10,
                    path.display()
                ),
            }
        })
    }

    /// Give the reserved space back ([`RESERVE`]).
    fn release(&self) {
        let _ = std::fs::remove_file(self.dir.join(RESERVE));
    }

    /// Write a restart checkpoint every `n` converged steps (0: none; default 1).
    pub fn checkpoint_every(mut self, n: usize) -> Self {
        self.checkpoint_every = n;
        self
    }

    /// Which steps get a VTU frame (`[output]`).
    pub fn frames_of(mut self, output: crate::case::OutputSpec) -> Self {
        self.vtu = output;
        self
    }

    /// The number of steps whose files are all written (the rows of steps.csv).
    pub fn steps_written(&self) -> usize {
        self.rows
    }

    /// The number of VTU frames written.
    pub fn frames(&self) -> usize {
        self.frames
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Write a VTU frame at pseudo-time `time` (the PVD timestep: stage − 1 + the fraction of
    /// the stage done, so 0 is the reference state and k the end of stage k).
    fn frame(
        &mut self,
        time: f64,
        tag: (usize, usize, usize),
        model: &Model,
        state: &State,
        contact: Option<&tubemem_fem::contact::Contact>,
    ) -> Result<(), BoxError> {
        use crate::units::Dimension;
        let cells = cell_values(model, state)?;
        // the case's units: lengths in m and resultants in N/m under SI, R and μH otherwise
        let (length, resultant, pressure) = (
            self.units.factor(Dimension::Length),
            self.units.factor(Dimension::Resultant),
            self.units.factor(Dimension::Pressure),
        );
        let disp: Vec<f64> = state
            .x
            .iter()
            .zip(&model.mesh().nodes)
            .flat_map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]].map(|d| d * length))
            .collect();
        let pick = |f: &dyn Fn(&tubemem_fem::post::CellValues) -> f64| {
            cells.iter().map(f).collect::<Vec<f64>>()
        };
        let (hoop, axial, n1, n2) = (
            pick(&|c| c.hoop_stretch),
            pick(&|c| c.axial_stretch),
            pick(&|c| c.n1 * resultant),
            pick(&|c| c.n2 * resultant),
        );
        let wrinkled = pick(&|c| regime_code(c.regime()));
        let pc: Vec<f64> = cell_contact_pressure(model, state, contact)
            .into_iter()
            .map(|p| p * pressure)
            .collect();
        let name = format!("step_{:05}.vtu", self.frames);
        // a frame is about as large as the last one: refuse before the series passes the cap
        let last = self.vtu_bytes / (self.frames.max(1) as u64);
        if self.vtu_bytes + last > MAX_VTU_BYTES {
            return Err(Box::new(AppError::Output {
                what: format!("VTU frame {name}"),
                source: format!(
                    "the VTU series would pass {} GiB ({} frames of about {} MiB so far)",
                    MAX_VTU_BYTES >> 30,
                    self.frames,
                    last >> 20
                )
                .into(),
            }));
        }
        // `[output] mirror`: the whole tube, the model reflected across its symmetry planes
        let axes: &[usize] = if self.vtu.mirror {
            model.mesh().symmetry.planes()
        } else {
            &[]
        };
        let m = Mirror::new(axes, &model.mesh().nodes);
        let (mut points, quads) = m.geometry(&state.x, &model.mesh().cells());
        if length != 1.0 {
            points.iter_mut().for_each(|p| *p = p.map(|c| c * length));
        }
        let disp = m.vector_field(&disp);
        let cellf: Vec<Vec<f64>> = [&hoop, &axial, &n1, &n2, &wrinkled, &pc]
            .iter()
            .map(|f| m.cell_field(f))
            .collect();
        let cell = |name, values| Field {
            name,
            components: 1,
            values,
        };
        self.journal.creating(&self.dir.join("vtu").join(&name));
        write_vtu(
            &self.dir.join("vtu").join(&name),
            &points,
            &quads,
            &[Field {
                name: "displacement",
                components: 3,
                values: &disp,
            }],
            &[
                // the names of steps.csv (λs, λz), and n_1 ≥ n_2 the principal resultants
                cell("lambda_s", &cellf[0]),
                cell("lambda_z", &cellf[1]),
                cell("n_1", &cellf[2]),
                cell("n_2", &cellf[3]),
                cell("wrinkled", &cellf[4]),
                cell("contact_pressure", &cellf[5]),
            ],
            &[
                (
                    "tubemem_version",
                    FieldValue::Text(env!("CARGO_PKG_VERSION")),
                ),
                ("case_hash", FieldValue::Text(&self.case_hash)),
                // what the points and fields are in
                (
                    "units",
                    FieldValue::Text(if self.units.is_si() {
                        VTU_UNITS_SI
                    } else {
                        VTU_UNITS_DIMENSIONLESS
                    }),
                ),
                // the steps.csv row, stage and step of the frame (0, 0, 0: the reference state)
                ("steps_csv_row", FieldValue::Numbers(&[tag.0 as f64])),
                ("stage", FieldValue::Numbers(&[tag.1 as f64])),
                ("step", FieldValue::Numbers(&[tag.2 as f64])),
            ],
            match self.vtu.vtu_format {
                crate::case::VtuFormat::Binary => tubemem_mesh::vtu::Encoding::Binary,
                crate::case::VtuFormat::Ascii => tubemem_mesh::vtu::Encoding::Ascii,
            },
        )?;
        self.vtu_bytes += std::fs::metadata(self.dir.join("vtu").join(&name))
            .map(|m| m.len())
            .unwrap_or(0);
        self.pvd.push((time, format!("vtu/{name}")));
        self.frames += 1;
        write_pvd(&self.dir.join("tube.pvd"), &self.pvd)?;
        Ok(())
    }

    fn write_manifest(
        &self,
        report: &RunReport,
        status: &str,
        error: Option<String>,
    ) -> Result<()> {
        let finished = report
            .stages
            .iter()
            .filter(|s| matches!(s.outcome, crate::report::StageOutcome::Finished(_)))
            .count();
        let m = Manifest {
            status,
            tubemem: env!("CARGO_PKG_VERSION"),
            pid: std::process::id(),
            case: &report.case,
            case_hash: &self.case_hash,
            started_unix: self.started,
            finished_unix: (status != "running").then(unix_now),
            stages_finished: finished,
            steps_written: self.rows,
            error,
        };
        let text = serde_json::to_string_pretty(&m).map_err(|e| AppError::Output {
            what: "run.json".into(),
            source: Box::new(e),
        })?;
        atomic_write(&self.dir.join("run.json"), &text)
    }

    fn write_summary(&self, report: &RunReport) -> Result<()> {
        self.write_summary_with(report, None)
    }

    /// summary.json; `error`, when given, goes in as a top-level `error` (a failure that no stage
    /// records: the mesh, the model, the memory guard, an interrupt between stages).
    fn write_summary_with(&self, report: &RunReport, error: Option<String>) -> Result<()> {
        let path = self.dir.join("summary.json");
        let fail = |e: serde_json::Error| AppError::Output {
            what: path.display().to_string(),
            source: Box::new(e),
        };
        let mut value = serde_json::to_value(report.summary()).map_err(fail)?;
        if let (Some(e), Some(obj)) = (error, value.as_object_mut()) {
            obj.insert("error".into(), serde_json::Value::String(e));
        }
        let text = serde_json::to_string_pretty(&value).map_err(fail)?;
        atomic_write(&path, &text)
    }
}

/// Write `text` as the whole of `path` ([`crate::output_file::write_whole`]).
fn atomic_write(path: &Path, text: &str) -> Result<()> {
    crate::output_file::write_whole(path, text.as_bytes())
}

/// The reflections that make the whole tube of a symmetry-reduced model: every combination of
/// the mirror planes' axes (2^k copies). A copy reflected an odd number of times has its quads'
/// node order reversed, so that every normal still points out. Nodes on a plane appear once per
/// copy (ParaView's "Clean" merges them).
struct Mirror {
    /// per copy: the sign of each coordinate
    signs: Vec<[f64; 3]>,
    /// the points written, as (copy, node): a node on a symmetry plane only in the first copy
    /// that reaches it (its mirror image is itself)
    points: Vec<(usize, usize)>,
    /// per copy, per node: its point
    index: Vec<Vec<usize>>,
}

impl Mirror {
    /// The copies of a model with the nodes `reference` reflected across the planes x_ax = 0
    /// of `axes`; a node on a plane (|x_ax| ≤ 1e-12 of the model's size) is one point.
    fn new(axes: &[usize], reference: &[[f64; 3]]) -> Self {
        let mut signs = vec![[1.0; 3]];
        for &ax in axes {
            let reflected: Vec<[f64; 3]> = signs
                .iter()
                .map(|s| {
                    let mut t = *s;
                    t[ax] = -t[ax];
                    t
                })
                .collect();
            signs.extend(reflected);
        }
        let size = reference
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-300);
        let mut points = vec![];
        let mut index = vec![vec![0; reference.len()]; signs.len()];
        for (k, s) in signs.iter().enumerate() {
            for (i, x) in reference.iter().enumerate() {
                // the copy whose image of this node is the same point: the signs with every
                // plane the node lies on unflipped
                let mut canonical = *s;
                for &ax in axes {
                    if x[ax].abs() <= 1e-12 * size {
                        canonical[ax] = 1.0;
                    }
                }
                let first = signs.iter().position(|t| *t == canonical).unwrap_or(k);
                index[k][i] = if first < k {
                    index[first][i]
                } else {
                    points.push((k, i));
                    points.len() - 1
                };
            }
        }
        Self {
            signs,
            points,
            index,
        }
    }

    fn geometry(&self, x: &[[f64; 3]], quads: &[Vec<usize>]) -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
        let points = self
            .points
            .iter()
            .map(|&(k, i)| {
                let (s, p) = (self.signs[k], x[i]);
                [s[0] * p[0], s[1] * p[1], s[2] * p[2]]
            })
            .collect();
        let mut cells = Vec::with_capacity(quads.len() * self.signs.len());
        for (k, s) in self.signs.iter().enumerate() {
            let flip = s.iter().filter(|v| **v < 0.0).count() % 2 == 1;
            // a reflected 9-node cell keeps its mid-side nodes on the matching edges
            const FLIP4: [usize; 4] = [0, 3, 2, 1];
            const FLIP9: [usize; 9] = [0, 3, 2, 1, 7, 6, 5, 4, 8];
            cells.extend(quads.iter().map(|q| {
                let order: &[usize] = match (flip, q.len()) {
                    (false, _) => &[0, 1, 2, 3, 4, 5, 6, 7, 8][..q.len()],
                    (true, 4) => &FLIP4,
                    (true, _) => &FLIP9,
                };
                order
                    .iter()
                    .map(|&a| self.index[k][q[a]])
                    .collect::<Vec<usize>>()
            }));
        }
        (points, cells)
    }

    fn vector_field(&self, v: &[f64]) -> Vec<f64> {
        self.points
            .iter()
            .flat_map(|&(k, i)| {
                let s = self.signs[k];
                [s[0] * v[3 * i], s[1] * v[3 * i + 1], s[2] * v[3 * i + 2]]
            })
            .collect()
    }

    fn cell_field(&self, v: &[f64]) -> Vec<f64> {
        self.signs.iter().flat_map(|_| v.iter().copied()).collect()
    }
}

/// The values of one ring, in [`PROFILE_HEADER`]'s order.
pub fn ring_row(r: &RingValues) -> [f64; 10] {
    let v = &r.values;
    [
        r.z_ref,
        r.z,
        r.radius,
        v.lambda_s,
        v.lambda_z,
        v.n_s,
        v.n_z,
        v.n_sz,
        r.contact_width,
        r.contact_force,
    ]
}

fn join(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| v.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// Keep the header and the rows whose first field (the steps.csv row) is at most `rows`;
/// whether the file was there.
fn trim_rows(path: &Path, rows: usize) -> Result<bool> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Ok(false);
    };
    let kept: Vec<&str> = text
        .lines()
        .enumerate()
        .filter(|(k, l)| {
            *k == 0
                || l.split(',')
                    .next()
                    .and_then(|r| r.parse::<usize>().ok())
                    .is_some_and(|r| r <= rows)
        })
        .map(|(_, l)| l)
        .collect();
    atomic_write(path, &format!("{}\n", kept.join("\n")))?;
    Ok(true)
}

/// Write a profile (one row per ring) as CSV, whole.
pub(crate) fn write_profile(path: &Path, rings: &[RingValues]) -> Result<()> {
    let mut text = format!("{PROFILE_HEADER}\n");
    for r in rings {
        text.push_str(&join(&ring_row(r)));
        text.push('\n');
    }
    atomic_write(path, &text)
}

impl Observer for RunWriter {
    fn started(
        &mut self,
        report: &RunReport,
        model: &Model,
        state: &State,
    ) -> Result<(), BoxError> {
        self.units = report.scales.map_or(
            crate::units::Units::dimensionless(),
            crate::units::Units::si,
        );
        self.write_manifest(report, "running", None)?;
        if self.resumed {
            return Ok(());
        }
        for sub in ["vtu", "profiles"] {
            let d = self.dir.join(sub);
            std::fs::create_dir_all(&d).map_err(|e| AppError::io(&d, e))?;
        }
        atomic_write(
            &self.dir.join("steps.csv"),
            &format!("{}\n", steps_header(report.scales.is_some())),
        )?;
        atomic_write(
            &self.dir.join("profiles").join("profiles.csv"),
            &format!("{PROFILES_HEADER}\n"),
        )?;
        self.all_or_none(|w| w.frame(0.0, (0, 0, 0), model, state, None))
    }

    /// A converged step's files, all or none: a write that fails (a full disk) undoes the
    /// step's other files (the journal), so the folder holds whole rows and frames of
    /// the steps before it, and `rows` counts them.
    fn step(&mut self, view: &StepView) -> Result<(), BoxError> {
        self.all_or_none(|w| w.write_step(view))
    }

    fn critical(
        &mut self,
        record: &crate::report::CriticalRecord,
        model: &Model,
        state: &State,
        mode: Option<&[[f64; 3]]>,
    ) -> Result<(), BoxError> {
        self.all_or_none(|w| w.write_critical(record, model, state, mode))
    }

    fn stage_finished(&mut self, report: &RunReport) -> Result<(), BoxError> {
        if let Some(stage) = report.stages.last() {
            let path = self
                .dir
                .join("profiles")
                .join(format!("stage{}_final.csv", stage.plan.index));
            write_profile(&path, &stage.profile)?;
        }
        self.write_summary(report)?;
        self.write_manifest(report, "running", None)?;
        Ok(())
    }

    fn finished(&mut self, report: &RunReport) -> Result<(), BoxError> {
        self.write_manifest(report, "finished", None)?;
        self.release();
        Ok(())
    }

    fn failed(&mut self, report: &RunReport, error: &AppError) {
        // Best effort: the run's error is what the user must see. The reserved space is given
        // back first, so that a run stopped by a full disk can still close its folder: the PVD
        // index of the kept frames, the summary, and the manifest that says what happened.
        if self.dir.is_dir() {
            self.release();
            let _ = write_pvd(&self.dir.join("tube.pvd"), &self.pvd);
            // a failure that no stage holds is recorded at the top
            let in_a_stage = report
                .stages
                .iter()
                .any(|s| matches!(s.outcome, crate::report::StageOutcome::Failed(_)));
            let _ = self.write_summary_with(report, (!in_a_stage).then(|| error.chain()));
            let status = if matches!(error, AppError::Interrupted { .. }) {
                "interrupted"
            } else {
                "failed"
            };
            let _ = self.write_manifest(report, status, Some(error.chain()));
        }
    }
}

impl RunWriter {
    /// Run `write` (one step's files) and keep all it wrote, or, when it fails, undo its
    /// files and the writer's counts of rows and frames with them.
    fn all_or_none(
        &mut self,
        write: impl FnOnce(&mut Self) -> Result<(), BoxError>,
    ) -> Result<(), BoxError> {
        let (rows, frames, pvd, vtu_bytes) =
            (self.rows, self.frames, self.pvd.len(), self.vtu_bytes);
        match write(self) {
            Ok(()) => {
                self.journal.commit();
                Ok(())
            }
            Err(e) => {
                // the write's error is the one to report; an undo that fails too leaves rows
                // past `steps_written`, which `--resume` cuts back to its checkpoint
                let _ = self.journal.rollback();
                self.rows = rows;
                self.frames = frames;
                self.pvd.truncate(pvd);
                self.vtu_bytes = vtu_bytes;
                Err(e)
            }
        }
    }

    /// Everything of one converged step, in the order the files are journaled: the iteration
    /// log, steps.csv's row, walls.csv, fronts.csv, the profile, the VTU frame and the PVD
    /// entry, and the checkpoint. Its length is that list of files.
    fn write_step(&mut self, view: &StepView) -> Result<(), BoxError> {
        let iterations = view.model.take_iteration_log();
        if self.vtu.iterations && !iterations.is_empty() {
            // the iterations since the last converged step (a cut-back's failed attempts
            // included), under this step's number
            let path = self.dir.join("iterations.csv");
            let rows: Vec<[f64; 12]> = iterations
                .iter()
                .enumerate()
                .map(|(k, it)| {
                    [
                        (self.rows + 1) as f64,
                        view.record.stage as f64,
                        view.record.step as f64,
                        (k + 1) as f64,
                        it.assembly,
                        it.line_search,
                        it.factorization,
                        it.solve,
                        it.residual,
                        it.negative_pivots as f64,
                        f64::from(u8::from(it.factorized)),
                        it.krylov as f64,
                    ]
                })
                .collect();
            self.journal
                .append(&path, ITERATIONS_HEADER, &csv_rows(&rows))?;
        }
        let units = view.report.scales;
        let row = match &units {
            None => format_row(view.record),
            Some(sc) => format!("{},{}", format_row(view.record), si_row(sc, view.record)),
        };
        self.journal.append(
            &self.dir.join("steps.csv"),
            &steps_header(units.is_some()),
            &format!("{row}\n"),
        )?;
        self.rows += 1;
        if !view.record.walls.is_empty() && view.fraction >= 1.0 {
            // the mid-span ring of a confine stage's end, whole (symmetry copies), for plots
            // against the closed-form section (`tubemem gps confine --figure … --ring …`)
            let path = self
                .dir
                .join("profiles")
                .join(format!("stage{}_midspan_ring.csv", view.plan.index));
            let ring = tubemem_fem::post::Ring::midspan(view.model);
            let signs = tubemem_fem::post::reflections(view.model);
            let mut text = String::from("x,y\n");
            for sg in &signs {
                for &i in &ring.nodes {
                    let x = view.state.x[i];
                    text.push_str(&format!("{},{}\n", sg[0] * x[0], sg[1] * x[1]));
                }
            }
            self.journal.create(&path, text.as_bytes())?;
        }
        if !view.record.walls.is_empty() {
            let r = view.record;
            let mut text = String::new();
            let cf = |c: &Option<tubemem_gps::confine::ConfineState>, k: usize| {
                c.as_ref()
                    .and_then(|c| c.walls.get(k))
                    .map_or([f64::NAN; 2], |w| [w.contact_length, w.force])
            };
            for (k, w) in r.walls.iter().enumerate() {
                let g = cf(&r.closed_form.gps_confine, k);
                let l = cf(&r.closed_form.local_confine, k);
                let vals = [
                    self.rows as f64,
                    r.stage as f64,
                    r.step as f64,
                    (k + 1) as f64,
                    w.contact_length,
                    w.force,
                    w.penetration,
                    g[0],
                    g[1],
                    l[0],
                    l[1],
                ];
                text.push_str(&crate::curves::csv_line(&vals));
                text.push('\n');
            }
            self.journal
                .append(&self.dir.join("walls.csv"), WALLS_HEADER, &text)?;
        }
        if !view.record.fronts.is_empty() {
            self.journal.append(
                &self.dir.join("fronts.csv"),
                FRONTS_HEADER,
                &csv_rows(&front_rows(self.rows, view.record)),
            )?;
        }
        if self.profiles && !view.record.profile.is_empty() {
            let r = view.record;
            let mut text = String::new();
            for ring in &r.profile {
                let head = [self.rows as f64, r.stage as f64, r.step as f64];
                text.push_str(&format!("{},{}\n", join(&head), join(&ring_row(ring))));
            }
            self.journal.append(
                &self.dir.join("profiles").join("profiles.csv"),
                PROFILES_HEADER,
                &text,
            )?;
        }
        use crate::case::VtuFrames;
        let stage_end = view.fraction >= 1.0;
        let wanted = match self.vtu.vtu {
            VtuFrames::Every => stage_end || view.record.step.is_multiple_of(self.vtu.vtu_every),
            VtuFrames::StageEnd => stage_end,
            VtuFrames::None => false,
        };
        if wanted {
            let time = (view.plan.index - 1) as f64 + view.fraction;
            let tag = (self.rows, view.record.stage, view.record.step);
            self.frame(
                time,
                tag,
                view.model,
                view.state,
                view.load.contact.as_ref(),
            )?;
        }
        // the checkpoint of this step, alternating between two files (the last two are kept)
        if self.checkpoint_every == 0 || !self.rows.is_multiple_of(self.checkpoint_every) {
            return Ok(());
        }
        let dir = self.dir.join("checkpoints");
        std::fs::create_dir_all(&dir).map_err(|e| AppError::io(&dir, e))?;
        let ck = Checkpoint {
            case_hash: self.case_hash.clone(),
            context: *view.context,
            progress: view.progress,
            report: view.report.clone(),
            steps: view.stage_steps.to_vec(),
            critical_points: view.stage_critical_points.to_vec(),
            rows: self.rows,
            frames: self.frames,
            pvd: self.pvd.clone(),
            x: view.state.x.clone(),
            p: view.state.p,
            multipliers: view.state.multipliers.clone(),
            previous: view.previous.map(|s| (s.x.clone(), s.p)),
        };
        let name = if (self.rows / self.checkpoint_every).is_multiple_of(2) {
            "ckpt-a.bin"
        } else {
            "ckpt-b.bin"
        };
        write_checkpoint(&dir.join(name), &ck)?;
        Ok(())
    }

    fn write_critical(
        &mut self,
        record: &crate::report::CriticalRecord,
        model: &Model,
        state: &State,
        mode: Option<&[[f64; 3]]>,
    ) -> Result<(), BoxError> {
        self.journal.append(
            &self.dir.join("critical_points.csv"),
            CRITICAL_HEADER,
            &csv_rows(&[critical_row(record)]),
        )?;
        // a bifurcation: the state with its critical mode, for ParaView
        if let (Some(mode), Some(name)) = (mode, &record.mode_vtu) {
            let disp: Vec<f64> = state
                .x
                .iter()
                .zip(&model.mesh().nodes)
                .flat_map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]])
                .collect();
            let m: Vec<f64> = mode.iter().flatten().copied().collect();
            let path = self.dir.join(name);
            self.journal.creating(&path);
            write_vtu(
                &path,
                &state.x,
                &model.mesh().cells(),
                &[
                    Field {
                        name: "displacement",
                        components: 3,
                        values: &disp,
                    },
                    Field {
                        name: "mode",
                        components: 3,
                        values: &m,
                    },
                ],
                &[],
                &[
                    (
                        "tubemem_version",
                        FieldValue::Text(env!("CARGO_PKG_VERSION")),
                    ),
                    ("case_hash", FieldValue::Text(&self.case_hash)),
                ],
                tubemem_mesh::vtu::Encoding::Binary,
            )?;
        }
        if let (Some(mode), Some(name)) = (mode, &record.mode_png) {
            let fig = crate::figures::mode_figure(
                model.mesh(),
                mode,
                &format!(
                    "Critical mode of stage {}, between steps {} and {}",
                    record.stage,
                    record.step - 1,
                    record.step
                ),
                match record.kind {
                    tubemem_fem::continuation::CriticalKind::Neutral => vec![format!(
                        "neutral (eigenvalue {:.1e}): a family of equilibria along this mode, e.g. a bulge's translation (u_z uniform in each straight end, u_r antisymmetric about the bulge)",
                        record.mode_eigenvalue.unwrap_or(f64::NAN)
                    )],
                    _ => vec![format!(
                        "{} — eigenvalue of K nearest zero: {:.1e}",
                        record.kind,
                        record.mode_eigenvalue.unwrap_or(f64::NAN)
                    )],
                },
            );
            self.journal.creating(&self.dir.join(name));
            let stem = self.dir.join(name.trim_end_matches(".png"));
            crate::figures::save(
                &fig,
                &stem,
                &crate::figures::FigureOptions {
                    png: true,
                    svg: false,
                    ..Default::default()
                },
            )?;
        }
        Ok(())
    }
}
