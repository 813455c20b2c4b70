//! A run's checkpoint: the state after a converged step and everything a restart needs to
//! continue the run bit for bit, with its binary format and its validation against the case.

use crate::report::{CriticalRecord, RunReport, StepRecord};
use crate::{AppError, Result};
use std::path::Path;

/// What a stage is set up with at its start. A checkpoint stores it, so that a restart
/// continues the stage exactly as the interrupted run would have.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StageContext {
    pub stage: usize,
    /// the load parameter at the start and the end of the stage
    pub from: f64,
    pub to: f64,
    /// Boyle's constant of a squeeze (0 otherwise)
    pub pv: f64,
    /// the pressure ϖ at the stage's start (a regulated squeeze or confinement holds it or
    /// ramps from it)
    #[serde(default)]
    pub start_pressure: f64,
    /// a closed-gas squeeze that continues a regulated one (the mixed path): the half-gap ρ
    /// and the pressure ϖ at which the gas was closed in
    #[serde(default)]
    pub gas_closed_at: Option<[f64; 2]>,
    /// an inflation between held plates (`plates = "held"`): their half-gap, where the squeeze
    /// before it left them
    #[serde(default)]
    pub held_plates: Option<f64>,
    /// the contact penalty of a squeeze (0 otherwise)
    pub penalty: f64,
    /// the mid-span λs at the stage start (λs* of a squeeze)
    pub start_lambda_s: f64,
}

/// A run's state after a converged step, to restart from ([`crate::output::RunWriter`] writes
/// them, [`crate::output::RunWriter::resume`] reads the newest back).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Checkpoint {
    pub case_hash: String,
    pub context: StageContext,
    pub progress: tubemem_fem::stepping::StepState,
    /// the finished stages
    pub report: RunReport,
    /// the current stage's steps so far
    pub steps: Vec<StepRecord>,
    /// the critical points the current stage (arc length) has located so far
    #[serde(default)]
    pub critical_points: Vec<CriticalRecord>,
    /// steps.csv rows and VTU frames written up to this step, and the PVD entries
    pub rows: usize,
    pub frames: usize,
    pub pvd: Vec<(f64, String)>,
    /// the state (stored in binary beside the header)
    #[serde(skip)]
    pub x: Vec<[f64; 3]>,
    #[serde(skip)]
    pub p: f64,
    /// the state's contact multipliers (an augmented squeeze; empty otherwise)
    #[serde(skip)]
    pub multipliers: Vec<f64>,
    /// the converged state before it in the stage, if any (in binary after the state)
    #[serde(skip)]
    pub previous: Option<(Vec<[f64; 3]>, f64)>,
}

/// The first checkpoint format: the state's positions and pressure (and the previous state's).
const CHECKPOINT_MAGIC_V1: &[u8; 12] = b"TUBEMEMCKPT1";
/// The second adds the state's contact multipliers (an augmented-Lagrangian squeeze).
const CHECKPOINT_MAGIC: &[u8; 12] = b"TUBEMEMCKPT2";

/// Write a checkpoint: magic, header length (u64 LE), the header as JSON (exact floats), the
/// node count and the multiplier count (u64 LE), the positions, the pressure and the
/// multipliers as f64 LE, then the previous state's positions and pressure when there is one.
pub(crate) fn write_checkpoint(path: &Path, ck: &Checkpoint) -> Result<()> {
    let header = serde_json::to_vec(ck).map_err(|e| AppError::Output {
        what: path.display().to_string(),
        source: Box::new(e),
    })?;
    let mut buf =
        Vec::with_capacity(48 + header.len() + 48 * ck.x.len() + 8 * ck.multipliers.len());
    buf.extend_from_slice(CHECKPOINT_MAGIC);
    buf.extend_from_slice(&(header.len() as u64).to_le_bytes());
    buf.extend_from_slice(&header);
    buf.extend_from_slice(&(ck.x.len() as u64).to_le_bytes());
    buf.extend_from_slice(&(ck.multipliers.len() as u64).to_le_bytes());
    for p in &ck.x {
        for v in p {
            buf.extend_from_slice(&v.to_le_bytes());
        }
    }
    buf.extend_from_slice(&ck.p.to_le_bytes());
    for v in &ck.multipliers {
        buf.extend_from_slice(&v.to_le_bytes());
    }
    // the stepping's previous state, same layout, when there is one (an older checkpoint
    // without it reads as none)
    if let Some((x, p)) = &ck.previous {
        for q in x {
            for v in q {
                buf.extend_from_slice(&v.to_le_bytes());
            }
        }
        buf.extend_from_slice(&p.to_le_bytes());
    }
    crate::output_file::write_whole(path, &buf)
}

/// Read a checkpoint written by [`write_checkpoint`]; `None` if it is not a whole one.
pub(crate) fn read_checkpoint(path: &Path) -> Option<Checkpoint> {
    let buf = std::fs::read(path).ok()?;
    let (rest, v2) = match buf.strip_prefix(CHECKPOINT_MAGIC) {
        Some(r) => (r, true),
        None => (buf.strip_prefix(CHECKPOINT_MAGIC_V1)?, false),
    };
    let u64_at =
        |b: &[u8]| -> Option<u64> { Some(u64::from_le_bytes(b.get(..8)?.try_into().ok()?)) };
    let hl = usize::try_from(u64_at(rest)?).ok()?;
    let header = rest.get(8..8usize.checked_add(hl)?)?;
    let mut ck: Checkpoint = serde_json::from_slice(header).ok()?;
    let rest = rest.get(8 + hl..)?;
    let n = usize::try_from(u64_at(rest)?).ok()?;
    let (m, data) = if v2 {
        let rest = rest.get(8..)?;
        (usize::try_from(u64_at(rest)?).ok()?, rest.get(8..)?)
    } else {
        (0, rest.get(8..)?)
    };
    let one = n.checked_mul(24)?.checked_add(8)?;
    let state_len = one.checked_add(m.checked_mul(8)?)?;
    if data.len() != state_len && data.len() != state_len.checked_add(one)? {
        return None;
    }
    // the length is checked above: 3n coordinates and the pressure, 8 bytes each
    let v: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| {
            let mut b = [0u8; 8];
            b.copy_from_slice(c);
            f64::from_le_bytes(b)
        })
        .collect();
    let positions =
        |w: &[f64]| -> Vec<[f64; 3]> { w.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect() };
    ck.x = positions(&v[..3 * n]);
    ck.p = v[3 * n];
    let s = 3 * n + 1 + m;
    ck.multipliers = v[3 * n + 1..s].to_vec();
    ck.previous = (v.len() > s).then(|| (positions(&v[s..s + 3 * n]), v[s + 3 * n]));
    Some(ck)
}

/// The contact edges a tracked mesh had at a checkpoint's step: its own stage's last record
/// with them, else the finished stages' (`None`: never fitted, the uniform mesh).
pub(crate) fn checkpoint_edges(ck: &Checkpoint) -> Option<Vec<f64>> {
    ck.steps
        .iter()
        .rev()
        .chain(
            ck.report
                .stages
                .iter()
                .rev()
                .flat_map(|s| s.steps.iter().rev()),
        )
        .find_map(|r| r.edge_tracking.as_ref())
        .map(|t| t.edges.clone())
        .filter(|e| !e.is_empty())
}

impl Checkpoint {
    /// Why this checkpoint cannot continue a run of the case whose text hashes to `case_hash`
    /// on a mesh of `nodes` nodes (`None`: not known yet), or `None` when it can. The one check
    /// of both the writer's [`crate::output::RunWriter::resume`] and the run's restart.
    pub fn mismatch(&self, case_hash: &str, nodes: Option<usize>) -> Option<String> {
        if self.case_hash != case_hash {
            return Some(format!(
                "the case has changed since the run started (hash {} then, {case_hash} now): resume with the same case file, or start afresh with --overwrite",
                self.case_hash
            ));
        }
        match nodes {
            Some(n) if n != self.x.len() => {
                Some("the checkpoint's state does not fit the case's mesh".into())
            }
            _ => None,
        }
    }
}
