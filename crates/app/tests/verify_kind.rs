//! Worked example: a verify kind written outside the crate, through the public
//! [`VerifyKind`] trait, and run by [`run_check_with`] as `tubemem verify` runs its own kinds.
//!
//! The toy kind, `axial-stretch`, runs the check's case and holds the mid-span axial stretch
//! at the last step against the closed form's λz at the FE's own hoop stretch (eq. 68's
//! system solved by `tubemem_gps::inflate`, an independent computation: the FE never calls
//! it). A second instance compares with plane strain (λz = 1), which the inflated tube does
//! not satisfy: that check must fail, so the test shows the kind can.
//!
//! Case: `cases/inflate_abb30_ls1.3.toml` (ABB 𝒩 = 30, L/R = 20, 64 around, λs* = 1.3).
//! Tolerance 1e-7: the CI suite's `inflate-closed-form` λz bound, whose source is the end
//! effect at L/R = 20 (5.4e-8 in ϖ, axisymmetric reference) and the Newton tolerance.

use std::path::{Path, PathBuf};
use tubemem_app::verify::kinds::{KindResult, VerifyKind};
use tubemem_app::verify::suite::{read_suite, Check};
use tubemem_app::verify::{
    run_check_with, run_member, vary, CheckResult, Measure, Status, VerifyOptions,
};
use tubemem_gps::Hypothesis;

struct AxialStretch(Hypothesis);

impl VerifyKind for AxialStretch {
    fn label(&self) -> &'static str {
        "axial-stretch"
    }
    fn evaluate(
        &self,
        c: &Check,
        dir: &Path,
        _opts: &VerifyOptions,
        r: &mut CheckResult,
    ) -> KindResult {
        let tol = c
            .spec
            .tolerance
            .get("lambda_z")
            .ok_or("the check needs tolerance.lambda_z")?;
        let run_dir = dir.join("run");
        r.runs.push(run_dir.display().to_string());
        let report = run_member(&vary(&c.case_text, |_| {})?, &c.base_dir, &run_dir, "toy")?;
        let law = report.material_spec.build().map_err(|e| e.to_string())?;
        let last = report.steps().last().ok_or("the run has no step")?;
        let gps = tubemem_gps::inflate(law.as_ref(), self.0, last.midspan.lambda_s)
            .map_err(|e| e.to_string())?;
        let err = (last.midspan.lambda_z / gps.lambda_z - 1.0).abs();
        r.measures.push(Measure::held(
            "lambda_z",
            err,
            tol,
            format!("last step, λs = {:.6}", last.midspan.lambda_s),
        ));
        Ok(None)
    }
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tubemem-verify-kind-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A one-check suite file next to `cases/`, so that its relative case path resolves.
fn check(out: &Path) -> Check {
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases");
    let suite = out.join("toy.toml");
    std::fs::write(
        &suite,
        format!(
            "[[check]]\nname = \"toy\"\nkind = \"closed-form\"\ncase = \"{}\"\n\
             tolerance.lambda_z = {{ value = 1e-7, source = \"end effect at L/R = 20 and the Newton tolerance\" }}\n",
            cases.join("inflate_abb30_ls1.3.toml").display()
        ),
    )
    .unwrap();
    let (_, mut checks) = read_suite(&suite).unwrap();
    checks.remove(0)
}

#[test]
fn a_toy_verify_kind_runs_through_the_public_trait() {
    let out = out_dir("gps");
    let c = check(&out);
    let r = run_check_with(
        &AxialStretch(Hypothesis::Gps),
        &c,
        &out,
        &VerifyOptions::default(),
    );
    assert_eq!(r.kind, "axial-stretch");
    assert_eq!(r.status, Status::Pass, "{}", r.message);
    assert_eq!(r.runs, vec!["toy/run".to_string()]);
    assert!(out.join("toy/run/steps.csv").is_file());
    let m = &r.measures[0];
    println!("toy kind, GPS: |λz/λz* − 1| = {:.2e}", m.measured);
    assert!(m.measured <= 1e-7);

    // the same FE against plane strain (λz = 1): the inflated tube is longer, the check fails
    let out = out_dir("ps");
    let c = check(&out);
    let r = run_check_with(
        &AxialStretch(Hypothesis::Ps),
        &c,
        &out,
        &VerifyOptions::default(),
    );
    assert_eq!(r.status, Status::Fail, "{}", r.message);
    assert!(r.message.starts_with("lambda_z:"), "{}", r.message);
}
