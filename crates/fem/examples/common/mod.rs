//! What the whole-tube examples (`neutral_mode`, `bulge_slide`) share: their argument parsing,
//! the model they build and how they report an error.
use tubemem_fem::model::{Model, State};
use tubemem_fem::stepping::{prestress, Stage, StepSettings};
use tubemem_mesh::tube::capped_tube;
use tubemem_mesh::Symmetry;

/// The largest mesh these examples build: 2 million nodes (the CLI's own resource guards do not
/// apply here).
pub const MAX_NODES: f64 = 2e6;

/// Run `run`; an error is printed with `usage` and exits with code 2.
pub fn main_with(
    name: &str,
    usage: &str,
    run: impl FnOnce() -> Result<(), Box<dyn std::error::Error>>,
) -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{name}: {}\nusage: {usage}", chain(e.as_ref()));
            std::process::ExitCode::from(2)
        }
    }
}

/// An error with its causes, "a: b: c".
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        s.push_str(&format!(": {c}"));
        cause = c.source();
    }
    s
}

/// The command line's arguments, read as positive numbers.
pub struct Args(Vec<String>);

impl Args {
    pub fn new() -> Self {
        Args(std::env::args().skip(1).collect())
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Argument `i` (from 0) as a finite positive number, or an error naming it.
    pub fn positive(&self, i: usize, name: &str) -> Result<f64, String> {
        let a = self.0.get(i).ok_or(format!("missing {name}"))?;
        a.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or(format!("{name} = {a:?}: a positive number"))
    }
}

/// The whole capped tube (no symmetry plane) of length `length` (R = 1), `per` elements per R
/// along and `around` around, ABB 𝒩 = 30, pre-stressed for an arc-length stage `stage`.
pub fn whole_tube(
    length: f64,
    per: f64,
    around: f64,
    stage: &Stage,
) -> Result<(Model, State), Box<dyn std::error::Error>> {
    if around * per * length > MAX_NODES {
        return Err(format!(
            "{around} around × {} along is more than {MAX_NODES} nodes",
            per * length
        )
        .into());
    }
    let mesh = capped_tube(
        1.0,
        length,
        around as usize,
        (per * length) as usize,
        Symmetry::None,
    )?;
    let law = tubemem_material::laws::AnssariBenamBucchi::new(1.0, 30.0)?;
    let mut model = Model::new(mesh, Box::new(law))?;
    let mut state = model.reference_state();
    prestress::<()>(&mut model, &mut state, stage).map_err(|e| match e {
        tubemem_fem::stepping::StageError::Solve(e) => format!("pre-stress: {e}"),
        _ => "pre-stress".to_string(),
    })?;
    Ok((model, state))
}

/// One arc-length stage from 1 to `to` of whatever the caller monitors.
pub fn stage(to: f64) -> Stage {
    Stage {
        index: 1,
        from: 1.0,
        to,
        settings: StepSettings::default(),
    }
}

/// Follow the arc-length path under pressure from `state` until `monitor` reaches `stage.to`,
/// every converged step to `on_step` (its number, state and K's negative pivots).
pub fn follow(
    model: &mut Model,
    state: &mut State,
    stage: &Stage,
    monitor: &dyn Fn(&State) -> f64,
    mut on_step: impl FnMut(usize, &State, usize, f64),
) -> Result<(), tubemem_fem::stepping::StageError<()>> {
    tubemem_fem::continuation::run_arc_stage(
        model,
        state,
        stage,
        None,
        tubemem_fem::continuation::ArcLoading::Pressure(None),
        monitor,
        1.0,
        None,
        |_, s, info| {
            on_step(
                info.step,
                s,
                info.newton.inertia.negative_pivots,
                info.fraction,
            );
            Ok::<(), ()>(())
        },
        |_, _| Ok(()),
    )
    .map(|_| ())
}
