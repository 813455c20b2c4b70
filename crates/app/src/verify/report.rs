//! The reports of a verification run: results.json (machine-readable), report.md, a
//! self-contained report.html (plots embedded as PNG data URIs, no external URL) and junit.xml
//! (one test case per check, for GitLab, Jenkins and GitHub).

use super::{CheckResult, Status};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The whole verification run (results.json).
#[derive(Debug, Serialize)]
pub struct Results<'a> {
    pub tubemem_version: &'static str,
    pub suites: Vec<String>,
    pub seconds: f64,
    pub passed: usize,
    pub failed: usize,
    pub errors: usize,
    pub skipped: usize,
    /// a plain statement (the `--case` study's verdict, or the suite's tally)
    pub verdict: String,
    pub checks: &'a [CheckResult],
}

impl<'a> Results<'a> {
    pub fn new(
        suites: Vec<String>,
        seconds: f64,
        checks: &'a [CheckResult],
        verdict: Option<String>,
    ) -> Self {
        let count = |s: Status| checks.iter().filter(|c| c.status == s).count();
        let (passed, failed, errors, skipped) = (
            count(Status::Pass),
            count(Status::Fail),
            count(Status::Error),
            count(Status::Skipped),
        );
        Results {
            tubemem_version: env!("CARGO_PKG_VERSION"),
            suites,
            seconds,
            passed,
            failed,
            errors,
            skipped,
            verdict: verdict.unwrap_or_else(|| {
                format!(
                    "{passed} passed, {failed} failed, {errors} errors, {skipped} skipped of {} checks",
                    checks.len()
                )
            }),
            checks,
        }
    }

    /// Whether every check passed or was skipped (exit code 0).
    pub fn ok(&self) -> bool {
        self.failed == 0 && self.errors == 0
    }
}

fn esc_xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
        // characters XML 1.0 does not allow
        .chars()
        .filter(|c| matches!(c, '\t' | '\n' | '\r') || *c >= ' ')
        .collect()
}

fn esc_md(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn num(v: f64) -> String {
    if v.is_nan() {
        "—".into()
    } else if v == 0.0 || (1e-3..1e4).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

/// junit.xml: one `<testcase>` per check; a failure or error carries its message, a skipped
/// check its reason.
pub fn junit(r: &Results) -> String {
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<testsuites name=\"tubemem verify\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"{}\" time=\"{:.3}\">",
        r.checks.len(),
        r.failed,
        r.errors,
        r.skipped,
        r.seconds
    );
    let mut suites: Vec<&str> = r.checks.iter().map(|c| c.suite.as_str()).collect();
    suites.dedup();
    for s in suites {
        let cs: Vec<&CheckResult> = r.checks.iter().filter(|c| c.suite == s).collect();
        let count = |st: Status| cs.iter().filter(|c| c.status == st).count();
        let _ = writeln!(
            x,
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"{}\" time=\"{:.3}\">",
            esc_xml(s),
            cs.len(),
            count(Status::Fail),
            count(Status::Error),
            count(Status::Skipped),
            cs.iter().map(|c| c.seconds).sum::<f64>()
        );
        for c in cs {
            let _ = write!(
                x,
                "    <testcase classname=\"tubemem.verify.{}\" name=\"{}\" time=\"{:.3}\"",
                c.kind,
                esc_xml(&c.name),
                c.seconds
            );
            let body = |tag: &str| {
                format!(
                    ">\n      <{tag} message=\"{}\" type=\"{}\">{}</{tag}>\n    </testcase>\n",
                    esc_xml(&c.message),
                    c.kind,
                    esc_xml(&c.message)
                )
            };
            match c.status {
                Status::Pass => x.push_str(" />\n"),
                Status::Fail => x.push_str(&body("failure")),
                Status::Error => x.push_str(&body("error")),
                Status::Skipped => {
                    let _ = write!(
                        x,
                        ">\n      <skipped message=\"{}\" />\n    </testcase>\n",
                        esc_xml(&c.message)
                    );
                }
            }
        }
        x.push_str("  </testsuite>\n");
    }
    x.push_str("</testsuites>\n");
    x
}

/// report.md: the verdict, a table of the checks, then every measure with its source.
pub fn markdown(r: &Results) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "# tubemem verify — {}\n", r.suites.join(", "));
    let _ = writeln!(m, "**{}** ({:.1} s)\n", esc_md(&r.verdict), r.seconds);
    let _ = writeln!(m, "| check | kind | status | result | time |");
    let _ = writeln!(m, "|---|---|---|---|---|");
    for c in r.checks {
        let _ = writeln!(
            m,
            "| {} | {} | {} | {} | {:.1} s |",
            esc_md(&c.name),
            c.kind,
            c.status.label(),
            esc_md(&c.message),
            c.seconds
        );
    }
    for c in r.checks {
        let _ = writeln!(m, "\n## {} ({}, {})\n", c.name, c.kind, c.status.label());
        if c.measures.is_empty() {
            let _ = writeln!(m, "{}", esc_md(&c.message));
            continue;
        }
        let _ = writeln!(
            m,
            "| quantity | measured | tolerance | pass | how | source |"
        );
        let _ = writeln!(m, "|---|---|---|---|---|---|");
        for q in &c.measures {
            let _ = writeln!(
                m,
                "| {} | {} | {} | {} | {} | {} |",
                esc_md(&q.quantity),
                num(q.measured),
                tolerance_cell(q),
                pass_cell(q, "**no**"),
                esc_md(&q.note),
                esc_md(q.source.as_deref().unwrap_or(""))
            );
        }
        if let Some(p) = &c.plot {
            let _ = writeln!(m, "\n![{}]({p})", c.name);
        }
    }
    m
}

fn esc_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// report.html: one file, no network: styles inline, plots as `data:image/png;base64` URIs.
pub fn html(r: &Results) -> String {
    let mut h = String::new();
    let status_color = |s: Status| match s {
        Status::Pass => "#1b7f3a",
        Status::Fail => "#b3261e",
        Status::Error => "#8a4b00",
        Status::Skipped => "#666666",
    };
    let overall = if r.ok() { Status::Pass } else { Status::Fail };
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>tubemem verify — {}</title>\n<style>\nbody{{font-family:sans-serif;margin:2em;max-width:1200px;color:#222}}\ntable{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #ccc;padding:4px 8px;text-align:left;vertical-align:top;font-size:14px}}\nth{{background:#f0f0f0}}.st{{font-weight:bold;color:white;padding:2px 8px;border-radius:4px}}\n.verdict{{font-size:20px;padding:12px;border-left:8px solid {};background:#f7f7f7}}\nimg{{max-width:100%;border:1px solid #ddd}}\n</style></head><body>\n",
        esc_html(&r.suites.join(", ")),
        status_color(overall)
    );
    let _ = writeln!(
        h,
        "<h1>tubemem verify — {}</h1>\n<p class=\"verdict\">{}</p>\n<p>{} passed, {} failed, {} errors, {} skipped; {:.1} s; tubemem {}</p>",
        esc_html(&r.suites.join(", ")),
        esc_html(&r.verdict),
        r.passed,
        r.failed,
        r.errors,
        r.skipped,
        r.seconds,
        r.tubemem_version
    );
    let _ = writeln!(
        h,
        "<table><tr><th>check</th><th>kind</th><th>status</th><th>result</th><th>time</th></tr>"
    );
    for c in r.checks {
        let _ = writeln!(
            h,
            "<tr><td><a href=\"#{0}\">{0}</a></td><td>{1}</td><td><span class=\"st\" style=\"background:{2}\">{3}</span></td><td>{4}</td><td>{5:.1} s</td></tr>",
            esc_html(&c.name),
            c.kind,
            status_color(c.status),
            c.status.label(),
            esc_html(&c.message),
            c.seconds
        );
    }
    h.push_str("</table>\n");
    for c in r.checks {
        let _ = writeln!(
            h,
            "<h2 id=\"{0}\">{0} <span class=\"st\" style=\"background:{1}\">{2}</span></h2>\n<p>{3} — {4}</p>",
            esc_html(&c.name),
            status_color(c.status),
            c.status.label(),
            c.kind,
            esc_html(&c.message)
        );
        if !c.measures.is_empty() {
            h.push_str("<table><tr><th>quantity</th><th>measured</th><th>tolerance</th><th>pass</th><th>how</th><th>source</th></tr>\n");
            for q in &c.measures {
                let _ = writeln!(
                    h,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                    esc_html(&q.quantity),
                    num(q.measured),
                    tolerance_cell(q),
                    pass_cell(q, "<b>no</b>"),
                    esc_html(&q.note),
                    esc_html(q.source.as_deref().unwrap_or(""))
                );
            }
            h.push_str("</table>\n");
        }
        if let Some(png) = &c.png {
            let _ = writeln!(
                h,
                "<img alt=\"{}\" src=\"data:image/png;base64,{}\">",
                esc_html(&c.name),
                tubemem_mesh::vtu::base64(png)
            );
        }
    }
    h.push_str("</body></html>\n");
    h
}

/// The report files a verification run writes into its `--out` folder.
pub const REPORT_FILES: [&str; 4] = ["results.json", "report.md", "report.html", "junit.xml"];

/// Whether the first 4 KiB `head` of the report file `name` is one a verification run wrote.
fn is_report(name: &str, head: &str) -> bool {
    match name {
        "results.json" => head.starts_with('{') && head.contains("\"tubemem_version\""),
        "report.md" => head.starts_with("# tubemem verify"),
        "report.html" => head.contains("<title>tubemem verify"),
        _ => head.contains("<testsuites name=\"tubemem verify\""),
    }
}

/// Refuse an `out` folder where a report file exists that no verification run wrote (a
/// user's own `results.json`), or that is a folder or not a regular file: checked before any
/// check runs, and again before the reports are written.
pub fn check_folder(out: &Path) -> crate::Result<()> {
    for name in REPORT_FILES {
        crate::output_file::check("--out", &out.join(name), &[], |head| is_report(name, head))?;
    }
    Ok(())
}

/// Write results.json, report.md, report.html and junit.xml into `out`; the files written.
/// A report file that a verification run did not write is refused ([`check_folder`]).
pub fn write_all(out: &Path, r: &Results) -> crate::Result<Vec<PathBuf>> {
    check_folder(out)?;
    let mut written = vec![];
    let json = serde_json::to_string_pretty(r).map_err(|e| crate::AppError::Output {
        what: "results.json".into(),
        source: Box::new(e),
    })?;
    for (name, text) in [
        ("results.json", json + "\n"),
        ("report.md", markdown(r)),
        ("report.html", html(r)),
        ("junit.xml", junit(r)),
    ] {
        let p = out.join(name);
        crate::output_file::write_whole(&p, text.as_bytes())?;
        written.push(p);
    }
    Ok(written)
}

/// The tolerance column: the value, "reported" for a quantity reported only, "—" for one that
/// failed with nothing to hold it to (an order that could not be observed).
fn tolerance_cell(q: &super::Measure) -> String {
    match (q.tolerance, q.pass) {
        (Some(t), _) => num(t),
        (None, true) => "reported".into(),
        (None, false) => "—".into(),
    }
}

/// The pass column: "yes"/`no` against a tolerance, "—" for a reported quantity (it is not
/// judged), `no` for one that failed without a tolerance.
fn pass_cell(q: &super::Measure, no: &'static str) -> &'static str {
    match (q.tolerance, q.pass) {
        (None, true) => "—",
        (_, true) => "yes",
        (_, false) => no,
    }
}
