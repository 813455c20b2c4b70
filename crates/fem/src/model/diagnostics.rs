//! Diagnostics of a run: how close a state is to the law's locking limit
//! ([`LockingProximity`]) and where one Newton iteration's time goes ([`IterationTiming`]).

use super::*;

/// The fraction of a law's extensible range, (I1 − 3)/(I1,lim − 3), from which a failed solve is
/// attributed to locking: the ABB energy's stiffness grows as 1/(1 − fraction)², 400× its
/// small-strain value at 0.95, and Newton steps from such a state overshoot the limit or stall.
pub const NEAR_LOCKING: f64 = 0.95;

/// Where a state comes closest to the law's locking limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LockingProximity {
    pub element: usize,
    pub gauss_point: usize,
    /// I1 = tr C + 1/det C there
    pub i1: f64,
    /// the law's limit of I1
    pub limit: f64,
}

impl LockingProximity {
    /// (I1 − 3)/(I1,lim − 3): 0 unstretched, 1 locked.
    pub fn fraction(&self) -> f64 {
        (self.i1 - 3.0) / (self.limit - 3.0)
    }
}

impl std::fmt::Display for LockingProximity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the last converged state is at {:.1} % of the law's locking range (I1 = {:.4} of the locking limit {:.4}) at element {}, Gauss point {}: the membrane is locking",
            100.0 * self.fraction(),
            self.i1,
            self.limit,
            self.element,
            self.gauss_point
        )
    }
}

impl Model {
    /// The Gauss point of largest I1 at `x` against the law's locking limit (`None` for a law
    /// without one).
    pub fn locking_proximity(&self, x: &[[f64; 3]]) -> Option<LockingProximity> {
        let limit = self.law.locking_limit()?;
        let mut best: Option<LockingProximity> = None;
        crate::with_elements!(&self.elements, els => for (e, el) in els.iter().enumerate() {
            let xe = el.gather(x);
            for g in 0..el.gauss.len() {
                let c = crate::element::cauchy_green(&el.gradient(g, &xe));
                let det = c[0] * c[1] - c[2] * c[2];
                let i1 = c[0] + c[1] + 1.0 / det;
                if i1.is_finite() && best.is_none_or(|b| i1 > b.i1) {
                    best = Some(LockingProximity {
                        element: e,
                        gauss_point: g,
                        i1,
                        limit,
                    });
                }
            }
        });
        best
    }
}

/// Wall-clock seconds of the three parts of one Newton iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationTiming {
    pub assembly: f64,
    pub factorization: f64,
    pub solve: f64,
    pub negative_pivots: usize,
    pub factor_nnz: usize,
    /// floating-point operations of the factorization
    pub factor_flops: f64,
}

impl Model {
    /// Time one Newton iteration at `state` under pressure control (for benchmarks).
    pub fn time_iteration(&mut self, state: &State) -> Result<IterationTiming, FemError> {
        let t0 = std::time::Instant::now();
        let a = self.assemble(&state.x, true, None)?;
        let t1 = std::time::Instant::now();
        let (neg, _) = self.factorize(&a, state.p)?;
        let t2 = std::time::Instant::now();
        let mut dx: Vec<f64> = a
            .f_int
            .iter()
            .zip(&a.g)
            .map(|(f, g)| state.p * g - f)
            .collect();
        self.ldlt.solve(&mut dx);
        let t3 = std::time::Instant::now();
        Ok(IterationTiming {
            assembly: (t1 - t0).as_secs_f64(),
            factorization: (t2 - t1).as_secs_f64(),
            solve: (t3 - t2).as_secs_f64(),
            negative_pivots: neg,
            factor_nnz: self.ldlt.factor_nnz(),
            factor_flops: self.ldlt.factor_flops(),
        })
    }
}
