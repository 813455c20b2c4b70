//! `tubemem run CASE.toml --out DIR`: the FE run of a case file.
//!
//! Every converged step is written as it comes: a row of `steps.csv` (flushed), a VTU file and
//! the `.pvd` index. `summary.json` is rewritten after every stage (and on failure, with the
//! error), so a run that fails midway loses nothing that had converged.

use crate::case::{Caps, Case, Target};
use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{json, Value};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use tubemem_fem::contact::{penalty_for, Plane};
use tubemem_fem::model::{nearest_node, run_stage, Control, Model, Stage, State};
use tubemem_fem::post::{
    cell_contact_pressure, cell_values, midspan, midspan_contact, ring_profile, ContactValues,
    MidSpan, RingValues,
};
use tubemem_gps::{flatten, inflate, section_at_pressure, Hypothesis, SectionState};
use tubemem_material::MembraneLaw;
use tubemem_mesh::tube::{capped_tube_with_cap_rows, plugged_tube};
use tubemem_mesh::vtu::{write_pvd, write_vtu, Field};

pub const STEPS_HEADER: &str = "stage,step,w,lambda_s,lambda_z,n_s,n_z,n_sz,volume,newton_iterations,negative_pivots,rho,chi,chi_geometric,force,displacement,contact_pressure,penetration,\
gps_w,gps_lambda_s,gps_lambda_z,gps_chi,gps_force,local_lambda_s,local_lambda_z,local_chi,local_force";

/// The closed form at one step: GPS at the same mid-span λs (inflation) or at the same ρ from the
/// run's λs* (squeeze, eqs. 76–77), then, for a squeeze, the GPS section under the FE's own
/// mid-span pressure (eq. 76 without the gas law: the local mechanics, free of the end effect that
/// acts through the shared gas). A closed form that has no solution leaves its steps.csv fields
/// empty (and the section's error goes to summary.json): the run goes on.
struct StepClosedForm {
    /// w, lambda_s, lambda_z, chi, force
    gps: [Option<f64>; 5],
    /// `None` for inflation steps or when the GPS flattening itself failed
    local: Option<Result<SectionState, String>>,
}

impl StepClosedForm {
    fn new(law: &dyn MembraneLaw, ms: &MidSpan, squeeze: Option<(&ContactValues, f64)>) -> Self {
        let mut gps = [None; 5];
        let mut local = None;
        match squeeze {
            None => {
                if let Ok(s) = inflate(law, Hypothesis::Gps, ms.lambda_s) {
                    gps[..3].copy_from_slice(&[Some(s.w), Some(s.lambda_s), Some(s.lambda_z)]);
                }
            }
            Some((c, ls0)) => {
                if let Ok(g) = flatten(law, Hypothesis::Gps, ls0, c.rho) {
                    gps = [g.w, g.lambda_s, g.lambda_z, g.chi, g.force].map(Some);
                    local = Some(
                        section_at_pressure(law, c.rho, ms.w, [g.lambda_s, g.lambda_z])
                            .map_err(|e| e.to_string()),
                    );
                }
            }
        }
        Self { gps, local }
    }

    /// The nine closed-form fields of a steps.csv row (`STEPS_HEADER` from `gps_w` on).
    fn columns(&self) -> impl Iterator<Item = Option<f64>> + '_ {
        let local = match &self.local {
            Some(Ok(l)) => [l.lambda_s, l.lambda_z, l.chi, l.force].map(Some),
            _ => [None; 4],
        };
        self.gps.into_iter().chain(local)
    }
}

/// The last converged step of a stage: what its summary entry reports.
struct LastStep {
    ms: MidSpan,
    contact: Option<ContactValues>,
    iterations: usize,
    negative_pivots: usize,
    local: Option<Result<SectionState, String>>,
}

struct Output {
    dir: PathBuf,
    steps: BufWriter<File>,
    pvd: Vec<(f64, String)>,
    frames: usize,
}

impl Output {
    fn new(dir: &Path) -> Result<Self> {
        for sub in ["vtu", "profiles"] {
            std::fs::create_dir_all(dir.join(sub))
                .with_context(|| format!("cannot create {}", dir.join(sub).display()))?;
        }
        let path = dir.join("steps.csv");
        let mut steps = BufWriter::new(
            File::create(&path).with_context(|| format!("cannot create {}", path.display()))?,
        );
        writeln!(steps, "{STEPS_HEADER}")?;
        steps.flush()?;
        Ok(Self {
            dir: dir.to_path_buf(),
            steps,
            pvd: vec![],
            frames: 0,
        })
    }

    /// One row; the contact columns are empty for inflation stages.
    fn row(
        &mut self,
        (stage, step): (usize, usize),
        m: &MidSpan,
        its: usize,
        neg: usize,
        c: Option<(&ContactValues, f64)>,
        cf: &StepClosedForm,
    ) -> std::io::Result<()> {
        write!(
            self.steps,
            "{stage},{step},{},{},{},{},{},{},{},{its},{neg}",
            m.w, m.lambda_s, m.lambda_z, m.n_s, m.n_z, m.n_sz, m.volume
        )?;
        match c {
            Some((c, d)) => write!(
                self.steps,
                ",{},{},{},{},{d},{},{}",
                c.rho, c.chi, c.chi_geometric, c.force, c.contact_pressure, c.penetration
            )?,
            None => write!(self.steps, ",,,,,,,")?,
        }
        for v in cf.columns() {
            match v {
                Some(v) => write!(self.steps, ",{v}")?,
                None => write!(self.steps, ",")?,
            }
        }
        writeln!(self.steps)?;
        self.steps.flush()
    }

    fn frame(&mut self, model: &Model, state: &State, planes: &[Plane]) -> Result<(), String> {
        let cells = cell_values(model, state).map_err(|e| e.to_string())?;
        let disp: Vec<f64> = state
            .x
            .iter()
            .zip(&model.mesh.nodes)
            .flat_map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]])
            .collect();
        let pick = |f: fn(&tubemem_fem::post::CellValues) -> f64| {
            cells.iter().map(f).collect::<Vec<f64>>()
        };
        let (hoop, axial, n1, n2) = (
            pick(|c| c.hoop_stretch),
            pick(|c| c.axial_stretch),
            pick(|c| c.n1),
            pick(|c| c.n2),
        );
        let wrinkled = pick(|c| f64::from(c.state()));
        let pc = cell_contact_pressure(model, state, planes);
        let name = format!("step_{:05}.vtu", self.frames);
        write_vtu(
            &self.dir.join("vtu").join(&name),
            &state.x,
            &model.mesh.quads,
            &[Field {
                name: "displacement",
                components: 3,
                values: &disp,
            }],
            &[
                Field {
                    name: "hoop_stretch",
                    components: 1,
                    values: &hoop,
                },
                Field {
                    name: "axial_stretch",
                    components: 1,
                    values: &axial,
                },
                Field {
                    name: "N1",
                    components: 1,
                    values: &n1,
                },
                Field {
                    name: "N2",
                    components: 1,
                    values: &n2,
                },
                Field {
                    name: "wrinkled",
                    components: 1,
                    values: &wrinkled,
                },
                Field {
                    name: "contact_pressure",
                    components: 1,
                    values: &pc,
                },
            ],
        )
        .map_err(|e| e.to_string())?;
        self.pvd.push((self.frames as f64, format!("vtu/{name}")));
        self.frames += 1;
        write_pvd(&self.dir.join("tube.pvd"), &self.pvd).map_err(|e| e.to_string())
    }
}

fn midspan_json(m: &MidSpan) -> Value {
    json!({"w": m.w, "lambda_s": m.lambda_s, "lambda_z": m.lambda_z, "n_s": m.n_s, "n_z": m.n_z, "n_sz": m.n_sz, "volume": m.volume})
}

fn write_profile(path: &Path, rings: &[RingValues]) -> Result<()> {
    let mut f = BufWriter::new(
        File::create(path).with_context(|| format!("cannot create {}", path.display()))?,
    );
    writeln!(f, "z_ref,z,radius,lambda_s,lambda_z,n_s,n_z,n_sz")?;
    for r in rings {
        let v = &r.values;
        writeln!(
            f,
            "{},{},{},{},{},{},{},{}",
            r.z_ref, r.z, r.radius, v.lambda_s, v.lambda_z, v.n_s, v.n_z, v.n_sz
        )?;
    }
    Ok(())
}

/// Distance (in R) from the cap junction (or plug) at which λs comes within `tol` of its
/// mid-span value and stays there all the way to mid-span; `None` if it never does.
pub fn boundary_layer(rings: &[RingValues], half_length: f64, mid: f64, tol: f64) -> Option<f64> {
    let mut side: Vec<&RingValues> = rings.iter().filter(|r| r.z_ref >= -1e-12).collect();
    side.sort_by(|a, b| b.z_ref.total_cmp(&a.z_ref)); // from the junction inwards
    let within = |r: &&RingValues| ((r.values.lambda_s - mid) / mid).abs() <= tol;
    let first_inside = side.iter().position(within)?;
    if side[first_inside..].iter().all(within) {
        Some(half_length - side[first_inside].z_ref)
    } else {
        None
    }
}

/// Where the membrane is wrinkled or slack at the end of a stage: element counts and the range
/// of reference height Z (in R) and of the polar angle from the tube axis they occupy.
fn wrinkle_report(model: &Model, state: &State) -> Result<Value> {
    let cells = cell_values(model, state)?;
    let mut out = json!({});
    for (code, name) in [(1u8, "wrinkled"), (2u8, "slack")] {
        let zs: Vec<f64> = cells
            .iter()
            .zip(&model.mesh.quads)
            .filter(|(c, _)| c.state() == code)
            .map(|(_, q)| q.iter().map(|&i| model.mesh.nodes[i][2]).sum::<f64>() / 4.0)
            .collect();
        let (lo, hi) = zs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &z| {
                (a.min(z), b.max(z))
            });
        out[name] = if zs.is_empty() {
            json!({"elements": 0})
        } else {
            json!({"elements": zs.len(), "z_ref_min": lo, "z_ref_max": hi})
        };
    }
    Ok(out)
}

fn rel(fe: f64, cf: f64) -> f64 {
    (fe - cf) / cf.abs().max(1e-300)
}

/// The closed-form comparison of a stage's final state.
fn closed_form(
    law: &dyn MembraneLaw,
    ms: &MidSpan,
    squeeze: Option<(&ContactValues, f64)>,
    local: Option<&Result<SectionState, String>>,
) -> Result<Value> {
    let mut out = json!({});
    for hyp in [Hypothesis::Gps, Hypothesis::Ps] {
        let key = hyp.label().to_lowercase();
        let (cf, err) = match squeeze {
            None => {
                let s = inflate(law, hyp, ms.lambda_s)?;
                (
                    json!({"w": s.w, "lambda_s": s.lambda_s, "lambda_z": s.lambda_z, "n_s": s.n_s, "n_z": s.n_z}),
                    json!({"w": rel(ms.w, s.w), "lambda_z": rel(ms.lambda_z, s.lambda_z), "n_s": rel(ms.n_s, s.n_s), "n_z": rel(ms.n_z, s.n_z)}),
                )
            }
            Some((c, ls0)) => {
                let s = flatten(law, hyp, ls0, c.rho)?;
                (
                    json!({"w": s.w, "lambda_s": s.lambda_s, "lambda_z": s.lambda_z, "n_s": s.n_s, "n_z": s.n_z,
                           "rho": s.rho, "chi": s.chi, "force": s.force, "displacement": s.displacement}),
                    json!({"w": rel(ms.w, s.w), "lambda_s": rel(ms.lambda_s, s.lambda_s), "lambda_z": rel(ms.lambda_z, s.lambda_z),
                           "chi": rel(c.chi, s.chi), "force": rel(c.force, s.force)}),
                )
            }
        };
        out[&key] = cf;
        out[format!("relative_error_vs_{key}")] = err;
    }
    // the section at the FE's pressure, as solved for the step's steps.csv row
    match (squeeze, local) {
        (Some((c, _)), Some(Ok(l))) => {
            out["gps_at_fe_pressure"] = json!({"w": l.w, "lambda_s": l.lambda_s, "lambda_z": l.lambda_z,
                "n_s": l.n_s, "n_z": l.n_z, "rho": l.rho, "chi": l.chi, "force": l.force});
            out["relative_error_vs_gps_at_fe_pressure"] = json!({"lambda_s": rel(ms.lambda_s, l.lambda_s),
                "lambda_z": rel(ms.lambda_z, l.lambda_z), "chi": rel(c.chi, l.chi), "force": rel(c.force, l.force)});
        }
        (Some(_), Some(Err(e))) => out["gps_at_fe_pressure"] = json!({ "error": e }),
        _ => {}
    }
    Ok(out)
}

pub fn run(case_path: &Path, out: &Path) -> Result<()> {
    let case = Case::read(case_path)?;
    run_case(&case, &case_path.display().to_string(), out)
}

/// Run a parsed case; `label` names it in the outputs.
pub fn run_case(case: &Case, label: &str, out: &Path) -> Result<()> {
    let g = &case.geometry;
    let half = 0.5 * g.length / g.radius;
    let ll = g.length / g.radius;
    let mesh = match (&case.mesh.file, case.mesh.around, case.mesh.along) {
        (Some(file), ..) => {
            let path = case.base_dir.join(file);
            tubemem_mesh::io::read_json(&path, g.radius)
                .with_context(|| format!("[mesh] file = {file:?}"))?
        }
        (None, Some(around), Some(along)) => {
            let cap_rows = case.mesh.cap_rows.unwrap_or(around / 8);
            match g.caps {
                Caps::Hemisphere => {
                    capped_tube_with_cap_rows(1.0, ll, around, along, cap_rows, case.mesh.symmetry)
                }
                Caps::RigidPlug => plugged_tube(1.0, ll, around, along, case.mesh.symmetry),
            }
            .context("[mesh]")?
        }
        _ => bail!("[mesh] needs `around` and `along`, or `file`"),
    };
    let symmetry = mesh.symmetry;
    let law = case.material.build_with(case.solver.wrinkling)?;
    let closed_form_law = case.material.build()?;
    let mut model = Model::new(mesh, law)?;
    model.settings.rtol = case.solver.rtol;
    model.settings.max_iterations = case.solver.max_iterations;
    let mut o = Output::new(out)?;
    let mut state = model.reference_state();
    o.frame(&model, &state, &[]).map_err(anyhow::Error::msg)?;
    let v0 = model.multiplicity() * model.mesh.volume();
    let node = nearest_node(&model.mesh, [1.0, 0.0, 0.0]);
    let mut summary = json!({
        "case": label,
        "mesh": {"nodes": model.mesh.nodes.len(), "elements": model.mesh.quads.len(), "equations": model.n_eq,
                 "symmetry": format!("{symmetry:?}").to_lowercase()},
        "material": model.law.name(),
        "material_spec": serde_json::to_value(case.material)?,
        "geometry": {"radius": g.radius, "length": g.length, "thickness": g.thickness,
                     "caps": format!("{:?}", g.caps).to_lowercase()},
        "units": "dimensionless: R = 1, μH = 1, w = pR/(μH), resultants N/(μH), force = plate force per length/(πμH)",
        "stages": [],
    });
    let write_summary = |summary: &Value| -> Result<()> {
        let p = out.join("summary.json");
        std::fs::write(&p, serde_json::to_string_pretty(summary)?)
            .with_context(|| format!("cannot write {}", p.display()))
    };
    println!(
        "tubemem run: {} — {} elements, {} equations ({:?} model), {}",
        label,
        model.mesh.quads.len(),
        model.n_eq,
        symmetry,
        model.law.name()
    );
    for (i, spec) in case.stages.iter().enumerate() {
        let target = spec.target(i)?;
        // for a squeeze: the inflated mid-span stretch λs* and the gas constant at its start
        let start = midspan(&model, &state)?;
        let pv = state.p * model.multiplicity() * model.mesh.volume_at(&state.x);
        let (from, to, control): (f64, f64, Box<dyn Fn(f64) -> Control>) = match target {
            Target::Pressure(p) => (state.p, p, Box::new(Control::Pressure)),
            Target::Stretch(s) => (
                state.x[node][0],
                s,
                Box::new(move |v| Control::Node {
                    node,
                    component: 0,
                    target: v,
                }),
            ),
            Target::VolumeRatio(r) => (
                model.multiplicity() * model.mesh.volume_at(&state.x),
                r * v0,
                Box::new(Control::Volume),
            ),
            Target::Rho(rho) => {
                if state.p.is_nan() || state.p <= 0.0 {
                    bail!(
                        "[[stage]] {}: the tube holds no gas pressure to squeeze (ϖ = {})",
                        i + 1,
                        state.p
                    );
                }
                let h0 = state.x.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
                if rho >= h0 {
                    bail!("[[stage]] {}: `target_rho` = {rho} must be below the current half-height {h0:.6} of the tube", i + 1);
                }
                model.penalty = spec.penalty.unwrap_or_else(|| {
                    penalty_for(
                        state.p,
                        start.lambda_s * start.lambda_z,
                        spec.penetration_tolerance.unwrap_or(1e-3),
                    )
                });
                (
                    h0,
                    rho,
                    Box::new(move |h| Control::Squeeze { pv, half_gap: h }),
                )
            }
        };
        let squeeze = matches!(target, Target::Rho(_));
        let bar = ProgressBar::new(1000);
        bar.set_style(
            ProgressStyle::with_template("stage {prefix} [{bar:40}] {percent:>3}% {msg}")
                .expect("a valid progress template")
                .progress_chars("=> "),
        );
        bar.set_prefix(format!("{}/{} ({:?})", i + 1, case.stages.len(), target));
        let stage = Stage {
            index: i + 1,
            from,
            to,
            initial_steps: spec.steps,
            max_cuts: 12,
        };
        let mut last: Option<LastStep> = None;
        let (mut newton_total, mut steps_total) = (0usize, 0usize);
        let result = run_stage(
            &mut model,
            &mut state,
            &stage,
            &control,
            |m, step, value, st, info| {
                let ms = midspan(m, st).map_err(|e| e.to_string())?;
                let cv = squeeze.then(|| midspan_contact(m, st, value));
                let mut vals = vec![
                    ms.w,
                    ms.lambda_s,
                    ms.lambda_z,
                    ms.n_s,
                    ms.n_z,
                    ms.n_sz,
                    ms.volume,
                ];
                if let Some(c) = &cv {
                    vals.extend([c.chi, c.force, c.contact_pressure, c.penetration]);
                }
                if vals.iter().any(|v| !v.is_finite()) {
                    return Err(format!(
                        "a non-finite mid-span value was computed: {vals:?}"
                    ));
                }
                let cf = StepClosedForm::new(
                    closed_form_law.as_ref(),
                    &ms,
                    cv.as_ref().map(|c| (c, start.lambda_s)),
                );
                o.row(
                    (i + 1, step),
                    &ms,
                    info.iterations,
                    info.negative_pivots,
                    cv.as_ref().map(|c| (c, start.lambda_s - c.rho)),
                    &cf,
                )
                .map_err(|e| e.to_string())?;
                o.frame(m, st, &control(value).plates())?;
                let frac = if to != from {
                    ((value - from) / (to - from)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                bar.set_position((1000.0 * frac) as u64);
                bar.set_message(format!(
                    "step {step}: ϖ = {:.5}, λs = {:.5}, {} its",
                    ms.w, ms.lambda_s, info.iterations
                ));
                last = Some(LastStep {
                    ms,
                    contact: cv,
                    iterations: info.iterations,
                    negative_pivots: info.negative_pivots,
                    local: cf.local,
                });
                newton_total += info.iterations;
                steps_total += 1;
                Ok(())
            },
        );
        bar.finish_and_clear();
        if let Err(e) = result {
            summary["stages"]
                .as_array_mut()
                .expect("stages is an array")
                .push(json!({"index": i + 1, "error": e.to_string(),
                "last_converged": last.map(|l| midspan_json(&l.ms))}));
            write_summary(&summary)?;
            return Err(e).with_context(|| {
                format!(
                    "stage {} of {} failed; converged steps are in {}",
                    i + 1,
                    case.stages.len(),
                    out.display()
                )
            });
        }
        let LastStep {
            ms,
            contact: cv,
            iterations: its,
            negative_pivots: neg,
            local,
        } = match last {
            Some(l) => l,
            None => LastStep {
                ms: midspan(&model, &state)?,
                contact: None,
                iterations: 0,
                negative_pivots: 0,
                local: None,
            },
        };
        let rings = ring_profile(&model, &state)?;
        let profile = out
            .join("profiles")
            .join(format!("stage{}_final.csv", i + 1));
        write_profile(&profile, &rings)?;
        let layer = boundary_layer(&rings, half, ms.lambda_s, 1e-3);
        let wrinkling = wrinkle_report(&model, &state)?;
        let mut fin = midspan_json(&ms);
        fin["newton_iterations"] = json!(its);
        fin["stage_steps"] = json!(steps_total);
        fin["stage_newton_iterations"] = json!(newton_total);
        fin["negative_pivots"] = json!(neg);
        if let Some(c) = &cv {
            for (k, v) in [
                ("rho", c.rho),
                ("chi", c.chi),
                ("chi_geometric", c.chi_geometric),
                ("force", c.force),
                ("displacement", start.lambda_s - c.rho),
                ("contact_pressure", c.contact_pressure),
                ("penetration", c.penetration),
                ("total_plate_force", c.total_force),
                ("penalty", model.penalty),
            ] {
                fin[k] = json!(v);
            }
            fin["initial_stretch"] = json!(start.lambda_s);
        }
        let cf = closed_form(
            closed_form_law.as_ref(),
            &ms,
            cv.as_ref().map(|c| (c, start.lambda_s)),
            local.as_ref(),
        )?;
        let mut entry = json!({
            "index": i + 1,
            "kind": if squeeze { "squeeze" } else { "inflate" },
            "target": format!("{target:?}"),
            "final": fin,
            "cap_boundary_layer_0.1pct": layer,
            "wrinkling": wrinkling,
            "profile": profile.display().to_string(),
        });
        for (k, v) in cf.as_object().expect("an object") {
            entry[k] = v.clone();
        }
        summary["stages"]
            .as_array_mut()
            .expect("stages is an array")
            .push(entry);
        write_summary(&summary)?;
        let gps = &summary["stages"][i]["gps"];
        let ps = &summary["stages"][i]["ps"];
        let f = |v: &Value, k: &str| v[k].as_f64().unwrap_or(f64::NAN);
        println!(
            "stage {}: ϖ = {:.6} (GPS {:.6}, {:+.3}%; PS {:.6}), λs = {:.6} (GPS {:.6}), λz = {:.6} (GPS {:.6}; PS 1), N_s = {:.6}, N_z = {:.6}, N_sz = {:.1e}",
            i + 1,
            ms.w,
            f(gps, "w"),
            100.0 * rel(ms.w, f(gps, "w")),
            f(ps, "w"),
            ms.lambda_s,
            f(gps, "lambda_s"),
            ms.lambda_z,
            f(gps, "lambda_z"),
            ms.n_s,
            ms.n_z,
            ms.n_sz
        );
        if let Some(c) = &cv {
            println!(
                "         ρ = {:.4}: χ = {:.5} (GPS {:.5}, PS {:.5}), force ϖχ = {:.5} (GPS {:.5}, {:+.2}%; PS {:.5}), contact pressure {:.4}, penetration {:.1e}",
                c.rho,
                c.chi,
                f(gps, "chi"),
                f(ps, "chi"),
                c.force,
                f(gps, "force"),
                100.0 * rel(c.force, f(gps, "force")),
                f(ps, "force"),
                c.contact_pressure,
                c.penetration
            );
        }
        let loc = &summary["stages"][i]["gps_at_fe_pressure"];
        if let (Some(c), Some(_)) = (&cv, loc.get("chi")) {
            println!(
                "         GPS section at the FE's pressure ϖ = {:.6} (eq. 76, no gas law): λs {:+.3}%, λz {:+.3}%, χ {:+.3}%, force {:+.3}%",
                ms.w,
                100.0 * rel(ms.lambda_s, f(loc, "lambda_s")),
                100.0 * rel(ms.lambda_z, f(loc, "lambda_z")),
                100.0 * rel(c.chi, f(loc, "chi")),
                100.0 * rel(c.force, f(loc, "force")),
            );
        }
        if let Some(d) = layer {
            println!("         λs is within 0.1 % of its mid-span value from {d:.3} R inside the cap junction (or plug)");
        }
    }
    println!(
        "wrote {}/steps.csv, summary.json, profiles/, tube.pvd ({} VTU frames)",
        out.display(),
        o.frames
    );
    Ok(())
}
