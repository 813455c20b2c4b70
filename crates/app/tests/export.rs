//! `tubemem export`: the Abaqus/CalculiX deck holds the run's mesh, its fixed dofs, the law's
//! constants and the pressure of each stage; what the codes cannot run is refused with the
//! reason. (CalculiX itself runs the deck in scripts/bench-vs-calculix.sh.)

use tubemem_app::case::Case;
use tubemem_app::export::{abaqus_deck, ShellChoice};

const NH: &str = r#"
[geometry]
radius = 2.0
length = 12.0
thickness = 0.01
caps = "hemisphere"

[material]
model = "neo-hookean"
shear_modulus = 3.0

[mesh]
around = 16
along = 12
symmetry = "eighth"
"#;

const STRETCH: &str = r#"
[[stage]]
kind = "inflate"
control = "pressure"
target_pressure = 0.3
steps = 4

[[stage]]
kind = "inflate"
control = "volume"
target_stretch = 1.3
steps = 5
"#;

fn deck(text: &str) -> Result<String, String> {
    let case = Case::parse(text).map_err(|e| e.to_string())?;
    abaqus_deck(&case, "test", ShellChoice::S4, 1000.0).map_err(|e| format!("{e}"))
}

/// The lines of keyword block `key` (up to the next keyword).
fn block<'a>(deck: &'a str, key: &str) -> Vec<&'a str> {
    let start = deck.find(key).unwrap_or_else(|| panic!("no {key}"));
    deck[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with('*'))
        .collect()
}

#[test]
fn the_deck_is_the_run_model() {
    let d = deck(&format!("{NH}{STRETCH}")).unwrap();
    let case = Case::parse(&format!("{NH}{STRETCH}")).unwrap();
    let mesh = tubemem_app::run::build_mesh(&case).unwrap();
    // nodes in physical units (× R = 2), elements S4 with tubemem's connectivity
    let nodes = block(&d, "*NODE, NSET=NALL");
    assert_eq!(nodes.len(), mesh.nodes.len());
    let first: Vec<f64> = nodes[1]
        .split(',')
        .skip(1)
        .map(|v| v.trim().parse().unwrap())
        .collect();
    // the deck prints 13 significant digits ({:.12e}): a number reads back within half a unit
    // of the 13th, 5e-13 relative
    let digits = |got: f64, want: f64| (got - want).abs() <= 5e-13 * want.abs();
    for (v, x) in first.iter().zip(mesh.nodes[1]) {
        assert!(digits(*v, 2.0 * x), "{v} vs {}", 2.0 * x);
    }
    let els = block(&d, "*ELEMENT, TYPE=S4, ELSET=EALL");
    assert_eq!(els.len(), mesh.quads.len());
    assert_eq!(
        els[0],
        format!(
            "1, {}",
            mesh.quads[0].map(|i| (i + 1).to_string()).join(", ")
        )
    );
    // neo-Hookean: C10 = μ/2, C01 = 0, D1 = 2/(1000 μ)
    let mat: Vec<f64> = block(&d, "*HYPERELASTIC, MOONEY-RIVLIN")[0]
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    assert_eq!(mat, vec![1.5, 0.0, 2.0 / 3000.0]);
    // every dof tubemem fixes, plus two rotations per symmetry plane a node lies on
    let dofs = tubemem_fem::dofs::DofMap::new(&mesh);
    let fixed = (0..mesh.nodes.len())
        .map(|i| (0..3).filter(|&k| dofs.eq(i, k).is_none()).count())
        .sum::<usize>();
    let planes = (0..3)
        .map(|ax| mesh.on_plane(ax).iter().filter(|&&b| b).count())
        .sum::<usize>();
    assert_eq!(block(&d, "*BOUNDARY").len(), fixed + 2 * planes);
    // the pressures: ϖ μH/R, the second stage's the GPS pressure of λs* = 1.3
    let loads: Vec<f64> = d
        .match_indices("*DLOAD\n")
        .map(|(i, _)| {
            d[i..]
                .lines()
                .nth(1)
                .unwrap()
                .split(',')
                .nth(2)
                .unwrap()
                .trim()
                .parse()
                .unwrap()
        })
        .collect();
    let scale = 3.0 * 0.01 / 2.0;
    let gps = tubemem_gps::inflate(
        case.material.build().unwrap().as_ref(),
        tubemem_gps::Hypothesis::Gps,
        1.3,
    )
    .unwrap()
    .w;
    assert_eq!(loads.len(), 2);
    assert!(digits(loads[0], 0.3 * scale));
    assert!(digits(loads[1], gps * scale), "{loads:?}");
    // four and five increments
    assert!(d.contains("*STATIC\n2.5e-1, 1.0"));
    assert!(d.contains("*STATIC\n2e-1, 1.0"));
    // the mid-span ring is a node set: 16/4 + 1 nodes on the eighth model's z = 0 ring
    let ring: usize = block(&d, "*NSET, NSET=MIDSPAN")
        .iter()
        .map(|l| l.split(',').count())
        .sum();
    assert_eq!(ring, 5);
}

#[test]
fn a_quad9_mesh_is_written_as_m3d9() {
    let text = format!(
        "{}{STRETCH}",
        NH.replace(
            "symmetry = \"eighth\"",
            "symmetry = \"eighth\"\nelement = \"quad9\""
        )
    );
    let d = deck(&text).unwrap();
    let els = block(&d, "*ELEMENT, TYPE=M3D9, ELSET=EALL");
    assert!(els.iter().all(|l| l.split(',').count() == 10));
    assert!(d.contains("*MEMBRANE SECTION"));
    // membranes have no rotations: translations only
    assert!(block(&d, "*BOUNDARY").iter().all(|l| l
        .split(',')
        .nth(1)
        .unwrap()
        .trim()
        .parse::<usize>()
        .unwrap()
        <= 3));
}

#[test]
fn what_the_codes_cannot_run_is_refused_with_the_reason() {
    let abb = NH.replace(
        "model = \"neo-hookean\"\nshear_modulus = 3.0",
        "model = \"abb\"\nshear_modulus = 1.0\nkuhn = 30",
    );
    let e = deck(&format!("{abb}{STRETCH}")).unwrap_err();
    assert!(e.contains("Anssari-Benam") && e.contains("UMAT"), "{e}");
    let squeeze = format!("{NH}{STRETCH}[[stage]]\nkind = \"squeeze\"\ntarget_rho = 1.0\n");
    let e = deck(&squeeze).unwrap_err();
    assert!(
        e.contains("stage 3 (squeeze)") && e.contains("fluid cavity"),
        "{e}"
    );
    let arc = STRETCH.replace("control = \"volume\"", "control = \"arc-length\"");
    let e = deck(&format!("{NH}{arc}")).unwrap_err();
    assert!(e.contains("stage 2: arc-length"), "{e}");
    let vol = STRETCH.replace("target_stretch = 1.3", "target_volume_ratio = 1.5");
    let e = deck(&format!("{NH}{vol}")).unwrap_err();
    assert!(e.contains("stage 2: a volume-ratio target"), "{e}");
    let plug = NH.replace("caps = \"hemisphere\"", "caps = \"rigid-plug\"");
    let e = deck(&format!("{plug}{STRETCH}")).unwrap_err();
    assert!(e.contains("rigid-plug"), "{e}");
    let case = Case::parse(&format!("{NH}{STRETCH}")).unwrap();
    let e = abaqus_deck(&case, "t", ShellChoice::S4, f64::NAN).unwrap_err();
    assert!(e.to_string().contains("K/μ"), "{e}");
}
