//! The atlas (`tubemem_app::atlas`): atlas/ci.toml run, its inverse laws held against FE runs at
//! lengths the atlas did not use, its coefficient against the README's direct L/R study, the
//! plane-strain map against the closed form, resume, failed members and bad files.

use std::path::{Path, PathBuf};
use tubemem_app::atlas::{self, member, Atlas, Member, MemberResult};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tubemem-atlas-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn ci_atlas() -> (Atlas, String) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../atlas/ci.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    (Atlas::read(&path).unwrap(), text)
}

/// One FE run of the atlas's tube at a length of our choosing.
fn run_at(atlas: &Atlas, stretch: f64, length: f64, dir: &Path) -> MemberResult {
    let m = Member {
        name: format!("held_out_ls{stretch}_lr{length}"),
        stretch,
        length,
        case_text: atlas.member_case(stretch, length).unwrap(),
    };
    let r = member::run(atlas, &m, dir);
    assert!(r.error.is_none(), "{:?}", r.error);
    r
}

fn measured(r: &MemberResult, rho: f64, q: &str) -> f64 {
    let qi = atlas::spec::QUANTITIES
        .iter()
        .position(|x| *x == q)
        .unwrap();
    r.level(rho).unwrap().values[qi].unwrap().error()
}

/// The ci atlas (ABB 𝒩 = 30, plates, 9-node 32 around, L/R = 10, 20, 40): every point has a
/// law; the law c + A/(L/R) predicts FE runs at L/R = 30 (not in the atlas) within 10 % of the
/// prediction at three (λs*, ρ) points (the issue's requirement); at the atlas's minimum L/R
/// for ε = 1e-2 the measured end effect |FE/GPS − 1 − c| lies in [0.8 ε, 1.2 ε] at three
/// points; ϖ's coefficient at λs* = 1.3, ρ = 0.8 matches the README's direct study
/// (A = −0.2521 from 64 four-node elements around at L/R = 20, 40, 80) within 5 %: two fits of
/// one law on different meshes and lengths, each with a relative residual of about 0.005, so a
/// few per cent is their expected spread; a wrong law (exponential) or a wrong quantity is off
/// by far more.
#[test]
fn the_ci_atlas_predicts_lengths_it_did_not_run() {
    let (atlas, text) = ci_atlas();
    let out = tmp("ci");
    let o = atlas::run(&atlas, &text, &out, 2, &|_| {}).unwrap();
    assert!(o.missing.is_empty());
    assert!(o.results.iter().all(|r| r.error.is_none()));
    let flagged: Vec<_> = o.points.iter().filter(|p| p.flag.is_some()).collect();
    assert!(flagged.is_empty(), "{flagged:?}");
    let point = |s: f64, rho: f64, q: &str| {
        o.points
            .iter()
            .find(|p| p.stretch == s && p.rho == rho && p.quantity == q)
            .unwrap()
    };
    let a = point(1.3, 0.8, "w").fit.unwrap().a;
    assert!((a / -0.2521 - 1.0).abs() < 0.05, "A = {a}");
    // held-out length L/R = 30
    let r13 = run_at(&atlas, 1.3, 30.0, &out.join("held_out_13"));
    let r12 = run_at(&atlas, 1.2, 30.0, &out.join("held_out_12"));
    for (r, s, rho, q) in [
        (&r13, 1.3, 0.8, "w"),
        (&r13, 1.3, 0.9, "force"),
        (&r12, 1.2, 1.0, "w"),
        (&r12, 1.2, 0.9, "force"),
    ] {
        let predicted = point(s, rho, q).predict(30.0).unwrap();
        let m = measured(r, rho, q);
        eprintln!("held out L/R = 30, λs* = {s}, ρ = {rho}, {q}: measured {m:.5e}, predicted {predicted:.5e}, {:.2} %", 100.0 * (m / predicted - 1.0));
        assert!(
            (m - predicted).abs() <= 0.1 * predicted.abs(),
            "{q} at ({s}, {rho}): {m} against {predicted}"
        );
    }
    // at the minimum length for ε = 1e-2
    for (s, rho, q) in [(1.3, 0.8, "w"), (1.3, 0.9, "force"), (1.2, 0.9, "force")] {
        let p = point(s, rho, q);
        let l = p.min_length[0].unwrap();
        let r = run_at(&atlas, s, l, &out.join(format!("min_{s}_{rho}_{q}")));
        let end = (measured(&r, rho, q) - p.fit.unwrap().c).abs();
        eprintln!("at the minimum L/R = {l:.3} for ε = 1e-2, λs* = {s}, ρ = {rho}, {q}: |FE/GPS − 1 − c| = {end:.4e}");
        assert!(
            (0.8e-2..=1.2e-2).contains(&end),
            "{q} at ({s}, {rho}), L/R = {l}: {end}"
        );
    }
    // resumed: nothing rerun, the same files
    let csv = std::fs::read(out.join("atlas.csv")).unwrap();
    let again = atlas::run(&atlas, &text, &out, 2, &|p| assert!(p.resumed)).unwrap();
    assert_eq!(again.resumed, atlas.members.len());
    assert_eq!(std::fs::read(out.join("atlas.csv")).unwrap(), csv);
    // every member folder keeps the case it ran, which the case reader accepts as it is
    for m in &atlas.members {
        let t = std::fs::read_to_string(out.join("runs").join(&m.name).join("case.toml")).unwrap();
        tubemem_app::case::Case::parse(&t).unwrap();
    }
    // predict at a grid point is the point's law; between grid points it interpolates
    let json = atlas::predict::read(&out).unwrap();
    let at = atlas::predict::predict(&json, 1.3, 0.8, 30.0).unwrap();
    assert_eq!(at[0].error, point(1.3, 0.8, "w").predict(30.0).unwrap());
    let mid = atlas::predict::predict(&json, 1.25, 0.85, 30.0).unwrap();
    assert!(mid[0].error.is_finite());
    let e = atlas::predict::predict(&json, 1.5, 0.85, 30.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("outside the atlas's grid"), "{e}");
    // issue #61: below every length run the end-effect law is not known (refused); beyond the
    // longest it is the law's extrapolation (answered, and marked so)
    let e = atlas::predict::predict(&json, 1.3, 0.8, 0.001)
        .unwrap_err()
        .to_string();
    assert!(e.contains("below every length the atlas ran"), "{e}");
    assert_eq!(at[0].length_extent, atlas::fit::Extent::Within);
    let far = atlas::predict::predict(&json, 1.3, 0.8, 400.0).unwrap();
    assert_eq!(far[0].length_extent, atlas::fit::Extent::BeyondRuns);
    // atlas.csv says where each minimum length lies against the runs
    let table = String::from_utf8(csv.clone()).unwrap();
    assert!(table
        .lines()
        .next()
        .unwrap()
        .contains("min_length_ratio,min_length_extent,"));
    std::fs::remove_dir_all(&out).unwrap();
}

/// The plane-strain map is the closed form: each grid value equals gps::flatten's at that
/// point, to the last bit (its CSV holds shortest round-trip numbers).
#[test]
fn the_ps_map_is_the_closed_form_at_every_point() {
    let law = tubemem_material::MaterialSpec::Svk {
        young_modulus: 1.0,
        poisson_ratio: 0.3,
    };
    let built = law.build().unwrap();
    let g = atlas::ps_map::grid(
        built.as_ref(),
        atlas::ps_map::MapSupply::Closed,
        (1.05, 1.4),
        (0.7, 1.4),
        9,
    );
    let csv = atlas::ps_map::csv(&g);
    let mut checked = 0;
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (s, rho): (f64, f64) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        let q = f[2];
        if rho >= s {
            assert!(f[3].is_empty() && f[4].is_empty(), "{line}");
            continue;
        }
        let v = |h| {
            let st = tubemem_gps::flatten(built.as_ref(), h, s, rho).unwrap();
            match q {
                "w" => st.w,
                "force" => st.force,
                "chi" => st.chi,
                _ => st.lambda_s,
            }
        };
        let (gps, ps) = (
            v(tubemem_gps::Hypothesis::Gps),
            v(tubemem_gps::Hypothesis::Ps),
        );
        assert_eq!(f[3].parse::<f64>().unwrap(), gps, "{line}");
        assert_eq!(f[4].parse::<f64>().unwrap(), ps, "{line}");
        assert_eq!(
            f[5].parse::<f64>().unwrap(),
            (ps / gps - 1.0).abs(),
            "{line}"
        );
        checked += 1;
    }
    assert!(checked > 100, "{checked}");
}

/// A member that fails is kept as an error with the levels it reached; the other members are
/// fitted and the failed member's points are flagged `run-failed` with its reason.
#[test]
fn a_failed_member_is_kept_and_loses_none_of_the_others() {
    let text = r#"
[geometry]
radius = 1.0
thickness = 0.01
caps = "hemisphere"
[material]
model = "abb"
shear_modulus = 1.0
kuhn = 30
[mesh]
around = 16
symmetry = "eighth"
[solver]
max_iterations = 4
[atlas]
stretches = [1.2, 2.0]
rho = [1.1, 1.0]
lengths = [10, 20, 40]
along_per_radius = 2
inflate = { steps = 1 }
"#;
    let atlas = Atlas::parse(text, Path::new(".")).unwrap();
    let out = tmp("failed");
    let o = atlas::run(&atlas, text, &out, 2, &|_| {}).unwrap();
    let failed: Vec<_> = o.results.iter().filter(|r| r.error.is_some()).collect();
    assert!(
        !failed.is_empty() && failed.iter().all(|r| r.stretch == 2.0),
        "{failed:?}"
    );
    for p in &o.points {
        if p.stretch == 1.2 {
            assert!(p.flag.is_none() && p.min_length[0].is_some(), "{p:?}");
        } else {
            let f = p.flag.as_ref().unwrap();
            assert_eq!(f.flag, "run-failed", "{f:?}");
            assert!(f.reason.contains("did not reach"), "{f:?}");
        }
    }
    let csv = std::fs::read_to_string(out.join("atlas.csv")).unwrap();
    assert!(csv.contains(",run-failed,"));
    let runs = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    assert!(runs.contains("no convergence"), "{runs}");
    std::fs::remove_dir_all(&out).unwrap();
}

/// Bad atlas files: the key (and where the TOML reader knows it, the line) is named, and
/// nothing is written.
#[test]
fn bad_atlas_files_name_the_key() {
    let base = r#"
[geometry]
radius = 1.0
thickness = 0.01
[material]
model = "neo-hookean"
shear_modulus = 1.0
[mesh]
around = 16
symmetry = "eighth"
"#;
    let err = |atlas: &str| {
        let e = Atlas::parse(&format!("{base}{atlas}"), Path::new(".")).unwrap_err();
        tubemem_app::error_chain(&e)
    };
    let ok =
        "[atlas]\nstretches = [1.3]\nrho = [1.0]\nlengths = [10, 20, 40]\nalong_per_radius = 2\n";
    assert!(Atlas::parse(&format!("{base}{ok}"), Path::new(".")).is_ok());
    let e = err(&ok.replace("rho =", "rhoo ="));
    assert!(e.contains("rhoo") && e.contains("line 13"), "{e}");
    let e = err(&ok.replace("[10, 20, 40]", "[10, 20]"));
    assert!(
        e.contains("atlas.lengths") && e.contains("third length"),
        "{e}"
    );
    let e = err(&ok.replace("[1.0]", "[1.4]"));
    assert!(
        e.contains("atlas.rho") && e.contains("no level is below λs* = 1.3"),
        "{e}"
    );
    let e = err(&ok.replace("[1.3]", "[0.9]"));
    assert!(e.contains("atlas.stretches"), "{e}");
    let e = err(&format!("{ok}quantities = [\"force\", \"pressure\"]\n"));
    assert!(
        e.contains("atlas.quantities") && e.contains("\"pressure\""),
        "{e}"
    );
    // planes: each plane's keys named with its index; the plates' quantities refused
    let planes = "[[atlas.plane]]\nnormal = [0, 1]\n[[atlas.plane]]\nnormal = [0, -1]\n";
    assert!(Atlas::parse(&format!("{base}{ok}{planes}"), Path::new(".")).is_ok());
    let e = err(&format!("{ok}{}", planes.replacen("[0, 1]", "[0, 0]", 1)));
    assert!(e.contains("atlas.plane[1].normal"), "{e}");
    let e = err(&format!(
        "{ok}{planes}[[atlas.plane]]\nnormal = [1, 0]\noffset = -2\n"
    ));
    assert!(e.contains("atlas.plane[3].offset"), "{e}");
    let fixed = "[[atlas.plane]]\nnormal = [0, 1]\noffset = 1.2\n[[atlas.plane]]\nnormal = [0, -1]\noffset = 1.2\n";
    let e = err(&format!("{ok}{fixed}"));
    assert!(e.contains("none moves with ρ"), "{e}");
    let e = err(&format!("{}quantities = [\"force\"]\n{planes}", ok));
    assert!(
        e.contains("atlas.quantities") && e.contains("wall_force"),
        "{e}"
    );
    let e = err(&format!("{ok}squeeze = {{ target_rho = 0.5 }}\n"));
    assert!(e.contains("atlas.squeeze.target_rho"), "{e}");
    let e = Atlas::parse(
        &format!(
            "{}{ok}",
            base.replace("thickness", "length = 20.0\nthickness")
        ),
        Path::new("."),
    )
    .unwrap_err();
    assert!(e.to_string().contains("geometry.length"), "{e}");
    let e = err(&format!("{ok}\n[[stage]]\nkind = \"inflate\"\n"));
    assert!(e.contains("`stage`"), "{e}");
    // a template the case reader refuses names the member
    let e = Atlas::parse(
        &format!("{}{ok}", base.replace("around = 16", "around = 3")),
        Path::new("."),
    )
    .unwrap_err();
    let chain = tubemem_app::error_chain(&e);
    assert!(
        chain.contains("atlas member ls1.3_lr10") && chain.contains("[mesh]"),
        "{chain}"
    );
    // a folder that holds something else is refused and left as it was
    let out = tmp("foreign");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let atlas = Atlas::parse(&format!("{base}{ok}"), Path::new(".")).unwrap();
    let e = atlas::run(&atlas, &format!("{base}{ok}"), &out, 1, &|_| {})
        .err()
        .unwrap();
    assert!(e.to_string().contains("holds no atlas"), "{e}");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1);
    std::fs::remove_dir_all(&out).unwrap();
    // issue #61: the grid's size is guarded before any member is built; an empty quantity
    // list and a plane normal of three components are refused
    let big: Vec<String> = (0..400)
        .map(|i| format!("{}", 1.1 + 1e-3 * f64::from(i)))
        .collect();
    let e = err(&ok.replace("[1.3]", &format!("[{}]", big.join(", "))));
    assert!(
        e.contains("atlas.max_runs") && e.contains("400 stretches × 3 lengths = 1200"),
        "{e}"
    );
    let e = err(&format!(
        "{ok}max_runs = 2
"
    ));
    assert!(
        e.contains("1 stretch × 3 lengths = 3") && e.contains("max_runs = 2"),
        "{e}"
    );
    let e = err(&format!(
        "{ok}max_runs = 0
"
    ));
    assert!(
        e.contains("atlas.max_runs") && e.contains("allows no run"),
        "{e}"
    );
    let e = err(&format!(
        "{ok}quantities = []
"
    ));
    assert!(
        e.contains("atlas.quantities") && e.contains("is empty"),
        "{e}"
    );
    let e = err(&format!(
        "{ok}{}",
        planes.replacen("[0, 1]", "[0, 1, 5]", 1)
    ));
    assert!(
        e.contains("line 17") && e.contains("normal") && e.contains("has 3 components"),
        "{e}"
    );
}

/// Issue #61: two atlases into one folder had failed each other's members; the folder is now
/// locked while an atlas writes into it, the second refused naming the holder, and free again
/// once the first lets go (as when its process ends, however it ends).
#[test]
fn an_atlas_folder_is_locked_while_an_atlas_writes_into_it() {
    let (_, text) = ci_atlas();
    let out = tmp("lock");
    let first = atlas::prepare(&text, &out).unwrap();
    let e = atlas::prepare(&text, &out).err().unwrap();
    let msg = tubemem_app::error_chain(&e);
    assert!(
        msg.contains("another tubemem command")
            && msg.contains(&format!("pid {}", std::process::id())),
        "{msg}"
    );
    drop(first);
    let again = atlas::prepare(&text, &out).unwrap();
    drop(again);
    std::fs::remove_dir_all(&out).unwrap();
}

/// Issue #61: the missing members of an interrupted atlas are summarised, not listed (9,867
/// names had been printed).
#[test]
fn missing_members_are_summarised() {
    let names: Vec<String> = (0..9867).map(|i| format!("ls1.{i}_lr10")).collect();
    let s = atlas::missing_summary(&names);
    assert!(
        s.len() < 400 && s.contains("9864 more") && s.contains("ls1.0_lr10"),
        "{s}"
    );
    assert_eq!(
        atlas::missing_summary(&names[..2]).matches("_lr10").count(),
        2
    );
}

/// The `atlas-point` verify kind through a suite, as a user writes it: a coarse atlas (its
/// runs take a tenth of a second) held at a length it did not run; a tolerance of 1e-6 of the
/// prediction fails it (the kind can fail: the law is a fit, not an identity); a point off the
/// grid or a length the atlas ran is refused before anything runs.
#[test]
fn the_atlas_point_kind_holds_a_held_out_length_and_can_fail() {
    use tubemem_app::verify::suite::read_suite;
    use tubemem_app::verify::{run_check, Status, VerifyOptions};
    let d = tmp("kind");
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(
        d.join("coarse.toml"),
        "[geometry]\nradius = 1.0\nthickness = 0.01\n[material]\nmodel = \"abb\"\nshear_modulus = 1.0\nkuhn = 30\n[mesh]\naround = 16\nsymmetry = \"eighth\"\n[atlas]\nstretches = [1.3]\nrho = [1.0, 0.9]\nlengths = [10, 20, 40]\nalong_per_radius = 2\n",
    )
    .unwrap();
    let suite = |point: &str, tol: f64| {
        std::fs::write(
            d.join("suite.toml"),
            format!("[[check]]\nname = \"p\"\nkind = \"atlas-point\"\ncase = \"coarse.toml\"\npoint = {point}\nquantities = [\"w\"]\ntolerance.prediction = {{ value = {tol:e}, source = \"test\" }}\n"),
        )
        .unwrap();
        read_suite(&d.join("suite.toml"))
            .map(|mut s| s.1.remove(0))
            .map_err(|e| e.to_string())
    };
    let at30 = "{ lambda_s_star = 1.3, rho = 0.9, length_ratio = 30 }";
    let r = run_check(
        &suite(at30, 0.1).unwrap(),
        &d.join("out"),
        &VerifyOptions::default(),
    );
    assert_eq!(r.status, Status::Pass, "{}", r.message);
    let off = r.measures[0].measured;
    assert!(off > 1e-6 && off < 0.1, "{off}");
    let r = run_check(
        &suite(at30, 1e-6).unwrap(),
        &d.join("out2"),
        &VerifyOptions::default(),
    );
    assert_eq!(r.status, Status::Fail, "{}", r.message);
    let e = suite(
        "{ lambda_s_star = 1.3, rho = 0.85, length_ratio = 30 }",
        0.1,
    )
    .unwrap_err();
    assert!(
        e.contains("point.rho") && e.contains("not on the atlas's grid"),
        "{e}"
    );
    let e = suite("{ lambda_s_star = 1.3, rho = 0.9, length_ratio = 20 }", 0.1).unwrap_err();
    assert!(e.contains("one of the atlas's lengths"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// A channel atlas (atlas/channel_abb30.toml: fixed side walls x = ±1.35 R, plates y = ±ρ moved
/// through four levels, one confine stage each): every confine stage after the first continues
/// from the walls where the last one left them and compares with GPS from the same inflated
/// λs* (as a squeeze continuing a squeeze does); every point has a law; the law predicts a run
/// at L/R = 30, which the atlas did not use, within 10 % of the prediction (the issue's
/// requirement) for ϖ and the wall force at two levels.
#[test]
fn a_channel_atlas_chains_its_confine_stages_and_predicts_a_held_out_length() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../atlas/channel_abb30.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let atlas = Atlas::read(&path).unwrap();
    let out = tmp("channel");
    let o = atlas::run(&atlas, &text, &out, 2, &|_| {}).unwrap();
    assert!(o.results.iter().all(|r| r.error.is_none()));
    let flagged: Vec<_> = o.points.iter().filter(|p| p.flag.is_some()).collect();
    assert!(flagged.is_empty(), "{flagged:?}");
    // every confine stage's closed form starts from the inflation's λs*
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("runs/ls1.3_lr20/summary.json")).unwrap(),
    )
    .unwrap();
    let stages = summary["stages"].as_array().unwrap();
    assert_eq!(stages.len(), 5);
    let first = stages[1]["initial_stretch"].as_f64().unwrap();
    assert!((first - 1.3).abs() < 1e-5, "{first}");
    for s in &stages[2..] {
        assert_eq!(s["initial_stretch"].as_f64(), Some(first));
    }
    let r = run_at(&atlas, 1.3, 30.0, &out.join("held_out"));
    for (rho, q) in [
        (1.2, "w"),
        (1.2, "wall_force"),
        (1.1, "w"),
        (1.1, "wall_force"),
    ] {
        let p = o
            .points
            .iter()
            .find(|p| p.stretch == 1.3 && p.rho == rho && p.quantity == q)
            .unwrap();
        let predicted = p.predict(30.0).unwrap();
        let m = measured(&r, rho, q);
        eprintln!("channel, held out L/R = 30, ρ = {rho}, {q}: measured {m:.5e}, predicted {predicted:.5e}, {:.2} %", 100.0 * (m / predicted - 1.0));
        assert!(
            (m - predicted).abs() <= 0.1 * predicted.abs(),
            "{q} at ρ = {rho}: {m} against {predicted}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// An atlas whose squeezes hold the pressure (`[atlas.squeeze] control = "pressure"`, the
/// shipped atlas/regulated.toml) maps PS against GPS with the pressure held: each grid value is
/// `flatten_at_pressure`'s, to the last bit, and not the closed gas's.
#[test]
fn a_regulated_atlas_maps_the_regulated_closed_form() {
    let built = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let g = atlas::ps_map::grid(
        &built,
        atlas::ps_map::MapSupply::Regulated,
        (1.05, 1.4),
        (0.7, 1.4),
        7,
    );
    let mut checked = 0;
    for p in g.iter().flatten().filter(|p| p.rho < p.stretch) {
        for h in [tubemem_gps::Hypothesis::Gps, tubemem_gps::Hypothesis::Ps] {
            let want = tubemem_gps::regulated::flatten_at_pressure(&built, h, p.stretch, p.rho)
                .unwrap()
                .as_flattening(p.stretch);
            let got = match h {
                tubemem_gps::Hypothesis::Gps => p.gps.unwrap(),
                tubemem_gps::Hypothesis::Ps => p.ps.unwrap(),
            };
            assert_eq!(got, want);
            let closed = tubemem_gps::flatten(&built, h, p.stretch, p.rho).unwrap();
            assert_ne!(
                got.w, closed.w,
                "the closed gas compresses: another pressure"
            );
        }
        checked += 1;
    }
    assert!(checked > 15, "{checked}");
    let spec = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../atlas/regulated.toml"),
    )
    .unwrap();
    assert!(spec.contains("control = \"pressure\"") && spec.contains("law = \"exponential\""));
}
