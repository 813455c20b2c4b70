//! The quantities a check compares, by name: the FE's mid-span value and its closed form at
//! one step (`step_pair`), and the FE's final value (`final_value`).

use crate::report::{RunReport, StepRecord};

/// (FE, closed form) of `q` at one step, if the step has both.
pub(crate) fn step_pair(s: &StepRecord, q: &str) -> Option<(f64, f64)> {
    let m = &s.midspan;
    let cf = &s.closed_form;
    if let Some(g) = &cf.gps_confine {
        // a confine step: the walls' forces compared wall by wall, the worst one kept
        let worst_wall = |c: &tubemem_gps::confine::ConfineState| {
            s.walls
                .iter()
                .zip(&c.walls)
                .filter(|(_, w)| w.force > 0.0)
                .map(|(fe, w)| (fe.force, w.force))
                .max_by(|a, b| (a.0 / a.1 - 1.0).abs().total_cmp(&(b.0 / b.1 - 1.0).abs()))
        };
        return match q {
            "w" => Some((m.w, g.w)),
            "lambda_s" => Some((m.lambda_s, g.lambda_s)),
            "lambda_z" => Some((m.lambda_z, g.lambda_z)),
            "n_s" => Some((m.n_s, g.n_s)),
            "n_z" => Some((m.n_z, g.n_z)),
            "wall_force" => worst_wall(g),
            "local_lambda_s" => cf.local_confine.as_ref().map(|l| (m.lambda_s, l.lambda_s)),
            "local_lambda_z" => cf.local_confine.as_ref().map(|l| (m.lambda_z, l.lambda_z)),
            "local_wall_force" => cf.local_confine.as_ref().and_then(worst_wall),
            "penetration" => Some((
                1.0 + s.walls.iter().map(|w| w.penetration).fold(0.0, f64::max),
                1.0,
            )),
            _ => None,
        };
    }
    if let Some(g) = &cf.gps_inflation {
        return match q {
            "w" => Some((m.w, g.w)),
            "lambda_s" => Some((m.lambda_s, g.lambda_s)),
            "lambda_z" => Some((m.lambda_z, g.lambda_z)),
            "n_s" => Some((m.n_s, g.n_s)),
            "n_z" => Some((m.n_z, g.n_z)),
            _ => None,
        };
    }
    let c = s.contact.as_ref()?;
    // deviations, compared as they are: (1 + d, 1) gives FE/GPS − 1 = d
    match q {
        "flat_pressure" => return c.values.flat_pressure_deviation.map(|d| (1.0 + d, 1.0)),
        "penetration" => return Some((1.0 + c.values.penetration, 1.0)),
        _ => {}
    }
    if let Some(local) = q.strip_prefix("local_") {
        let l = cf.local.as_ref()?.as_ref().ok()?;
        return match local {
            "lambda_s" => Some((m.lambda_s, l.lambda_s)),
            "lambda_z" => Some((m.lambda_z, l.lambda_z)),
            "chi" => Some((c.values.chi, l.chi)),
            "force" => Some((c.values.force, l.force)),
            _ => None,
        };
    }
    let g = cf.gps_flattening.as_ref()?;
    match q {
        "w" => Some((m.w, g.w)),
        "lambda_s" => Some((m.lambda_s, g.lambda_s)),
        "lambda_z" => Some((m.lambda_z, g.lambda_z)),
        "n_s" => Some((m.n_s, g.n_s)),
        "n_z" => Some((m.n_z, g.n_z)),
        "chi" => Some((c.values.chi, g.chi)),
        "force" => Some((c.values.force, g.force)),
        _ => None,
    }
}

/// The final mid-span value of `q` (the last step of the run).
pub(crate) fn final_value(report: &RunReport, q: &str) -> Option<f64> {
    let s = report.steps().last()?;
    let m = &s.midspan;
    match q {
        "w" => Some(m.w),
        "lambda_s" => Some(m.lambda_s),
        "lambda_z" => Some(m.lambda_z),
        "n_s" => Some(m.n_s),
        "n_z" => Some(m.n_z),
        "chi" => s.contact.map(|c| c.values.chi),
        "force" => s.contact.map(|c| c.values.force),
        _ => None,
    }
}
