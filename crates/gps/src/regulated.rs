//! Pressure-controlled ("regulated") squeeze between two frictionless parallel plates y = ±ρ:
//! the paper's *pressure-controlled membranes* (Sec. 3.6: eqs. 55–59 without Boyle's law, eq.
//! 60), for any plate half-gap ρ, plates touching the tube before inflation included; the
//! inflation between fixed plates and its critical pressure; and the closed gas from any
//! squeezed state (the mixed path: squeezed at constant pressure, then the valve closed).
//!
//! **The states at fixed ρ.** Between the plates the section is two flat zones and two free
//! arcs of radius ρ; eqs. (76) give N_s = ϖρ and N_z = (ϖρ/2)(2λs − ρ)/λs, χ = λs − ρ. With ϖ
//! eliminated, each hoop stretch λs ≥ λ0 = max(ρ, 1) carries one state:
//!
//! ```text
//! N_z(λs, λz) = q N_s(λs, λz),   q = 1 − ρ/(2λs)      (solved for λz; λz = 1 under PS)
//! ϖ = N_s/ρ,   χ = λs − ρ
//! ```
//!
//! starting at λ0: for ρ ≥ 1 the free inflation at λs = ρ (χ = 0: the plates just touch); for
//! ρ < 1 the stress-free tube (ϖ = 0, χ = 1 − ρ: the plates touch it before any pressure).
//! Along these states, by implicit differentiation,
//!
//! ```text
//! λz' = −(∂N_z/∂λs − q ∂N_s/∂λs − N_s ρ/(2λs²)) / (∂N_z/∂λz − q ∂N_s/∂λz)   (0 under PS)
//! dϖ/dλs = (∂N_s/∂λs + ∂N_s/∂λz λz')/ρ
//! ```
//!
//! At fixed plates and pressure, (λs, λz) solves eqs. (76); its Jacobian is singular exactly
//! where dϖ/dλs = 0, so a pressure-controlled section is stable while ϖ rises with λs along
//! its states (as a free inflation is on the rising branch of its curve), and its **critical
//! pressure** ϖc(ρ) is the first maximum of ϖ along them ([`critical_pressure`]): raising the
//! pressure between fixed plates past it, the section snaps. The scan is the one of
//! [`crate::limits`] (λs from λ0 in steps of 0.005, sign changes of dϖ/dλs refined by
//! bisection to |Δλs| < 1e-13).
//!
//! **Paths.** [`squeeze_at_pressure`] moves the plates (and the pressure, if it is ramped)
//! linearly from a known state to (ρ, ϖ), each state solved from the previous one (Newton on
//! eqs. 76 with step cut-back, as [`crate::flatten`] does), and refuses a state where dϖ/dλs
//! ≤ 0 ([`GpsError::Unstable`]). [`between_plates`] raises the pressure from zero at fixed
//! ρ < 1 along the states above. [`flatten_closed_from`] closes the gas in a squeezed state and
//! moves the plates on (Boyle, eq. 77₂, with the gas constant of that state).

use crate::error::{invalid, GpsError};
use crate::limits::{LimitPoint, SCAN_MAX_STRETCH};
use crate::{newton, resultants, Hypothesis, SectionState};
use tubemem_material::{MembraneLaw, Num};

const SCAN_STEP: f64 = 0.005;
const MAX_CUTS: usize = 30;

/// One state of the section between plates at a fixed half-gap, with the slope of its pressure.
#[derive(Clone, Copy, Debug)]
struct FamilyPoint {
    state: SectionState,
    /// dϖ/dλs along the states at this ρ
    slope: f64,
}

/// The states of the section between plates at half-gap `rho`, by hoop stretch.
struct Family<'a> {
    law: &'a dyn MembraneLaw,
    hyp: Hypothesis,
    rho: f64,
}

impl Family<'_> {
    /// The first hoop stretch of the states: ρ (the plates just touch the free tube) or 1 (the
    /// stress-free tube, plates closer than its radius).
    fn start(&self) -> f64 {
        self.rho.max(1.0)
    }

    fn at(&self, ls: f64, lz_guess: f64) -> Result<FamilyPoint, GpsError> {
        let (law, rho) = (self.law, self.rho);
        let at = format!("ρ = {}, λs = {}", Num(rho), Num(ls));
        let q = 1.0 - rho / (2.0 * ls);
        let lz = match self.hyp {
            Hypothesis::Ps => 1.0,
            Hypothesis::Gps => {
                let g = |lz: f64| {
                    let r = resultants::resultants(law, ls, lz)?;
                    Ok((r.nz - q * r.ns, r.jac[1][1] - q * r.jac[0][1]))
                };
                let scale = resultants::resultants(law, ls, lz_guess)
                    .map(|r| r.ns.abs() + r.nz.abs())
                    .unwrap_or(1.0);
                // at the stress-free state (λs = 1) the resultants vanish with λz = 1
                if ls == 1.0 {
                    1.0
                } else {
                    newton::scalar(g, lz_guess, 1e-12 * (1.0 + scale)).map_err(|f| {
                        f.into_error("the section between plates (GPS, eq. 76)", &at)
                    })?
                }
            }
        };
        let r = resultants::resultants(law, ls, lz).map_err(|source| GpsError::Material {
            stage: "the section between plates",
            at: at.clone(),
            source,
        })?;
        if r.ns < 0.0 {
            return Err(GpsError::Compressive {
                stage: "the section between plates",
                at,
                n_s: r.ns,
                w: r.ns / rho,
            });
        }
        let dlz = match self.hyp {
            Hypothesis::Ps => 0.0,
            Hypothesis::Gps => {
                -(r.jac[1][0] - q * r.jac[0][0] - r.ns * rho / (2.0 * ls * ls))
                    / (r.jac[1][1] - q * r.jac[0][1])
            }
        };
        let w = r.ns / rho;
        Ok(FamilyPoint {
            state: SectionState {
                w,
                rho,
                lambda_s: ls,
                lambda_z: lz,
                n_s: r.ns,
                n_z: r.nz,
                chi: ls - rho,
                force: w * (ls - rho),
            },
            slope: (r.jac[0][0] + r.jac[0][1] * dlz) / rho,
        })
    }

    /// Walk the states from λ0 in steps of [`SCAN_STEP`] until `stop` says so at a pair of
    /// neighbours (a, b), or the law locks, or λs reaches [`SCAN_MAX_STRETCH`]: the pair, or
    /// `None`.
    fn scan(
        &self,
        mut stop: impl FnMut(&FamilyPoint, &FamilyPoint) -> bool,
    ) -> Result<Option<(FamilyPoint, FamilyPoint)>, GpsError> {
        let mut ls = self.start();
        let mut prev = self.at(ls, crate::eq68_lambda_z(ls))?;
        let mut before: Option<FamilyPoint> = None;
        while ls < SCAN_MAX_STRETCH {
            ls = (ls + SCAN_STEP).min(SCAN_MAX_STRETCH);
            let guess = match before {
                Some(b) => {
                    let t = (ls - prev.state.lambda_s) / (prev.state.lambda_s - b.state.lambda_s);
                    prev.state.lambda_z + t * (prev.state.lambda_z - b.state.lambda_z)
                }
                None => prev.state.lambda_z,
            };
            let next = match self
                .at(ls, guess)
                .or_else(|_| self.at(ls, prev.state.lambda_z))
            {
                Ok(n) => n,
                // locking (or the law's end) ends the states
                Err(GpsError::Material { .. }) => return Ok(None),
                Err(e) => return Err(e),
            };
            if stop(&prev, &next) {
                return Ok(Some((prev, next)));
            }
            before = Some(prev);
            prev = next;
        }
        Ok(None)
    }

    /// Bisection on λs between `a` and `b` for the sign change of `f` (|Δλs| < 1e-13).
    fn bisect(
        &self,
        a: FamilyPoint,
        b: FamilyPoint,
        f: impl Fn(&FamilyPoint) -> f64,
    ) -> Result<FamilyPoint, GpsError> {
        let (mut a, mut b) = (a, b);
        let sa = f(&a).signum();
        while b.state.lambda_s - a.state.lambda_s > 1e-13 {
            let m = 0.5 * (a.state.lambda_s + b.state.lambda_s);
            let guess = 0.5 * (a.state.lambda_z + b.state.lambda_z);
            let p = self.at(m, guess)?;
            if f(&p).signum() == sa {
                a = p;
            } else {
                b = p;
            }
        }
        Ok(a)
    }

    /// The first maximum of ϖ along the states, if there is one before locking or λs = 50.
    fn critical(&self) -> Result<Option<FamilyPoint>, GpsError> {
        match self.scan(|a, b| a.slope > 0.0 && b.slope <= 0.0)? {
            Some((a, b)) => Ok(Some(self.bisect(a, b, |p| p.slope)?)),
            None => Ok(None),
        }
    }
}

fn check_rho(rho: f64) -> Result<(), GpsError> {
    if rho.is_finite() && rho > 0.0 && rho <= SCAN_MAX_STRETCH {
        Ok(())
    } else {
        Err(invalid(
            "rho",
            rho,
            "the plates' half-gap ρ must be positive and at most 50",
        ))
    }
}

/// The critical pressure of the section between plates at half-gap `rho`: the first maximum
/// of ϖ along its states from λ0 = max(ρ, 1) (see the module), `None` where ϖ rises up to the
/// law's locking or λs = 50. Pressure-controlled, a section between these plates is stable
/// below it and snaps above it.
pub fn critical_pressure(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    rho: f64,
) -> Result<Option<LimitPoint>, GpsError> {
    check_rho(rho)?;
    let fam = Family { law, hyp, rho };
    Ok(fam.critical()?.map(|p| LimitPoint {
        lambda_s: p.state.lambda_s,
        lambda_z: p.state.lambda_z,
        w: p.state.w,
    }))
}

/// The section between plates fixed at half-gap `rho` < 1 (closer than the stress-free
/// tube's radius: they touch it before any pressure), inflated from zero to the pressure `w`:
/// the first state along the states at ρ where ϖ = w (see the module). Above the critical
/// pressure, [`GpsError::Unstable`].
pub fn between_plates(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    rho: f64,
    w: f64,
) -> Result<SectionState, GpsError> {
    check_rho(rho)?;
    if rho >= 1.0 {
        return Err(invalid(
            "rho",
            rho,
            "inflation between fixed plates starts with the plates touching the stress-free tube: ρ < 1 (a larger gap is a free inflation until the tube reaches the plates, then a squeeze)",
        ));
    }
    check_w(w)?;
    let fam = Family { law, hyp, rho };
    let at = format!("ρ = {}, ϖ = {}", Num(rho), Num(w));
    match fam.scan(|a, b| b.state.w >= w || (a.slope > 0.0 && b.slope <= 0.0))? {
        Some((a, b)) if b.state.w >= w && b.slope > 0.0 => {
            let p = fam.bisect(a, b, |p| p.state.w - w)?;
            polish(law, hyp, rho, w, [p.state.lambda_s, p.state.lambda_z], &at)
        }
        Some((a, b)) => {
            let c = fam.bisect(a, b, |p| p.slope)?;
            if c.state.w >= w {
                let p = fam.bisect(a, c, |p| p.state.w - w)?;
                return polish(law, hyp, rho, w, [p.state.lambda_s, p.state.lambda_z], &at);
            }
            Err(GpsError::Unstable {
                stage: "inflation between fixed plates",
                at,
                w,
                w_critical: c.state.w,
                lambda_s_critical: c.state.lambda_s,
            })
        }
        None => Err(GpsError::NoConvergence {
            stage: "inflation between fixed plates (the pressure is not reached before the law locks or λs = 50)",
            at,
            residual: f64::NAN,
            iterations: 0,
        }),
    }
}

/// A squeeze from `from` moves the plates in, not out.
fn check_closing(rho: f64, from: &SectionState) -> Result<(), GpsError> {
    if rho > from.rho {
        return Err(invalid(
            "rho",
            rho,
            "a squeeze moves the plates in: ρ must not exceed the starting half-gap",
        ));
    }
    Ok(())
}

fn check_w(w: f64) -> Result<(), GpsError> {
    if w.is_finite() && w > 0.0 {
        Ok(())
    } else {
        Err(invalid("w", w, "the gas pressure ϖ must be positive"))
    }
}

/// The section at half-gap `rho` under pressure `w` from `guess` (λs, λz): eqs. (76) by
/// Newton, both unknowns under GPS, λs alone under PS (λz = 1, N_z the reaction).
fn polish(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    rho: f64,
    w: f64,
    guess: [f64; 2],
    at: &str,
) -> Result<SectionState, GpsError> {
    let (ls, lz) = match hyp {
        Hypothesis::Gps => {
            let s = crate::section_at_pressure(law, rho, w, guess)?;
            return Ok(s);
        }
        Hypothesis::Ps => {
            let scale = w * rho;
            let h = |ls: f64| {
                let r = resultants::resultants(law, ls, 1.0)?;
                Ok(((r.ns - w * rho) / scale, r.jac[0][0] / scale))
            };
            let ls = newton::scalar(h, guess[0], 1e-12)
                .map_err(|f| f.into_error("PS section at a given pressure (eq. 78₁)", at))?;
            (ls, 1.0)
        }
    };
    let r = resultants::resultants(law, ls, lz).map_err(|source| GpsError::Material {
        stage: "PS section at a given pressure",
        at: at.to_string(),
        source,
    })?;
    let chi = ls - rho;
    if chi < -1e-10 {
        return Err(GpsError::NoContact {
            stage: "PS section at a given pressure",
            at: at.to_string(),
            lambda_s: ls,
            rho,
        });
    }
    Ok(crate::section_state(w, rho, ls, lz, &r))
}

/// The slope dϖ/dλs of the states at `s.rho` through `s` (see the module): > 0 where a
/// pressure-controlled section is stable.
fn pressure_slope(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    s: &SectionState,
) -> Result<f64, GpsError> {
    let fam = Family {
        law,
        hyp,
        rho: s.rho,
    };
    Ok(fam.at(s.lambda_s, s.lambda_z)?.slope)
}

/// The effective stiffness of the plates at a pressure-controlled state `s`, a gripper's
/// −dF/dgap at fixed ϖ: the gap 2ρ, the force ϖχ = ϖ(λs − ρ) (eq. 80), so
/// −d(ϖχ)/d(2ρ) = ϖ(1 − dλs/dρ)/2, in the force's unit per R. dλs/dρ at fixed ϖ comes from
/// eqs. (76) differentiated, N_s = ϖρ and N_z = ϖρ − ϖρ²/(2λs):
///
/// ```text
/// [∂N_s/∂λs                  ∂N_s/∂λz] [λs']   [ϖ           ]
/// [∂N_z/∂λs − ϖρ²/(2λs²)     ∂N_z/∂λz] [λz'] = [ϖ − ϖρ/λs   ]
/// ```
///
/// (under PS λz' = 0 and the first row alone: λs' = ϖ/(∂N_s/∂λs)).
pub fn plate_stiffness(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    s: &SectionState,
) -> Result<f64, GpsError> {
    let (w, rho, ls) = (s.w, s.rho, s.lambda_s);
    let r = resultants::resultants(law, ls, s.lambda_z).map_err(|source| GpsError::Material {
        stage: "the plates' stiffness",
        at: format!("ρ = {}, ϖ = {}", Num(rho), Num(w)),
        source,
    })?;
    let dls = match hyp {
        Hypothesis::Ps => w / r.jac[0][0],
        Hypothesis::Gps => {
            let a = [
                [r.jac[0][0], r.jac[0][1]],
                [r.jac[1][0] - w * rho * rho / (2.0 * ls * ls), r.jac[1][1]],
            ];
            let b = [w, w - w * rho / ls];
            let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
            (b[0] * a[1][1] - a[0][1] * b[1]) / det
        }
    };
    let k = 0.5 * w * (1.0 - dls);
    if !k.is_finite() {
        return Err(GpsError::NoConvergence {
            stage:
                "the plates' stiffness (the section's Jacobian is singular: the critical pressure)",
            at: format!("ρ = {}, ϖ = {}", Num(rho), Num(w)),
            residual: f64::NAN,
            iterations: 0,
        });
    }
    Ok(k)
}

/// A pressure-controlled squeeze: from the state `from` (a free inflation as a
/// [`SectionState`] with χ = 0 and ρ = λs, or any squeezed state), the plates moved to
/// half-gap `rho` and the pressure ramped to `w` (held: `w` = `from.w`), both linearly, each
/// state solved from the previous one with step cut-back. A state past the critical pressure
/// of its plates ([`GpsError::Unstable`]) or one the plates leave ([`GpsError::NoContact`])
/// ends the path.
pub fn squeeze_at_pressure(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    from: SectionState,
    rho: f64,
    w: f64,
) -> Result<SectionState, GpsError> {
    check_rho(rho)?;
    check_w(w)?;
    check_w(from.w)?;
    check_closing(rho, &from)?;
    let point = |t: f64| (from.rho + t * (rho - from.rho), from.w + t * (w - from.w));
    let predict = |a: &(f64, SectionState), b: Option<&(f64, SectionState)>, t: f64| match b {
        Some(b) if a.0 != b.0 => {
            let s = (t - a.0) / (a.0 - b.0);
            [
                a.1.lambda_s + s * (a.1.lambda_s - b.1.lambda_s),
                a.1.lambda_z + s * (a.1.lambda_z - b.1.lambda_z),
            ]
        }
        _ => [a.1.lambda_s, a.1.lambda_z],
    };
    let (mut cur, mut before): ((f64, SectionState), Option<(f64, SectionState)>) =
        ((0.0, from), None);
    // a tenth of the travel at first: a squeeze from the free tube starts with χ = 0
    let mut step = 0.1;
    let mut cuts = 0;
    let unstable = |s: &SectionState| -> Result<GpsError, GpsError> {
        let fam = Family {
            law,
            hyp,
            rho: s.rho,
        };
        let at = format!("ρ = {}, ϖ = {}", Num(s.rho), Num(s.w));
        let c = fam.critical()?;
        Ok(match c {
            Some(c) => GpsError::Unstable {
                stage: "pressure-controlled squeeze",
                at,
                w: s.w,
                w_critical: c.state.w,
                lambda_s_critical: c.state.lambda_s,
            },
            None => GpsError::Snaps {
                stage: "pressure-controlled squeeze",
                at,
                w: s.w,
                lambda_s: s.lambda_s,
            },
        })
    };
    loop {
        let t = (cur.0 + step).min(1.0);
        let (r, p) = point(t);
        let at = format!("ρ = {}, ϖ = {}", Num(r), Num(p));
        let solved = polish(law, hyp, r, p, predict(&cur, before.as_ref(), t), &at)
            .or_else(|_| polish(law, hyp, r, p, [cur.1.lambda_s, cur.1.lambda_z], &at));
        match solved {
            Ok(s) if s.chi < 0.0 => {
                return Err(GpsError::NoContact {
                    stage: "pressure-controlled squeeze",
                    at,
                    lambda_s: s.lambda_s,
                    rho: r,
                })
            }
            Ok(s) => {
                if pressure_slope(law, hyp, &s)? <= 0.0 {
                    return Err(unstable(&s)?);
                }
                before = Some(cur);
                cur = (t, s);
                if t >= 1.0 {
                    return Ok(s);
                }
                step = (2.0 * step).min(0.1);
            }
            Err(e) => {
                cuts += 1;
                if cuts > MAX_CUTS {
                    // a failure next to a limit point is the snap, not the solver
                    let near = pressure_slope(law, hyp, &cur.1).map(|d| d < 1e-3 * (1.0 + cur.1.w));
                    return Err(match near {
                        Ok(true) => unstable(&SectionState {
                            w: p,
                            rho: r,
                            ..cur.1
                        })?,
                        _ => e,
                    });
                }
                step *= 0.5;
            }
        }
    }
}

/// The free inflation at hoop stretch `lambda_s` as the state a squeeze starts from (χ = 0,
/// ρ = λs).
pub fn free_start(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    lambda_s: f64,
) -> Result<SectionState, GpsError> {
    let s = crate::inflate(law, hyp, lambda_s)?;
    Ok(SectionState {
        w: s.w,
        rho: s.lambda_s,
        lambda_s: s.lambda_s,
        lambda_z: s.lambda_z,
        n_s: s.n_s,
        n_z: s.n_z,
        chi: 0.0,
        force: 0.0,
    })
}

/// `points` states of a regulated squeeze from the free tube at `initial_stretch` (ρ = λs*)
/// to `rho_to`, equally spaced in ρ, the pressure held at ϖ(λs*) or ramped linearly to `w`;
/// each solved from the previous one ([`squeeze_at_pressure`]).
pub fn regulated_curve(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    initial_stretch: f64,
    rho_to: f64,
    points: usize,
    w: Option<f64>,
) -> Result<Vec<SectionState>, GpsError> {
    match regulated_curve_until(law, hyp, initial_stretch, rho_to, points, w)? {
        (states, None) => Ok(states),
        (_, Some(e)) => Err(e),
    }
}

/// [`regulated_curve`] up to the first state the path cannot reach: the states before it, and
/// why it stopped ([`GpsError::Unstable`], [`GpsError::Snaps`], [`GpsError::NoContact`], a
/// failed solve), or `None` when it reached `rho_to`. Bad input is the outer error.
pub fn regulated_curve_until(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    initial_stretch: f64,
    rho_to: f64,
    points: usize,
    w: Option<f64>,
) -> Result<(Vec<SectionState>, Option<GpsError>), GpsError> {
    crate::check_points(points)?;
    let start = free_start(law, hyp, initial_stretch)?;
    let target = w.unwrap_or(start.w);
    check_w(target)?;
    check_rho(rho_to)?;
    if rho_to >= initial_stretch {
        return Err(invalid(
            "rho",
            rho_to,
            "the half-gap ρ must be below λs* (the plates start at the inflated radius)",
        ));
    }
    let mut out = Vec::with_capacity(points);
    out.push(start);
    for i in 1..points {
        let t = i as f64 / (points - 1) as f64;
        let prev = out[i - 1];
        let rho = initial_stretch + t * (rho_to - initial_stretch);
        match squeeze_at_pressure(law, hyp, prev, rho, start.w + t * (target - start.w)) {
            Ok(s) => out.push(s),
            Err(e) => return Ok((out, Some(e))),
        }
    }
    Ok((out, None))
}

/// The regulated squeeze of the paper's set-up: inflated to `initial_stretch` λs*, then the
/// plates moved from λs* to `rho` with the pressure held at its inflated value ϖ*.
pub fn flatten_at_pressure(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    initial_stretch: f64,
    rho: f64,
) -> Result<SectionState, GpsError> {
    let start = free_start(law, hyp, initial_stretch)?;
    if rho.partial_cmp(&initial_stretch) != Some(std::cmp::Ordering::Less) {
        return Err(invalid(
            "rho",
            rho,
            "the half-gap ρ must be below λs* (the plates start at the inflated radius)",
        ));
    }
    squeeze_at_pressure(law, hyp, start, rho, start.w)
}

/// The mixed path's second part: the gas closed in the squeezed state `from` (its gas constant
/// ϖ A λz with A = ρ(2λs − ρ) the section's area over πR², eq. 77₂; λz = 1 under PS), then
/// the plates moved on to `rho`.
pub fn flatten_closed_from(
    law: &dyn MembraneLaw,
    hyp: Hypothesis,
    from: SectionState,
    rho: f64,
) -> Result<SectionState, GpsError> {
    check_rho(rho)?;
    check_w(from.w)?;
    check_closing(rho, &from)?;
    let s = crate::flatten_from(law, hyp, from, rho)?;
    Ok(SectionState {
        w: s.w,
        rho: s.rho,
        lambda_s: s.lambda_s,
        lambda_z: s.lambda_z,
        n_s: s.n_s,
        n_z: s.n_z,
        chi: s.chi,
        force: s.force,
    })
}
