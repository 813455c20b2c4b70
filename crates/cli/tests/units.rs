//! Issue #60: a case in SI and its dimensionless twin give the same results and the same
//! verdicts, in every command: `run` (steps.csv, summary.json, the VTU), `verify --case`,
//! `atlas`, `figures` and `gps`. The twin is written from the SI numbers by the paper's scales
//! (lengths per R, pressures ϖ = pR/(μH), moduli per μ, contact stiffness per μH/R²); the
//! results must agree to round-off (1e-9 relative, the Newton tolerance's order being far
//! larger than the differences round-off leaves: measured 2e-16 on the newcomer's tube), and
//! every SI column must be its dimensionless twin times its factor.

mod common;

use common::{tmp, tubemem};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// R, H, μ of the SI twins (a silicone tube: R = 12 mm, H = 0.4 mm, μ = 0.2 MPa).
const R: f64 = 0.012;
const H: f64 = 4e-4;
const MU: f64 = 2e5;

/// The same tube written twice: (SI text, dimensionless text). `body` is the case with the
/// placeholders `{R}`, `{L}`, `{H}` (lengths), `{MU}` (a modulus: μ; `{HALF_MU}` is μ/2, a
/// Yeoh law's C10), `{P}` (a pressure), `{GAP}`,
/// `{D0}`, `{D1}` (lengths), `{K}` (a contact stiffness), filled in SI or per the scales;
/// values given per the dimensionless core.
struct Twin {
    l: f64,
    p: f64,
    gap: f64,
    d: [f64; 2],
    k: f64,
}

impl Twin {
    fn text(&self, body: &str, si: bool) -> String {
        let (len, pre, mu, stiff) = if si {
            (R, MU * H / R, MU, MU * H / (R * R))
        } else {
            (1.0, 1.0, 1.0, 1.0)
        };
        let t = body
            .replace("{R}", &format!("{:?}", len))
            .replace("{L}", &format!("{:?}", self.l * len))
            .replace("{H}", &format!("{:?}", H / R * len))
            .replace("{MU}", &format!("{:?}", mu))
            .replace("{HALF_MU}", &format!("{:?}", 0.5 * mu))
            .replace("{P}", &format!("{:?}", self.p * pre))
            .replace("{GAP}", &format!("{:?}", self.gap * len))
            .replace("{D0}", &format!("{:?}", self.d[0] * len))
            .replace("{D1}", &format!("{:?}", self.d[1] * len))
            .replace("{K}", &format!("{:?}", self.k * stiff));
        if si {
            format!("[units]\nsystem = \"SI\"\n\n{t}")
        } else {
            t
        }
    }
}

/// The squeeze twins' numbers: L/R = 10, ϖ = 0.55, half-gap 1.05 R, penalty 2e4 μH/R².
const SQUEEZE_TWIN: Twin = Twin {
    l: 10.0,
    p: 0.55,
    gap: 1.05,
    d: [0.0, 0.0],
    k: 2e4,
};

/// Inflated by a pressure target, squeezed to a half-gap given as a length, with the
/// penalty given as a stiffness: every converted key at once.
const SQUEEZE: &str = r#"
[geometry]
radius = {R}
length = {L}
thickness = {H}

[material]
model = "mooney-rivlin"
shear_modulus = {MU}
alpha = 0.1

[mesh]
around = 16
along = 20
symmetry = "eighth"

[[stage]]
kind = "inflate"
control = "pressure"
target_pressure = {P}
steps = 4

[[stage]]
kind = "squeeze"
target_gap = {GAP}
contact_method = "penalty"
penalty = {K}
steps = 4
"#;

/// Inflated to a stretch, then confined by two planes whose offsets are lengths.
const CONFINE: &str = r#"
[geometry]
radius = {R}
length = {L}
thickness = {H}

[material]
model = "yeoh"
c10 = {HALF_MU}
c20 = {HALF_MU}
c30 = 0.0

[mesh]
around = 16
along = 20
symmetry = "eighth"

[[stage]]
kind = "inflate"
control = "volume"
target_stretch = 1.3
steps = 4

[[stage]]
kind = "confine"
steps = 4

[[stage.plane]]
normal = [0.0, 1.0]
offset = {D0}
target = {D1}

[[stage.plane]]
normal = [0.0, -1.0]
offset = {D0}
target = {D1}
"#;

/// The VTU field data `units` (a text, written as its bytes' codes).
fn units_of(vtu: &str) -> String {
    let at = vtu.find("Name=\"units\"").expect("a `units` field");
    let body = &vtu[at..];
    let start = body.find('>').unwrap() + 1;
    let end = body.find("</DataArray>").unwrap();
    let bytes: Vec<u8> = body[start..end]
        .split_whitespace()
        .map(|b| b.parse().unwrap())
        .collect();
    String::from_utf8(bytes).unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn ok(args: &[&str]) -> String {
    let o = tubemem(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).to_string()
}

fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

/// a and b agree to 1e-9 of the larger, or of `floor` (a value that is round-off around zero,
/// n_sz ~ 1e-17, is compared on the scale of its column)
fn close(a: f64, b: f64, floor: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(floor)
}

/// Columns compared on the scale 1 rather than their own values: deviations from 1 and
/// lengths that are round-off around 0.
const UNIT_SCALE: [&str; 6] = [
    "flat_pressure_deviation",
    "nonuniformity",
    "penetration",
    "contact_gap",
    "multiplier_change",
    "n_sz",
];

/// Every column `b` has, row by row; `floor` per column: the column's largest magnitude (1 at
/// least for [`UNIT_SCALE`]'s).
fn same_columns(a: &Path, b: &Path, skip: &[&str]) {
    let ((ha, ra), (hb, rb)) = (csv(a), csv(b));
    assert_eq!(ra.len(), rb.len(), "{}: rows", a.display());
    for (j, name) in hb.iter().enumerate() {
        if skip.contains(&name.as_str()) {
            continue;
        }
        let i = ha
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("{}: no column {name}", a.display()));
        let mut floor = rb
            .iter()
            .filter_map(|r| r[j].parse::<f64>().ok())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        // deviations from 1 and lengths that are round-off around 0 (penetrations, gaps):
        // on their natural scale, 1 (a ratio; R)
        if UNIT_SCALE.contains(&name.as_str()) {
            floor = floor.max(1.0);
        }
        for (k, (x, y)) in ra.iter().zip(&rb).enumerate() {
            match (x[i].parse::<f64>(), y[j].parse::<f64>()) {
                (Ok(x), Ok(y)) => assert!(
                    close(x, y, floor),
                    "{} row {} `{name}`: {x} against {y}",
                    a.display(),
                    k + 1
                ),
                _ => assert_eq!(x[i], y[j], "{} row {} `{name}`", a.display(), k + 1),
            }
        }
    }
}

/// Each SI column of `steps` is its dimensionless column times its factor.
fn si_columns_scale(steps: &Path) {
    let (h, rows) = csv(steps);
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let pair = [
        ("w", "pressure_pa", MU * H / R),
        ("n_s", "n_s_n_per_m", MU * H),
        ("n_z", "n_z_n_per_m", MU * H),
        ("force", "force_n_per_m", std::f64::consts::PI * MU * H),
        ("rho", "half_gap_m", R),
        ("plate_force", "plate_force_n", MU * H * R),
        ("gps_w", "gps_pressure_pa", MU * H / R),
        (
            "gps_force",
            "gps_force_n_per_m",
            std::f64::consts::PI * MU * H,
        ),
        // the plates' stiffness −ΔF/Δgap: force per length over gap, and total force over gap
        (
            "stiffness",
            "stiffness_pa",
            std::f64::consts::PI * MU * H / R,
        ),
        (
            "gps_stiffness",
            "gps_stiffness_pa",
            std::f64::consts::PI * MU * H / R,
        ),
        ("plate_stiffness", "plate_stiffness_n_per_m", MU * H),
    ];
    for r in &rows {
        for (core, si, f) in pair {
            let (c, s) = (&r[col(core)], &r[col(si)]);
            match (c.parse::<f64>(), s.parse::<f64>()) {
                (Ok(c), Ok(s)) => {
                    assert!(close(c * f, s, 0.0), "{si}: {s} against {core} {c} × {f}")
                }
                _ => assert_eq!(c.is_empty(), s.is_empty(), "{core} `{c}`, {si} `{s}`"),
            }
        }
    }
}

/// The numbers of two JSON values agree (close), keys and texts alike but `skip`.
fn same_json(a: &Value, b: &Value, path: &str, skip: &[&str]) {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(close(x, y, 1e-12), "{path}: {x} against {y}");
        }
        (Value::Object(x), Value::Object(y)) => {
            for (k, v) in y {
                if skip.contains(&k.as_str()) {
                    continue;
                }
                let w = x.get(k).unwrap_or_else(|| panic!("{path}.{k} missing"));
                same_json(w, v, &format!("{path}.{k}"), skip);
            }
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{path}");
            for (k, (v, w)) in x.iter().zip(y).enumerate() {
                same_json(v, w, &format!("{path}[{k}]"), skip);
            }
        }
        (x, y) => assert_eq!(x, y, "{path}"),
    }
}

#[test]
fn an_si_run_and_its_dimensionless_twin_give_the_same_results() {
    let d = tmp("units-run");
    let twins = [
        ("squeeze", SQUEEZE, SQUEEZE_TWIN),
        (
            "confine",
            CONFINE,
            Twin {
                l: 10.0,
                p: 0.0,
                gap: 0.0,
                d: [1.3, 1.1],
                k: 0.0,
            },
        ),
    ];
    for (name, body, twin) in twins {
        let si = write(&d, &format!("{name}_si.toml"), &twin.text(body, true));
        let dl = write(&d, &format!("{name}_dl.toml"), &twin.text(body, false));
        let (a, b) = (d.join(format!("{name}_si")), d.join(format!("{name}_dl")));
        let out = ok(&["run", si.to_str().unwrap(), "--out", a.to_str().unwrap()]);
        ok(&["run", dl.to_str().unwrap(), "--out", b.to_str().unwrap()]);
        // the SI run's console names its units
        assert!(out.contains("in SI: p = "), "{out}");
        same_columns(&a.join("steps.csv"), &b.join("steps.csv"), &[]);
        si_columns_scale(&a.join("steps.csv"));
        same_columns(
            &a.join("profiles/profiles.csv"),
            &b.join("profiles/profiles.csv"),
            &[],
        );
        let sa: Value =
            serde_json::from_str(&std::fs::read_to_string(a.join("summary.json")).unwrap())
                .unwrap();
        let sb: Value =
            serde_json::from_str(&std::fs::read_to_string(b.join("summary.json")).unwrap())
                .unwrap();
        // the stages (targets, finals, closed forms, errors): the same numbers; the case's
        // own words (material, geometry, units) differ by design
        same_json(&sa["stages"], &sb["stages"], "stages", &[]);
        assert_eq!(sa["warnings"], sb["warnings"], "the same warnings");
        assert!(sa["final_si"].is_array() && sb.get("final_si").is_none());
        // the VTU: points in m against R, and the units in the field data
        let last = |dir: &Path| {
            let mut v: Vec<PathBuf> = std::fs::read_dir(dir.join("vtu"))
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            v.sort();
            std::fs::read_to_string(v.last().unwrap()).unwrap()
        };
        let (va, vb) = (units_of(&last(&a)), units_of(&last(&b)));
        assert!(
            va.starts_with("SI: points and displacement in m"),
            "{name}: {va}"
        );
        assert!(
            vb.starts_with("dimensionless: points and displacement in R"),
            "{name}: {vb}"
        );
    }
}

#[test]
fn an_si_study_and_its_dimensionless_twin_give_the_same_verdict() {
    let d = tmp("units-study");
    let twin = SQUEEZE_TWIN;
    let mut results = vec![];
    for si in [true, false] {
        let case = write(&d, &format!("tube_{si}.toml"), &twin.text(SQUEEZE, si));
        let out = d.join(format!("study_{si}"));
        let o = tubemem(&[
            "verify",
            "--case",
            case.to_str().unwrap(),
            "--quick",
            "--out",
            out.to_str().unwrap(),
            "--python",
            "/nonexistent/python",
        ]);
        assert!(
            o.status.code() == Some(0) || o.status.code() == Some(1),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let r: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap())
                .unwrap();
        results.push(r);
    }
    let checks = |r: &Value| r["checks"].as_array().unwrap().clone();
    let (a, b) = (checks(&results[0]), checks(&results[1]));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x["name"], y["name"]);
        assert_eq!(x["status"], y["status"], "{}", x["name"]);
        // the measures' numbers; their notes name units and differ by design
        let ma = x["measures"].as_array().unwrap();
        let mb = y["measures"].as_array().unwrap();
        assert_eq!(ma.len(), mb.len(), "{}", x["name"]);
        for (p, q) in ma.iter().zip(mb) {
            same_json(p, q, &format!("{}", x["name"]), &["note", "source"]);
        }
    }
    // the invariant core is a fraction of the tube in both (it had been 4293 % in SI)
    let core = |r: &Value| {
        checks(r)
            .iter()
            .find(|c| c["name"] == "invariance")
            .unwrap()["measures"][0]["measured"]
            .as_f64()
            .unwrap()
    };
    let (ca, cb) = (core(&results[0]), core(&results[1]));
    assert!((0.0..=1.0).contains(&ca) && close(ca, cb, 0.0), "{ca} {cb}");
    let verdict = |r: &Value| {
        r["verdict"]
            .as_str()
            .unwrap()
            .split(':')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(verdict(&results[0]), verdict(&results[1]));
}

#[test]
fn si_figures_gps_and_atlas_agree_with_their_dimensionless_twins() {
    let d = tmp("units-more");
    // gps: the same state, and its SI values are the state's times the scales
    let law_si = format!("model = \"neo-hookean\", shear_modulus = {MU:?}");
    let (rs, hs) = (format!("{R:?}"), format!("{H:?}"));
    let si: Value = serde_json::from_str(&ok(&[
        "gps",
        "flatten",
        "--law",
        &law_si,
        "--radius",
        &rs,
        "--thickness",
        &hs,
        "--initial-stretch",
        "1.3",
        "--rho",
        "1.1",
        "--json",
    ]))
    .unwrap();
    let dl: Value = serde_json::from_str(&ok(&[
        "gps",
        "flatten",
        "--law",
        "model = \"neo-hookean\", shear_modulus = 1.0",
        "--initial-stretch",
        "1.3",
        "--rho",
        "1.1",
        "--json",
    ]))
    .unwrap();
    same_json(&si, &dl, "gps flatten", &[]);
    let w = dl["w"].as_f64().unwrap();
    assert!(close(
        si["pressure_pa"].as_f64().unwrap(),
        w * MU * H / R,
        0.0
    ));
    assert!(close(si["half_gap_m"].as_f64().unwrap(), 1.1 * R, 0.0));
    // confine at a given pressure: Pa and m against ϖ and R
    let conf = |si: bool| -> Value {
        let (p, d0) = if si {
            (0.6 * MU * H / R, 1.2 * R)
        } else {
            (0.6, 1.2)
        };
        let mut args = vec![
            "gps".to_string(),
            "confine".into(),
            "--law".into(),
            if si {
                law_si.clone()
            } else {
                "model = \"neo-hookean\", shear_modulus = 1.0".into()
            },
            "--pressure".into(),
            format!("{p:?}"),
            format!("--plane=0,1,{d0:?}"),
            format!("--plane=0,-1,{d0:?}"),
            "--json".into(),
        ];
        if si {
            args.extend([
                "--radius".into(),
                rs.clone(),
                "--thickness".into(),
                hs.clone(),
            ]);
        }
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        serde_json::from_str(&ok(&a)).unwrap()
    };
    same_json(&conf(true), &conf(false), "gps confine", &[]);

    // figures over the twins' runs: the same FE points (the CSV is dimensionless), the SI
    // figure's axes in units
    let twin = SQUEEZE_TWIN;
    let mut points = vec![];
    for si in [true, false] {
        let case = write(&d, &format!("fig_{si}.toml"), &twin.text(SQUEEZE, si));
        let run = d.join(format!("run_{si}"));
        ok(&[
            "run",
            case.to_str().unwrap(),
            "--out",
            run.to_str().unwrap(),
        ]);
        let figs = d.join(format!("figs_{si}"));
        ok(&[
            "figures",
            "--out",
            figs.to_str().unwrap(),
            "--overlay",
            run.to_str().unwrap(),
        ]);
        let p = std::fs::read_dir(&figs)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| {
                p.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with("fe_points")
            })
            .unwrap();
        points.push(p);
        let fig5 = std::fs::read_to_string(figs.join("fig5_pressure_stretch.svg")).unwrap();
        assert_eq!(
            fig5.contains("(kPa)"),
            si,
            "fig. 5's axis in kPa exactly in SI"
        );
    }
    same_columns(&points[0], &points[1], &[]);

    // an atlas whose template is in SI: the same members and fitted laws
    let atlas = |si: bool| {
        let (len, mu) = if si { (R, MU) } else { (1.0, 1.0) };
        let units = if si {
            "[units]\nsystem = \"SI\"\n\n"
        } else {
            ""
        };
        format!(
            "{units}[geometry]\nradius = {len:?}\nthickness = {:?}\ncaps = \"hemisphere\"\n\n[material]\nmodel = \"neo-hookean\"\nshear_modulus = {mu:?}\n\n[mesh]\naround = 16\nsymmetry = \"eighth\"\n\n[atlas]\nstretches = [1.3]\nrho = [1.2, 1.1]\nlengths = [6, 8, 10]\nalong_per_radius = 2\nepsilon = [1e-2]\n",
            H / R * len
        )
    };
    let mut csvs = vec![];
    for si in [true, false] {
        let f = write(&d, &format!("atlas_{si}.toml"), &atlas(si));
        let out = d.join(format!("atlas_{si}"));
        ok(&["atlas", f.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        csvs.push(out.join("atlas.csv"));
    }
    same_columns(&csvs[0], &csvs[1], &[]);
    let _ = std::fs::remove_dir_all(&d);
}
