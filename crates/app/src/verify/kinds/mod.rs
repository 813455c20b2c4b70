//! The kinds of check, one file each, behind one trait.
//!
//! A kind runs its check's case (or a family of variations of it) and judges what the typed
//! [`RunReport`]s say. It pushes [`Measure`](super::Measure)s onto the [`CheckResult`] (each
//! with its tolerance and the tolerance's source), the member run folders, and optionally a
//! figure; [`run_check_with`](super::run_check_with) turns the measures into the status and
//! the one-line message. To add a kind: implement [`VerifyKind`] in a file here (the built-in
//! kinds do it with the `kind!` macro: a unit type whose check is one function), add a
//! [`CheckKind`] variant (the name a suite file gives it) and its line in [`kind_of`].
//! `crates/app/tests/verify_kind.rs` is a worked example: a toy kind run through the trait.

use super::suite::{Check, CheckKind};
use super::{run_member, vary, CheckResult, VerifyOptions};
use crate::figures::{rasterize, render_svg, Figure};
use crate::report::RunReport;
use std::path::{Path, PathBuf};

/// A kind whose check is one function `f(check, dir, options, result)`: its unit type and its
/// [`VerifyKind`] implementation.
macro_rules! kind {
    ($(#[$doc:meta])* $name:ident, $label:literal, $f:path) => {
        $(#[$doc])*
        pub struct $name;

        impl $crate::verify::kinds::VerifyKind for $name {
            fn label(&self) -> &'static str {
                $label
            }

            fn evaluate(
                &self,
                c: &$crate::verify::suite::Check,
                dir: &std::path::Path,
                opts: &$crate::verify::VerifyOptions,
                r: &mut $crate::verify::CheckResult,
            ) -> $crate::verify::kinds::KindResult {
                $f(c, dir, opts, r)
            }
        }
    };
}

mod atlas_point;
mod closed_form;
mod convergence;
mod end_effect;
mod gold;
mod invariance;
mod manufactured;
mod reference;
pub(crate) mod tension_field;

pub use reference::REFERENCES_HOWTO;

/// One kind of check.
pub trait VerifyKind: Sync {
    /// The kind's name, as a suite file and the reports give it.
    fn label(&self) -> &'static str;
    /// Run check `c` under its folder `dir` and add what it measured to `r`.
    fn evaluate(
        &self,
        c: &Check,
        dir: &Path,
        opts: &VerifyOptions,
        r: &mut CheckResult,
    ) -> KindResult;
}

/// The kind a suite file's `kind = "..."` names.
pub fn kind_of(kind: CheckKind) -> &'static dyn VerifyKind {
    match kind {
        CheckKind::ClosedForm => &closed_form::ClosedForm,
        CheckKind::Reference => &reference::Reference,
        CheckKind::Convergence => &convergence::Convergence,
        CheckKind::EndEffect => &end_effect::EndEffect,
        CheckKind::Invariance => &invariance::Invariance,
        CheckKind::Gold => &gold::Gold,
        CheckKind::Manufactured => &manufactured::Manufactured,
        CheckKind::TensionField => &tension_field::TensionField,
        CheckKind::AtlasPoint => &atlas_point::AtlasPoint,
    }
}

/// Outcome of a kind's evaluation: `Ok(None)` judged by the measures, `Ok(Some(reason))`
/// skipped, `Err(message)` an error.
pub type KindResult = Result<Option<String>, String>;

fn member(c: &Check, text: &str, dir: &Path, r: &mut CheckResult) -> Result<RunReport, String> {
    r.runs.push(dir.display().to_string());
    let text = vary(text, |_| {})?;
    Ok(run_member(
        &text,
        &c.base_dir,
        dir,
        &format!("check {}", c.spec.name),
    )?)
}

fn rel(a: f64, b: f64) -> f64 {
    a / b - 1.0
}

/// Draw a small figure to PNG bytes (for the HTML report).
fn plot(fig: &Figure, r: &mut CheckResult) {
    r.figure = Some(crate::figures::audit(fig));
    let p = PathBuf::from(format!("{}.png", r.name));
    if let Ok(svg) = render_svg(fig, &p) {
        r.png = rasterize(&svg, 70.0, &p).ok();
    }
}
