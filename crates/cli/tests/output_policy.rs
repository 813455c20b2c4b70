//! Issue #61's data-loss findings in `gps`, `fit` and `verify`: an output that is an input is
//! refused before anything is read or written, an existing file tubemem did not write is
//! replaced only with `--overwrite`, and a check's name cannot lead its run out of `--out`.

mod common;

use common::{tmp, tubemem};
use std::path::Path;

fn refused(args: &[&str], needle: &str) {
    let o = tubemem(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains(needle),
        "{args:?}: exit {:?}, expected `{needle}` in: {err}",
        o.status.code()
    );
}

fn unchanged(path: &Path, text: &str) {
    assert_eq!(
        std::fs::read_to_string(path).unwrap(),
        text,
        "{}",
        path.display()
    );
}

#[test]
fn gps_outputs_never_replace_their_inputs_or_a_users_file() {
    let d = tmp("policy-gps");
    let ring = d.join("ring.csv");
    let ring_text = "x,y\n1.0,0.0\n0.0,1.0\n";
    std::fs::write(&ring, ring_text).unwrap();
    let r = ring.to_str().unwrap();
    // --csv is the --ring it has not read yet
    refused(
        &[
            "gps",
            "confine",
            "--material",
            "neo-hookean",
            "--initial-stretch",
            "1.3",
            "--plane=0,1,1.2",
            "--plane=0,-1,1.2",
            "--points",
            "3",
            "--csv",
            r,
            "--figure",
            d.join("f.svg").to_str().unwrap(),
            "--ring",
            r,
        ],
        "is the input",
    );
    unchanged(&ring, ring_text);
    // a user's file at --csv: refused, then replaced with --overwrite; the command's own
    // file is replaced on a second run without it
    let user = d.join("mine.csv");
    std::fs::write(&user, "my notes\n").unwrap();
    let curve = |extra: &[&str]| {
        let mut a = vec![
            "gps",
            "inflate",
            "--material",
            "neo-hookean",
            "--to",
            "2",
            "--points",
            "5",
            "--csv",
            user.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        tubemem(&a)
    };
    assert!(!curve(&[]).status.success());
    unchanged(&user, "my notes\n");
    assert!(curve(&["--overwrite"]).status.success());
    assert!(curve(&[]).status.success(), "its own file is replaced");
}

#[test]
fn fit_plot_never_replaces_its_data() {
    let d = tmp("policy-fit");
    let data = d.join("data.png");
    let text = "stretch,nominal_stress_mpa\n1.0,0.0\n1.2,0.1\n1.4,0.18\n1.6,0.25\n1.8,0.31\n";
    std::fs::write(&data, text).unwrap();
    refused(
        &[
            "fit",
            "--law",
            "neo-hookean",
            "--uniaxial",
            data.to_str().unwrap(),
            "--plot",
            d.join("data").to_str().unwrap(),
        ],
        "is the input",
    );
    unchanged(&data, text);
}

#[test]
fn a_check_named_with_dots_cannot_leave_its_folder() {
    let d = tmp("policy-verify");
    for name in ["..", ".", "..."] {
        let suite = d.join("s.toml");
        std::fs::write(
            &suite,
            format!(
                "[[check]]\nname = \"{name}\"\ncase = \"../../cases/small_abb30_ls1.2.toml\"\nkind = \"closed-form\"\ntolerance.w = {{ value = 1.0, source = \"test\" }}\n"
            ),
        )
        .unwrap();
        let out = d.join("out");
        let o = tubemem(&[
            "verify",
            suite.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            o.status.code() == Some(2) && err.contains("not only dots"),
            "{name}: {err}"
        );
        assert!(!d.join("run").exists(), "{name}: a run beside --out");
    }
}

/// Every file under `dir`, with its bytes (symlinks as their target, not followed).
fn snapshot(dir: &Path) -> std::collections::BTreeMap<std::path::PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let meta = std::fs::symlink_metadata(&p).unwrap();
            if meta.file_type().is_symlink() {
                let t = std::fs::read_link(&p).unwrap();
                out.insert(p, t.to_string_lossy().as_bytes().to_vec());
            } else if meta.is_dir() {
                todo.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// The inputs every command of the property below reads, written into `dir`.
fn inputs(dir: &Path) {
    let case = include_str!("../../../cases/small_abb30_ls1.2.toml")
        .replace("around = 16", "around = 8")
        .replace("along = 24", "along = 4")
        .replace("model = \"abb\"", "model = \"neo-hookean\"")
        .replace("kuhn = 30", "")
        + "\n[output]\nvtu = \"none\"\n";
    std::fs::write(dir.join("case.toml"), case).unwrap();
    std::fs::write(
        dir.join("law.toml"),
        "[material]\nmodel = \"neo-hookean\"\nshear_modulus = 1.0\n",
    )
    .unwrap();
    std::fs::write(dir.join("ring.csv"), "x,y\n1.0,0.0\n0.0,1.0\n").unwrap();
    // the same ring under a figure's name, so that a figure output can alias it
    std::fs::write(dir.join("ring.svg"), "x,y\n1.0,0.0\n0.0,1.0\n").unwrap();
    std::fs::write(
        dir.join("data.csv"),
        "stretch,nominal_stress_mpa\n1.0,0.0\n1.2,0.1\n1.4,0.18\n1.6,0.25\n1.8,0.31\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("suite.toml"),
        "[[check]]\nname = \"c\"\ncase = \"case.toml\"\nkind = \"closed-form\"\ntolerance.w = { value = 1.0, source = \"test\" }\n",
    )
    .unwrap();
    let atlas = include_str!("../../../atlas/ci.toml")
        .replace("around = 32", "around = 8")
        .replace("stretches = [1.2, 1.3]", "stretches = [1.2]")
        .replace("rho = [1.1, 1.0, 0.9, 0.8]", "rho = [1.0]")
        .replace("lengths = [10, 20, 40]", "lengths = [4, 6, 8]");
    std::fs::write(dir.join("atlas.toml"), atlas).unwrap();
}

/// A command line of the property below with its placeholders filled in: `OUT` the output,
/// `OUTDIR` a run folder, `SIDE.x` a second output, `IN_name` the input `name` in `d` (the fit's
/// data as data.svg where `data_svg`).
fn expand(args: &[&str], d: &Path, out: &Path, data_svg: bool) -> Vec<String> {
    let path = |p: std::path::PathBuf| p.to_str().unwrap().to_string();
    args.iter()
        .map(|a| match *a {
            "OUT" => path(out.to_path_buf()),
            "OUTDIR" => path(d.join("run")),
            "SIDE.svg" => path(d.join("side.svg")),
            "SIDE.csv" => path(d.join("side.csv")),
            a => match a.strip_prefix("IN_") {
                Some("data.csv") if data_svg => path(d.join("data.svg")),
                Some(name) => path(d.join(name)),
                None => a.to_string(),
            },
        })
        .collect()
}

/// Issue #61's output policy, by property: every subcommand and every output option, pointed
/// at one of its own inputs (the path itself, through `..`, a symbolic link and a hard link to
/// it) or at an existing file of the user's (or a folder holding one under an output's name),
/// is refused with a message, and no file that existed before the command changed. Nothing is
/// passed `--overwrite`: a user's file is replaced only when asked.
#[test]
fn every_output_option_refuses_inputs_links_and_users_files() {
    // (command line with IN_x for inputs and OUT for the output, the input OUT may alias, the
    // file name the command writes when OUT is a folder)
    let commands: &[(&[&str], &str, Option<&str>)] = &[
        (
            &["run", "IN_case.toml", "--out", "OUT"],
            "case.toml",
            Some("steps.csv"),
        ),
        (
            &["run", "IN_case.toml", "--out", "OUTDIR", "--log", "OUT"],
            "case.toml",
            None,
        ),
        (
            &[
                "gps",
                "inflate",
                "--law",
                "IN_law.toml",
                "--to",
                "2",
                "--points",
                "3",
                "--csv",
                "OUT",
            ],
            "law.toml",
            None,
        ),
        (
            &[
                "gps",
                "flatten",
                "--law",
                "IN_law.toml",
                "--initial-stretch",
                "1.3",
                "--to",
                "0.9",
                "--points",
                "3",
                "--csv",
                "OUT",
            ],
            "law.toml",
            None,
        ),
        (
            &[
                "gps",
                "confine",
                "--material",
                "neo-hookean",
                "--initial-stretch",
                "1.3",
                "--plane=0,1,1.2",
                "--plane=0,-1,1.2",
                "--points",
                "3",
                "--ring",
                "IN_ring.csv",
                "--figure",
                "SIDE.svg",
                "--csv",
                "OUT",
            ],
            "ring.csv",
            None,
        ),
        (
            &[
                "gps",
                "confine",
                "--law",
                "IN_law.toml",
                "--initial-stretch",
                "1.3",
                "--plane=0,1,1.2",
                "--plane=0,-1,1.2",
                "--points",
                "3",
                "--csv",
                "SIDE.csv",
                "--ring",
                "IN_ring.svg",
                "--figure",
                "OUT",
            ],
            "ring.svg",
            None,
        ),
        (
            &[
                "fit",
                "--law",
                "neo-hookean",
                "--uniaxial",
                "IN_data.csv",
                "--plot",
                "OUT",
            ],
            "data.csv",
            None,
        ),
        (
            &["verify", "IN_suite.toml", "--out", "OUT"],
            "suite.toml",
            Some("results.json"),
        ),
        (
            &["atlas", "IN_atlas.toml", "--out", "OUT"],
            "atlas.toml",
            Some("atlas.csv"),
        ),
        (
            &["export", "IN_case.toml", "--out", "OUT"],
            "case.toml",
            None,
        ),
        (
            &["figures", "--out", "OUT"],
            "case.toml",
            Some("fig5_pressure_stretch.svg"),
        ),
        (&["man", "--out", "OUT"], "case.toml", Some("tubemem.1")),
    ];
    let root = tmp("policy-property");
    // each command line is valid: it succeeds with a fresh output path (so the refusals below
    // are the output policy's, not a usage error's)
    for (i, (args, _, _)) in commands.iter().enumerate() {
        let d = root.join(format!("{i}-fresh"));
        std::fs::create_dir_all(&d).unwrap();
        inputs(&d);
        let figure = args.contains(&"--figure") && !args.contains(&"SIDE.svg");
        let out = d.join(if figure { "fresh.svg" } else { "fresh" });
        let args = expand(args, &d, &out, false);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = tubemem(&refs);
        assert!(
            o.status.success(),
            "{args:?} fails with a fresh output: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let hazards = [
        "itself",
        "dotdot",
        "symlink",
        "hardlink",
        "users-file",
        "users-folder",
    ];
    let mut tried = 0;
    for (i, (args, aliased, writes)) in commands.iter().enumerate() {
        for hazard in hazards {
            let folder_output = writes.is_some();
            if hazard == "users-folder" && !folder_output {
                continue;
            }
            let d = root.join(format!("{i}-{hazard}"));
            std::fs::create_dir_all(d.join("sub")).unwrap();
            inputs(&d);
            let input = d.join(aliased);
            // `fit --plot P` writes P.svg and P.png: alias through the stem
            let fit = args[0] == "fit";
            let stem = |p: &Path| p.with_extension("");
            let out = match hazard {
                "itself" => input.clone(),
                "dotdot" => d.join("sub").join("..").join(aliased),
                "symlink" => {
                    let l = d.join("link");
                    std::os::unix::fs::symlink(&input, &l).unwrap();
                    l
                }
                "hardlink" => {
                    let l = d.join("hard");
                    std::fs::hard_link(&input, &l).unwrap();
                    l
                }
                "users-file" => {
                    // `fit --plot mine` writes mine.svg and mine.png
                    let figure = args.contains(&"--figure") && !args.contains(&"SIDE.svg");
                    let u = d.join(if fit || figure {
                        "mine.svg"
                    } else {
                        "mine.txt"
                    });
                    std::fs::write(&u, "the user's notes\n").unwrap();
                    u
                }
                _ => {
                    let f = d.join("mine");
                    std::fs::create_dir_all(&f).unwrap();
                    std::fs::write(f.join(writes.unwrap()), "the user's own\n").unwrap();
                    f
                }
            };
            let out = if fit && hazard == "users-file" {
                stem(&out)
            } else if fit {
                // the data file as the plot's SVG (data.svg), through each alias
                let svg = out.with_extension("svg");
                if !svg.exists() {
                    if hazard == "itself" || hazard == "dotdot" {
                        std::fs::rename(&input, input.with_extension("svg")).unwrap();
                    } else {
                        std::fs::rename(&out, &svg).unwrap();
                    }
                }
                stem(&out)
            } else {
                out
            };
            // the data moved to data.svg above (or its link points there)
            let args = expand(args, &d, &out, fit && hazard != "users-file");
            let before = snapshot(&d);
            let refs: Vec<&str> = args.iter().map(String::as_str).collect();
            let o = tubemem(&refs);
            let err = String::from_utf8_lossy(&o.stderr);
            tried += 1;
            assert!(
                !o.status.success() && !err.trim().is_empty(),
                "{hazard}: {args:?} was accepted (exit {:?}); stderr: {err}",
                o.status.code()
            );
            let after = snapshot(&d);
            for (path, bytes) in &before {
                assert!(
                    after.get(path) == Some(bytes),
                    "{hazard}: {args:?} changed or removed {}; stderr: {err}",
                    path.display()
                );
            }
        }
    }
    assert!(tried >= 60, "{tried} combinations");
}
