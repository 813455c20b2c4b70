//! FE points drawn over the closed-form curves: an [`Overlay`] per run, from its typed report
//! or its folder, and its points as CSV.

use crate::report::RunReport;
use crate::{AppError, Result};
use std::path::{Path, PathBuf};
use tubemem_material::MaterialSpec;

/// One FE point of a squeeze step.
#[derive(Clone, Debug)]
pub struct SqueezePoint {
    pub lambda_s: f64,
    pub w: f64,
    pub rho: f64,
    pub displacement: f64,
    pub force: f64,
    /// the run's λs* (mid-span stretch when the squeeze started)
    pub initial_stretch: f64,
    /// the λs* the case inflated to (`target_stretch` of the inflation before the squeeze):
    /// the start whose curves the point belongs to. The FE's measured λs* differs from it by
    /// the ring polygon's discretization (the 9-node tube of the main job: 1.5e-6), not by a
    /// different start
    pub target_stretch: Option<f64>,
    /// GPS flattening from the run's λs* at the same ρ, when it has a solution
    pub gps_force: Option<f64>,
    /// how the step's gas was supplied: the figure it belongs on
    pub supply: PointSupply,
}

/// How the gas of a squeeze step was supplied, which decides its figure: the closed gas on the
/// paper's Figs. 6–7, the regulated supply on their pressure-held companions; an inflation
/// between held plates on neither (its plates do not move).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointSupply {
    Closed,
    Regulated,
    HeldPlates,
}

impl PointSupply {
    /// The supply of a stage from its kind, its `control` and whether it holds plates.
    fn of(kind: &str, control: Option<&str>, held: bool) -> Self {
        match (kind, control) {
            _ if held => PointSupply::HeldPlates,
            ("inflate", _) => PointSupply::HeldPlates,
            (_, Some("pressure")) => PointSupply::Regulated,
            _ => PointSupply::Closed,
        }
    }
}

/// The FE points of one run to draw over the closed-form curves.
#[derive(Clone, Debug)]
pub struct Overlay {
    pub label: String,
    /// where it came from (the run folder), for messages
    pub source: PathBuf,
    pub material: MaterialSpec,
    /// the run's `[units]` scales (None: dimensionless)
    pub scales: Option<tubemem_gps::Scales>,
    /// (λs, ϖ) of the inflation steps
    pub inflation: Vec<(f64, f64)>,
    pub squeeze: Vec<SqueezePoint>,
}

impl Overlay {
    /// The points of a run's typed report.
    pub fn from_report(report: &RunReport, label: &str, source: &Path) -> Self {
        let mut o = Overlay {
            label: label.to_string(),
            source: source.to_path_buf(),
            material: report.material_spec.clone(),
            scales: report.scales,
            inflation: vec![],
            squeeze: vec![],
        };
        // the target λs* of the last stretch-controlled inflation before each stage
        let mut target = vec![None; report.stages.len() + 1];
        let mut last = None;
        for st in &report.stages {
            match st.plan.target {
                crate::case::Target::Stretch(l) => last = Some(l),
                crate::case::Target::Pressure(_) | crate::case::Target::VolumeRatio(_) => {
                    last = None
                }
                _ => {}
            }
            if let Some(t) = target.get_mut(st.plan.index) {
                *t = last;
            }
        }
        for s in report.steps() {
            match &s.contact {
                Some(c) => o.squeeze.push(SqueezePoint {
                    target_stretch: target.get(s.stage).copied().flatten(),
                    lambda_s: s.midspan.lambda_s,
                    w: s.midspan.w,
                    rho: c.values.rho,
                    displacement: c.displacement,
                    force: c.values.force,
                    initial_stretch: c.initial_stretch,
                    gps_force: s.closed_form.gps_flattening.as_ref().map(|g| g.force),
                    supply: report.stages.get(s.stage.wrapping_sub(1)).map_or(
                        PointSupply::Closed,
                        |st| {
                            let kind = match st.plan.target {
                                crate::case::Target::Rho(_) | crate::case::Target::Confine(_) => {
                                    "squeeze"
                                }
                                _ => "inflate",
                            };
                            PointSupply::of(kind, st.plan.control(), st.plan.held_plates)
                        },
                    ),
                }),
                None => o.inflation.push((s.midspan.lambda_s, s.midspan.w)),
            }
        }
        o
    }

    /// The points of a `tubemem run` folder: the law from summary.json, the steps from
    /// steps.csv.
    pub fn read(dir: &Path) -> Result<Self> {
        let summary_path = dir.join("summary.json");
        let overlay = |path: &Path, message: String| AppError::Overlay {
            path: path.to_path_buf(),
            message,
        };
        let text = std::fs::read_to_string(&summary_path).map_err(|e| {
            overlay(
                &summary_path,
                format!("cannot read it ({e}): is this a tubemem run folder?"),
            )
        })?;
        let summary: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| overlay(&summary_path, format!("not valid JSON: {e}")))?;
        let material: MaterialSpec =
            serde_json::from_value(summary.get("material_spec").cloned().unwrap_or_default())
                .map_err(|e| overlay(&summary_path, format!("no readable `material_spec`: {e}")))?;
        let path = dir.join("steps.csv");
        let text = std::fs::read_to_string(&path).map_err(|e| {
            overlay(
                &path,
                format!("cannot read it ({e}): is this a tubemem run folder?"),
            )
        })?;
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
        let col = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| overlay(&path, format!("no column `{name}`")))
        };
        // each stage's target λs* (summary.json `stages[k].target`), carried to the squeezes
        // after a stretch-controlled inflation, as from a report
        let mut targets: Vec<Option<f64>> = vec![None];
        let mut supplies: Vec<PointSupply> = vec![PointSupply::Closed];
        let mut last = None;
        for st in summary
            .get("stages")
            .and_then(|s| s.as_array())
            .into_iter()
            .flatten()
        {
            let t = st.get("target");
            match t.and_then(|t| t.get("key")).and_then(|k| k.as_str()) {
                Some("target_stretch") => {
                    last = t.and_then(|t| t.get("value")).and_then(|v| v.as_f64())
                }
                Some("target_pressure" | "target_volume_ratio") => last = None,
                _ => {}
            }
            targets.push(last);
            let text = |k: &str| st.get(k).and_then(|v| v.as_str());
            supplies.push(PointSupply::of(
                text("kind").unwrap_or("squeeze"),
                text("control"),
                false,
            ));
        }
        let cstage = col("stage").ok();
        let (cw, cls, crho, cdisp, cforce, cgps) = (
            col("w")?,
            col("lambda_s")?,
            col("rho")?,
            col("displacement")?,
            col("force")?,
            col("gps_force").ok(),
        );
        // summary.json's `units`: the scales of a run with `[units]`, else a text
        let units = summary.get("units").filter(|u| u.is_object());
        let scales = units.and_then(|u| {
            let f = |k: &str| u.get(k).and_then(|v| v.as_f64());
            tubemem_gps::Scales::new(f("radius_m")?, f("thickness_m")?, f("shear_modulus_pa")?).ok()
        });
        let mut o = Overlay {
            label: dir
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_else(|| dir.display().to_string()),
            source: dir.to_path_buf(),
            material,
            scales,
            inflation: vec![],
            squeeze: vec![],
        };
        for (k, line) in lines.enumerate() {
            let f: Vec<&str> = line.split(',').collect();
            let num = |i: usize| -> Result<f64> {
                f.get(i)
                    .and_then(|v| v.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        overlay(
                            &path,
                            format!("row {}: column {i} is not a finite number", k + 2),
                        )
                    })
            };
            if f.get(crho).is_some_and(|v| !v.is_empty()) {
                let (rho, d) = (num(crho)?, num(cdisp)?);
                o.squeeze.push(SqueezePoint {
                    lambda_s: num(cls)?,
                    w: num(cw)?,
                    rho,
                    displacement: d,
                    force: num(cforce)?,
                    initial_stretch: d + rho,
                    target_stretch: cstage
                        .and_then(|c| f.get(c))
                        .and_then(|v| v.parse::<usize>().ok())
                        .and_then(|st| targets.get(st).copied().flatten()),
                    gps_force: match cgps {
                        Some(c) if f.get(c).is_some_and(|v| !v.is_empty()) => Some(num(c)?),
                        _ => None,
                    },
                    supply: cstage
                        .and_then(|c| f.get(c))
                        .and_then(|v| v.parse::<usize>().ok())
                        .and_then(|st| supplies.get(st).copied())
                        .unwrap_or(PointSupply::Closed),
                });
            } else {
                o.inflation.push((num(cls)?, num(cw)?));
            }
        }
        Ok(o)
    }
}

/// The law in a few words, for titles and messages.
pub fn law_label(spec: &MaterialSpec) -> String {
    match *spec {
        MaterialSpec::Abb { kuhn, .. } => format!("ABB, Kuhn N = {kuhn}"),
        MaterialSpec::MooneyRivlin { alpha, .. } => format!("Mooney–Rivlin, α = {alpha}"),
        MaterialSpec::NeoHookean { .. } => "neo-Hookean".into(),
        _ => spec
            .build()
            .map(|l| l.name())
            .unwrap_or_else(|_| spec.model().to_string()),
    }
}

/// Whether two specs are the same law (the shear modulus only scales, results are per μH): the
/// paper's laws by their parameters, any other by their dimensionless resultants N/(μH) at
/// probe stretches (uniaxial, equibiaxial, pure shear and a general state), to 1e-12.
pub fn same_law(a: &MaterialSpec, b: &MaterialSpec) -> bool {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * x.abs().max(y.abs());
    let paper = |s: &MaterialSpec| {
        matches!(
            s,
            MaterialSpec::Abb { .. }
                | MaterialSpec::MooneyRivlin { .. }
                | MaterialSpec::NeoHookean { .. }
        )
    };
    if !(paper(a) && paper(b)) {
        let (Ok(la), Ok(lb)) = (a.build(), b.build()) else {
            return false;
        };
        let probes = [
            (1.3, 1.3f64.powf(-0.5)),
            (1.2, 1.2),
            (1.25, 1.0),
            (1.4, 1.1),
        ];
        return probes.iter().all(|&(l1, l2)| {
            match (la.resultants(l1, l2), lb.resultants(l1, l2)) {
                (Ok(x), Ok(y)) => close(x[0], y[0]) && close(x[1], y[1]),
                _ => false,
            }
        });
    }
    match (a, b) {
        (MaterialSpec::Abb { kuhn: x, .. }, MaterialSpec::Abb { kuhn: y, .. }) => close(*x, *y),
        (
            MaterialSpec::MooneyRivlin { alpha: x, .. },
            MaterialSpec::MooneyRivlin { alpha: y, .. },
        ) => close(*x, *y),
        (MaterialSpec::NeoHookean { .. }, MaterialSpec::NeoHookean { .. }) => true,
        (MaterialSpec::NeoHookean { .. }, MaterialSpec::MooneyRivlin { alpha, .. })
        | (MaterialSpec::MooneyRivlin { alpha, .. }, MaterialSpec::NeoHookean { .. }) => {
            *alpha == 0.0
        }
        _ => false,
    }
}

/// The paper's law, the figures' default without overlays: ABB with 𝒩 = 30.
pub const PAPER_LAW: MaterialSpec = MaterialSpec::PAPER;

/// A file-name-safe form of a label.
pub(super) fn slug(s: &str) -> String {
    let t: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    t.trim_matches('_').to_string()
}

/// The overlays' points as CSV, one file each: every FE point drawn, with the GPS force at the
/// same ρ from the run's λs* and the difference shown in the error panels.
pub(super) fn points_file(dir: &Path, k: usize, o: &Overlay) -> (PathBuf, Vec<u8>) {
    let p = dir.join(format!("fe_points_{}_{}.csv", k + 1, slug(&o.label)));
    let mut rows: Vec<Vec<f64>> = o
        .inflation
        .iter()
        .map(|&(ls, w)| {
            vec![
                0.0,
                ls,
                w,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
            ]
        })
        .collect();
    for s in &o.squeeze {
        let (g, d) = match s.gps_force {
            Some(g) => (g, s.force - g),
            None => (f64::NAN, f64::NAN),
        };
        rows.push(vec![
            1.0,
            s.lambda_s,
            s.w,
            s.rho,
            s.displacement,
            s.force,
            s.initial_stretch,
            g,
            d,
        ]);
    }
    // empty fields, not NaN, for what a point does not have
    let mut text = String::from(
        "squeeze,lambda_s,w,rho,displacement,force,initial_stretch,gps_force,force_minus_gps\n",
    );
    for r in rows {
        text.push_str(&crate::curves::csv_line(&r));
        text.push('\n');
    }
    (p, text.into_bytes())
}

/// Two squeezes start from the same λs* (one figure, one pair of curves) within this relative
/// difference: a stretch-controlled inflation ends at its target to Newton's tolerance.
pub(super) const SAME_START: f64 = 1e-6;

impl SqueezePoint {
    /// The start whose curves the point belongs to: the case's target λs*, else the measured.
    pub fn start(&self) -> f64 {
        self.target_stretch.unwrap_or(self.initial_stretch)
    }
}

pub(super) fn same_start(a: f64, b: f64) -> bool {
    (a / b - 1.0).abs() <= SAME_START
}

/// A start λs* as the figures' file names and titles write it: one decimal where that is exact
/// (the paper's 1.3 and 6.0), else up to four, trailing zeros dropped (1.25, 1.4142).
pub(super) fn start_tag(l: f64) -> String {
    if ((l * 10.0).round() - l * 10.0).abs() <= 1e-9 * l.abs().max(1.0) {
        format!("{l:.1}")
    } else {
        let t = format!("{l:.4}");
        t.trim_end_matches('0').to_string()
    }
}
