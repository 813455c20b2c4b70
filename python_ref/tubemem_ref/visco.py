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


def _solve(f, guess, n):
    sol = optimize.root(f, guess[:n], tol=1e-15)
    return sol.x


def _section(law, hyp, q, fix, value, rho, guess):
    """(ls, lz, w, ns, nz) of the section with relaxed stresses q = (sum q_s, sum q_z): free
    (rho None) or between plates at +-rho; fix: "pressure" (w = value), "gas" (w times the
    enclosed volume per unit reference length over pi R^2 = value), "stretch", "volume"."""
    qs, qz = q

    def n(ls, lz):
        n0s, n0z = resultants(ls, lz, law)
        return n0s - ls / lz * qs, n0z - lz / ls * qz

    def eqs(ls, lz):
        ns, nz = n(ls, lz)
        if rho is None:
            w = ns / ls
            vol = ls * ls * lz
            axial = ns - 2 * nz
        else:
            w = ns / rho
            vol = rho * (2 * ls - rho) * lz
            axial = ns * (2 * ls - rho) / (2 * ls) - nz
        first = {"pressure": lambda: w - value, "gas": lambda: w * vol / value - 1.0,
                 "stretch": lambda: ls - value, "volume": lambda: ls * ls * lz - value}[fix]()
        return first, axial

    if hyp == "ps":
        ls = _solve(lambda x: [eqs(x[0], 1.0)[0]], guess, 1)[0]
        lz = 1.0
    else:
        ls, lz = _solve(lambda x: list(eqs(x[0], x[1])), guess, 2)
    ns, nz = n(ls, lz)
    return ls, lz, ns / (ls if rho is None else rho), ns, nz


def _s0(law, ls, lz):
    n0s, n0z = resultants(ls, lz, law)
    return n0s * lz / ls, n0z * ls / lz


def program(law, prony, hyp, segments, times, rtol=1e-12, atol=1e-14):
    """The states (t, w, ls, lz, rho, force) at `times` under `segments`, a list of
    (control, target, duration): control "pressure", "stretch" or "volume" (the free tube) or
    "plates-gas" / "plates-pressure" (plates y = +-rho R from first contact, the gas closed or
    the pressure held at the segment's start); target None holds; duration 0 jumps. Also the
    plates' work over the program, the integral of force d(-rho) (scipy quad on the dense
    solution)."""
    gs = np.array([g for g, _ in prony])
    taus = np.array([t for _, t in prony])
    y = np.zeros(2 * len(gs))
    st = {"t": 0.0, "w": 0.0, "ls": 1.0, "lz": 1.0, "rho": None, "chi": 0.0}
    guess = [1.0, 1.0]
    out, work = {}, 0.0

    def at(t, y, ctl, value_of, fixval):
        q = y.reshape(len(gs), 2).sum(axis=0)
        if ctl.startswith("plates"):
            rho = value_of(t)
            fix = "gas" if ctl == "plates-gas" else "pressure"
            free = _section(law, hyp, q, fix, fixval, None, guess)
            s = free if free[0] <= rho else _section(law, hyp, q, fix, fixval, rho, guess)
            guess[0], guess[1] = s[0], s[1]
            return (*s, rho, max(s[0] - rho, 0.0))
        s = _section(law, hyp, q, ctl, value_of(t), None, guess)
        guess[0], guess[1] = s[0], s[1]
        return (*s, None, 0.0)

    for ctl, target, duration in segments:
        t0 = st["t"]
        start = {"pressure": st["w"], "stretch": st["ls"], "volume": st["ls"] ** 2 * st["lz"]}.get(
            ctl, st["rho"] if st["rho"] is not None else st["ls"])
        end = start if target is None else target
        value_of = (lambda t, a=start, b=end, t0=t0, d=duration:
                    b if d == 0 else a + (b - a) * (t - t0) / d)
        fixval = None
        if ctl == "plates-pressure":
            fixval = st["w"]
        elif ctl == "plates-gas":
            r = st["rho"]
            fixval = (st["w"] * r * (2 * st["ls"] - r) * st["lz"] if st["chi"] > 0
                      else st["w"] * st["ls"] ** 2 * st["lz"])
        if duration == 0:
            ls, lz, w, _, _, rho, chi = at(t0, y, ctl, value_of, fixval)
            # a jump: no time to relax, q unchanged
        else:
            rhs = lambda t, yy: ((gs[:, None] * np.array(_s0(law, *at(t, yy, ctl, value_of, fixval)[:2]))[None, :]
                                  - yy.reshape(len(gs), 2)) / taus[:, None]).ravel()
            sol = integrate.solve_ivp(rhs, (t0, t0 + duration), y, method="DOP853", rtol=rtol,
                                      atol=atol, dense_output=True)
            assert sol.success, sol.message
            for t in times:
                if t0 < t <= t0 + duration:
                    ls_, lz_, w_, _, _, rho_, chi_ = at(t, sol.sol(t), ctl, value_of, fixval)
                    out[t] = (w_, ls_, lz_, rho_, w_ * chi_)
            if ctl.startswith("plates") and start != end:
                speed = (end - start) / duration
                f = lambda t: at(t, sol.sol(t), ctl, value_of, fixval)
                force = lambda t: f(t)[2] * f(t)[6]
                work += -speed * integrate.quad(force, t0, t0 + duration, epsabs=1e-14, epsrel=1e-12,
                                                limit=400)[0]
            y = sol.y[:, -1]
            ls, lz, w, _, _, rho, chi = at(t0 + duration, y, ctl, value_of, fixval)
        st = {"t": t0 + duration, "w": w, "ls": ls, "lz": lz, "rho": rho, "chi": chi}
        if duration == 0 and t0 in times:
            out[t0] = (w, ls, lz, rho, w * chi)
    return [(t, *out[t]) for t in sorted(out)], work


def history(law, prony, hyp, control, to, ramp, hold, times, rtol=1e-12, atol=1e-14):
    """The states (t, w, ls, lz) at `times` of a ramp of `control` ("pressure", "stretch" or
    "volume") from the unloaded tube to `to` over `ramp` (0: a jump), then held for `hold`.
    prony: [(g, tau), ...]."""
    segs = [(control, to, ramp)] + ([(control, None, hold)] if hold > 0 else [])
    rows, _ = program(law, prony, hyp, segs, times, rtol, atol)
    return [(t, w, ls, lz) for t, w, ls, lz, _, _ in rows]
