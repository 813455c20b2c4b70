//! `tubemem completions SHELL` and `tubemem man --out DIR`: shell completion scripts and man
//! pages generated from the command-line definition itself (clap_complete, clap_mangen), so
//! they cannot drift from the options the program takes.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The shells `tubemem completions` writes a script for.
pub use clap_complete::Shell;

/// Write the completion script of `cmd` for `shell` to standard output.
pub fn completions(shell: Shell, mut cmd: clap::Command) -> Result<()> {
    let name = cmd.get_name().to_string();
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut cmd, name, &mut script);
    use std::io::Write;
    let mut o = std::io::stdout().lock();
    o.write_all(&script)
        .and_then(|()| o.flush())
        .context("cannot write the completion script to standard output")
}

/// Whether the file at `path` is a man page this command wrote (its `.TH` line names the page),
/// so that `tubemem man` replaces its own pages and refuses any other file.
fn is_own_page(path: &Path, title: &str) -> bool {
    std::fs::read_to_string(path).is_ok_and(|text| {
        text.lines()
            .take(8)
            .any(|l| l.starts_with(&format!(".TH {title} 1 ")))
    })
}

/// The page of `cmd` (named `prefix` + its name) and of each of its subcommands, depth first:
/// `(file name, title, roff text)`.
fn pages(cmd: &clap::Command, prefix: &str) -> Result<Vec<(String, String, Vec<u8>)>> {
    let title = if prefix.is_empty() {
        cmd.get_name().to_string()
    } else {
        format!("{prefix}-{}", cmd.get_name())
    };
    // clap_mangen titles a page by the command's name: give the subcommand its full name
    let page_cmd = cmd.clone().name(title.clone());
    let mut text = Vec::new();
    clap_mangen::Man::new(page_cmd)
        .render(&mut text)
        .with_context(|| format!("cannot render the man page {title}"))?;
    let mut out = vec![(format!("{title}.1"), title.clone(), text)];
    // clap's generated `help` subcommands repeat the pages they point to
    for sub in cmd
        .get_subcommands()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
    {
        out.extend(pages(sub, &title)?);
    }
    Ok(out)
}

/// Write `tubemem.1` and a page per subcommand (`tubemem-run.1`, `tubemem-gps-inflate.1`, …)
/// into `out`. Every page is checked before any is written: a file of that name that is not a
/// tubemem man page is refused and nothing is written.
pub fn man_pages(mut cmd: clap::Command, out: &Path) -> Result<Vec<PathBuf>> {
    cmd.build();
    let pages = pages(&cmd, "")?;
    for (file, title, _) in &pages {
        let path = out.join(file);
        if path.exists() && !is_own_page(&path, title) {
            anyhow::bail!(
                "man --out: {} exists and is not a tubemem man page; nothing was written (choose another folder)",
                path.display()
            );
        }
    }
    std::fs::create_dir_all(out)
        .with_context(|| format!("man --out: cannot create {}", out.display()))?;
    let mut written = Vec::with_capacity(pages.len());
    for (file, _, text) in pages {
        let path = out.join(file);
        tubemem_mesh::file::write_whole(&path, &text)
            .with_context(|| format!("man --out: cannot write {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}
