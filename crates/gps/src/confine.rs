//! Confinement by a convex set of frictionless planes parallel to the axis: the paper's general
//! GPS theory (Sec. 3.6, eqs. 55–60) for any walls, not only two plates.
//!
//! A wall is {x : n·x = d} in the cross-section plane, the membrane on the side n·x ≤ d (n is
//! normalized here). In equilibrium the free parts of the section are circular arcs of one radius
//! r (eq. 55₁: N_s = p r) and the rest lies flat on walls. The section is therefore the Minkowski
//! sum P ⊕ B(r) of a convex set P with the disc of radius r, where P lies in the inner parallel
//! set Q_r = {x : n_i·x ≤ d_i − r for every wall} and has its edges on the lines of Q_r:
//!
//! ```text
//! L = perimeter(P) + 2πr,   A = area(P) + r·perimeter(P) + πr²,   λs = L/(2πR)      (57)
//! N_s = ϖ r,   N_z = ϖ A/L,   (N_s, N_z) from the law (56),   λz ϖ A = λz* ϖ* π λs*²   (55, 60)
//! ```
//!
//! Three regimes, continuous in λs, with r_in the inradius of the walls (the largest r with Q_r
//! non-empty) and Q_{r_in} a point or a segment of length ℓ:
//! 1. free: λs ≤ r_in, a circle of radius λs touching no wall (it fits);
//! 2. stadium: r = r_in and P a segment of length c = π(λs − r_in) ≤ ℓ along Q_{r_in} — two
//!    parallel walls at distance 2r_in hold it, as the paper's two plates (Sec. 4); the other
//!    walls are not touched yet;
//! 3. polygon: r < r_in and P = Q_r; every wall whose line bounds Q_r carries a contact length
//!    equal to that side. A wall becomes active when its side appears.
//!
//! Walls that do not confine (the normals leave a direction open) are refused, except two
//! parallel plates alone, the paper's case (ℓ = ∞).

use crate::newton;
use crate::resultants::resultants;
use crate::{inflate, GpsError, Hypothesis};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use tubemem_material::MembraneLaw;

/// A wall {x : n·x = d}, the membrane on n·x ≤ d; `normal` is a unit vector.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Wall {
    pub normal: [f64; 2],
    pub offset: f64,
}

impl Wall {
    /// The wall n·x = d for any non-zero (nx, ny) (normalized here).
    pub fn new(nx: f64, ny: f64, d: f64) -> Result<Self, GpsError> {
        let len = nx.hypot(ny);
        if !(len.is_finite() && len > 0.0 && d.is_finite()) {
            return Err(GpsError::Walls {
                message: format!(
                    "the plane ({nx}, {ny}, {d}) needs a finite, non-zero normal (nx, ny) and a finite offset d"
                ),
            });
        }
        Ok(Wall {
            normal: [nx / len, ny / len],
            offset: d / len,
        })
    }
}

/// What a wall carries in a state.
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallContact {
    /// flat contact length on the wall, per R
    pub contact_length: f64,
    /// force per unit length on the wall over πμH: ϖ × contact length / π (as ϖχ, eq. 80)
    pub force: f64,
}

/// Which regime the section is in.
#[derive(schemars::JsonSchema, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Regime {
    Free,
    Stadium,
    Polygon,
}

/// A confined state (dimensionless, R = μH = 1).
#[derive(schemars::JsonSchema, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConfineState {
    pub w: f64,
    pub lambda_s: f64,
    pub lambda_z: f64,
    pub n_s: f64,
    pub n_z: f64,
    /// radius of the free arcs
    pub r: f64,
    /// enclosed area of the section per R²
    pub area: f64,
    /// "free" (a circle), "stadium" (two parallel walls) or "polygon" (a rounded polygon)
    pub regime: Regime,
    /// the walls in the order given
    pub walls: Vec<WallContact>,
    /// the scale s of the offsets (s·d) at this state, on a path; 1 for a single state
    pub scale: f64,
}

/// Half-size of the box the inner sets are clipped from (far larger than any section here).
const SPAN: f64 = 1e4;

/// The convex polygon Q_r = {x : n_i·x ≤ s d_i − r} (Sutherland–Hodgman on a large box).
fn inner(walls: &[Wall], s: f64, r: f64) -> Vec<[f64; 2]> {
    let mut poly = vec![[-SPAN, -SPAN], [SPAN, -SPAN], [SPAN, SPAN], [-SPAN, SPAN]];
    for w in walls {
        let lim = s * w.offset - r;
        let f = |p: &[f64; 2]| w.normal[0] * p[0] + w.normal[1] * p[1] - lim;
        let mut out = Vec::with_capacity(poly.len() + 1);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let (fa, fb) = (f(&a), f(&b));
            if fa <= 0.0 {
                out.push(a);
            }
            if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
                let t = fa / (fa - fb);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        poly = out;
        if poly.is_empty() {
            break;
        }
    }
    // each vertex where two walls meet, recomputed as their exact intersection (the clipping's
    // interpolation between far box corners loses digits; the solve needs the perimeter to
    // rounding)
    for v in poly.iter_mut() {
        let on: Vec<&Wall> = walls
            .iter()
            .filter(|w| {
                let lim = s * w.offset - r;
                (w.normal[0] * v[0] + w.normal[1] * v[1] - lim).abs() <= 1e-7 * (1.0 + lim.abs())
            })
            .collect();
        let mut best: Option<([f64; 2], f64)> = None;
        for i in 0..on.len() {
            for j in i + 1..on.len() {
                let (a, b) = (on[i], on[j]);
                let det = a.normal[0] * b.normal[1] - a.normal[1] * b.normal[0];
                if det.abs() < 1e-9 {
                    continue;
                }
                let (ca, cb) = (s * a.offset - r, s * b.offset - r);
                let x = [
                    (ca * b.normal[1] - a.normal[1] * cb) / det,
                    (a.normal[0] * cb - ca * b.normal[0]) / det,
                ];
                let d = (x[0] - v[0]).hypot(x[1] - v[1]);
                if best.is_none_or(|(_, e)| d < e) {
                    best = Some((x, d));
                }
            }
        }
        if let Some((x, _)) = best {
            *v = x;
        }
    }
    poly
}

fn perimeter(p: &[f64; 2], q: &[f64; 2]) -> f64 {
    (q[0] - p[0]).hypot(q[1] - p[1])
}

fn poly_perimeter(poly: &[[f64; 2]]) -> f64 {
    (0..poly.len())
        .map(|k| perimeter(&poly[k], &poly[(k + 1) % poly.len()]))
        .sum()
}

fn poly_area(poly: &[[f64; 2]]) -> f64 {
    0.5 * (0..poly.len())
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
        .abs()
}

/// How a set of walls holds the section.
#[derive(Clone, Copy, Debug)]
enum Hold {
    /// every direction is closed: a bounded polygon
    Bounded,
    /// two parallel plates alone (indices), half-gap at scale 1
    Strip(usize, usize),
}

/// The most walls a section is confined by: 32. The closed form's cost grows as about n^3.7
/// with n walls (a regular n-gon of walls at 1.1 from λs* = 1.3, `tubemem gps confine
/// --json`, release, 2026-12-02: 0.07, 0.21, 1.9 and 25.7 s at 8, 16, 32 and 64 walls), and an
/// FE confine stage evaluates it at every step; more walls are refused at once instead of
/// running for minutes (issue #25, class 2).
pub const MAX_WALLS: usize = 32;

fn classify(walls: &[Wall]) -> Result<Hold, GpsError> {
    if walls.len() > MAX_WALLS {
        return Err(GpsError::Walls {
            message: format!(
                "{} planes given: at most {MAX_WALLS} (the closed form's cost grows as about the 3.7th power of their number: 1.9 s at 32, 26 s at 64)",
                walls.len()
            ),
        });
    }
    if walls.len() == 2 {
        let [a, b] = [walls[0].normal, walls[1].normal];
        if a[0] * b[0] + a[1] * b[1] < -1.0 + 1e-12 {
            if walls[0].offset + walls[1].offset <= 0.0 {
                return Err(GpsError::Walls {
                    message: "the two plates leave no room between them (their offsets sum to ≤ 0)"
                        .into(),
                });
            }
            return Ok(Hold::Strip(0, 1));
        }
    }
    // bounded iff the normals leave no angular gap of π or more
    let mut ang: Vec<f64> = walls
        .iter()
        .map(|w| w.normal[1].atan2(w.normal[0]))
        .collect();
    ang.sort_by(f64::total_cmp);
    let mut open = None;
    for k in 0..ang.len() {
        let next = if k + 1 < ang.len() {
            ang[k + 1]
        } else {
            ang[0] + 2.0 * PI
        };
        if next - ang[k] >= PI - 1e-12 {
            // the direction half-way through the gap is not held by any wall
            let mid = 0.5 * (ang[k] + next);
            open = Some([mid.cos(), mid.sin()]);
        }
    }
    if let Some(u) = open {
        return Err(GpsError::Walls {
            message: format!(
                "the planes do not confine the section: it is free to move along ({:.3}, {:.3}); add a plane that closes that side (two parallel plates alone are the paper's squeeze and are accepted)",
                u[0], u[1]
            ),
        });
    }
    Ok(Hold::Bounded)
}

/// The section of perimeter 2πλs in the walls scaled by `s`: (r, area, contact lengths, regime).
struct Section {
    r: f64,
    area: f64,
    contact: Vec<f64>,
    regime: Regime,
}

struct Walls<'a> {
    walls: &'a [Wall],
    hold: Hold,
}

impl Walls<'_> {
    /// The inradius at scale s (the largest r with Q_r non-empty).
    fn inradius(&self, s: f64) -> f64 {
        if let Hold::Strip(i, j) = self.hold {
            return 0.5 * s * (self.walls[i].offset + self.walls[j].offset);
        }
        let (mut lo, mut hi) = (0.0, SPAN);
        if inner(self.walls, s, 0.0).len() < 3 || poly_area(&inner(self.walls, s, 0.0)) <= 0.0 {
            return 0.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if inner(self.walls, s, mid).is_empty() {
                hi = mid;
            } else {
                lo = mid;
            }
            if hi - lo <= 1e-15 * hi {
                break;
            }
        }
        lo
    }

    /// The segment Q_{r_in}: its length ℓ and the two parallel walls that pin it, if any.
    fn pinned_segment(&self, s: f64, r_in: f64) -> Option<(f64, usize, usize)> {
        if let Hold::Strip(i, j) = self.hold {
            return Some((f64::INFINITY, i, j));
        }
        let tol = 1e-9 * r_in.max(1e-300);
        for i in 0..self.walls.len() {
            for j in i + 1..self.walls.len() {
                let (a, b) = (self.walls[i], self.walls[j]);
                let dot = a.normal[0] * b.normal[0] + a.normal[1] * b.normal[1];
                if dot > -1.0 + 1e-12 || (0.5 * s * (a.offset + b.offset) - r_in).abs() > tol {
                    continue;
                }
                // the mid-line n·x = m, clipped by the other walls offset by r_in
                let n = a.normal;
                let m = 0.5 * s * (a.offset - b.offset);
                let u = [-n[1], n[0]];
                let p0 = [m * n[0], m * n[1]];
                let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
                for (k, w) in self.walls.iter().enumerate() {
                    if k == i || k == j {
                        continue;
                    }
                    let c = w.normal[0] * u[0] + w.normal[1] * u[1];
                    let rhs = s * w.offset - r_in - (w.normal[0] * p0[0] + w.normal[1] * p0[1]);
                    if c > 0.0 {
                        t1 = t1.min(rhs / c);
                    } else if c < 0.0 {
                        t0 = t0.max(rhs / c);
                    }
                }
                return Some(((t1 - t0).max(0.0), i, j));
            }
        }
        None
    }

    /// The section of hoop stretch `ls` in the walls at scale `s`.
    fn section(&self, s: f64, ls: f64) -> Result<Section, GpsError> {
        let n = self.walls.len();
        let r_in = self.inradius(s);
        if ls <= r_in {
            return Ok(Section {
                r: ls,
                area: PI * ls * ls,
                contact: vec![0.0; n],
                regime: Regime::Free,
            });
        }
        if let Some((ell, i, j)) = self.pinned_segment(s, r_in) {
            let c = PI * (ls - r_in);
            if c <= ell {
                let mut contact = vec![0.0; n];
                contact[i] = c;
                contact[j] = c;
                return Ok(Section {
                    r: r_in,
                    area: PI * r_in * r_in + 2.0 * r_in * c,
                    contact,
                    regime: Regime::Stadium,
                });
            }
        }
        // polygon: L(r) = perimeter(Q_r) + 2πr = 2πλs, L decreasing in r on (0, r_in)
        let big_l = |r: f64| poly_perimeter(&inner(self.walls, s, r)) + 2.0 * PI * r;
        let target = 2.0 * PI * ls;
        if big_l(0.0) < target {
            return Err(GpsError::Walls {
                message: format!(
                    "the walls' perimeter {:.6} R is shorter than the membrane's 2πλs = {target:.6} R at λs = {ls}: it cannot lie flat on them (no equilibrium; the gas would need the membrane to fold)",
                    big_l(0.0)
                ),
            });
        }
        let (mut lo, mut hi) = (0.0, r_in);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if big_l(mid) > target {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-16 * r_in {
                break;
            }
        }
        let r = 0.5 * (lo + hi);
        let q = inner(self.walls, s, r);
        let per = poly_perimeter(&q);
        let contact = self
            .walls
            .iter()
            .map(|w| {
                let lim = s * w.offset - r;
                let on = |p: &[f64; 2]| {
                    (w.normal[0] * p[0] + w.normal[1] * p[1] - lim).abs()
                        <= 1e-12 * (1.0 + lim.abs())
                };
                (0..q.len())
                    .filter(|&k| on(&q[k]) && on(&q[(k + 1) % q.len()]))
                    .map(|k| perimeter(&q[k], &q[(k + 1) % q.len()]))
                    .sum()
            })
            .collect();
        Ok(Section {
            r,
            area: poly_area(&q) + r * per + PI * r * r,
            contact,
            regime: Regime::Polygon,
        })
    }
}

/// Confinement with the gas closed in: the tube inflated to mid-span `initial_stretch` under
/// `hyp`, then held by `walls` (offsets at scale `s`, e.g. 1). GPS solves eqs. (55)–(60) for
/// (λs, λz); PS fixes λz = 1 and drops N_z (Sec. 3.7). `guess` = (λs, λz) of a nearby state.
/// What holds the section's pressure.
#[derive(Clone, Copy, Debug)]
enum Load<'a> {
    /// the gas closed in at the inflated state (Boyle, eq. 60)
    Gas(&'a crate::InflationState),
    /// a given pressure ϖ
    Pressure(f64),
}

fn solve_at(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    ws: &Walls,
    s: f64,
    load: Load,
    guess: [f64; 2],
) -> Result<ConfineState, GpsError> {
    let (at, gas, scale_ns) = match load {
        Load::Gas(initial) => (
            format!("scale {s} of the wall offsets (λs* = {})", initial.lambda_s),
            initial.lambda_z * initial.w * PI * initial.lambda_s.powi(2),
            initial.n_s,
        ),
        Load::Pressure(w) => (format!("ϖ = {w}"), f64::NAN, w),
    };
    let residual = |x: [f64; 2]| -> Result<[f64; 2], tubemem_material::MaterialError> {
        let [ls, lz] = x;
        // a trial λs the walls cannot hold is rejected like a state the law rejects: the
        // Newton step is halved
        let sec = ws
            .section(s, ls)
            .map_err(|_| tubemem_material::MaterialError::InvalidState {
                what: "λs in the walls",
                value: ls,
                requirement: "the membrane must fit the walls' perimeter",
            })?;
        let res = resultants(law, ls, lz)?;
        let l = 2.0 * PI * ls;
        match load {
            Load::Gas(_) => {
                let w = res.ns / sec.r;
                match hyp {
                    Hypothesis::Gps => Ok([
                        (res.nz - w * sec.area / l) / scale_ns,
                        lz * w * sec.area / gas - 1.0,
                    ]),
                    // λz = 1: the second unknown is pinned (residual lz − 1)
                    Hypothesis::Ps => Ok([w * sec.area / gas - 1.0, lz - 1.0]),
                }
            }
            Load::Pressure(w) => match hyp {
                Hypothesis::Gps => Ok([
                    (res.ns - w * sec.r) / (w * sec.r),
                    (res.nz - w * sec.area / l) / (w * sec.r),
                ]),
                Hypothesis::Ps => Ok([(res.ns - w * sec.r) / (w * sec.r), lz - 1.0]),
            },
        }
    };
    let f = |x: [f64; 2]| {
        let fx = residual(x)?;
        let mut j = [[0.0; 2]; 2];
        for c in 0..2 {
            let h = 1e-7 * x[c].abs().max(1.0);
            let (mut xp, mut xm) = (x, x);
            xp[c] += h;
            xm[c] -= h;
            let (fp, fm) = (residual(xp)?, residual(xm)?);
            for r in 0..2 {
                j[r][c] = (fp[r] - fm[r]) / (2.0 * h);
            }
        }
        Ok((fx, j))
    };
    let g = match hyp {
        Hypothesis::Gps => guess,
        Hypothesis::Ps => [guess[0], 1.0],
    };
    let [ls, lz] =
        newton::system2(f, g, 1e-10).map_err(|e| e.into_error("confinement (eqs. 55–60)", &at))?;
    let sec = ws.section(s, ls)?;
    let res = resultants(law, ls, lz).map_err(|source| GpsError::Material {
        stage: "confinement",
        at: at.clone(),
        source,
    })?;
    let w = res.ns / sec.r;
    if res.ns < 0.0 {
        return Err(GpsError::Compressive {
            stage: "confinement",
            at,
            n_s: res.ns,
            w,
        });
    }
    Ok(ConfineState {
        w,
        lambda_s: ls,
        lambda_z: lz,
        n_s: res.ns,
        n_z: res.nz,
        r: sec.r,
        area: sec.area,
        regime: sec.regime,
        walls: sec
            .contact
            .iter()
            .map(|&c| WallContact {
                contact_length: c,
                force: w * c / PI,
            })
            .collect(),
        scale: s,
    })
}

/// Whether `walls` can hold a section: a bounded set, or two parallel plates (else the error
/// that says which direction is open).
pub fn check_walls(walls: &[Wall]) -> Result<(), GpsError> {
    if walls.is_empty() {
        return Err(GpsError::Walls {
            message: "no planes given".into(),
        });
    }
    classify(walls).map(|_| ())
}

/// The free circle of an inflated state, touching none of `n` walls.
fn free_state(st: &crate::InflationState, n: usize, scale: f64) -> ConfineState {
    ConfineState {
        w: st.w,
        lambda_s: st.lambda_s,
        lambda_z: st.lambda_z,
        n_s: st.n_s,
        n_z: st.n_z,
        r: st.lambda_s,
        area: PI * st.lambda_s.powi(2),
        regime: Regime::Free,
        walls: vec![
            WallContact {
                contact_length: 0.0,
                force: 0.0
            };
            n
        ],
        scale,
    }
}

fn check(walls: &[Wall], initial_stretch: f64) -> Result<Hold, GpsError> {
    if walls.is_empty() {
        return Err(GpsError::Walls {
            message: "no planes given".into(),
        });
    }
    if !(initial_stretch.is_finite() && initial_stretch > 1.0) {
        return Err(crate::invalid(
            "initial_stretch",
            initial_stretch,
            "confinement needs an inflated tube (λs* > 1) holding gas",
        ));
    }
    classify(walls)
}

/// The scale s0 at which the walls (offsets s·d) first touch the inflated circle of radius
/// λs*: s0 = λs*/inradius(1) (offsets scale the inner sets about the origin, which the walls
/// must enclose: every d > 0).
fn first_contact(ws: &Walls, initial_stretch: f64) -> Result<f64, GpsError> {
    if ws.walls.iter().any(|w| w.offset <= 0.0) {
        return Err(GpsError::Walls {
            message: "every plane must have the origin (the tube's axis) on the membrane's side: all offsets d > 0".into(),
        });
    }
    let r1 = ws.inradius(1.0);
    if r1.is_nan() || r1 <= 0.0 {
        return Err(GpsError::Walls {
            message: "the planes enclose no area".into(),
        });
    }
    Ok(initial_stretch / r1)
}

/// The path of the gas-closed tube (inflated to λs* under `hyp`) as the walls' offsets are
/// scaled from first contact down to the given ones, in `points` equal steps of the scale;
/// the first state is the inflated circle at first contact. If the walls never touch the
/// inflated tube, the single state is that circle (no contact).
pub fn confine_path(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    walls: &[Wall],
    initial_stretch: f64,
    points: usize,
) -> Result<Vec<ConfineState>, GpsError> {
    // the curves' size guard (it had none: `gps confine --points` of 10⁹ grew memory)
    crate::check_points(points)?;
    let hold = check(walls, initial_stretch)?;
    let ws = Walls { walls, hold };
    let initial = inflate(law, hyp, initial_stretch)?;
    let s0 = first_contact(&ws, initial_stretch)?;
    let free = |s: f64| free_state(&initial, walls.len(), s);
    if s0 <= 1.0 {
        return Ok(vec![free(1.0)]);
    }
    let mut out = vec![free(s0)];
    let mut cur = free(s0);
    for k in 1..points {
        let target = s0 + (1.0 - s0) * k as f64 / (points - 1) as f64;
        // sub-steps of at most 1 % of λs*'s scale, halved on failure
        let mut step = (target - cur.scale).signum() * 0.01 * s0;
        let mut cuts = 0;
        while cur.scale != target {
            let s = if (target - cur.scale).abs() <= step.abs() {
                target
            } else {
                cur.scale + step
            };
            match solve_at(
                law,
                hyp,
                &ws,
                s,
                Load::Gas(&initial),
                [cur.lambda_s, cur.lambda_z],
            ) {
                Ok(st) => cur = st,
                Err(e) => {
                    cuts += 1;
                    if cuts > 30 {
                        // the usual cause: the corners' radius has gone to zero, the section
                        // is the walls' polygon and N_s = ϖr cannot stay positive
                        let r_in = ws.inradius(s);
                        if cur.regime == Regime::Polygon && cur.r < 0.05 * r_in {
                            return Err(GpsError::Walls {
                                message: format!(
                                    "no taut equilibrium past scale {:.4} of the wall offsets: the free arcs' radius has fallen to r = {:.3e} R (ϖ = {:.4}, λs = {:.4}), the section is the walls' polygon and the gas cannot keep it taut against them; the membrane would wrinkle ({e})",
                                    cur.scale, cur.r, cur.w, cur.lambda_s
                                ),
                            });
                        }
                        return Err(e);
                    }
                    step *= 0.5;
                }
            }
        }
        out.push(cur.clone());
    }
    Ok(out)
}

/// The state of the gas-closed tube (inflated to λs* under `hyp`) held by `walls` at their
/// given offsets (reached along the path from first contact).
pub fn confine(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    walls: &[Wall],
    initial_stretch: f64,
) -> Result<ConfineState, GpsError> {
    confine_path(law, hyp, walls, initial_stretch, 2)?
        .pop()
        .ok_or_else(|| GpsError::Walls {
            message: "internal error: an empty confinement path; please report this input".into(),
        })
}

/// The state under a given pressure `w` in `walls` at their offsets (no gas law): the free
/// inflation at ϖ if the circle fits (on the rising branch, λs below the pressure maximum),
/// else continued in ϖ from the pressure at first contact.
pub fn confine_at_pressure(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    walls: &[Wall],
    w: f64,
) -> Result<ConfineState, GpsError> {
    if walls.is_empty() {
        return Err(GpsError::Walls {
            message: "no planes given".into(),
        });
    }
    if !(w.is_finite() && w > 0.0) {
        return Err(crate::invalid(
            "pressure",
            w,
            "the pressure ϖ must be positive",
        ));
    }
    let hold = classify(walls)?;
    let ws = Walls { walls, hold };
    let r_in = ws.inradius(1.0);
    if r_in.is_nan() || r_in <= 0.0 || walls.iter().any(|x| x.offset <= 0.0) {
        return Err(GpsError::Walls {
            message: "every plane must have the origin (the tube's axis) on the membrane's side: all offsets d > 0".into(),
        });
    }
    if r_in <= 1.0 {
        return held_from_the_start(law, hyp, &ws, w);
    }
    let contact = inflate(law, hyp, r_in)?;
    let free = |st: crate::InflationState| free_state(&st, walls.len(), 1.0);
    if w <= contact.w {
        // the free circle at ϖ: λs on the rising branch up to the contact radius
        let (mut lo, mut hi) = (1.0, r_in);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if inflate(law, hyp, mid)?.w < w {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-15 * hi {
                break;
            }
        }
        return Ok(free(inflate(law, hyp, 0.5 * (lo + hi))?));
    }
    // continuation in ϖ from first contact
    let mut cur = free(contact);
    let mut step = 0.02 * (w - contact.w).max(1e-3 * w);
    let mut cuts = 0;
    while cur.w < w {
        let target = (cur.w + step).min(w);
        match solve_at(
            law,
            hyp,
            &ws,
            1.0,
            Load::Pressure(target),
            [cur.lambda_s * (1.0 + 1e-6), cur.lambda_z],
        ) {
            Ok(st) => cur = ConfineState { w: target, ..st },
            Err(e) => {
                cuts += 1;
                if cuts > 30 {
                    return Err(e);
                }
                step *= 0.5;
            }
        }
    }
    Ok(cur)
}

/// Walls that hold the stress-free tube (inradius ≤ R: they touch it before any pressure),
/// inflated between them to `w`: continued in ϖ from the stress-free section in the walls
/// (λs = λz = 1), in fiftieths of `w` halved where Newton fails.
fn held_from_the_start(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    ws: &Walls,
    w: f64,
) -> Result<ConfineState, GpsError> {
    let (mut done, mut guess, mut last) = (0.0, [1.0 + 1e-9, 1.0], None);
    let mut step = 0.02 * w;
    let mut cuts = 0;
    while done < w {
        let target = (done + step).min(w);
        match solve_at(law, hyp, ws, 1.0, Load::Pressure(target), guess) {
            Ok(st) => {
                guess = [st.lambda_s * (1.0 + 1e-6), st.lambda_z];
                done = target;
                last = Some(ConfineState { w: target, ..st });
            }
            Err(e) => {
                cuts += 1;
                if cuts > 30 {
                    return Err(e);
                }
                step *= 0.5;
            }
        }
    }
    last.ok_or_else(|| GpsError::Walls {
        message: "internal error: no pressure step was taken; please report this input".into(),
    })
}

/// The reference angles (in [0, 2π), from the x axis, per R = 1) of the ends of every flat
/// contact of `state` in `walls`, for walls symmetric under y → −y (so that the material point
/// on the positive x axis stays at the outline's point whose normal is e_x).
///
/// The outline Q ⊕ B(r) walked counterclockwise from that point: its support point at normal
/// direction t moves along the arcs at the rate r and jumps along wall j's flat (length c_j)
/// where t passes the wall's normal angle α_j, so the arc length to direction t is
/// ```text
/// S(t) = r t + Σ_{0 < α_j < t} c_j + c_0/2      (c_0: a flat centred on t = 0, if any)
/// ```
/// and a material line at reference angle θ sits at S = λs R θ (the stretch is uniform,
/// L = 2πλs R = 2πr + Σ c_j). Wall j's flat spans θ ∈ [S(α_j), S(α_j) + c_j]/λs.
pub fn contact_edges(walls: &[Wall], state: &ConfineState) -> Result<Vec<f64>, GpsError> {
    let mirrored = walls.iter().all(|w| {
        walls.iter().any(|v| {
            (v.normal[0] - w.normal[0]).abs() < 1e-12
                && (v.normal[1] + w.normal[1]).abs() < 1e-12
                && (v.offset - w.offset).abs() < 1e-12 * (1.0 + w.offset.abs())
        })
    });
    if !mirrored {
        return Err(GpsError::Walls {
            message: "the contact edges' reference angles need walls symmetric about the plane y = 0 (each wall's mirror image among them): otherwise the closed form leaves the section's rotation against the material free".into(),
        });
    }
    let flats: Vec<(f64, f64)> = walls
        .iter()
        .zip(&state.walls)
        .filter(|(_, c)| c.contact_length > 0.0)
        .map(|(w, c)| {
            let a = w.normal[1].atan2(w.normal[0]).rem_euclid(2.0 * PI);
            // a wall whose normal is e_x to rounding
            let a = if a.min(2.0 * PI - a) < 1e-12 { 0.0 } else { a };
            (a, c.contact_length)
        })
        .collect();
    let centred = flats.iter().find(|f| f.0 == 0.0).map_or(0.0, |f| 0.5 * f.1);
    let mut edges = vec![];
    for &(a, c) in &flats {
        if a == 0.0 {
            edges.push((-centred / state.lambda_s).rem_euclid(2.0 * PI));
            edges.push(centred / state.lambda_s);
            continue;
        }
        let before: f64 = flats
            .iter()
            .filter(|f| f.0 > 0.0 && f.0 < a)
            .map(|f| f.1)
            .sum();
        let start = state.r * a + before + centred;
        edges.push(start / state.lambda_s);
        edges.push((start + c) / state.lambda_s);
    }
    edges.sort_by(f64::total_cmp);
    Ok(edges)
}

/// The outline of the section P ⊕ B(r) of `state` in `walls` (offsets at the state's scale):
/// `n` points of the support function, arcs at the corners and straight flats between them.
pub fn section_outline(walls: &[Wall], state: &ConfineState, n: usize) -> Vec<[f64; 2]> {
    let s = state.scale;
    let q = match state.regime {
        Regime::Free => vec![[0.0, 0.0]],
        Regime::Polygon => inner(walls, s, state.r),
        Regime::Stadium => {
            // the segment of length c along the pinned walls, centred where Q_r allows
            let p = inner(walls, s, state.r * (1.0 - 1e-12));
            let c = state
                .walls
                .iter()
                .fold(0.0f64, |m, w| m.max(w.contact_length));
            if p.is_empty() {
                vec![[0.0, 0.0]]
            } else {
                let cx = p.iter().map(|v| v[0]).sum::<f64>() / p.len() as f64;
                let cy = p.iter().map(|v| v[1]).sum::<f64>() / p.len() as f64;
                let w = walls
                    .iter()
                    .zip(&state.walls)
                    .find(|(_, c)| c.contact_length > 0.0)
                    .map(|(w, _)| w.normal)
                    .unwrap_or([0.0, 1.0]);
                let u = [-w[1], w[0]];
                vec![
                    [cx - 0.5 * c * u[0], cy - 0.5 * c * u[1]],
                    [cx + 0.5 * c * u[0], cy + 0.5 * c * u[1]],
                ]
            }
        }
    };
    (0..n)
        .map(|k| {
            let t = 2.0 * PI * k as f64 / n as f64;
            let d = [t.cos(), t.sin()];
            let v = q
                .iter()
                .copied()
                .max_by(|a, b| (a[0] * d[0] + a[1] * d[1]).total_cmp(&(b[0] * d[0] + b[1] * d[1])))
                .unwrap_or([0.0, 0.0]);
            [v[0] + state.r * d[0], v[1] + state.r * d[1]]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    //! The confinement against hand calculations from eqs. (55)–(60), written here with the
    //! corner-angle formulas of a polygon with rounded corners (independent of the half-plane
    //! clipping above) and solved with their own Newton iteration:
    //!
    //! ```text
    //! L = P + r Σ[(π − a_k) − 2 cot(a_k/2)],   A = A_P − r² Σ[cot(a_k/2) − (π − a_k)/2]
    //! N_s = ϖ r,  N_z = ϖ A/L,  λs = L/(2π),  λz ϖ A = λz* ϖ* π λs*²
    //! ```
    //! (P, A_P the polygon's perimeter and area, a_k its interior angles; every wall active).
    use super::*;
    use crate::{flatten, Hypothesis};
    use tubemem_material::laws::AnssariBenamBucchi;

    /// Issue #25, class 2: more than `MAX_WALLS` walls are refused at once, naming the
    /// count and the limit (64 walls ran for 26 s); `MAX_WALLS` of them still solve.
    #[test]
    fn too_many_walls_are_refused_at_once() {
        let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
        let gon = |n: usize| -> Vec<Wall> {
            (0..n)
                .map(|k| {
                    let a = 2.0 * PI * k as f64 / n as f64;
                    Wall::new(a.cos(), a.sin(), 1.1).unwrap()
                })
                .collect()
        };
        let e = confine(&law, Hypothesis::Gps, &gon(MAX_WALLS + 1), 1.3)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("33 planes given") && e.contains("at most 32"),
            "{e}"
        );
        assert!(check_walls(&gon(64)).is_err());
        assert!(confine(&law, Hypothesis::Gps, &gon(16), 1.3).is_ok());
    }

    /// The walls |x|, |y| ≤ h.
    fn square_channel(h: f64) -> [Wall; 4] {
        [
            Wall::new(1.0, 0.0, h).unwrap(),
            Wall::new(-1.0, 0.0, h).unwrap(),
            Wall::new(0.0, 1.0, h).unwrap(),
            Wall::new(0.0, -1.0, h).unwrap(),
        ]
    }

    fn abb() -> AnssariBenamBucchi {
        AnssariBenamBucchi::new(1.0, 30.0).unwrap()
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    /// The hand calculation for a polygon (perimeter, area, interior angles) with every wall
    /// active: (w, r, λz) by Newton with a finite-difference Jacobian, from a guess.
    fn hand_polygon(per: f64, area_p: f64, angles: &[f64], ls0: f64, guess: [f64; 3]) -> [f64; 3] {
        let law = abb();
        let init = inflate(&law, Hypothesis::Gps, ls0).unwrap();
        let gas = init.lambda_z * init.w * PI * ls0 * ls0;
        let cot = |a: f64| 1.0 / (0.5 * a).tan();
        let kl: f64 = angles.iter().map(|&a| (PI - a) - 2.0 * cot(a)).sum();
        let ka: f64 = angles.iter().map(|&a| cot(a) - 0.5 * (PI - a)).sum();
        let f = |x: [f64; 3]| {
            let [w, r, lz] = x;
            let l = per + r * kl;
            let a = area_p - r * r * ka;
            let ls = l / (2.0 * PI);
            let n = law.resultants(ls, lz).unwrap();
            [w * r - n[0], w * a / l - n[1], (lz * w * a - gas) / gas]
        };
        let mut x = guess;
        for _ in 0..50 {
            let fx = f(x);
            let mut j = [[0.0; 3]; 3];
            for c in 0..3 {
                let h = 1e-7 * x[c].abs().max(1e-3);
                let (mut xp, mut xm) = (x, x);
                xp[c] += h;
                xm[c] -= h;
                let (fp, fm) = (f(xp), f(xm));
                for r in 0..3 {
                    j[r][c] = (fp[r] - fm[r]) / (2.0 * h);
                }
            }
            // Cramer's rule for the 3 × 3 step
            let det = |m: [[f64; 3]; 3]| {
                m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                    - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                    + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
            };
            let d = det(j);
            let mut step = [0.0; 3];
            for c in 0..3 {
                let mut m = j;
                for r in 0..3 {
                    m[r][c] = -fx[r];
                }
                step[c] = det(m) / d;
            }
            for c in 0..3 {
                x[c] += step[c];
            }
            if step
                .iter()
                .zip(&x)
                .all(|(s, v)| s.abs() <= 1e-14 * v.abs().max(1.0))
            {
                break;
            }
        }
        x
    }

    /// Two plates are the paper's squeeze: the flattening of eqs. (76)–(77) (GPS) and (78)–(79)
    /// (PS) to 1e-12 (both Newton solves stop at steps below 1e-13).
    #[test]
    fn two_plates_reproduce_the_flattening() {
        let law = abb();
        for hyp in [Hypothesis::Gps, Hypothesis::Ps] {
            for rho in [1.2, 1.0, 0.8] {
                let walls = [
                    Wall::new(0.0, 1.0, rho).unwrap(),
                    Wall::new(0.0, -1.0, rho).unwrap(),
                ];
                let c = confine(&law, hyp, &walls, 1.3).unwrap();
                let f = flatten(&law, hyp, 1.3, rho).unwrap();
                assert_eq!(c.regime, Regime::Stadium);
                for (a, b, what) in [
                    (c.w, f.w, "w"),
                    (c.lambda_s, f.lambda_s, "λs"),
                    (c.lambda_z, f.lambda_z, "λz"),
                    (c.walls[0].force, f.force, "force"),
                    (c.walls[1].force, f.force, "force"),
                ] {
                    assert!(rel(a, b) < 1e-12, "{hyp:?} ρ = {rho} {what}: {a} vs {b}");
                }
            }
        }
    }

    /// Square channel |x|, |y| ≤ h = 1.1 from λs* = 1.3: P = 8h, A_P = 4h², four right angles
    /// (L = 2πr + 8(h − r), A = 4h² − (4 − π)r²).
    #[test]
    fn square_channel_matches_the_hand_calculation() {
        let law = abb();
        let h = 1.1;
        let walls = square_channel(h);
        let c = confine(&law, Hypothesis::Gps, &walls, 1.3).unwrap();
        assert_eq!(c.regime, Regime::Polygon);
        let [w, r, lz] = hand_polygon(
            8.0 * h,
            4.0 * h * h,
            &[PI / 2.0; 4],
            1.3,
            [c.w, c.r, c.lambda_z],
        );
        assert!(
            rel(c.w, w) < 1e-10 && rel(c.r, r) < 1e-10 && rel(c.lambda_z, lz) < 1e-10,
            "{c:?} vs {w} {r} {lz}"
        );
        // each wall: flat 2(h − r), force ϖ·2(h − r)/π
        for wc in &c.walls {
            assert!(rel(wc.contact_length, 2.0 * (h - r)) < 1e-9);
            assert!(rel(wc.force, w * 2.0 * (h - r) / PI) < 1e-9);
        }
    }

    /// A 60° V-groove closed by a plate: an equilateral triangle (normals 120° apart), the plate
    /// nearer the axis than the groove walls; the hand calculation for a triangle of inradius
    /// ρ_in has P = 6√3 ρ_in, A_P = 3√3 ρ_in², three 60° angles, whatever the position of the
    /// axis inside it.
    #[test]
    fn v_groove_matches_the_hand_calculation() {
        let law = abb();
        let d = |deg: f64, off: f64| {
            let t = deg.to_radians();
            Wall::new(t.cos(), t.sin(), off).unwrap()
        };
        // the triangle's inradius is (d1 + d2 + d3)/3 for normals 120° apart
        let walls = [d(90.0, 1.0), d(210.0, 1.2), d(330.0, 1.2)];
        let rin = (1.0 + 1.2 + 1.2) / 3.0;
        let c = confine(&law, Hypothesis::Gps, &walls, 1.3).unwrap();
        let s3 = 3f64.sqrt();
        let [w, r, lz] = hand_polygon(
            6.0 * s3 * rin,
            3.0 * s3 * rin * rin,
            &[PI / 3.0; 3],
            1.3,
            [c.w, c.r, c.lambda_z],
        );
        assert!(
            rel(c.w, w) < 1e-10 && rel(c.r, r) < 1e-10 && rel(c.lambda_z, lz) < 1e-10,
            "{c:?} vs {w} {r} {lz}"
        );
        // equal flats 2√3 (ρ_in − r) on the three walls
        for wc in &c.walls {
            assert!(
                rel(wc.contact_length, 2.0 * s3 * (rin - r)) < 1e-9,
                "{wc:?}"
            );
        }
    }

    /// A rectangular channel 2a × 2b (a = 1.2 > b = 1.0) closing on the tube inflated to 1.3:
    /// the long walls y = ±b touch first and hold a stadium (the end walls untouched: contact 0);
    /// when the stadium's flats reach the end walls (c = 2(a − b)) those become active and the
    /// section is a rounded rectangle. Along the path the pressure is continuous across the
    /// activation and rises.
    #[test]
    fn a_wall_becomes_active_along_the_path() {
        let law = abb();
        let (a, b) = (1.2, 1.0);
        let walls = [
            Wall::new(1.0, 0.0, a).unwrap(),
            Wall::new(-1.0, 0.0, a).unwrap(),
            Wall::new(0.0, 1.0, b).unwrap(),
            Wall::new(0.0, -1.0, b).unwrap(),
        ];
        let path = confine_path(&law, Hypothesis::Gps, &walls, 1.3, 201).unwrap();
        assert_eq!(path[0].regime, Regime::Free);
        let first_polygon = path
            .iter()
            .position(|s| s.regime == Regime::Polygon)
            .expect("the end walls come into play");
        let stadium: Vec<&ConfineState> = path
            .iter()
            .filter(|s| s.regime == Regime::Stadium)
            .collect();
        assert!(!stadium.is_empty());
        for s in &stadium {
            assert_eq!(s.walls[0].contact_length, 0.0);
            assert!(s.walls[2].contact_length > 0.0);
        }
        for s in &path[first_polygon..] {
            assert!(s.walls[0].contact_length > 0.0);
        }
        // continuity: the step of ϖ across the activation is of the size of its neighbours'
        // (steps of 1/200 of the path); a discontinuous regime change would jump by the
        // stadium-to-polygon difference instead. 3× a neighbour's step is the criterion: the
        // step sizes vary by less than that along a smooth path (the path's curvature)
        let jumps: Vec<f64> = path.windows(2).map(|p| (p[1].w - p[0].w).abs()).collect();
        let at = jumps[first_polygon - 1];
        let typical = jumps[first_polygon + 1];
        assert!(at < 3.0 * typical, "jump {at} against {typical}");
        assert!(path.windows(2).all(|p| p[1].w >= p[0].w - 1e-12));
    }

    /// Pressure control: two plates give the GPS section at that pressure (eq. 76 without the
    /// gas law, `section_at_pressure`), and below the contact pressure the free inflation.
    #[test]
    fn pressure_control_matches_the_section_at_pressure() {
        let law = abb();
        let rho = 1.1;
        let walls = [
            Wall::new(0.0, 1.0, rho).unwrap(),
            Wall::new(0.0, -1.0, rho).unwrap(),
        ];
        let contact = inflate(&law, Hypothesis::Gps, rho).unwrap().w;
        let w = 0.8;
        assert!(w > contact);
        let c = confine_at_pressure(&law, Hypothesis::Gps, &walls, w).unwrap();
        let f = crate::section_at_pressure(&law, rho, w, [c.lambda_s, c.lambda_z]).unwrap();
        assert_eq!(c.regime, Regime::Stadium);
        assert!(
            rel(c.lambda_s, f.lambda_s) < 1e-10 && rel(c.lambda_z, f.lambda_z) < 1e-10,
            "{c:?} {f:?}"
        );
        assert!(rel(c.walls[0].force, f.force) < 1e-9);
        let low = confine_at_pressure(&law, Hypothesis::Gps, &walls, 0.3).unwrap();
        let g = inflate(&law, Hypothesis::Gps, low.lambda_s).unwrap();
        assert_eq!(low.regime, Regime::Free);
        assert!(0.3 < contact && rel(g.w, 0.3) < 1e-12);
    }

    /// The flats' reference angles ([`contact_edges`]) against independent geometry: between
    /// plates, π/2 ± πχ/(2λs) and their mirror images with χ and λs from eq. 76's section
    /// (`section_at_pressure`, its own solver); in the square channel the hand calculation's
    /// flats 2(h − r) centred on the walls' normals, at (α_j r ± (h − r) + Σ of the flats
    /// before)/λs; walls not symmetric about y = 0 are refused. Tolerance 1e-9 rad: the two
    /// solvers' Newton tolerances (1e-10 relative on their states, as in
    /// `pressure_control_matches_the_section_at_pressure`).
    #[test]
    fn contact_edges_match_the_section_geometry() {
        let law = abb();
        let (rho, w) = (1.1, 0.8);
        let plates = [
            Wall::new(0.0, 1.0, rho).unwrap(),
            Wall::new(0.0, -1.0, rho).unwrap(),
        ];
        let c = confine_at_pressure(&law, Hypothesis::Gps, &plates, w).unwrap();
        let f = crate::section_at_pressure(&law, rho, w, [c.lambda_s, c.lambda_z]).unwrap();
        let a = PI * f.chi / (2.0 * f.lambda_s);
        let expect = [PI / 2.0 - a, PI / 2.0 + a, 1.5 * PI - a, 1.5 * PI + a];
        let edges = contact_edges(&plates, &c).unwrap();
        assert_eq!(edges.len(), 4);
        for (e, x) in edges.iter().zip(expect) {
            assert!((e - x).abs() < 1e-9, "{edges:?} vs {expect:?}");
        }
        // the square channel: flats of 2(h − r) centred on 0, π/2, π, 3π/2
        let h = 1.1;
        let walls = square_channel(h);
        let s = confine(&law, Hypothesis::Gps, &walls, 1.3).unwrap();
        let half = (h - s.r) / s.lambda_s;
        let quarter = (s.r * PI / 2.0 + 2.0 * (h - s.r)) / s.lambda_s;
        assert!(
            (quarter - PI / 2.0).abs() < 1e-9,
            "a quarter of the outline is π/2"
        );
        let mut expect = vec![];
        for q in 0..4 {
            let centre = q as f64 * PI / 2.0;
            expect.push((centre - half).rem_euclid(2.0 * PI));
            expect.push(centre + half);
        }
        expect.sort_by(f64::total_cmp);
        let edges = contact_edges(&walls, &s).unwrap();
        for (e, x) in edges.iter().zip(&expect) {
            assert!((e - x).abs() < 1e-9, "{edges:?} vs {expect:?}");
        }
        // the channel with its lower wall further out: not symmetric about y = 0
        let mut lopsided = walls;
        lopsided[3] = Wall::new(0.0, -1.0, 1.3).unwrap();
        let s1 = confine_at_pressure(&law, Hypothesis::Gps, &lopsided, 0.8).unwrap();
        assert!(contact_edges(&lopsided, &s1).is_err());
    }

    /// Issue #25, class 2: a confinement path is capped like the curves (at most 10,000,000
    /// points, refused before anything is allocated) and needs at least 2.
    #[test]
    fn a_confine_path_has_the_curves_size_guard() {
        let law = abb();
        let walls = square_channel(1.1);
        for (points, needle) in [(1, "at least 2"), (1usize << 40, "at most 10,000,000")] {
            let e = confine_path(&law, Hypothesis::Gps, &walls, 1.3, points)
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{e}");
        }
    }

    #[test]
    fn bad_plane_sets_are_refused() {
        let law = abb();
        let msg = |walls: &[Wall]| {
            confine(&law, Hypothesis::Gps, walls, 1.3)
                .unwrap_err()
                .to_string()
        };
        // a U-shaped channel open along −x
        let m = msg(&[
            Wall::new(1.0, 0.0, 1.1).unwrap(),
            Wall::new(0.0, 1.0, 1.1).unwrap(),
            Wall::new(0.0, -1.0, 1.1).unwrap(),
        ]);
        assert!(
            m.contains("do not confine") && m.contains("(-1.000, 0.000)"),
            "{m}"
        );
        assert!(Wall::new(0.0, 0.0, 1.0)
            .unwrap_err()
            .to_string()
            .contains("non-zero normal"));
        assert!(msg(&[]).contains("no planes"));
        let m = msg(&[
            Wall::new(0.0, 1.0, 1.0).unwrap(),
            Wall::new(0.0, -1.0, -1.0).unwrap(),
        ]);
        assert!(m.contains("no room"), "{m}");
        // a tiny square: closing it, its perimeter falls below the membrane's length
        let m = msg(&[
            Wall::new(1.0, 0.0, 0.3).unwrap(),
            Wall::new(-1.0, 0.0, 0.3).unwrap(),
            Wall::new(0.0, 1.0, 0.3).unwrap(),
            Wall::new(0.0, -1.0, 0.3).unwrap(),
        ]);
        assert!(
            m.contains("no taut equilibrium") && m.contains("the membrane would wrinkle"),
            "{m}"
        );
    }
}
