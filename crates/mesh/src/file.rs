//! Whole-file writes: a file tubemem writes is either its complete new content, its complete old
//! content, or absent, whatever stops the write (a full disk, a kill, a power cut of the
//! process). The content goes to a temporary sibling `.NAME.PID.tmp` (created exclusively, so a
//! file of that name that tubemem did not write is never touched), which is then renamed over
//! `NAME`; a failed write removes its temporary file, so a full disk leaves no partial file
//! behind. A kill between the two leaves only the temporary file, which [`partial_of`] names
//! as such.
//!
//! No `fsync`: the guarantee is against a failed write or a killed process, not against the
//! machine losing power (a renamed file may then be empty on some file systems).

use std::io::Write;
use std::path::{Path, PathBuf};

/// The temporary sibling of `path` that [`write_whole`] writes first.
fn temporary(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// The `NAME` of a temporary file of [`write_whole`], `.NAME.PID.tmp`; `None` for any other.
pub fn partial_of(name: &str) -> Option<&str> {
    name.strip_prefix('.')
        .and_then(|r| r.strip_suffix(".tmp"))
        .and_then(|r| r.rsplit_once('.'))
        .filter(|(stem, pid)| {
            !stem.is_empty() && !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit())
        })
        .map(|(stem, _)| stem)
}

/// Write `bytes` as the whole content of `path`: to a temporary sibling, then renamed over
/// `path`. On an error `path` is as it was and the temporary file is gone.
pub fn write_whole(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = temporary(path);
    let result = (|| {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        f.write_all(bytes)?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_write_replaces_or_leaves_the_file() {
        let d = std::env::temp_dir().join(format!("tubemem-file-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let p = d.join("a.csv");
        write_whole(&p, b"one\n").unwrap();
        write_whole(&p, b"two\n").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two\n");
        // a write whose rename fails (a folder is in the way) leaves the folder and no
        // temporary file; one into a missing folder fails at once
        std::fs::create_dir(d.join("sub")).unwrap();
        assert!(write_whole(&d.join("sub"), b"x").is_err());
        assert!(d.join("sub").is_dir());
        std::fs::remove_dir(d.join("sub")).unwrap();
        assert!(write_whole(&d.join("missing").join("b.csv"), b"x").is_err());
        // the only file left is the written one: no temporary sibling
        let names: Vec<String> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["a.csv"]);
        let tmp = temporary(&p);
        assert_eq!(
            partial_of(&tmp.file_name().unwrap().to_string_lossy()),
            Some("a.csv")
        );
        for other in ["a.csv", ".a.tmp", ".a.x1.tmp"] {
            assert_eq!(partial_of(other), None, "{other}");
        }
        std::fs::remove_dir_all(&d).unwrap();
    }
}
