//! The files of one converged step, kept or undone together: a step of a run appends rows to
//! several CSV files (steps.csv, profiles.csv, walls.csv, …) and may create new files (a VTU
//! frame, a stage's mid-span ring). When one of these writes fails (a full disk), every file the
//! step touched is taken back to where it was: appended files are cut to their earlier length,
//! created files are removed. Neither needs free space, so after any failure each file holds
//! whole rows of the steps before, and no partial row or frame remains.
//!
//! Files that replace an earlier version (the PVD index, summary.json, run.json, checkpoints)
//! are not journalled: they are written whole ([`tubemem_mesh::file::write_whole`]).

use crate::{AppError, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The files one step has touched so far, with what each was before.
#[derive(Debug, Default)]
pub struct Journal {
    /// (file, its length before the step; `None`: it did not exist)
    touched: Vec<(PathBuf, Option<u64>)>,
}

impl Journal {
    /// Remember `path` as it is now, the first time the step touches it.
    fn note(&mut self, path: &Path) {
        if self.touched.iter().all(|(p, _)| p != path) {
            let len = std::fs::metadata(path).ok().map(|m| m.len());
            self.touched.push((path.to_path_buf(), len));
        }
    }

    /// Append `text` to `path`, with `header` (and a newline) first when the file is new or
    /// empty.
    pub fn append(&mut self, path: &Path, header: &str, text: &str) -> Result<()> {
        self.note(path);
        let fresh = std::fs::metadata(path).map_or(true, |m| m.len() == 0);
        let mut all = String::with_capacity(header.len() + 1 + text.len());
        if fresh {
            all.push_str(header);
            all.push('\n');
        }
        all.push_str(text);
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .and_then(|mut f| f.write_all(all.as_bytes()))
            .map_err(|e| AppError::io(path, e))
    }

    /// Write the whole file `path`: removed again if the step is undone and the file is new
    /// (an existing file is replaced whole, and stays replaced).
    pub fn create(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        if !path.exists() {
            self.note(path);
        }
        crate::output_file::write_whole(path, bytes)
    }

    /// Remember a file that a writer outside the journal is about to create (a VTU frame), so
    /// that undoing the step removes it.
    pub(crate) fn creating(&mut self, path: &Path) {
        if !path.exists() {
            self.note(path);
        }
    }

    /// The step's files are all written: keep them.
    pub(crate) fn commit(&mut self) {
        self.touched.clear();
    }

    /// Undo the step: cut every appended file back to its earlier length and remove every file
    /// it created, newest first. Best effort (neither needs free space); the first failure is
    /// returned, after the rest have been tried.
    pub(crate) fn rollback(&mut self) -> Result<()> {
        let mut first = None;
        for (path, len) in self.touched.drain(..).rev() {
            let r = match len {
                Some(n) => std::fs::OpenOptions::new()
                    .write(true)
                    .open(&path)
                    .and_then(|f| f.set_len(n)),
                None => match std::fs::remove_file(&path) {
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
                    r => r,
                },
            };
            if let Err(e) = r {
                first.get_or_insert(AppError::io(&path, e));
            }
        }
        first.map_or(Ok(()), Err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An undone step leaves its appended file at its earlier length and its created files
    /// gone; a committed one keeps them.
    #[test]
    fn an_undone_step_leaves_the_files_as_they_were() {
        let d = std::env::temp_dir().join(format!("tubemem-journal-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let (csv, frame) = (d.join("steps.csv"), d.join("frame.vtu"));
        let mut j = Journal::default();
        j.append(&csv, "a,b", "1,2\n").unwrap();
        j.commit();
        j.append(&csv, "a,b", "3,4\n").unwrap();
        j.create(&frame, b"<VTKFile/>").unwrap();
        j.append(&csv, "a,b", "5,6\n").unwrap();
        j.rollback().unwrap();
        assert_eq!(std::fs::read_to_string(&csv).unwrap(), "a,b\n1,2\n");
        assert!(!frame.exists());
        j.append(&csv, "a,b", "3,4\n").unwrap();
        j.create(&frame, b"<VTKFile/>").unwrap();
        j.commit();
        j.rollback().unwrap();
        assert_eq!(std::fs::read_to_string(&csv).unwrap(), "a,b\n1,2\n3,4\n");
        assert!(frame.exists());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
