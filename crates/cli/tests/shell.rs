//! `tubemem completions` and `tubemem man`: the generated completion scripts complete what the
//! program takes, and the man pages cover every subcommand and render without a warning;
//! `tubemem columns` documents every column a real run writes.

mod common;
use common::{tmp, tubemem};
use std::process::Command;

/// The subcommands (and their own subcommands) the program has: the specification these
/// pages and scripts must cover, written here, not read from the program.
const PAGES: &[&str] = &[
    "tubemem",
    "tubemem-gps",
    "tubemem-gps-inflate",
    "tubemem-gps-flatten",
    "tubemem-gps-confine",
    "tubemem-gps-limits",
    "tubemem-gps-history",
    "tubemem-run",
    "tubemem-fit",
    "tubemem-verify",
    "tubemem-atlas",
    "tubemem-atlas-predict",
    "tubemem-export",
    "tubemem-figures",
    "tubemem-schema",
    "tubemem-columns",
    "tubemem-completions",
    "tubemem-man",
];

/// What bash's completion of `words` (the cursor at the end of the last word) offers, with the
/// script `tubemem completions bash` printed.
fn bash_complete(script: &std::path::Path, words: &[&str]) -> Vec<String> {
    let quoted: Vec<String> = words.iter().map(|w| format!("'{w}'")).collect();
    let line = words.join(" ");
    let prog = format!(
        "source '{}'; COMP_WORDS=({}); COMP_CWORD={}; COMP_LINE='{line}'; COMP_POINT={}; \
         _tubemem tubemem '{}' '{}'; printf '%s\\n' \"${{COMPREPLY[@]}}\"",
        script.display(),
        quoted.join(" "),
        words.len() - 1,
        line.len(),
        words[words.len() - 1],
        words[words.len() - 2],
    );
    let out = Command::new("bash")
        .args(["-c", &prog])
        .output()
        .expect("bash runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .map(str::to_string)
        .collect()
}

#[test]
fn the_bash_completion_completes_subcommands_options_and_values() {
    let out = tubemem(&["completions", "bash"]);
    assert!(out.status.success());
    let dir = tmp("completions");
    let script = dir.join("tubemem.bash");
    std::fs::write(&script, &out.stdout).unwrap();
    let syntax = Command::new("bash")
        .arg("-n")
        .arg(&script)
        .output()
        .unwrap();
    assert!(syntax.status.success(), "the script is not valid bash");
    assert_eq!(bash_complete(&script, &["tubemem", "ru"]), ["run"]);
    assert_eq!(
        bash_complete(&script, &["tubemem", "gps", "infl"]),
        ["inflate"]
    );
    assert_eq!(
        bash_complete(&script, &["tubemem", "run", "--ov"]),
        ["--overwrite"]
    );
    assert_eq!(
        bash_complete(&script, &["tubemem", "completions", "f"]),
        ["fish"]
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn every_shell_gets_a_script_naming_every_subcommand() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let out = tubemem(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        let text = String::from_utf8(out.stdout).unwrap();
        for page in &PAGES[1..] {
            let last = page.rsplit('-').next().unwrap();
            assert!(text.contains(last), "{shell}: {last} is not completed");
        }
    }
    let out = tubemem(&["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("invalid value 'tcsh'"), "{err}");
}

#[test]
fn the_man_pages_cover_every_subcommand_and_render_without_warnings() {
    let dir = tmp("man");
    let _ = std::fs::remove_dir_all(&dir);
    let out = tubemem(&["man", "--out", dir.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut written: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    let mut expected: Vec<String> = PAGES.iter().map(|p| format!("{p}.1")).collect();
    expected.sort();
    assert_eq!(written, expected);
    for page in PAGES {
        let path = dir.join(format!("{page}.1"));
        // groff (groff-base, which the test command installs) with every warning on and the
        // UTF-8 input converted (-k), as man does
        let r = Command::new("groff")
            .args(["-k", "-man", "-Tutf8", "-ww", "-z"])
            .arg(&path)
            .output()
            .expect("groff is installed (scripts/test-all.sh installs groff-base)");
        assert!(r.status.success(), "{page}");
        assert!(
            r.stderr.is_empty(),
            "{page}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
    let run = std::fs::read_to_string(dir.join("tubemem-run.1")).unwrap();
    assert!(run.contains(".TH tubemem-run 1 "));
    assert!(run.contains(r"\-\-resume"), "the run page lists --resume");

    // a second call replaces its own pages
    let again = tubemem(&["man", "--out", dir.to_str().unwrap()]);
    assert!(again.status.success());
    // a file of a page's name that tubemem did not write is refused, and nothing is written
    std::fs::write(dir.join("tubemem-fit.1"), "my own notes\n").unwrap();
    std::fs::remove_file(dir.join("tubemem-run.1")).unwrap();
    let refused = tubemem(&["man", "--out", dir.to_str().unwrap()]);
    assert_eq!(refused.status.code(), Some(1));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        err.contains("tubemem-fit.1 exists and is not a tubemem man page"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("tubemem-fit.1")).unwrap(),
        "my own notes\n"
    );
    assert!(!dir.join("tubemem-run.1").exists(), "nothing was written");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_column_dictionary_documents_every_column_a_run_writes() {
    let dir = tmp("columns");
    let _ = std::fs::remove_dir_all(&dir);
    let case = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../cases/small_abb30_ls1.2.toml"
    );
    let out = tubemem(&["run", case, "--out", dir.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dictionary = String::from_utf8(tubemem(&["columns"]).stdout).unwrap();
    for (file, name) in [
        ("steps.csv", "steps.csv"),
        ("profiles/profiles.csv", "profiles/profiles.csv"),
        ("profiles/stage1_final.csv", "profiles/stageN_final.csv"),
    ] {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let header = text.lines().next().unwrap();
        for column in header.split(',') {
            assert!(
                dictionary.contains(&format!("| `{column}` |")),
                "{file}: column {column} is not in `tubemem columns`"
            );
        }
        assert!(
            dictionary.contains(&format!("## `{name}`")),
            "no section for {name}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
