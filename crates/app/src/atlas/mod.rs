//! # The atlas: where generalized plane strain holds
//!
//! An atlas file names a law, a tube (a case template without stages), a grid of inflations
//! λs*, the half-gaps ρ along each squeeze path, and the lengths L/R to run. One FE run per
//! (λs*, L/R) gives the whole squeeze path ([`member`]); per (λs*, ρ, quantity) the mid-span
//! error FE/GPS − 1 is fitted against L/R by the end-effect law ([`fit`]), and the minimum L/R
//! for each tolerance ε reported, with the discretization's part c separated. The runs go on
//! threads here, or on a Dask cluster from Python (the same [`member::run`] on each worker;
//! [`assemble`] turns their results into the same files bit for bit).
//!
//! ```text
//! ATLAS.toml → Atlas (validated, every member case parsed) → members run (runs/<name>/)
//!            → points (fits, flags) → atlas.csv, runs.csv, atlas.json, figures/
//! ```

pub mod contour;
pub mod fit;
pub mod member;
pub mod output;
pub mod predict;
pub mod ps_map;
pub mod spec;

pub use fit::{Flag, Point};
pub use member::MemberResult;
pub use spec::{Atlas, AtlasSpec, Member};

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use thiserror::Error;

/// Why an atlas cannot be read, planned or written.
#[derive(Debug, Error)]
pub enum AtlasError {
    #[error("cannot read {path}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("the atlas file is not valid TOML or its [atlas] table has a wrong key")]
    Syntax(#[source] toml::de::Error),
    #[error("`{key}`: {message}")]
    Invalid { key: String, message: String },
    #[error("the case of atlas member {member} is refused")]
    Member {
        member: String,
        #[source]
        source: crate::case::CaseError,
    },
    #[error("{path}: {message}")]
    Folder { path: PathBuf, message: String },
    #[error(transparent)]
    Write(#[from] crate::AppError),
    #[error("{path}: not an atlas output (no readable atlas.json)")]
    NotAnAtlas {
        path: PathBuf,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    #[error("{0}")]
    Predict(String),
}

static INTERRUPT: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The flag a SIGINT handler sets: the member runs stop at their next Newton iteration; the
/// members not started are not run.
pub fn set_interrupt(flag: Arc<AtomicBool>) {
    let _ = INTERRUPT.set(flag);
}

fn interrupt_flag() -> Option<Arc<AtomicBool>> {
    INTERRUPT.get().cloned()
}

fn interrupted() -> bool {
    INTERRUPT.get().is_some_and(|f| f.load(Ordering::Relaxed))
}

/// A member finished (or was found done on disk).
pub struct Progress<'a> {
    pub done: usize,
    pub total: usize,
    pub result: &'a MemberResult,
    /// taken from an earlier run of this atlas in the same folder
    pub resumed: bool,
}

/// What [`run`] produced.
pub struct AtlasOutcome {
    pub results: Vec<MemberResult>,
    pub points: Vec<Point>,
    pub written: Vec<PathBuf>,
    /// members not run (interrupted)
    pub missing: Vec<String>,
    pub resumed: usize,
}

/// The folder of member `name`.
pub fn member_dir(out: &Path, name: &str) -> PathBuf {
    out.join("runs").join(name)
}

/// A member's earlier result in `out`, if its case is the one the atlas now builds.
pub fn earlier_result(out: &Path, member: &Member) -> Option<MemberResult> {
    let dir = member_dir(out, &member.name);
    let case = std::fs::read_to_string(dir.join("case.toml")).ok()?;
    if case != member.case_text {
        return None;
    }
    let text = std::fs::read_to_string(dir.join("member.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// Claim `out` for this atlas: a new folder, or one holding the same atlas (resumed: its
/// finished members are kept). A folder holding anything else is refused, untouched.
/// The lock is held while the returned value lives: a second atlas (or a run) into the same
/// folder is refused, not let to fail this one's members.
pub fn prepare(atlas_text: &str, out: &Path) -> Result<crate::output_file::FolderLock, AtlasError> {
    let folder = |message: String| AtlasError::Folder {
        path: out.to_path_buf(),
        message,
    };
    if out.exists() {
        if !out.is_dir() {
            return Err(folder("is not a folder".into()));
        }
        let own = out.join("atlas.toml");
        match std::fs::read_to_string(&own) {
            Ok(t) if t == atlas_text => {}
            Ok(_) => {
                return Err(folder(
                    "holds a different atlas (its atlas.toml differs): choose another --out".into(),
                ))
            }
            Err(_) if std::fs::read_dir(out).is_ok_and(|mut d| d.next().is_none()) => {}
            Err(_) => {
                return Err(folder(
                    "exists and holds no atlas: choose an empty or new folder".into(),
                ))
            }
        }
    }
    crate::output_file::create_folder(out)?;
    let lock = crate::output_file::lock_folder(out, ATLAS_LOCK)?;
    crate::output_file::write_whole(&out.join("atlas.toml"), atlas_text.as_bytes())?;
    Ok(lock)
}

/// The atlas folder's lock file ([`prepare`]).
pub const ATLAS_LOCK: &str = ".tubemem-atlas.lock";

/// Run the atlas into `out` on `workers` threads (its members not yet done), then fit and
/// write. `atlas_text` is the atlas file (kept as `out/atlas.toml`, which is how a rerun knows
/// its folder). A failed member is kept as an error; an interrupted one is left to a rerun.
pub fn run(
    atlas: &Atlas,
    atlas_text: &str,
    out: &Path,
    workers: usize,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<AtlasOutcome, AtlasError> {
    let _lock = prepare(atlas_text, out)?;
    let n = atlas.members.len();
    let slots: Mutex<Vec<Option<MemberResult>>> = Mutex::new(vec![None; n]);
    let done = AtomicUsize::new(0);
    let mut todo = vec![];
    let mut resumed = 0;
    for (i, m) in atlas.members.iter().enumerate() {
        match earlier_result(out, m) {
            Some(r) => {
                resumed += 1;
                let k = done.fetch_add(1, Ordering::SeqCst) + 1;
                progress(Progress {
                    done: k,
                    total: n,
                    result: &r,
                    resumed: true,
                });
                slots.lock().expect("no panic holds it")[i] = Some(r);
            }
            None => todo.push(i),
        }
    }
    // the longest tubes first: the last runs to finish are short ones
    todo.sort_by(|&a, &b| atlas.members[b].length.total_cmp(&atlas.members[a].length));
    let next = AtomicUsize::new(0);
    let write_error: Mutex<Option<crate::AppError>> = Mutex::new(None);
    std::thread::scope(|scope| {
        for _ in 0..workers.clamp(1, todo.len().max(1)) {
            scope.spawn(|| loop {
                let j = next.fetch_add(1, Ordering::SeqCst);
                if j >= todo.len() || interrupted() {
                    break;
                }
                let i = todo[j];
                let m = &atlas.members[i];
                let dir = member_dir(out, &m.name);
                let r = member::run(atlas, m, &dir);
                if interrupted() {
                    // stopped part-way: not a result, a rerun does it again
                    break;
                }
                let json = serde_json::to_string_pretty(&r).expect("plain data serializes");
                if let Err(e) =
                    crate::output_file::write_whole(&dir.join("member.json"), json.as_bytes())
                {
                    write_error
                        .lock()
                        .expect("no panic holds it")
                        .get_or_insert(e);
                }
                let k = done.fetch_add(1, Ordering::SeqCst) + 1;
                progress(Progress {
                    done: k,
                    total: n,
                    result: &r,
                    resumed: false,
                });
                slots.lock().expect("no panic holds it")[i] = Some(r);
            });
        }
    });
    if let Some(e) = write_error.into_inner().expect("no panic holds it") {
        return Err(e.into());
    }
    let slots = slots.into_inner().expect("no panic holds it");
    let missing: Vec<String> = slots
        .iter()
        .zip(&atlas.members)
        .filter(|(s, _)| s.is_none())
        .map(|(_, m)| m.name.clone())
        .collect();
    if !missing.is_empty() {
        return Ok(AtlasOutcome {
            results: slots.into_iter().flatten().collect(),
            points: vec![],
            written: vec![],
            missing,
            resumed,
        });
    }
    let results: Vec<MemberResult> = slots.into_iter().flatten().collect();
    let (points, written) = assemble(atlas, &results, out)?;
    Ok(AtlasOutcome {
        results,
        points,
        written,
        missing,
        resumed,
    })
}

/// Fit the members' results and write atlas.csv, runs.csv, atlas.json and the figures into
/// `out`: the same bytes whichever machine ran the members.
pub fn assemble(
    atlas: &Atlas,
    results: &[MemberResult],
    out: &Path,
) -> Result<(Vec<Point>, Vec<PathBuf>), AtlasError> {
    for m in &atlas.members {
        if !results
            .iter()
            .any(|r| r.stretch == m.stretch && r.length == m.length)
        {
            return Err(AtlasError::Invalid {
                key: "results".into(),
                message: format!("no result for member {}", m.name),
            });
        }
    }
    let points = fit::points(atlas, results);
    let written = output::write_all(atlas, results, &points, out)?;
    Ok((points, written))
}

/// The members not run, as a message shows them: every name up to 5, else the first 3 and a
/// count (an interrupted 100 × 100 atlas had printed all 9,867 names).
pub fn missing_summary(missing: &[String]) -> String {
    const SHOWN: usize = 3;
    if missing.len() <= 5 {
        missing.join(", ")
    } else {
        format!(
            "{}, … and {} more; runs/ holds the finished ones",
            missing[..SHOWN].join(", "),
            missing.len() - SHOWN
        )
    }
}

/// `secs` in words: "40 s", "12 min", "3.5 h", "2.1 days".
pub fn duration_words(secs: f64) -> String {
    if secs < 90.0 {
        format!("{secs:.0} s")
    } else if secs < 5400.0 {
        format!("{:.0} min", secs / 60.0)
    } else if secs < 172_800.0 {
        format!("{:.1} h", secs / 3600.0)
    } else {
        format!("{:.1} days", secs / 86_400.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_members_are_summarized_not_listed() {
        let names: Vec<String> = (0..9867).map(|i| format!("m{i}")).collect();
        let s = missing_summary(&names);
        assert!(s.len() < 100 && s.contains("9864 more"), "{s}");
        assert_eq!(missing_summary(&names[..2]), "m0, m1");
        assert_eq!(duration_words(40.0), "40 s");
        assert_eq!(duration_words(3600.0), "60 min");
        assert_eq!(duration_words(36_000.0), "10.0 h");
    }
}
