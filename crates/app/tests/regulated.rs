//! Issue #62: squeeze and confine stages with the pressure regulated (`control = "pressure"`),
//! the mixed path (regulated, then the gas closed), their closed form, their case keys and their
//! SI twin.

use tubemem_app::case::Case;
use tubemem_app::report::{StageOutcome, StepRecord};
use tubemem_app::run::run;
use tubemem_gps::regulated::{flatten_closed_from, free_start, squeeze_at_pressure};
use tubemem_gps::Hypothesis;

/// The small tube shared with the CLI and Python tests (ABB 30, L/R = 8, 16 around, λs* = 1.2).
const SMALL: &str = include_str!("../../../cases/small_abb30_ls1.2.toml");
/// The shipped regulated squeeze (9-node, 32 around, L/R = 20, λs* = 1.3 → ρ = 0.8).
const REGULATED: &str = include_str!("../../../cases/squeeze_abb30_ls1.3_quad9_regulated.toml");

fn finished(
    report: &tubemem_app::report::RunReport,
    i: usize,
) -> tubemem_app::report::StageSummary {
    match &report.stages[i].outcome {
        StageOutcome::Finished(s) => (**s).clone(),
        o => panic!("stage {}: {o:?}", i + 1),
    }
}

fn stage_steps(report: &tubemem_app::report::RunReport, i: usize) -> &[StepRecord] {
    &report.stages[i].steps
}

/// The shipped case: the pressure is the inflated one at every squeeze step, bit for bit, the
/// summary names the control, and the end state is the GPS section at the same ρ and pressure.
/// Bounds: twice the refinement study's values at 32 around (docs, "Verification of the
/// regulated squeeze": λs −4.7e-6, λz +2.6e-6, χ and force +6.0e-5, converging at order 3.7–3.9
/// from 16 to 64 around); the penetration bound is the issue's, 1e-8 R.
#[test]
fn a_regulated_squeeze_holds_its_pressure_and_ends_at_the_gps_section_of_that_pressure() {
    let case = Case::parse(REGULATED).unwrap();
    let report = run(&case, "regulated", &mut []).into_result().unwrap();
    let inflated = finished(&report, 0).final_state.midspan.w;
    let steps = stage_steps(&report, 1);
    assert!(steps.len() >= 2);
    for s in steps {
        assert_eq!(s.midspan.w, inflated, "step {}", s.step);
        let gps = s.closed_form.gps_flattening.expect("GPS at every step");
        assert_eq!(gps.w, inflated);
    }
    // the gripper's stiffness over each step after the first: FE and GPS secants over the same
    // two plate positions (measured FE/GPS − 1 from 4.0e-5 to 1.15e-4 on this mesh; bound
    // 2.5e-4), positive (the force grows as the plates close)
    assert!(steps[0].stiffness.is_none());
    for s in &steps[1..] {
        let k = s.stiffness.expect("a stiffness after the first step");
        let g = k.gps_force.expect("GPS's");
        assert!(k.force > 0.0 && k.plate_force > 0.0, "step {}", s.step);
        assert!(
            (k.force / g - 1.0).abs() < 2.5e-4,
            "step {}: {} vs {g}",
            s.step,
            k.force
        );
    }
    let s = finished(&report, 1);
    assert_eq!(s.control.as_deref(), Some("pressure"));
    assert_eq!(finished(&report, 0).control.as_deref(), Some("volume"));
    let e = &s.relative_error_vs_gps;
    for (name, v, bound) in [
        ("λs", e.lambda_s, 1e-5),
        ("λz", e.lambda_z, 6e-6),
        ("χ", e.chi, 1.2e-4),
        ("force", e.force, 1.2e-4),
    ] {
        let v = v.unwrap();
        assert!(v.abs() < bound, "{name}: {v:e}");
    }
    let c = s.final_state.contact.unwrap();
    assert_eq!(c.rho, 0.8);
    assert!(c.penetration < 1e-8, "penetration {}", c.penetration);
    // the closed-gas squeeze to the same ρ ends at another pressure: the control matters
    // (measured ϖ 0.821 against the held 0.651, 26 % higher; bound 5 %, well inside the
    // difference and far above any discretization error of either run)
    let closed = Case::parse(&REGULATED.replace("control = \"pressure\"\n", "")).unwrap();
    let rc = run(&closed, "closed", &mut []).into_result().unwrap();
    let w_closed = finished(&rc, 1).final_state.midspan.w;
    assert!(
        w_closed > 1.05 * inflated,
        "closed gas ϖ {w_closed} vs {inflated}"
    );
    assert_eq!(finished(&rc, 1).control.as_deref(), Some("gas"));
}

/// Issue #62's must-show: the shipped tube (L/R = 20) at 64 around agrees with the GPS section
/// at the same ρ and the same held pressure to 2e-6 in λs and λz and 1e-5 in χ and the force
/// (the bounds), the observed order from 32 to 64 around is at least 3.5 in each (the
/// issue's; measured 3.67, 3.85, 3.92, 3.92 by scripts/regulated-study.py --length 20, the
/// meshes nested by `edge_fit_around = 32`), and no step penetrates by more than 1e-8 R.
#[test]
fn the_regulated_squeeze_at_64_around_converges_at_the_elements_order() {
    let errors = |around: usize| {
        let text = REGULATED
            .replace("\naround = 32\n", &format!("\naround = {around}\n"))
            .replace("along = 80", &format!("along = {}", around * 20 / 8));
        let report = run(&Case::parse(&text).unwrap(), "n", &mut [])
            .into_result()
            .unwrap();
        let pen = stage_steps(&report, 1)
            .iter()
            .map(|s| s.contact.as_ref().expect("contact").values.penetration)
            .fold(0.0, f64::max);
        assert!(pen < 1e-8, "{around} around: penetration {pen:e} R");
        let e = finished(&report, 1).relative_error_vs_gps;
        [e.lambda_s, e.lambda_z, e.chi, e.force].map(Option::unwrap)
    };
    let (coarse, fine) = (errors(32), errors(64));
    for (i, (name, bound)) in [("λs", 2e-6), ("λz", 2e-6), ("χ", 1e-5), ("force", 1e-5)]
        .into_iter()
        .enumerate()
    {
        assert!(fine[i].abs() < bound, "{name}: {:e} at 64 around", fine[i]);
        let order = (coarse[i] / fine[i]).abs().log2();
        assert!(
            order >= 3.5,
            "{name}: order {order:.2} from 32 to 64 around"
        );
    }
}

/// A ramped pressure ends exactly at its target; the SI twin (R = 5 mm, H = 0.5 mm, μ = 0.4
/// MPa, the target in Pa) runs the same dimensionless problem, bit for bit, with the same
/// verdicts.
#[test]
fn a_ramped_regulated_squeeze_ends_at_its_target_and_its_si_twin_is_the_same_run() {
    let stage = "\n[[stage]]\nkind = \"squeeze\"\ncontrol = \"pressure\"\ntarget_rho = 1.0\ntarget_pressure = 0.45\nsteps = 4\n";
    let (mu, h, r) = (4.0e5, 5.0e-4, 5.0e-3);
    let dimless = Case::parse(&format!("{SMALL}{stage}")).unwrap();
    let si = format!("{SMALL}{stage}")
        .replace("radius = 1.0", "radius = 0.005\nthickness = 0.0005")
        .replace("length = 8.0", "length = 0.04")
        .replace("shear_modulus = 1.0", "shear_modulus = 4.0e5")
        .replace(
            "target_pressure = 0.45",
            &format!("target_pressure = {}", 0.45 * mu * h / r),
        )
        + "\n[units]\nsystem = \"SI\"\n";
    let si = Case::parse(&si).unwrap();
    let a = run(&dimless, "dimless", &mut []).into_result().unwrap();
    let b = run(&si, "si", &mut []).into_result().unwrap();
    let (sa, sb) = (finished(&a, 1), finished(&b, 1));
    // 0.45 μH/R in Pa read back as ϖ: 0.45 to a rounding of the product
    assert!((sa.final_state.midspan.w - 0.45).abs() < 1e-15);
    assert!((sb.final_state.midspan.w / sa.final_state.midspan.w - 1.0).abs() < 1e-14);
    let rel = |x: f64, y: f64| (x / y - 1.0).abs();
    // the same equations to a rounding of the target: the states agree to Newton's tolerance
    assert!(
        rel(
            sb.final_state.midspan.lambda_s,
            sa.final_state.midspan.lambda_s
        ) < 1e-9
    );
    assert_eq!(sa.gps_applicable, sb.gps_applicable);
    let (ea, eb) = (&sa.relative_error_vs_gps, &sb.relative_error_vs_gps);
    assert!((ea.force.unwrap() - eb.force.unwrap()).abs() < 1e-8);
    // the stiffness: the same in both (secants of states equal to 1e-9; bound 1e-6), and in
    // Pa in the SI twin's rows: stiffness·πμH/R
    let scales = tubemem_gps::Scales::new(r, h, mu).unwrap();
    for (x, y) in a.stages[1].steps.iter().zip(&b.stages[1].steps).skip(1) {
        let (kx, ky) = (x.stiffness.unwrap(), y.stiffness.unwrap());
        assert!(
            rel(ky.force, kx.force) < 1e-6,
            "{} vs {}",
            ky.force,
            kx.force
        );
        let si = tubemem_app::output::si_values(&scales, y);
        let pa = ky.force * std::f64::consts::PI * mu * h / r;
        assert!(rel(si[8].unwrap(), pa) < 1e-14, "{:?} vs {pa}", si[8]);
    }
    // the GPS end state is the section at (ρ, 0.45), reached from the free tube at λs*
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let c = sa.final_state.contact.unwrap();
    let g = squeeze_at_pressure(
        &law,
        Hypothesis::Gps,
        free_start(&law, Hypothesis::Gps, c.initial_stretch).unwrap(),
        1.0,
        0.45,
    )
    .unwrap();
    assert!(rel(ea.force.unwrap() + 1.0, c.force / g.force) < 1e-12);
    // on this coarse mesh (4-node, 16 around) the force is off by the squeeze's own
    // discretization error: −12 %, as the closed-gas squeeze to ρ = 1 on it is off against the
    // section at its pressure (−14 %); bound: that twin's error
    let closed = Case::parse(&format!(
        "{SMALL}\n[[stage]]\nkind = \"squeeze\"\ntarget_rho = 1.0\nsteps = 4\n"
    ))
    .unwrap();
    let rc = run(&closed, "closed", &mut []).into_result().unwrap();
    let twin = finished(&rc, 1)
        .relative_error_vs_gps_at_fe_pressure
        .unwrap()
        .force
        .unwrap();
    assert!(
        ea.force.unwrap().abs() < twin.abs(),
        "{:?} vs the closed gas's {twin}",
        ea.force
    );
}

/// The mixed path on the shipped mesh: the pressure regulated from λs* = 1.3 to ρ = 1.0, then
/// the valve closed and the plates moved on to ρ = 0.8. The closed stage compares with Boyle's
/// law from the regulated state (its gas constant ϖρ(2λs − ρ)λz there), not from the free tube.
/// Against the section at its own pressure its error is the mesh's (measured 1.0e-4 in χ at 32
/// around; bound twice that); its pressure is below GPS by the caps' gas, as the paper's
/// closed-gas squeeze's is (measured −0.46 % here, −1.35 % for the closed gas from λs*; bound
/// 1 %), while the paper's closed-gas squeeze from λs* holds 13 % more pressure: the gas the
/// regulator let in.
#[test]
fn the_mixed_path_compares_with_boyle_from_where_the_valve_closed() {
    let text = REGULATED.replace("target_rho = 0.8", "target_rho = 1.0")
        + "\n[[stage]]\nkind = \"squeeze\"\ncontrol = \"gas\"\ntarget_rho = 0.8\nsteps = 6\n";
    let case = Case::parse(&text).unwrap();
    let report = run(&case, "mixed", &mut []).into_result().unwrap();
    let (reg, closed) = (finished(&report, 1), finished(&report, 2));
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let ls0 = closed.final_state.contact.unwrap().initial_stretch;
    let valve = squeeze_at_pressure(
        &law,
        Hypothesis::Gps,
        free_start(&law, Hypothesis::Gps, ls0).unwrap(),
        1.0,
        reg.final_state.midspan.w,
    )
    .unwrap();
    let expected = flatten_closed_from(&law, Hypothesis::Gps, valve, 0.8).unwrap();
    let fe = closed.final_state.contact.unwrap();
    let rel = |x: f64, y: f64| (x / y - 1.0).abs();
    assert!(
        rel(
            closed.relative_error_vs_gps.force.unwrap() + 1.0,
            fe.force / expected.force
        ) < 1e-12
    );
    let local = closed
        .relative_error_vs_gps_at_fe_pressure
        .as_ref()
        .unwrap();
    assert!(local.chi.unwrap().abs() < 2e-4, "{:?}", local.chi);
    assert!(rel(closed.final_state.midspan.w, expected.w) < 1e-2);
    let paper = tubemem_gps::flatten(&law, Hypothesis::Gps, ls0, 0.8).unwrap();
    assert!(
        rel(paper.w, expected.w) > 0.1,
        "the regulator let gas in: {} vs {}",
        paper.w,
        expected.w
    );
}

/// A regulated confine stage with two plates y = ±ρ is the regulated squeeze; at ρ = 1 its
/// walls touch the stress-free tube, where the confinement's closed form at a given pressure
/// starts in contact (it had refused such walls).
#[test]
fn a_regulated_confine_stage_with_two_plates_is_the_regulated_squeeze() {
    let squeeze =
        "\n[[stage]]\nkind = \"squeeze\"\ncontrol = \"pressure\"\ntarget_rho = 1.0\nsteps = 4\n";
    let plates = "\n[[stage]]\nkind = \"confine\"\ncontrol = \"pressure\"\nsteps = 4\n[[stage.plane]]\nnormal = [0, 1]\noffset = 1.21\ntarget = 1.0\n[[stage.plane]]\nnormal = [0, -1]\noffset = 1.21\ntarget = 1.0\n";
    let rs = run(
        &Case::parse(&format!("{SMALL}{squeeze}")).unwrap(),
        "s",
        &mut [],
    )
    .into_result()
    .unwrap();
    let rc = run(
        &Case::parse(&format!("{SMALL}{plates}")).unwrap(),
        "c",
        &mut [],
    )
    .into_result()
    .unwrap();
    let (a, b) = (rs.steps().last().unwrap(), rc.steps().last().unwrap());
    let rel = |x: f64, y: f64| (x / y - 1.0).abs();
    assert_eq!(a.midspan.w, b.midspan.w);
    // both stop Newton at 1e-9 of the residual (states 1e-7, the force ten times as
    // sensitive: the bound of the closed-gas twin of this test)
    assert!(rel(b.midspan.lambda_s, a.midspan.lambda_s) < 1e-7);
    let force = a.contact.as_ref().unwrap().values.force;
    assert!(
        rel(b.walls[0].force, force) < 1e-6,
        "{} {force}",
        b.walls[0].force
    );
    let g = b.closed_form.gps_confine.as_ref().unwrap();
    let f = a.closed_form.gps_flattening.as_ref().unwrap();
    assert!(rel(g.w, f.w) < 1e-12);
    assert!(
        rel(g.walls[0].force, f.force) < 1e-9,
        "{} {}",
        g.walls[0].force,
        f.force
    );
    assert_eq!(finished(&rc, 1).control.as_deref(), Some("pressure"));
}

#[test]
fn the_gas_control_keys_are_checked_with_their_stage() {
    for (stage, words) in [
        (
            "kind = \"inflate\"\ncontrol = \"gas\"\ntarget_pressure = 0.5",
            &["[[stage]] 2", "control = \"gas\"", "squeeze and confine"][..],
        ),
        (
            "kind = \"squeeze\"\ntarget_rho = 1.0\ntarget_pressure = 0.5",
            &["[[stage]] 2", "`target_pressure`", "control = \"pressure\""][..],
        ),
        (
            "kind = \"squeeze\"\ncontrol = \"pressure\"\ntarget_rho = 1.0\ntarget_pressure = -0.5",
            &["[[stage]] 2", "`target_pressure`", "positive"][..],
        ),
        (
            "kind = \"squeeze\"\ncontrol = \"volume\"\ntarget_rho = 1.0",
            &["[[stage]] 2", "\"gas\"", "\"pressure\""][..],
        ),
        (
            "kind = \"squeeze\"\ncontrol = \"pressure\"\ntarget_pressure = 0.5",
            &["[[stage]] 2", "`target_rho`"][..],
        ),
    ] {
        let text = format!("{SMALL}\n[[stage]]\n{stage}\n");
        let e = Case::parse(&text).unwrap_err().to_string();
        for w in words {
            assert!(e.contains(w), "{stage}: {e}");
        }
    }
}

/// A regulated squeeze's steps are drawn on the pressure-held companion of Fig. 6, against the
/// pressure-held GPS curve, and not on Fig. 6 itself (whose curves are the closed gas's); a
/// closed-gas squeeze's steps are drawn on Fig. 6 and not on the companion.
#[test]
fn regulated_steps_go_on_the_pressure_held_figure_and_closed_ones_on_the_papers() {
    use tubemem_app::figures::{write_all, FigureOptions, Overlay};
    let stage = |control: &str| {
        format!("{SMALL}\n[[stage]]\nkind = \"squeeze\"\n{control}target_rho = 1.0\nsteps = 3\n")
    };
    let texts = |svg: &std::path::Path| -> Vec<String> {
        std::fs::read_to_string(svg)
            .unwrap()
            .split("</text>")
            .filter_map(|t| t.rsplit_once('>').map(|(_, x)| x.trim().to_string()))
            .collect()
    };
    let opts = FigureOptions {
        png: false,
        ..FigureOptions::default()
    };
    for (control, label, on_held) in [
        ("control = \"pressure\"\n", "regulated", true),
        ("", "closed", false),
    ] {
        let case = Case::parse(&stage(control)).unwrap();
        let report = run(&case, label, &mut []).into_result().unwrap();
        // the small case inflates to λs* = 1.2: its squeeze has a figure of its own (Fig. 8)
        let dir = std::env::temp_dir().join(format!("tubemem-fig-{label}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let overlay = Overlay::from_report(&report, label, &dir);
        let files = write_all(&dir, None, &[overlay], &opts).unwrap();
        let find = |suffix: &str| {
            files
                .iter()
                .find(|f| f.to_string_lossy().ends_with(suffix))
                .unwrap_or_else(|| panic!("{suffix} in {files:?}"))
                .clone()
        };
        let held = texts(&find("ls1.2_pressure_held.svg"));
        let paper = texts(&find("ls1.2.svg"));
        let fe = format!("FE: {label}");
        assert_eq!(held.contains(&fe), on_held, "{label}: {held:?}");
        assert_eq!(paper.contains(&fe), !on_held, "{label}: {paper:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
