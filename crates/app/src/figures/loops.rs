//! The force–gap loops of a viscoelastic tube squeezed between plates and released, one per
//! plate speed (the GPS section in time, [`tubemem_gps::visco`]): the paper's Figs. 6–7 in
//! time. The reduced force ϖχ (eq. 80) against the reduced displacement from first contact,
//! λs* − ρ, in reduced units (the same figure for a case in SI and its dimensionless twin).

use super::{series_color, Figure, Series, Stroke};
use tubemem_gps::visco::TimePoint;

/// The title every loops figure starts with (what `--plot` recognizes as its own file).
pub const LOOPS_TITLE: &str = "Force–gap loops of a viscoelastic tube";

/// One plate speed's cycle: its travel time, where the plates first touched (λs*) and the
/// history's states.
pub struct Loop<'a> {
    pub travel: f64,
    pub touch: f64,
    pub points: &'a [TimePoint],
}

/// The figure of `loops` (`law` and `prony` describe the law in the notes).
pub fn loops_figure(law: &str, prony: &str, loops: &[Loop<'_>]) -> Figure {
    let series = loops
        .iter()
        .enumerate()
        .map(|(k, l)| Series {
            label: format!("plates' travel time T = {}", l.travel),
            points: thinned(
                l.points
                    .iter()
                    .filter_map(|p| p.rho.map(|rho| (l.touch - rho, p.force)))
                    .collect(),
            ),
            color: series_color(k),
            stroke: Stroke::Solid,
            width: 2,
        })
        .collect();
    let mut fig = Figure::new(
        format!("{LOOPS_TITLE} (GPS section in time)"),
        "reduced displacement λs* − ρ from first contact",
        "reduced force ϖχ per plate (πμH per unit length)",
        series,
    );
    fig.notes = vec![
        format!("{law}; Prony series {prony} (τ in the time unit of T)"),
        "each loop: plates from first contact to the gap and back in T each; the area is the work dissipated".into(),
    ];
    fig
}

/// At most about [`MAX_POINTS`] of `points`, evenly picked, the first and the last kept (a
/// history to a tolerance has up to 2^20 steps a segment; the figure needs a few hundred).
fn thinned(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    let every = points.len().div_ceil(MAX_POINTS).max(1);
    let last = points.last().copied();
    let mut out: Vec<_> = points.into_iter().step_by(every).collect();
    if let (Some(l), Some(o)) = (last, out.last()) {
        if *o != l {
            out.push(l);
        }
    }
    out
}

/// The points a loop is drawn with, about.
pub const MAX_POINTS: usize = 600;
