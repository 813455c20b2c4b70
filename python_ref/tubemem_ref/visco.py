"""The GPS free inflation of a capped tube in time with a QLV Prony law, integrated independently
of tubemem's recursion (issue #63).

tubemem integrates the hereditary stress S = g_inf S0 + sum h_i with the recursive update of
Taylor-Pister-Goudreau (exact for S0 linear in a step). Here the same law is written with the
relaxed parts q_i = g_i S0 - h_i as state:

    S = S0(C) - sum_i q_i,        dq_i/dt = (g_i S0(C) - q_i) / tau_i,

(which follows from dh_i/dt + h_i/tau_i = g_i dS0/dt), a semi-explicit index-1 DAE whose
algebraic part is the GPS section at each instant, eqs. (66):

    N_s = (ls/lz) S_s = w ls,      N_s = 2 N_z = 2 (lz/ls) S_z   (PS: lz = 1)

under a pressure w(t), or with the enclosed volume v = ls^2 lz given instead of w. The ODE in q
is integrated by scipy's DOP853 (an explicit Runge-Kutta of order 8 with its own error control)
with the algebraic part solved by scipy.optimize.root at every evaluation. S0 comes from the
resultants of `closed_form.resultants` (each law's energy differentiated by hand there):
S0_s = N0_s lz / ls, S0_z = N0_z ls / lz.
"""

import numpy as np
from scipy import integrate, optimize

from .closed_form import resultants


def _section(law, hyp, q, control, value, guess):
    """(ls, lz, w, ns, nz) of the section with relaxed stresses q = (sum q_s, sum q_z)."""
    qs, qz = q

    def n(ls, lz):
        n0s, n0z = resultants(ls, lz, law)
        return n0s - ls / lz * qs, n0z - lz / ls * qz

    if control == "pressure":
        if hyp == "ps":
            f = lambda x: [n(x[0], 1.0)[0] - value * x[0]]
            ls = optimize.root(f, [guess[0]], tol=1e-15).x[0]
            lz = 1.0
        else:
            def f(x):
                ns, nz = n(x[0], x[1])
                return [ns - value * x[0], ns - 2 * nz]
            ls, lz = optimize.root(f, guess, tol=1e-15).x
    elif control == "volume":
        if hyp == "ps":
            ls, lz = np.sqrt(value), 1.0
        else:
            def f(x):
                ls_ = np.sqrt(value / x[0])
                ns, nz = n(ls_, x[0])
                return [ns - 2 * nz]
            lz = optimize.root(f, [guess[1]], tol=1e-15).x[0]
            ls = np.sqrt(value / lz)
    else:
        raise ValueError(control)
    ns, nz = n(ls, lz)
    return ls, lz, ns / ls, ns, nz


def _s0(law, ls, lz):
    n0s, n0z = resultants(ls, lz, law)
    return n0s * lz / ls, n0z * ls / lz


def history(law, prony, hyp, control, to, ramp, hold, times, rtol=1e-12, atol=1e-14):
    """The states (t, w, ls, lz) at `times` of a ramp of `control` ("pressure" or "volume") from
    the unloaded tube to `to` over `ramp` (0: a jump), then held for `hold`.
    prony: [(g, tau), ...]."""
    gs = np.array([g for g, _ in prony])
    taus = np.array([t for _, t in prony])
    start = 0.0 if control == "pressure" else 1.0
    value = lambda t: to if ramp == 0 or t >= ramp else start + (to - start) * t / ramp
    guess = [1.0, 1.0]

    def state(t, y):
        q = y.reshape(len(gs), 2).sum(axis=0)
        s = _section(law, hyp, q, control, value(t), guess)
        guess[0], guess[1] = s[0], s[1]
        return s

    def rhs(t, y):
        ls, lz = state(t, y)[:2]
        s0 = np.array(_s0(law, ls, lz))
        yy = y.reshape(len(gs), 2)
        return ((gs[:, None] * s0[None, :] - yy) / taus[:, None]).ravel()

    y = np.zeros(2 * len(gs))
    out = {}
    pieces = ([(0.0, ramp)] if ramp > 0 else []) + ([(ramp, ramp + hold)] if hold > 0 else [])
    if ramp == 0:
        # the jump: q = 0 (no time to relax), the base law's state at the target
        guess[:] = [1.2, 1.0]
    for a, b in pieces:
        ts = sorted(t for t in times if a <= t <= b)
        sol = integrate.solve_ivp(rhs, (a, b), y, method="DOP853", rtol=rtol, atol=atol,
                                  dense_output=True)
        assert sol.success, sol.message
        for t in ts:
            ls, lz, w, _, _ = state(t, sol.sol(t))
            out[t] = (w, ls, lz)
        y = sol.y[:, -1]
    return [(t, *out[t]) for t in sorted(out)]
