//! One atlas member: its FE run, and what the atlas keeps of it, the mid-span FE and GPS values
//! at each ρ level (the end of each squeeze stage) with the flags that decide whether the level
//! can be fitted. Written as `runs/<name>/member.json` (exact: serde_json's round-trip floats),
//! which is how an interrupted atlas knows which runs it has.

use super::spec::{Atlas, Member, QUANTITIES};
use crate::quantity::step_pair;
use crate::report::{RunReport, StageOutcome};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A quantity at one level: the FE's mid-span value and the GPS flattening's at the same ρ.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct Pair {
    pub fe: f64,
    pub gps: f64,
}

impl Pair {
    /// FE/GPS − 1.
    pub fn error(&self) -> f64 {
        self.fe / self.gps - 1.0
    }
}

/// The member at one ρ level.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Level {
    pub rho: f64,
    /// the mid-span ring touches the plates (χ > 0)
    pub contact: bool,
    /// the run's own uniformity test at the step: the central half of the tube is uniform
    /// (false: a bulge, the section is not translation invariant)
    pub uniform: Option<bool>,
    /// a critical point (limit point or bifurcation) was located on the path up to this level
    pub critical: bool,
    /// the values per quantity, in [`QUANTITIES`] order; `None` where the closed form has none
    pub values: Vec<Option<Pair>>,
}

/// What the atlas keeps of one run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct MemberResult {
    pub name: String,
    pub stretch: f64,
    pub length: f64,
    /// the levels reached, highest ρ first (a failed run keeps those it reached)
    pub levels: Vec<Level>,
    /// the run's error chain when it did not finish
    pub error: Option<String>,
    /// the run's wall time in seconds (not part of any result)
    #[serde(default)]
    pub seconds: f64,
}

impl MemberResult {
    /// The level at `rho` (exactly: the stage ends land on the atlas's levels).
    pub fn level(&self, rho: f64) -> Option<&Level> {
        self.levels.iter().find(|l| l.rho == rho)
    }
}

/// The member's values from its report: the last step of each finished squeeze stage.
pub fn extract(member: &Member, atlas: &Atlas, report: &RunReport) -> Vec<Level> {
    let levels = atlas.levels(member.stretch);
    let mut out = vec![];
    let mut critical = report
        .stages
        .first()
        .is_some_and(|s| stage_critical(&s.outcome));
    // stage 0 inflates; stage k ≥ 1 ends at levels[k − 1]
    for (stage, &rho) in report.stages.iter().skip(1).zip(&levels) {
        critical |= stage_critical(&stage.outcome);
        if !matches!(stage.outcome, StageOutcome::Finished(_)) {
            break;
        }
        let Some(last) = stage.steps.last() else {
            break;
        };
        // plates: the mid-span ring's contact width; planes: any wall that pushes
        let contact = last.contact.is_some_and(|c| c.values.chi > 0.0)
            || last.walls.iter().any(|w| w.force > 0.0);
        out.push(Level {
            rho,
            contact,
            uniform: last.gps_applicable,
            critical,
            values: QUANTITIES
                .iter()
                .map(|q| step_pair(last, q).map(|(fe, gps)| Pair { fe, gps }))
                .collect(),
        });
    }
    out
}

fn stage_critical(o: &StageOutcome) -> bool {
    match o {
        StageOutcome::Finished(f) => !f.critical_points.is_empty(),
        StageOutcome::Failed(f) => !f.critical_points.is_empty(),
    }
}

/// Run one member into `dir` (its case.toml, the run's files and member.json) and return what
/// the atlas keeps; a failed run is a result with its error and the levels it reached.
pub fn run(atlas: &Atlas, member: &Member, dir: &Path) -> MemberResult {
    let t0 = std::time::Instant::now();
    let mut result = MemberResult {
        name: member.name.clone(),
        stretch: member.stretch,
        length: member.length,
        levels: vec![],
        error: None,
        seconds: 0.0,
    };
    let label = format!("atlas member {}", member.name);
    match run_case(atlas, member, dir, &label) {
        Ok(outcome) => {
            result.levels = extract(member, atlas, &outcome.report);
            let failed = outcome.report.stages.iter().find_map(|s| match &s.outcome {
                StageOutcome::Failed(f) => Some(format!("stage {}: {}", s.plan.index, f.error)),
                StageOutcome::Finished(_) => None,
            });
            result.error = outcome.error.map(|e| crate::error_chain(&e)).or(failed);
        }
        Err(e) => result.error = Some(e),
    }
    result.seconds = t0.elapsed().as_secs_f64();
    result
}

fn run_case(
    atlas: &Atlas,
    member: &Member,
    dir: &Path,
    label: &str,
) -> Result<crate::report::RunOutcome, String> {
    use crate::output::{FolderMode, RunWriter};
    let mut case =
        crate::case::Case::parse(&member.case_text).map_err(|e| crate::error_chain(&e))?;
    case.base_dir = atlas.base_dir.clone();
    let mut writer = RunWriter::create(dir, FolderMode::Overwrite, case.hash(), &[])
        .map_err(|e| crate::error_chain(&e))?
        .checkpoint_every(case.solver.checkpoint_every)
        .frames_of(case.output);
    crate::output_file::write_whole(&dir.join("case.toml"), member.case_text.as_bytes())
        .map_err(|e| crate::error_chain(&e))?;
    let options = crate::run::RunOptions {
        interrupt: super::interrupt_flag(),
        ..Default::default()
    };
    // a run that stopped part-way keeps the report of the stages it finished
    Ok(crate::run::run_with(
        &case,
        label,
        &options,
        &mut [&mut writer],
    ))
}
