//! The run writer: an [`Observer`] that turns the report into files as the run goes.
//!
//! * `steps.csv`: one row per converged step, flushed at once ([`STEPS_HEADER`]);
//! * `vtu/step_NNNNN.vtu` + `tube.pvd`: a frame per step (frame 0 is the reference state);
//! * `profiles/stageN_final.csv`: the profile along the tube at each stage end;
//! * `summary.json`: [`RunReport::summary`], rewritten (atomically: write, then rename) after
//!   every stage and on failure, so a run that fails midway loses nothing that had converged.

use crate::report::{RunReport, StepRecord};
use crate::run::{BoxError, Observer, StepView};
use crate::{AppError, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use tubemem_fem::model::{Model, State};
use tubemem_fem::post::{cell_contact_pressure, cell_values, regime_code, RingValues};
use tubemem_mesh::vtu::{write_pvd, write_vtu, Field};

/// The columns of steps.csv. New columns are only ever appended.
pub const STEPS_HEADER: &str = "stage,step,w,lambda_s,lambda_z,n_s,n_z,n_sz,volume,newton_iterations,negative_pivots,rho,chi,chi_geometric,force,displacement,contact_pressure,penetration,\
gps_w,gps_lambda_s,gps_lambda_z,gps_chi,gps_force,local_lambda_s,local_lambda_z,local_chi,local_force";

/// The values of one steps.csv row, `None` for an empty field.
pub fn step_row(r: &StepRecord) -> Vec<Option<f64>> {
    let m = &r.midspan;
    let mut v: Vec<Option<f64>> = vec![
        Some(r.stage as f64),
        Some(r.step as f64),
        Some(m.w),
        Some(m.lambda_s),
        Some(m.lambda_z),
        Some(m.n_s),
        Some(m.n_z),
        Some(m.n_sz),
        Some(m.volume),
        Some(r.newton_iterations as f64),
        Some(r.negative_pivots as f64),
    ];
    match &r.contact {
        Some(c) => {
            let c0 = &c.values;
            v.extend(
                [
                    c0.rho,
                    c0.chi,
                    c0.chi_geometric,
                    c0.force,
                    c.displacement,
                    c0.contact_pressure,
                    c0.penetration,
                ]
                .map(Some),
            );
        }
        None => v.extend([None; 7]),
    }
    let cf = &r.closed_form;
    match (&cf.gps_inflation, &cf.gps_flattening) {
        (Some(s), _) => v.extend([Some(s.w), Some(s.lambda_s), Some(s.lambda_z), None, None]),
        (None, Some(g)) => v.extend([g.w, g.lambda_s, g.lambda_z, g.chi, g.force].map(Some)),
        _ => v.extend([None; 5]),
    }
    match &cf.local {
        Some(Ok(l)) => v.extend([l.lambda_s, l.lambda_z, l.chi, l.force].map(Some)),
        _ => v.extend([None; 4]),
    }
    v
}

fn format_row(r: &StepRecord) -> String {
    let fields: Vec<String> = step_row(r)
        .into_iter()
        .enumerate()
        .map(|(k, v)| match (k, v) {
            // integers as integers
            (0 | 1 | 9 | 10, Some(x)) => format!("{}", x as u64),
            (_, Some(x)) => format!("{x}"),
            (_, None) => String::new(),
        })
        .collect();
    fields.join(",")
}

/// Writes a run folder.
pub struct RunWriter {
    dir: PathBuf,
    steps: Option<BufWriter<File>>,
    pvd: Vec<(f64, String)>,
    frames: usize,
}

impl RunWriter {
    pub fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
            steps: None,
            pvd: vec![],
            frames: 0,
        }
    }

    /// The number of VTU frames written.
    pub fn frames(&self) -> usize {
        self.frames
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn frame(
        &mut self,
        model: &Model,
        state: &State,
        contact: Option<&tubemem_fem::contact::Contact>,
    ) -> Result<(), BoxError> {
        let cells = cell_values(model, state)?;
        let disp: Vec<f64> = state
            .x
            .iter()
            .zip(&model.mesh().nodes)
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
        let wrinkled = pick(|c| regime_code(c.regime()));
        let pc = cell_contact_pressure(model, state, contact);
        let name = format!("step_{:05}.vtu", self.frames);
        let cell = |name, values| Field {
            name,
            components: 1,
            values,
        };
        write_vtu(
            &self.dir.join("vtu").join(&name),
            &state.x,
            &model.mesh().quads,
            &[Field {
                name: "displacement",
                components: 3,
                values: &disp,
            }],
            &[
                cell("hoop_stretch", &hoop),
                cell("axial_stretch", &axial),
                cell("N1", &n1),
                cell("N2", &n2),
                cell("wrinkled", &wrinkled),
                cell("contact_pressure", &pc),
            ],
        )?;
        self.pvd.push((self.frames as f64, format!("vtu/{name}")));
        self.frames += 1;
        write_pvd(&self.dir.join("tube.pvd"), &self.pvd)?;
        Ok(())
    }

    fn write_summary(&self, report: &RunReport) -> Result<()> {
        let path = self.dir.join("summary.json");
        let tmp = self.dir.join(".summary.json.tmp");
        let text =
            serde_json::to_string_pretty(&report.summary()).map_err(|e| AppError::Output {
                what: path.display().to_string(),
                source: Box::new(e),
            })?;
        std::fs::write(&tmp, text).map_err(|e| AppError::io(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| AppError::io(&path, e))
    }
}

/// Write a profile (one row per ring) as CSV.
pub fn write_profile(path: &Path, rings: &[RingValues]) -> Result<()> {
    let mut text = String::from("z_ref,z,radius,lambda_s,lambda_z,n_s,n_z,n_sz\n");
    for r in rings {
        let v = &r.values;
        text.push_str(&format!(
            "{},{},{},{},{},{},{},{}\n",
            r.z_ref, r.z, r.radius, v.lambda_s, v.lambda_z, v.n_s, v.n_z, v.n_sz
        ));
    }
    std::fs::write(path, text).map_err(|e| AppError::io(path, e))
}

impl Observer for RunWriter {
    fn started(
        &mut self,
        _report: &RunReport,
        model: &Model,
        state: &State,
    ) -> Result<(), BoxError> {
        for sub in ["vtu", "profiles"] {
            let d = self.dir.join(sub);
            std::fs::create_dir_all(&d).map_err(|e| AppError::io(&d, e))?;
        }
        let path = self.dir.join("steps.csv");
        let mut steps = BufWriter::new(File::create(&path).map_err(|e| AppError::io(&path, e))?);
        writeln!(steps, "{STEPS_HEADER}")?;
        steps.flush()?;
        self.steps = Some(steps);
        self.frame(model, state, None)
    }

    fn step(&mut self, view: &StepView) -> Result<(), BoxError> {
        if let Some(steps) = &mut self.steps {
            writeln!(steps, "{}", format_row(view.record))?;
            steps.flush()?;
        }
        self.frame(view.model, view.state, view.load.contact.as_ref())
    }

    fn stage_finished(&mut self, report: &RunReport) -> Result<(), BoxError> {
        if let Some(stage) = report.stages.last() {
            let path = self
                .dir
                .join("profiles")
                .join(format!("stage{}_final.csv", stage.plan.index));
            write_profile(&path, &stage.profile)?;
        }
        self.write_summary(report)?;
        Ok(())
    }

    fn failed(&mut self, report: &RunReport, _error: &AppError) {
        // Best effort: the run's error is what the user must see; a summary that cannot be
        // written here would have failed at the last stage end as well.
        if self.dir.is_dir() {
            let _ = self.write_summary(report);
        }
    }
}
