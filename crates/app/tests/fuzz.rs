//! The fuzz harness: structure-aware random case files and user meshes through the whole
//! application (parse → validate → mesh → model → run → outputs). The property: no input makes
//! tubemem panic, no input takes more than 10 s (issue #25's per-input limit; runs are stopped
//! at 2 s, below), every failure is a typed error whose message is not empty, holds no `NaN`
//! and no run of more than 20 digits (1e308 reads as 1e308; a double written plain in
//! [1e-4, 1e15), as messages write it, has at most 17 significant digits and 3 leading zeros
//! after its point), and every number a finished run reports is finite.
//!
//! * In the test command: `cargo test -p tubemem-app --test fuzz` runs 48 generated inputs (a few
//!   seconds, from a fixed seed) plus the crash inputs found before as regression seeds.
//! * The generators cover issue #25's classes that reach the application: user meshes scaled,
//!   shifted, turned and doubled (class 1), extreme integer keys and confinement by up to 40
//!   planes (class 2), and the contact-edge keys of issue #23 (tracked and fitted meshes).
//!   Output paths that alias inputs are a front end's and are tested in `crates/cli/tests`.
//! * The long run: `TUBEMEM_FUZZ_CASES=100000 TUBEMEM_FUZZ_SECONDS=1800 cargo test --release -p
//!   tubemem-app --test fuzz -- --nocapture` (stops at whichever comes first, and prints how
//!   many inputs it ran).
//!
//! Runs are kept small (meshes of at most 24 × 24 elements, at most 6 initial steps) and each is
//! stopped after 2 s by the interrupt flag, so an input that merely runs long is an
//! `Interrupted` outcome, which is allowed.

mod common;

use common::all_finite;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tubemem_app::case::Case;
use tubemem_app::output::{FolderMode, RunWriter};
use tubemem_app::run::{run_with, RunOptions};

/// A number as a case file may give it: ordinary, boundary, extreme or not a number at all.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (0.5f64..3.0).prop_map(|v| format!("{v}")),
        1 => Just("0".to_string()),
        1 => Just("-1.5".to_string()),
        1 => Just("1e-300".to_string()),
        1 => Just("1e308".to_string()),
        1 => Just("nan".to_string()),
        1 => Just("inf".to_string()),
        1 => Just("\"many\"".to_string()),
        1 => (1u32..200).prop_map(|v| format!("{v}")),
    ]
}

/// An energy written as text (issue #61): sums, products, quotients and powers of the
/// invariants and of constants from 0 to 1e300, through exp, ln, sqrt and tanh; some deep or
/// long. Most are not laws a membrane could have: they must be refused, or give finite answers.
fn energy() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        3 => Just("(I1 - 3)".to_string()),
        2 => Just("(I2 - 3)".to_string()),
        1 => Just("I1".to_string()),
        1 => Just("I2".to_string()),
        1 => Just("l".to_string()),
        1 => Just("0".to_string()),
        1 => Just("1e150".to_string()),
        1 => Just("1e-300".to_string()),
        1 => Just("1e300".to_string()),
        2 => (0.01f64..5.0).prop_map(|v| format!("{v}")),
        1 => Just("jm".to_string()),
    ];
    let tree = leaf.prop_recursive(4, 24, 3, |inner| {
        prop_oneof![
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} + {b})")),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} - {b})")),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{a} * {b}")),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{a} / {b}")),
            (inner.clone(), 0u32..5).prop_map(|(a, k)| format!("{a}^{k}")),
            inner.clone().prop_map(|a| format!("exp({a})")),
            inner.clone().prop_map(|a| format!("ln({a})")),
            inner.clone().prop_map(|a| format!("sqrt({a})")),
            inner.clone().prop_map(|a| format!("tanh({a})")),
            inner.prop_map(|a| format!("-{a}")),
        ]
    });
    prop_oneof![
        8 => tree,
        // admissible laws, so that some text laws reach the closed form and the run
        4 => prop_oneof![
            Just("(I1 - 3) / 2".to_string()),
            Just("(I1 - 3) / 2 + 0.1 * (I2 - 3)".to_string()),
            Just("(I1 - 3) / 2 + 0.01 * (I1 - 3)^2 + 1e-4 * (I1 - 3)^3".to_string()),
            (0.05f64..1.0).prop_map(|c| format!("(I1 - 3) / 2 + {c} * (I1 - 3)^2")),
        ],
        // the probe's shapes: deep, long, a near-miss of a known law
        1 => (1usize..400).prop_map(|n| format!("{}(I1 - 3){}", "(".repeat(n), ")".repeat(n))),
        1 => (1usize..30000).prop_map(|n| vec!["(I1 - 3)"; n].join(" + ")),
        1 => Just("-(jm / 2) * ln(1 - (I1 - 3) / jm)".to_string()),
        1 => Just("(I1 - 3) / 2 + ".to_string()),
        1 => Just("1e150*(I1-3)^2".to_string()),
    ]
}

/// A `[material]` table's body with an energy written as text, by invariants or by principal
/// stretches.
fn text_law() -> impl Strategy<Value = String> {
    (energy(), any::<bool>()).prop_map(|(e, principal)| {
        if principal {
            format!(
                "model = \"principal\"\nshear_modulus = 1.0\nenergy = \"{}\"",
                e.replace("I1", "l").replace("I2", "l")
            )
        } else {
            format!(
                "model = \"invariants\"\nshear_modulus = 1.0\nparameters = {{ jm = 40 }}\nenergy = \"{e}\""
            )
        }
    })
}

fn material() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => text_law(),
        3 => (number()).prop_map(|k| format!("model = \"abb\"\nshear_modulus = 1.0\nkuhn = {k}")),
        2 => (number())
            .prop_map(|a| format!("model = \"mooney-rivlin\"\nshear_modulus = 1.0\nalpha = {a}")),
        2 => Just("model = \"neo-hookean\"\nshear_modulus = 1.0".to_string()),
        1 => Just("model = \"abb\"".to_string()),
        1 => Just("model = \"rubber\"\nshear_modulus = 1.0".to_string()),
    ]
}

fn mesh_table() -> impl Strategy<Value = String> {
    let sym = prop_oneof![
        Just("none"),
        Just("half"),
        Just("quarter"),
        Just("eighth"),
        Just("sixteenth")
    ];
    // the contact-edge keys and the element (issue #23's mesh that follows the edges)
    let extra = prop_oneof![
        3 => Just(""),
        1 => Just("\ntrack_contact_edge = true"),
        1 => Just("\nfit_contact_edge = true"),
        1 => Just("\ntrack_contact_edge = true\nelement = \"quad9\""),
        1 => Just("\nelement = \"quad9\"\nfit_contact_edge = true\ntrack_contact_edge = true"),
    ];
    // extreme integer keys (issue #25, class 2)
    let huge = prop_oneof![
        Just("cap_rows = 9223372036854775807"),
        Just("cap_rows = 1000000"),
        Just("around = 1000000000\nalong = 2"),
        Just("around = 8\nalong = 1000000000000"),
        Just("around = 18446744073709551616\nalong = 2"),
    ];
    prop_oneof![
        5 => ((1usize..4).prop_map(|k| 8 * k), (1usize..12).prop_map(|k| 2 * k), sym.clone(), extra)
            .prop_map(|(a, l, s, x)| format!("around = {a}\nalong = {l}\nsymmetry = \"{s}\"{x}")),
        1 => (huge, sym.clone()).prop_map(|(h, s)| if h.contains("around") {
            format!("{h}\nsymmetry = \"{s}\"")
        } else {
            format!("around = 8\nalong = 4\nsymmetry = \"{s}\"\n{h}")
        }),
        1 => (0usize..30, 0usize..30).prop_map(|(a, l)| format!("around = {a}\nalong = {l}")),
        1 => Just("file = \"mesh.json\"".to_string()),
        1 => Just("file = \"/dev/zero\"".to_string()),
        1 => Just(String::new()),
    ]
}

fn stage() -> impl Strategy<Value = String> {
    let steps = prop_oneof![Just(1usize), Just(2), Just(4), Just(6), Just(0)];
    prop_oneof![
        (number(), steps.clone()).prop_map(|(v, n)| format!(
            "[[stage]]\nkind = \"inflate\"\ncontrol = \"volume\"\ntarget_stretch = {v}\nsteps = {n}"
        )),
        (number(), steps.clone()).prop_map(|(v, n)| format!(
            "[[stage]]\nkind = \"inflate\"\ncontrol = \"pressure\"\ntarget_pressure = {v}\nsteps = {n}"
        )),
        (number(), steps.clone()).prop_map(|(v, n)| format!(
            "[[stage]]\nkind = \"inflate\"\ncontrol = \"volume\"\ntarget_volume_ratio = {v}\nsteps = {n}"
        )),
        (number(), steps.clone(), prop::option::of(number())).prop_map(|(v, n, k)| format!(
            "[[stage]]\nkind = \"squeeze\"\ntarget_rho = {v}\nsteps = {n}{}",
            k.map(|k| format!("\npenalty = {k}")).unwrap_or_default()
        )),
        Just("[[stage]]\nkind = \"inflate\"".to_string()),
        // confinement by 1 to 40 planes (issue #25, class 2: many planes)
        (prop::collection::vec((0.0f64..6.3, 0.9f64..1.5), 1..40), steps.clone()).prop_map(
            |(planes, n)| {
                let mut t = format!("[[stage]]\nkind = \"confine\"\nsteps = {n}");
                for (a, d) in planes {
                    t += &format!(
                        "\n[[stage.plane]]\nnormal = [{}, {}]\noffset = {d}\ntarget = {}",
                        a.cos(),
                        a.sin(),
                        0.8 * d
                    );
                }
                t
            }
        ),
    ]
}

/// A whole case file: half of them ordinary (a valid law, mesh and stages, so that the mesh,
/// the model, the contact and the outputs are reached), half hostile.
fn case_text() -> impl Strategy<Value = String> {
    prop_oneof![1 => ordinary_case(), 1 => hostile_case()]
}

/// An ordinary case: an admissible law (a built-in one or an energy written as text), a small
/// generated mesh, an inflation, then perhaps a squeeze or a confinement by two planes.
fn ordinary_case() -> impl Strategy<Value = String> {
    let law = prop_oneof![
        Just("model = \"abb\"\nshear_modulus = 1.0\nkuhn = 30".to_string()),
        Just("model = \"mooney-rivlin\"\nshear_modulus = 1.0\nalpha = 0.1".to_string()),
        Just("model = \"neo-hookean\"\nshear_modulus = 1.0".to_string()),
        (0.0f64..0.5).prop_map(|c| format!(
            "model = \"invariants\"\nshear_modulus = 1.0\nenergy = \"(I1 - 3) / 2 + {c} * (I1 - 3)^2\""
        )),
        Just("model = \"principal\"\nshear_modulus = 1.0\nenergy = \"(l^2 - 1) / 2\"".to_string()),
    ];
    let mesh = (
        prop_oneof![Just(8usize), Just(16)],
        (2usize..9).prop_map(|k| 2 * k),
        prop_oneof![Just("eighth"), Just("quarter"), Just("half")],
        prop_oneof![
            3 => Just(""),
            1 => Just("\ntrack_contact_edge = true\nelement = \"quad9\""),
            1 => Just("\nelement = \"quad9\""),
        ],
    )
        .prop_map(|(a, l, s, x)| format!("around = {a}\nalong = {l}\nsymmetry = \"{s}\"{x}"));
    let inflate = prop_oneof![
        (1.05f64..1.8, 1usize..4).prop_map(|(v, n)| format!(
            "[[stage]]\nkind = \"inflate\"\ncontrol = \"volume\"\ntarget_stretch = {v}\nsteps = {n}"
        )),
        (0.05f64..1.0, 1usize..4).prop_map(|(v, n)| format!(
            "[[stage]]\nkind = \"inflate\"\ncontrol = \"pressure\"\ntarget_pressure = {v}\nsteps = {n}"
        )),
    ];
    let next = prop_oneof![
        Just(String::new()),
        (0.3f64..1.0, 1usize..4).prop_map(|(r, n)| format!(
            "[[stage]]\nkind = \"squeeze\"\ntarget_rho = {r}\nsteps = {n}"
        )),
        (0.5f64..1.0, 1usize..4).prop_map(|(f, n)| format!(
            "[[stage]]\nkind = \"confine\"\nsteps = {n}\n[[stage.plane]]\nnormal = [0, 1]\noffset = 2.0\ntarget = {f}\n[[stage.plane]]\nnormal = [0, -1]\noffset = 2.0\ntarget = {f}"
        )),
    ];
    (0.5f64..3.0, 2.0f64..12.0, law, mesh, inflate, next).prop_map(|(r, l, law, mesh, i, n)| {
        format!(
            "[geometry]\nradius = {r}\nlength = {}\n[material]\n{law}\n[mesh]\n{mesh}\n{i}\n{n}\n",
            l * r
        )
    })
}

/// A hostile case file, sometimes with a damaged line.
fn hostile_case() -> impl Strategy<Value = String> {
    // mostly ordinary radii and lengths, and one file in eight damaged, so that most inputs
    // reach the mesh, the model and the run
    let dimension = prop_oneof![6 => (0.5f64..3.0).prop_map(|v| format!("{v}")), 1 => number()];
    (
        dimension.clone(),
        dimension.prop_map(|l| l.replace("0.", "4.")),
        material(),
        mesh_table(),
        // three inputs in four start with an ordinary inflation, so that later stages run
        (
            prop::option::weighted(
                0.75,
                (1.05f64..1.6, 1usize..4).prop_map(|(v, n)| format!(
                    "[[stage]]\nkind = \"inflate\"\ncontrol = \"volume\"\ntarget_stretch = {v}\nsteps = {n}"
                )),
            ),
            prop::collection::vec(stage(), 0..3),
        )
            .prop_map(|(first, rest)| first.into_iter().chain(rest).collect::<Vec<_>>()),
        prop::bool::weighted(0.125),
        0usize..400,
    )
        .prop_map(|(r, l, mat, mesh, stages, damage, at)| {
            let mut t = format!(
                "[geometry]\nradius = {r}\nlength = {l}\n[material]\n{mat}\n[mesh]\n{mesh}\n{}\n",
                stages.join("\n")
            );
            if damage && !t.is_empty() {
                let at = at.min(t.len() - 1);
                let at = (0..=at).rev().find(|&i| t.is_char_boundary(i)).unwrap_or(0);
                t.insert_str(at, "]=\"");
            }
            t
        })
}

/// A user mesh in tubemem's JSON form: a cube surface, damaged in one of several ways.
fn mesh_json() -> impl Strategy<Value = String> {
    let nodes = "[-1,-1,-1],[1,-1,-1],[1,1,-1],[-1,1,-1],[-1,-1,1],[1,-1,1],[1,1,1],[-1,1,1]";
    let quads = "[0,3,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]";
    prop_oneof![
        Just(format!(r#"{{"nodes": [{nodes}], "quads": [{quads}]}}"#)),
        Just(format!(
            r#"{{"nodes": [{nodes}], "quads": [{quads}], "plugs": [[]]}}"#
        )),
        Just(format!(
            r#"{{"nodes": [{nodes},[5,5,5]], "quads": [{quads}]}}"#
        )),
        Just(format!(
            r#"{{"nodes": [{nodes}], "quads": [{quads},[0,1,2,99]]}}"#
        )),
        Just(format!(
            r#"{{"nodes": [{nodes}], "quads": [{quads}], "plugs": [[0,1],[1,2]]}}"#
        )),
        Just(format!(r#"{{"nodes": [{nodes}], "quads": [[0,1,2,3]]}}"#)),
        Just(r#"{"nodes": [], "quads": []}"#.to_string()),
        Just(format!(
            r#"{{"nodes": [{nodes}], "quads": [{quads}], "symmetry": "eighth"}}"#
        )),
        (0usize..6).prop_map(move |i| {
            let q = quads.replace(&format!("[{i},"), "[0,");
            format!(r#"{{"nodes": [{nodes}], "quads": [{q}]}}"#)
        }),
        // transformed (issue #25, class 1): scaled, shifted, turned onto the x axis, doubled
        Just(format!(
            r#"{{"nodes": [{}], "quads": [{quads}]}}"#,
            nodes.replace('1', "2")
        )),
        Just(format!(
            r#"{{"nodes": [{}], "quads": [{quads}]}}"#,
            nodes.replace("-1,-1,", "4,-1,").replace("1,-1,", "6,-1,")
        )),
        Just(format!(
            r#"{{"nodes": [{nodes},{}], "quads": [{quads},{}]}}"#,
            nodes.replace("-1,", "9,"),
            quads
                .split("],[")
                .map(|q| q
                    .trim_matches(|c| c == '[' || c == ']')
                    .split(',')
                    .map(|v| (v.parse::<usize>().unwrap() + 8).to_string())
                    .collect::<Vec<_>>()
                    .join(","))
                .map(|q| format!("[{q}]"))
                .collect::<Vec<_>>()
                .join(",")
        )),
    ]
}

static SEQ: AtomicUsize = AtomicUsize::new(0);

/// Run one input; a panic or a NaN in a message or a finished run's numbers fails. `Ok(true)`
/// when the run finished, `Ok(false)` when it was refused or stopped with a good message.
fn check(text: &str, mesh: &str) -> Result<bool, TestCaseError> {
    let dir = std::env::temp_dir().join(format!(
        "tubemem-fuzz-{}-{}",
        std::process::id(),
        SEQ.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("mesh.json"), mesh).unwrap();
    let started = Instant::now();
    let outcome = std::panic::catch_unwind(|| {
        let mut case = match Case::parse(text) {
            Ok(c) => c,
            Err(e) => return Err(tubemem_app::error_chain(&e)),
        };
        case.base_dir = dir.clone();
        let mut writer = RunWriter::create(&dir.join("out"), FolderMode::Fresh, case.hash(), &[])
            .map_err(|e| e.chain())?;
        let flag = Arc::new(AtomicBool::new(false));
        let f = flag.clone();
        let done = Arc::new(AtomicBool::new(false));
        let d = done.clone();
        let timer = std::thread::spawn(move || {
            let t0 = Instant::now();
            while !d.load(Ordering::Relaxed) && t0.elapsed() < Duration::from_secs(2) {
                std::thread::sleep(Duration::from_millis(5));
            }
            f.store(true, Ordering::Relaxed);
        });
        let options = RunOptions {
            interrupt: Some(flag),
            ..RunOptions::default()
        };
        let out = run_with(&case, "fuzz", &options, &mut [&mut writer]);
        done.store(true, Ordering::Relaxed);
        let _ = timer.join();
        match out.error {
            Some(e) => Err(e.chain()),
            None => Ok(serde_json::to_value(out.report.summary()).unwrap()),
        }
    });
    let seconds = started.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&dir);
    prop_assert!(
        seconds < 10.0,
        "{seconds:.1} s (over the 10 s limit) for:\n{text}"
    );
    match outcome {
        Err(_) => Err(TestCaseError::fail(format!(
            "panic on input:\n{text}\n--- mesh:\n{mesh}"
        ))),
        Ok(Err(msg)) => {
            if std::env::var_os("TUBEMEM_FUZZ_SHOW").is_some() {
                eprintln!(
                    "REFUSED: {}",
                    msg.chars()
                        .take(600)
                        .collect::<String>()
                        .replace('\n', " / ")
                );
            }
            check_message(&msg, text).map(|()| false)
        }
        Ok(Ok(summary)) => {
            prop_assert!(
                all_finite(&summary),
                "a non-finite number in the summary of:\n{}",
                text
            );
            Ok(true)
        }
    }
}

/// An error message: not empty, no `NaN` unless the input has one, no run of more than 20
/// digits, and no line longer than the longest a message may quote (an echoed input is cut).
fn check_message(msg: &str, full_input: &str) -> Result<(), TestCaseError> {
    let input: String = full_input.chars().take(3000).collect();
    prop_assert!(
        !msg.trim().is_empty(),
        "empty error message for:\n{}",
        input
    );
    // a NaN in a message is a missing check upstream, unless it is the user's own value or the
    // message says that this value is what is wrong ("… is NaN, not a finite number")
    let explained = msg.contains("not a finite number") || msg.contains("not finite");
    prop_assert!(
        !msg.contains("NaN") || full_input.to_lowercase().contains("nan") || explained,
        "NaN in the message `{}` for:\n{}",
        msg,
        input
    );
    let digits = msg
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    prop_assert!(
        digits <= 20,
        "a number of {} digits in the message `{}` for:\n{}",
        digits,
        msg,
        input
    );
    let longest = msg.lines().map(|l| l.chars().count()).max().unwrap_or(0);
    prop_assert!(
        longest <= tubemem_material::MAX_MESSAGE_LINE + 60,
        "a message line of {} characters for an input of {} bytes",
        longest,
        input.len()
    );
    Ok(())
}

/// The runner of a fuzz test, its number of inputs and its time limit: `default_cases` inputs
/// from a fixed seed in the test command; with `TUBEMEM_FUZZ_CASES` (and `TUBEMEM_FUZZ_SECONDS`,
/// default 600) a long run from a fresh seed, which explores.
fn fuzz_runner(default_cases: u32) -> (TestRunner, u32, u64) {
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let cases =
        env("TUBEMEM_FUZZ_CASES").map_or(default_cases, |c| c.min(u64::from(u32::MAX)) as u32);
    let seconds = env("TUBEMEM_FUZZ_SECONDS").unwrap_or(600);
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let runner = if std::env::var_os("TUBEMEM_FUZZ_CASES").is_some() {
        TestRunner::new(config)
    } else {
        TestRunner::new_with_rng(
            config,
            proptest::test_runner::TestRng::deterministic_rng(
                proptest::test_runner::RngAlgorithm::ChaCha,
            ),
        )
    };
    (runner, cases, seconds)
}

/// The failing inputs of a fuzz test. In the test command the first one fails the test at
/// once; in a long run (`TUBEMEM_FUZZ_CASES`) each is written whole, with its message, to
/// `target/fuzz-findings/<test>-<n>.txt` and the run goes on, so that one finding does not end
/// a 30-minute run; the test fails at its end if there was any.
struct Findings {
    test: &'static str,
    long: bool,
    count: usize,
}

impl Findings {
    fn new(test: &'static str) -> Self {
        Findings {
            test,
            long: std::env::var_os("TUBEMEM_FUZZ_CASES").is_some(),
            count: 0,
        }
    }

    fn folder() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-findings")
    }

    fn record(&mut self, n: u64, failure: &str, input: &str) {
        if !self.long {
            panic!("fuzz input {n} failed: {failure}");
        }
        self.count += 1;
        let dir = Self::folder();
        let _ = std::fs::create_dir_all(&dir);
        let path = dir.join(format!("{}-{n}.txt", self.test));
        let _ = std::fs::write(&path, format!("{failure}\n=== input ===\n{input}\n"));
        let head: String = failure.chars().take(200).collect();
        eprintln!(
            "fuzz ({}): input {n} failed, written to {}: {head}",
            self.test,
            path.display()
        );
    }

    /// The run's outcome in words, for its summary line.
    fn outcome(&self) -> String {
        match self.count {
            0 => "no failure".to_string(),
            n => format!("{n} failing inputs (in {})", Self::folder().display()),
        }
    }

    fn finish(&self) {
        assert!(
            self.count == 0,
            "{} failing inputs, written to {}",
            self.count,
            Self::folder().display()
        );
    }
}

/// The generated inputs: 48 in the test command, more with `TUBEMEM_FUZZ_CASES`, for at most
/// `TUBEMEM_FUZZ_SECONDS`.
#[test]
fn no_input_makes_tubemem_panic() {
    let (mut runner, cases, seconds) = fuzz_runner(48);
    let mut found = Findings::new("runs");
    let t0 = Instant::now();
    // inputs drawn one by one, so that a long run stops at its deadline
    let strategy = (case_text(), mesh_json());
    let mut ran = 0u64;
    let mut finished = 0u64;
    while ran < u64::from(cases) && t0.elapsed().as_secs() < seconds {
        let (text, mesh) = strategy
            .new_tree(&mut runner)
            .expect("the strategy always produces a value")
            .current();
        ran += 1;
        match check(&text, &mesh) {
            Ok(done) => finished += u64::from(done),
            Err(e) => found.record(ran, &format!("{e}"), &format!("{text}\n--- mesh:\n{mesh}")),
        }
    }
    eprintln!(
        "fuzz (runs): {ran} inputs ({finished} finished, {} refused or stopped with a message) in {:.1} s, {}",
        ran - finished,
        t0.elapsed().as_secs_f64(),
        found.outcome()
    );
    found.finish();
}

/// The crash inputs reported before, as regression seeds: each is now a typed error (or runs).
#[test]
fn reported_crash_inputs_are_errors_now() {
    let small = include_str!("../../../cases/small_abb30_ls1.2.toml");
    let user = small
        .replace("around = 16\n", "file = \"mesh.json\"\n")
        .replace("along = 24\n", "")
        .replace("symmetry = \"eighth\"\n", "");
    let nodes = "[-1,-1,-1],[1,-1,-1],[1,1,-1],[-1,1,-1],[-1,-1,1],[1,-1,1],[1,1,1],[-1,1,1]";
    let quads = "[0,3,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]";
    let seeds = [
        // P3: an empty plug ring
        (user.clone(), format!(r#"{{"nodes": [{nodes}], "quads": [{quads}], "plugs": [[]]}}"#)),
        // P4: a node no quad uses
        (user.clone(), format!(r#"{{"nodes": [{nodes},[5,5,5]], "quads": [{quads}]}}"#)),
        // S2, D1: a squeeze to ρ = 1e-300, a penalty of 1e-300
        (format!("{small}\n[[stage]]\nkind = \"squeeze\"\ntarget_rho = 1e-300\n"), String::new()),
        (format!("{small}\n[[stage]]\nkind = \"squeeze\"\ntarget_rho = 1.0\npenalty = 1e-300\n"), String::new()),
        // a squeeze after a squeeze
        (format!("{small}\n[[stage]]\nkind = \"squeeze\"\ntarget_rho = 1.0\n\n[[stage]]\nkind = \"squeeze\"\ntarget_rho = 0.9\n"), String::new()),
        // radius and length at the ends of the floating-point range
        (small.replace("radius = 1.0", "radius = 1e-308"), String::new()),
        (small.replace("length = 8.0", "length = 1e308"), String::new()),
        // found by the long fuzz run: a squeeze that shuts a short tube (the gas volume goes
        // through zero and the residual was NaN in the Newton history)
        (
            "[geometry]\nradius = 6\nlength = 1\n[material]\nmodel = \"neo-hookean\"\nshear_modulus = 1.0\n[mesh]\naround = 8\nalong = 2\nsymmetry = \"none\"\n[[stage]]\nkind = \"inflate\"\ncontrol = \"volume\"\ntarget_stretch = 2\nsteps = 1\n[[stage]]\nkind = \"squeeze\"\ntarget_rho = 1e-300\nsteps = 1\npenalty = 1e308\n".to_string(),
            String::new(),
        ),
        // found by the 30-minute run of 2026-12-02: a pressure target of 1e308 beyond the law's
        // maximum, with the mesh fitted by a locating solve; the probe for the maximum walked
        // towards 1e308 for over ten minutes and the locator ignored the interrupt
        (
            "[geometry]\nradius = 2.3874449059406295\nlength = 1.0486937012836541\n[material]\nmodel = \"abb\"\nshear_modulus = 1.0\nkuhn = 77\n[mesh]\naround = 8\nalong = 16\nsymmetry = \"quarter\"\nfit_contact_edge = true\n[[stage]]\nkind = \"inflate\"\ncontrol = \"pressure\"\ntarget_pressure = 1e308\nsteps = 2\n[[stage]]\nkind = \"squeeze\"\ntarget_rho = 1.7142699393509986\nsteps = 4\n".to_string(),
            String::new(),
        ),
        // found by the 30-minute run of 2026-12-07: a principal energy of 7000 terms; the
        // run's closed-form limit-point scan took minutes and ignored the interrupt (28 s here)
        (
            format!(
                "[geometry]\nradius = 1.14\nlength = 2.1\n[material]\nmodel = \"principal\"\nshear_modulus = 1.0\nenergy = \"{}\"\n[mesh]\naround = 16\nalong = 12\nsymmetry = \"eighth\"\n[[stage]]\nkind = \"inflate\"\ncontrol = \"volume\"\ntarget_stretch = 1.59\nsteps = 3\n",
                vec!["(l - 3)"; 7000].join(" + ")
            ),
            String::new(),
        ),
        // a case file that is /dev/zero is covered by `Case::read`'s size limit; a mesh file too
        (user.replace("mesh.json", "/dev/zero"), String::new()),
    ];
    for (text, mesh) in seeds {
        check(&text, &mesh).unwrap();
    }
}

/// A fit's test data as a CSV file (issue #61): headers in either order, with or without a
/// unit, extra columns, decimal commas, text, non-finite and extreme values, a missing header.
fn fit_csv() -> impl Strategy<Value = String> {
    let header = prop_oneof![
        Just("stretch,nominal_stress_mpa"),
        Just("stretch,nominal_stress_kpa"),
        Just("stretch,nominal_stress_pa"),
        Just("nominal_stress_mpa,stretch"),
        Just("stretch,nominal_stress"),
        Just("stretch,stress_mpa,temperature"),
        Just("time,stretch,nominal_stress_mpa"),
        Just("a,b"),
        Just(""),
    ];
    let value = prop_oneof![
        6 => (0.0f64..3.0).prop_map(|v| format!("{v}")),
        1 => Just("nan".to_string()),
        1 => Just("inf".to_string()),
        1 => Just("1e300".to_string()),
        1 => Just("-1e300".to_string()),
        1 => Just("0,5".to_string()),
        1 => Just("x".to_string()),
        1 => Just(String::new()),
    ];
    (
        header,
        prop::collection::vec((1.0f64..3.0, value.clone(), value), 0..12),
        any::<bool>(),
    )
        .prop_map(|(h, rows, exact)| {
            let mut t = format!("{h}\n");
            for (l, a, b) in rows {
                // exact data of a neo-Hookean law (μ = 0.3 MPa) are a fit's easiest input
                if exact {
                    t += &format!("{l},{}\n", 0.3 * (l - 1.0 / (l * l)));
                } else if h.starts_with("time") {
                    t += &format!("{a},{l},{b}\n");
                } else {
                    t += &format!("{l},{a}\n");
                }
            }
            t
        })
}

/// An atlas file: the CI atlas's template with its `[atlas]` keys drawn from ordinary and
/// hostile values (empty lists, non-positive lengths, three-component normals, huge grids).
fn atlas_text() -> impl Strategy<Value = String> {
    let list = |ok: &'static str| {
        prop_oneof![
            4 => Just(ok.to_string()),
            1 => Just("[]".to_string()),
            1 => Just("[-1, 0]".to_string()),
            1 => Just("[nan]".to_string()),
            1 => Just("[1e308, 2e308]".to_string()),
            1 => (2usize..2000).prop_map(|n| format!(
                "[{}]",
                (0..n).map(|i| format!("{}", 1.1 + i as f64 * 1e-3)).collect::<Vec<_>>().join(", ")
            )),
        ]
    };
    let extra = prop_oneof![
        3 => Just(String::new()),
        1 => Just("quantities = []".to_string()),
        1 => Just("quantities = [\"w\", \"force\", \"nonsense\"]".to_string()),
        1 => Just("max_runs = 0".to_string()),
        1 => Just("max_runs = 3".to_string()),
        1 => Just("[[atlas.plane]]\nnormal = [0, 1, 5]\noffset = 1.2".to_string()),
        1 => Just("[[atlas.plane]]\nnormal = [0, 0]\noffset = 1.2".to_string()),
        1 => Just("along_per_radius = 1e300".to_string()),
    ];
    (
        list("[1.2, 1.3]"),
        list("[1.0, 0.9]"),
        list("[10, 20, 40]"),
        list("[1e-2, 1e-3]"),
        extra,
    )
        .prop_map(|(s, r, l, e, x)| {
            let along = if x.starts_with("along") {
                String::new()
            } else {
                "along_per_radius = 4\n".to_string()
            };
            format!(
                "[geometry]\nradius = 1.0\nthickness = 0.01\ncaps = \"hemisphere\"\n[material]\nmodel = \"abb\"\nshear_modulus = 1.0\nkuhn = 30\n[mesh]\naround = 16\nsymmetry = \"eighth\"\n[atlas]\nstretches = {s}\nrho = {r}\nlengths = {l}\nepsilon = {e}\n{along}{x}\n"
            )
        })
}

/// A verification suite: checks whose names, kinds, tolerances and cases are drawn from
/// ordinary and hostile values (names with dots and slashes, NaN or negative tolerances, a
/// rel_err outside (0, 1), missing cases, duplicates).
fn suite_text() -> impl Strategy<Value = String> {
    let name = prop_oneof![
        4 => "[a-z]{1,8}".prop_map(|s| s),
        1 => Just("..".to_string()),
        1 => Just(".".to_string()),
        1 => Just("a/b".to_string()),
        1 => Just("".to_string()),
        1 => Just("ä ü".to_string()),
    ];
    let kind = prop_oneof![
        Just("closed-form"),
        Just("convergence"),
        Just("reference"),
        Just("gold"),
        Just("invariance"),
        Just("nonsense"),
    ];
    let tol = prop_oneof![
        4 => (1e-6f64..1.0).prop_map(|v| format!("{{ value = {v}, source = \"fuzz\" }}")),
        1 => Just("{ value = nan, source = \"fuzz\" }".to_string()),
        1 => Just("{ value = -1.0, source = \"fuzz\" }".to_string()),
        1 => Just("{ value = 1.0 }".to_string()),
        1 => Just("1.0".to_string()),
    ];
    let case = prop_oneof![
        4 => Just("case.toml"),
        1 => Just("missing.toml"),
        1 => Just("/dev/zero"),
        1 => Just("."),
    ];
    let extra = prop_oneof![
        4 => Just(String::new()),
        1 => Just("rel_err = 2.0".to_string()),
        1 => Just("rel_err = nan".to_string()),
        1 => Just("abs_zero = -1.0".to_string()),
        1 => Just("meshes = [8, 0]".to_string()),
        1 => Just("start = -10".to_string()),
        1 => Just("refinement = 1.0".to_string()),
    ];
    prop::collection::vec((name, kind, tol, case, extra), 0..5).prop_map(|checks| {
        checks
            .into_iter()
            .map(|(n, k, t, c, x)| {
                format!("[[check]]\nname = \"{n}\"\ncase = \"{c}\"\nkind = \"{k}\"\ntolerance.w = {t}\n{x}\n")
            })
            .collect::<Vec<_>>()
            .join("\n")
    })
}

/// One input of the library-level generators, in a scratch folder `dir`.
#[derive(Debug, Clone)]
enum LibraryInput {
    /// a text law, then a closed-form inflation to `to` and a flattening to `rho`
    Law(String, f64, f64),
    Fit(String, &'static str),
    Atlas(String),
    Suite(String),
}

fn library_input() -> impl Strategy<Value = LibraryInput> {
    prop_oneof![
        3 => (text_law(), 1.0f64..8.0, 0.05f64..1.5).prop_map(|(l, t, r)| LibraryInput::Law(l, t, r)),
        2 => (fit_csv(), prop_oneof![Just("neo-hookean"), Just("yeoh"), Just("mooney-rivlin"), Just("ogden")])
            .prop_map(|(c, m)| LibraryInput::Fit(c, m)),
        2 => atlas_text().prop_map(LibraryInput::Atlas),
        2 => suite_text().prop_map(LibraryInput::Suite),
    ]
}

/// Run one library-level input: a panic fails; an error must name its cause (as
/// [`check_message`]); a returned closed-form state, fit or plan must be finite, and a
/// returned closed-form state must be a tensed membrane under a non-negative pressure (issue
/// #61: a compressive branch is reported as such, never returned).
/// `Ok(true)` when the input was accepted, `Ok(false)` when it was refused with a good message.
fn check_library(input: &LibraryInput, dir: &Path) -> Result<bool, TestCaseError> {
    use tubemem_gps::Hypothesis;
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("case.toml"),
        include_str!("../../../cases/small_abb30_ls1.2.toml"),
    )
    .unwrap();
    let started = Instant::now();
    let full = format!("{input:?}");
    let shown: String = full.chars().take(3000).collect();
    let outcome = std::panic::catch_unwind(|| -> Result<serde_json::Value, String> {
        match input {
            LibraryInput::Law(body, to, rho) => {
                let spec: tubemem_material::MaterialSpec = toml::from_str(body)
                    .map_err(|e| tubemem_material::tidy_numbers(&e.to_string()))?;
                let law = spec.build().map_err(|e| e.to_string())?;
                let mut out = vec![];
                for hyp in [Hypothesis::Gps, Hypothesis::Ps] {
                    match tubemem_gps::inflation_curve(law.as_ref(), hyp, 1.0, *to, 4) {
                        Ok(states) => {
                            for s in &states {
                                if s.n_s < 0.0 || s.w < 0.0 {
                                    return Ok(
                                        serde_json::json!({"compressive": true, "n_s": s.n_s, "w": s.w}),
                                    );
                                }
                            }
                            out.push(serde_json::to_value(&states).unwrap());
                        }
                        Err(e) => return Err(e.to_string()),
                    }
                    let initial = to.max(1.05);
                    match tubemem_gps::flatten(law.as_ref(), hyp, initial, rho * initial) {
                        Ok(s) => {
                            if s.n_s < 0.0 || s.w < 0.0 {
                                return Ok(
                                    serde_json::json!({"compressive": true, "n_s": s.n_s, "w": s.w}),
                                );
                            }
                            out.push(serde_json::to_value(s).unwrap());
                        }
                        Err(e) => return Err(e.to_string()),
                    }
                }
                Ok(serde_json::Value::Array(out))
            }
            LibraryInput::Fit(csv, model) => {
                let path = dir.join("data.csv");
                std::fs::write(&path, csv).unwrap();
                let file = tubemem_app::fit::read_test_file(
                    &path,
                    tubemem_material::fit::Mode::Uniaxial,
                    None,
                )
                .map_err(|e| tubemem_app::error_chain(&e))?;
                let data = [file.data];
                let start = tubemem_app::fit::default_start(model, &data)
                    .map_err(|e| tubemem_app::error_chain(&e))?;
                let r = tubemem_app::fit::run_fit(&start, &data)
                    .map_err(|e| tubemem_app::error_chain(&e))?;
                Ok(serde_json::to_value(&r).unwrap())
            }
            LibraryInput::Atlas(text) => {
                let atlas = tubemem_app::atlas::Atlas::parse(text, dir)
                    .map_err(|e| tubemem_app::error_chain(&e))?;
                // every member's case is a valid case (checked, not run)
                for m in atlas.members.iter().take(50) {
                    Case::parse(&m.case_text).map_err(|e| tubemem_app::error_chain(&e))?;
                }
                Ok(serde_json::json!({"members": atlas.members.len()}))
            }
            LibraryInput::Suite(text) => {
                let path = dir.join("suite.toml");
                std::fs::write(&path, text).unwrap();
                let (_, checks) = tubemem_app::verify::suite::read_suite(&path)
                    .map_err(|e| tubemem_app::error_chain(&e))?;
                Ok(serde_json::json!({"checks": checks.len()}))
            }
        }
    });
    let seconds = started.elapsed().as_secs_f64();
    prop_assert!(
        seconds < 10.0,
        "{seconds:.1} s (over the 10 s limit) for:\n{shown}"
    );
    match outcome {
        Err(_) => Err(TestCaseError::fail(format!("panic on input:\n{shown}"))),
        Ok(Err(msg)) => {
            if std::env::var_os("TUBEMEM_FUZZ_SHOW").is_some() {
                eprintln!(
                    "REFUSED: {}",
                    msg.chars()
                        .take(600)
                        .collect::<String>()
                        .replace('\n', " / ")
                );
            }
            check_message(&msg, &full).map(|()| false)
        }
        Ok(Ok(v)) => {
            prop_assert!(
                v.get("compressive").is_none(),
                "a compressive closed-form state returned ({v}) for:\n{shown}"
            );
            prop_assert!(all_finite(&v), "a non-finite number in {v} for:\n{shown}");
            Ok(true)
        }
    }
}

/// The library-level generators (issue #61): energies as text through the closed form, fit
/// CSVs through the reader and the fit, atlas files through the planner, verify suites
/// through the reader. 64 inputs in the test command (fixed seed); more with
/// `TUBEMEM_FUZZ_CASES` and `TUBEMEM_FUZZ_SECONDS`, as the run-level test above.
#[test]
fn no_law_fit_atlas_or_suite_input_makes_tubemem_panic() {
    let (mut runner, cases, seconds) = fuzz_runner(64);
    let mut found = Findings::new("library");
    let t0 = Instant::now();
    let dir = std::env::temp_dir().join(format!("tubemem-fuzz-lib-{}", std::process::id()));
    let strategy = library_input();
    let mut counts = [0u64; 4];
    let mut refused = 0u64;
    let mut ran = 0u64;
    while ran < u64::from(cases) && t0.elapsed().as_secs() < seconds {
        let input = strategy
            .new_tree(&mut runner)
            .expect("the strategy always produces a value")
            .current();
        ran += 1;
        counts[match input {
            LibraryInput::Law(..) => 0,
            LibraryInput::Fit(..) => 1,
            LibraryInput::Atlas(_) => 2,
            LibraryInput::Suite(_) => 3,
        }] += 1;
        match check_library(&input, &dir) {
            Ok(accepted) => refused += u64::from(!accepted),
            Err(e) => found.record(ran, &format!("{e}"), &format!("{input:?}")),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "fuzz (laws, fits, atlases, suites): {ran} inputs ({} laws, {} fits, {} atlases, {} suites; {} accepted, {refused} refused with a message) in {:.1} s, {}",
        counts[0],
        counts[1],
        counts[2],
        counts[3],
        ran - refused,
        t0.elapsed().as_secs_f64(),
        found.outcome()
    );
    found.finish();
}
