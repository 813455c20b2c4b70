//! One policy for the paths a command writes: the output folders (`run --out`, `figures
//! --out`) must be folders (`create_folder`), and the single files it writes beside a run
//! folder (`run --log`, `export --out`): such a file is written only where it cannot destroy an input or a file
//! tubemem did not write. Checked before anything is written:
//! - a folder at the path is refused ("is a folder");
//! - the path of an input (the case file, a user mesh file), however it is spelled, is refused;
//! - an existing file is replaced only if it is one of the command's own earlier files, which
//!   its first lines say (`ours`); anything else is refused, with what to do.

use crate::{AppError, Result};
use std::path::Path;

/// Whether `a` and `b` name the same existing file (canonical paths; `false` if either is
/// missing).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// The first 4 KiB of `path` as text (lossy).
fn head(path: &Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut buf = vec![0u8; 4096];
    let n = std::fs::File::open(path)?.read(&mut buf)?;
    Ok(String::from_utf8_lossy(&buf[..n]).into_owned())
}

/// Check that the command's file `path` (given as `key`, e.g. "--log") may be written: not a
/// folder, none of `inputs`, and, if it exists, a file whose first lines `ours` recognises.
pub fn check(
    key: &'static str,
    path: &Path,
    inputs: &[&Path],
    ours: impl Fn(&str) -> bool,
) -> Result<()> {
    let refuse = |message: String| {
        Err(AppError::OutputFile {
            key,
            path: path.to_path_buf(),
            message,
        })
    };
    if path.is_dir() {
        return refuse("is a folder: give a file path".into());
    }
    if let Some(input) = inputs.iter().find(|i| same_file(path, i)) {
        return refuse(format!(
            "is the input {}: tubemem never writes over its inputs; give another path",
            input.display()
        ));
    }
    if path.exists() && !path.is_file() {
        // a FIFO would block the write until a reader comes, a device would take the bytes
        return refuse(
            "is not a regular file (a FIFO, a device or a socket): give a file path".into(),
        );
    }
    if path.exists() {
        let text = head(path).map_err(|source| AppError::io(path, source))?;
        if !ours(&text) {
            return refuse(
                "exists and was not written by this tubemem command: tubemem replaces only its own files; give another path, or remove the file yourself".into(),
            );
        }
    }
    Ok(())
}

/// The inputs of a case read from `case_path`: the case file and its user mesh file, if any.
pub fn case_inputs(case_path: &Path, case: &crate::case::Case) -> Vec<std::path::PathBuf> {
    let mut v = vec![case_path.to_path_buf()];
    if let Some(f) = &case.mesh.file {
        v.push(case.base_dir.join(f));
    }
    v
}

/// Whether `text` begins as a `run --log` file does (its column header).
pub fn is_log(text: &str) -> bool {
    text.lines().next().is_some_and(|l| {
        l.split_whitespace().eq([
            "stage",
            "step",
            "elapsed_s",
            "w",
            "lambda_s",
            "newton",
            "residual",
            "fraction",
        ])
    })
}

/// Whether `text` begins as an `export` deck does (`*HEADING`, then "tubemem export of").
pub fn is_deck(text: &str) -> bool {
    let mut l = text.lines();
    l.next() == Some("*HEADING") && l.next().is_some_and(|s| s.starts_with("tubemem export of"))
}

/// Write `bytes` as the whole of `path` ([`tubemem_mesh::file::write_whole`]: the old file or
/// the new one, never a partial one); the error names the path.
pub fn write_whole(path: &Path, bytes: &[u8]) -> Result<()> {
    tubemem_mesh::file::write_whole(path, bytes).map_err(|e| AppError::io(path, e))
}

/// Create the output folder `dir` (and its parents), or refuse a path that is a file (or
/// whose parent is one) as "not a folder" instead of the system's "File exists".
pub(crate) fn create_folder(dir: &Path) -> Result<()> {
    let mut p = Some(dir);
    while let Some(q) = p.filter(|q| !q.as_os_str().is_empty()) {
        let link = q
            .symlink_metadata()
            .is_ok_and(|m| m.file_type().is_symlink());
        if link && !q.exists() {
            return Err(AppError::Folder {
                path: dir.to_path_buf(),
                message: format!(
                    "{} is a symbolic link to {}, which does not exist: create its target or give another path",
                    q.display(),
                    std::fs::read_link(q).map_or_else(|_| "?".into(), |t| t.display().to_string())
                ),
            });
        }
        if q.exists() {
            if !q.is_dir() {
                return Err(AppError::Folder {
                    path: dir.to_path_buf(),
                    message: if q == dir {
                        "is a file, not a folder: give a folder path".into()
                    } else {
                        format!("{} is a file, not a folder", q.display())
                    },
                });
            }
            break;
        }
        p = q.parent();
    }
    std::fs::create_dir_all(dir).map_err(|e| AppError::io(dir, e))
}

/// Write `files` into the folder `dir` of a command (`who`, e.g. "tubemem figures") that
/// records in `dir/manifest` the names it has written there: an existing file is replaced only
/// if the manifest lists it (or, in a folder written before manifests existed, if it begins
/// with the same 64 bytes as its new content: the same CSV header, SVG preamble or PNG
/// header); any other is refused, with every such file named, before anything is written.
/// The manifest is written first, so a file is never on disk unlisted. Returns the paths.
pub(crate) fn write_owned(
    dir: &Path,
    manifest: &str,
    who: &str,
    files: &[(std::path::PathBuf, Vec<u8>)],
) -> Result<Vec<std::path::PathBuf>> {
    let list = dir.join(manifest);
    let listed: Vec<String> = std::fs::read_to_string(&list)
        .map(|t| t.lines().map(str::to_string).collect())
        .unwrap_or_default();
    let name = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let mut foreign = vec![];
    for (path, bytes) in files {
        if path.is_dir() {
            foreign.push(format!("{} (a folder)", path.display()));
        } else if path.exists() && !listed.contains(&name(path)) {
            let n = bytes.len().min(64);
            let same_start = std::fs::read(path).is_ok_and(|old| old.get(..n) == bytes.get(..n));
            if !(listed.is_empty() && same_start) {
                foreign.push(path.display().to_string());
            }
        }
    }
    if !foreign.is_empty() {
        return Err(AppError::Folder {
            path: dir.to_path_buf(),
            message: format!(
                "{} would replace files it did not write: {}; give another --out, or move them",
                who,
                foreign.join(", ")
            ),
        });
    }
    let mut names = listed;
    for (path, _) in files {
        if !names.contains(&name(path)) {
            names.push(name(path));
        }
    }
    write_whole(&list, format!("{}\n", names.join("\n")).as_bytes())?;
    let mut written = vec![];
    for (path, bytes) in files {
        write_whole(path, bytes)?;
        written.push(path.clone());
    }
    Ok(written)
}

/// An exclusive lock on a folder a command writes into, held while this value lives (the
/// operating system releases it when the process ends, however it ends).
#[derive(Debug)]
pub struct FolderLock {
    _file: std::fs::File,
}

/// Take the exclusive lock `name` in `dir` (a file holding the holder's pid): a second
/// command writing into the same folder is refused with the holder named.
pub fn lock_folder(dir: &Path, name: &str) -> Result<FolderLock> {
    use std::io::{Seek, Write};
    let lock_path = dir.join(name);
    let mut lock = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&lock_path)
        .map_err(|e| AppError::io(&lock_path, e))?;
    match lock.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            let holder = std::fs::read_to_string(&lock_path).unwrap_or_default();
            return Err(AppError::Folder {
                path: dir.to_path_buf(),
                message: format!(
                    "another tubemem command is writing into it ({}); wait for it or choose another --out",
                    if holder.trim().is_empty() {
                        "process unknown"
                    } else {
                        holder.trim()
                    }
                ),
            });
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(AppError::io(&lock_path, e)),
    }
    lock.set_len(0).map_err(|e| AppError::io(&lock_path, e))?;
    lock.seek(std::io::SeekFrom::Start(0))
        .map_err(|e| AppError::io(&lock_path, e))?;
    write!(lock, "pid {}", std::process::id()).map_err(|e| AppError::io(&lock_path, e))?;
    Ok(FolderLock { _file: lock })
}
