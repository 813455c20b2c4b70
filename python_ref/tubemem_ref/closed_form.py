"""The paper's closed form, written independently of the Rust crate `tubemem-gps`.

Different formulations on purpose, so that agreement means something:

* free inflation (GPS): eq. (66) solved for lambda_z by Brent's method on N_s - 2 N_z;
* flattening (GPS): the full four-unknown system (76)-(77) in (w, lambda_s, lambda_z, chi)
  solved by scipy.optimize.root (MINPACK hybrd), continued in rho from the inflated state;
* limit points: zeros of dw/dlambda_s from a complex-step derivative of eq. (68) + eq. (66);
* Maxwell pressure: equal areas on the (v, w) curve with scipy.integrate.quad.

Laws: the Anssari-Benam--Bucchi law (eqs. 58-59, 62) everywhere; Mooney-Rivlin (eqs. 86-87,
alpha = 0 is neo-Hookean) and the law library (Yeoh, Gent, Gent-Gent, Arruda-Boyce, Ogden,
plane-stress Saint-Venant-Kirchhoff: `law_resultants`, written from each published energy by
hand, not from the Rust code) for free inflation, flattening and the pressure maximum
(`law=(name, parameters)`; `law_of_spec` maps a summary.json or case-file material table).
Limit points by complex step, the Maxwell pressure and the channel/polygon hand calculations
are the paper's ABB example only.
"""

import numpy as np
from scipy import integrate, optimize


def abb_n(ls, lz, kuhn):
    """eq. (59)."""
    p = ls**2 * lz**2
    return ((1 - kuhn) * (1 + p * (ls**2 + lz**2 - 9 * kuhn))
            / ((ls * lz) ** 3 * (1 - 3 * kuhn) * (1 + p * (ls**2 + lz**2 - 3 * kuhn))))


def abb_resultants(ls, lz, kuhn):
    """eq. (58): (N_s, N_z) / (mu H)."""
    n = abb_n(ls, lz, kuhn)
    return n * (ls**4 * lz**2 - 1), n * (ls**2 * lz**4 - 1)


def lock_lambda_z(ls, kuhn):
    """The lambda_z at which I1 = ls^2 + lz^2 + (ls lz)^-2 reaches 3 N (largest root)."""
    f = lambda lz: ls**2 + lz**2 + 1 / (ls * lz) ** 2 - 3 * kuhn
    return optimize.brentq(f, 1.0, np.sqrt(3 * kuhn), xtol=1e-15)


def law_of_spec(spec):
    """The `law` tuple of a summary.json `material_spec` or a case file's [material] table
    (results are per mu H: the modulus drops out where it only scales)."""
    model = spec.get("model")
    if model == "abb":
        return ("abb", float(spec["kuhn"]))
    if model == "mooney-rivlin":
        return ("mooney-rivlin", float(spec["alpha"]))
    if model == "neo-hookean":
        return ("mooney-rivlin", 0.0)
    if model == "yeoh":
        return ("yeoh", (float(spec["c10"]), float(spec.get("c20", 0.0)), float(spec.get("c30", 0.0))))
    if model == "gent":
        return ("gent", float(spec["jm"]))
    if model == "gent-gent":
        return ("gent-gent", (float(spec["jm"]), float(spec["c2"]) / float(spec["shear_modulus"])))
    if model == "arruda-boyce":
        return ("arruda-boyce", float(spec["kuhn"]))
    if model == "ogden":
        return ("ogden", (tuple(map(float, spec["mu"])), tuple(map(float, spec["alpha"]))))
    if model in ("saint-venant-kirchhoff", "svk"):
        return ("svk", float(spec["poisson_ratio"]))
    raise ValueError(f"unknown material model {model!r}")


def inverse_langevin(y):
    """beta with coth(beta) - 1/beta = y, 0 < y < 1, by Brent's method (scipy)."""
    f = lambda b: 1.0 / np.tanh(b) - 1.0 / b - y
    return optimize.brentq(f, 1e-12, 1.0 / (1.0 - y) + 1.0, xtol=1e-15, rtol=1e-15)


def _i1_law_w1(kind, p, i1):
    """dW/dI1 per mu of the laws of I1 alone, from their published energies."""
    if kind == "yeoh":  # W = C10 x + C20 x^2 + C30 x^3, mu = 2 C10
        c10, c20, c30 = p
        x = i1 - 3.0
        return (c10 + 2 * c20 * x + 3 * c30 * x * x) / (2 * c10)
    if kind == "gent":  # W = -(mu Jm/2) ln(1 - (I1 - 3)/Jm)
        return 0.5 / (1.0 - (i1 - 3.0) / p)
    if kind == "arruda-boyce":  # W = mu N [beta lr + ln(beta/sinh beta)], lr = sqrt(I1/(3N))
        lr = np.sqrt(i1 / (3.0 * p))
        return inverse_langevin(lr) / (6.0 * lr)
    raise ValueError(kind)


def law_resultants(ls, lz, law):
    """(N_s, N_z)/(mu H) of the law library, lambda_I = ls, lambda_II = lz, from
    N_1 = (1/lambda_2) dW/dlambda_1 (eq. 18) with each published energy differentiated by hand."""
    kind, p = law
    l3 = 1.0 / (ls * lz)
    if kind in ("yeoh", "gent", "arruda-boyce", "gent-gent"):
        i1 = ls**2 + lz**2 + l3**2
        w1 = _i1_law_w1("gent", p[0], i1) if kind == "gent-gent" else _i1_law_w1(kind, p, i1)
        # dI1/dls = 2 ls - 2/(ls^3 lz^2)
        ns = 2 * w1 * (ls - 1.0 / (ls**3 * lz**2)) / lz
        nz = 2 * w1 * (lz - 1.0 / (lz**3 * ls**2)) / ls
        if kind == "gent-gent":  # + C2 ln(I2/3), dI2/dls = -2/ls^3 + 2 ls lz^2
            i2 = 1 / ls**2 + 1 / lz**2 + (ls * lz) ** 2
            w2 = p[1] / i2
            ns += w2 * (-2.0 / ls**3 + 2 * ls * lz**2) / lz
            nz += w2 * (-2.0 / lz**3 + 2 * lz * ls**2) / ls
        return ns, nz
    if kind == "ogden":  # W = sum mu_p/alpha_p (l1^a + l2^a + l3^a - 3), per mu = sum mu a / 2
        mus, als = p
        mu = 0.5 * sum(m * a for m, a in zip(mus, als))
        wp = lambda l: sum(m * l ** (a - 1) for m, a in zip(mus, als)) / mu
        # dW/dls = w'(ls) + w'(l3) dl3/dls, dl3/dls = -l3/ls
        return (wp(ls) - wp(l3) * l3 / ls) / lz, (wp(lz) - wp(l3) * l3 / lz) / ls
    if kind == "svk":  # W/mu = tr E^2 + nu/(1 - nu) (tr E)^2, E = (C - I)/2, plane stress
        k = p / (1.0 - p)
        es, ez = 0.5 * (ls**2 - 1), 0.5 * (lz**2 - 1)
        return 2 * ls / lz * (es + k * (es + ez)), 2 * lz / ls * (ez + k * (es + ez))
    raise ValueError(f"unknown law {kind!r}")


def resultants(ls, lz, law):
    """(N_s, N_z)/(mu H) of `law` = ("abb", kuhn) (eq. 58), ("mooney-rivlin", alpha) (eqs. 86-87)
    or a law of the library (`law_resultants`)."""
    kind, param = law
    if kind == "abb":
        return abb_resultants(ls, lz, param)
    if kind == "mooney-rivlin":
        return mr_resultants(ls, lz, param)
    return law_resultants(ls, lz, law)


def _lock_i1(law):
    """The I1 at which the law locks, or None."""
    kind, p = law
    return {"abb": lambda: 3 * p, "gent": lambda: 3 + p, "gent-gent": lambda: 3 + p[0],
            "arruda-boyce": lambda: 3 * p}.get(kind, lambda: None)()


def _lz_bracket(ls, law):
    """An interval of lambda_z holding the root of N_s - 2 N_z (below locking, if the law locks)."""
    lock = _lock_i1(law)
    if lock is not None:
        f = lambda lz: ls**2 + lz**2 + 1 / (ls * lz) ** 2 - lock
        return 0.5, optimize.brentq(f, 1.0, np.sqrt(lock), xtol=1e-15) * (1 - 1e-12)
    return 0.5, 20.0


def gps_inflation(ls, kuhn=30.0, law=None):
    """(w, lambda_z) for free inflation under GPS, eq. (66)."""
    law = law or ("abb", kuhn)
    if ls == 1.0:
        return 0.0, 1.0
    def g(lz):
        ns, nz = resultants(ls, lz, law)
        return ns - 2 * nz

    lo, hi = _lz_bracket(ls, law)
    lz = optimize.brentq(g, lo, hi, xtol=1e-15, rtol=1e-15)
    ns, _ = resultants(ls, lz, law)
    return ns / ls, lz


def gps_pressure_maximum(kuhn=30.0, law=None, top=4.0):
    """(lambda_s, w, lambda_z) at the first maximum of the GPS inflation curve w(lambda_s), or
    None: a scan of w over (1, top] in steps of 0.01 brackets it, a bounded Brent search refines
    it to 1e-12 in lambda_s."""
    law = law or ("abb", kuhn)
    ls = np.arange(1.01, top, 0.01)
    w = np.array([gps_inflation(x, law=law)[0] for x in ls])
    k = next((i for i in range(1, len(w) - 1) if w[i] >= w[i - 1] and w[i] >= w[i + 1]), None)
    if k is None:
        return None
    r = optimize.minimize_scalar(lambda x: -gps_inflation(x, law=law)[0], bounds=(ls[k - 1], ls[k + 1]),
                                 method="bounded", options={"xatol": 1e-12})
    wm, lz = gps_inflation(r.x, law=law)
    return r.x, wm, lz


def ps_inflation(ls, kuhn=30.0, law=None):
    """w for free inflation under PS, eq. (70) (ABB) or N_s(ls, 1)/ls for any law."""
    if law is not None and law[0] != "abb":
        return resultants(ls, 1.0, law)[0] / ls
    k = law[1] if law is not None else kuhn
    return ((1 - k) * (ls**4 - 1) * (1 + ls**2 * (ls**2 + 1 - 9 * k))
            / (ls**4 * (1 - 3 * k) * (1 + ls**2 * (ls**2 + 1 - 3 * k))))


def gps_flattening(ls0, rhos, kuhn=30.0, law=None):
    """States along the GPS flattening, eqs. (76)-(77), for the decreasing half-gaps `rhos`.

    Unknowns x = (w, ls, lz, chi); returns a list of dicts.
    """
    law = law or ("abb", kuhn)
    w0, lz0 = gps_inflation(ls0, law=law)
    gas = w0 * ls0**2 * lz0

    def residual(x, rho):
        w, ls, lz, chi = x
        ns, nz = resultants(ls, lz, law)
        return [w * rho - ns,
                0.5 * w * rho * (rho + 2 * chi) / (rho + chi) - nz,
                ls - rho - chi,
                (lz * w * rho * (rho + 2 * chi) - gas) / gas]

    x = np.array([w0, ls0, lz0, 0.0])
    out, rho_prev = [], ls0
    for rho in rhos:
        # sub-steps of at most 0.01 ls0 keep hybrd inside its basin of attraction
        n = max(1, int(np.ceil(abs(rho_prev - rho) / (0.01 * ls0))))
        for r in np.linspace(rho_prev, rho, n + 1)[1:]:
            sol = optimize.root(residual, x, args=(r,), method="hybr", tol=1e-14)
            # hybrd reports "no further improvement" once at machine precision: judge by residual
            if not sol.success and np.max(np.abs(residual(sol.x, r))) > 1e-11:
                raise RuntimeError(f"hybrd failed at rho = {r}: {sol.message}")
            x = sol.x
        rho_prev = rho
        w, ls, lz, chi = x
        out.append(dict(rho=rho, w=w, lambda_s=ls, lambda_z=lz, chi=chi, force=w * chi))
    return out


def _w_eq68(ls, kuhn):
    lz = 0.5 * np.sqrt(ls**2 + np.sqrt(ls**4 + 8 / ls**2))
    ns, _ = abb_resultants(ls, lz, kuhn)
    return ns / ls


def gps_limit_points(kuhn=30.0):
    """(ls_max, w_max), (ls_min, w_min) from the complex-step derivative of eq. (68)+(66)."""
    h = 1e-30
    dw = lambda ls: np.imag(_w_eq68(ls + 1j * h, kuhn)) / h
    ls_max = optimize.brentq(dw, 1.2, 2.5, xtol=1e-14)
    ls_min = optimize.brentq(dw, 3.0, 6.0, xtol=1e-14)
    return (ls_max, _w_eq68(ls_max, kuhn)), (ls_min, _w_eq68(ls_min, kuhn))


def gps_maxwell(kuhn=30.0):
    """(w_M, ls_lower, ls_upper): equal areas on (v, w), v = pi ls^2 lz, by adaptive quadrature."""
    (ls_max, w_max), (ls_min, w_min) = gps_limit_points(kuhn)
    lz68 = lambda ls: 0.5 * np.sqrt(ls**2 + np.sqrt(ls**4 + 8 / ls**2))
    v = lambda ls: np.pi * ls**2 * lz68(ls)
    h = 1e-30
    dv = lambda ls: np.imag(v(ls + 1j * h)) / h

    def area(p):
        l1 = optimize.brentq(lambda s: _w_eq68(s, kuhn) - p, 1.0 + 1e-12, ls_max, xtol=1e-15)
        l3 = optimize.brentq(lambda s: _w_eq68(s, kuhn) - p, ls_min, 7.7, xtol=1e-15)
        f = lambda s: (_w_eq68(s, kuhn) - p) * dv(s)
        a = sum(integrate.quad(f, a, b, epsabs=1e-14, epsrel=1e-13, limit=200)[0]
                for a, b in [(l1, ls_max), (ls_max, ls_min), (ls_min, l3)])
        return a, l1, l3

    p = optimize.brentq(lambda q: area(q)[0], w_min + 1e-9, w_max - 1e-9, xtol=1e-15, rtol=1e-14)
    _, l1, l3 = area(p)
    return p, l1, l3


def gps_square_channel(ls0, hs, kuhn=30.0):
    """Hand calculation from the paper's general GPS equations (55)-(60) for a tube inflated to
    ls0, gas closed in, then squeezed in a square channel |x|, |y| <= h (h < r*): the section is a
    square of side 2h with four corner arcs of radius r (Sec. 3.2), so
        L = 2 pi r + 8 (h - r),  A = 4 h^2 - (4 - pi) r^2,
        w r = N_s,  w A / L = N_z,  ls = L / (2 pi),  lz w A = w* lz* pi ls*^2.
    Unknowns (w, r, lz) for each h (ls follows from r); continuation from h = r*."""
    w0, lz0 = gps_inflation(ls0, kuhn)
    gas = w0 * lz0 * np.pi * ls0**2

    def res(z, h):
        w, r, lz = z
        length = 2 * np.pi * r + 8 * (h - r)
        area = 4 * h * h - (4 - np.pi) * r * r
        ls = length / (2 * np.pi)
        ns, nz = abb_resultants(ls, lz, kuhn)
        return [w * r - ns, w * area / length - nz, (lz * w * area - gas) / gas]

    z = np.array([w0, ls0, lz0])
    out, h_prev = [], ls0
    for h in hs:
        n = max(1, int(np.ceil((h_prev - h) / (0.01 * ls0))))
        for hh in np.linspace(h_prev, h, n + 1)[1:]:
            sol = optimize.root(res, z, args=(hh,), method="hybr", tol=1e-14)
            if not sol.success and np.max(np.abs(res(sol.x, hh))) > 1e-11:
                raise RuntimeError(f"square channel: hybrd failed at h = {hh}: {sol.message}")
            z = sol.x
        h_prev = h
        w, r, lz = z
        length = 2 * np.pi * r + 8 * (h - r)
        out.append(dict(h=h, w=w, r=r, lambda_s=length / (2 * np.pi), lambda_z=lz,
                        area=4 * h * h - (4 - np.pi) * r * r,
                        force=w * 2 * (h - r) / np.pi))  # p x flat width 2(h - r), over pi
    return out


def mr_resultants(ls, lz, alpha):
    """eqs. (86)-(87): Mooney-Rivlin (N_s, N_z)/(mu H), lambda_I = ls, lambda_II = lz."""
    j3 = (ls * lz) ** 3
    return (ls / lz - 1 / j3) * (1 + alpha * lz**2), (lz / ls - 1 / j3) * (1 + alpha * ls**2)


def gps_inflation_mr(ls, alpha):
    """(w, lambda_z) of GPS free inflation for Mooney-Rivlin: eq. (66) with eqs. (86)-(87)."""
    return gps_inflation(ls, law=("mooney-rivlin", alpha))


def gps_polygon(ls0, lines, hs, kuhn=30.0):
    """Hand calculation (paper Secs. 3.2 and 3.6, eqs. 55-60) for a tube inflated to ls0, gas
    closed in, then confined by straight walls forming a convex polygon, lines(h) -> list of
    (nx, ny, d) with the region nx x + ny y >= d. Where the membrane is free it is a circular arc
    of one radius r; the section is the polygon with each corner replaced by a tangent arc:
        L = P + r sum[(pi - a_k) - 2 cot(a_k / 2)],  A = A_P - r^2 sum[cot(a_k / 2) - (pi - a_k) / 2]
    (P, A_P the polygon's perimeter and area, a_k its interior angles), and
        w r = N_s,  w A / L = N_z,  ls = L / (2 pi),  lz w A = w* lz* pi ls*^2.
    Returns, for each h, w, r, ls, lz, A and the force on each wall over pi, w (side - flat cut)."""
    w0, lz0 = gps_inflation(ls0, kuhn)
    gas = w0 * lz0 * np.pi * ls0**2

    def polygon(h):
        ls_ = lines(h)
        n = len(ls_)
        verts = []
        for i in range(n):
            (a1, b1, d1), (a2, b2, d2) = ls_[i], ls_[(i + 1) % n]
            verts.append(np.linalg.solve([[a1, b1], [a2, b2]], [d1, d2]))
        verts = np.array(verts)  # vertex i joins side i and side i+1
        sides = np.array([np.linalg.norm(verts[i] - verts[i - 1]) for i in range(n)])  # side i
        per = sides.sum()
        x, y = verts[:, 0], verts[:, 1]
        area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
        angles = []
        for i in range(n):
            u, v = verts[i - 1] - verts[i], verts[(i + 1) % n] - verts[i]
            angles.append(np.arccos(np.dot(u, v) / np.linalg.norm(u) / np.linalg.norm(v)))
        return per, area, np.array(angles), sides

    def res(z, h):
        w, r, lz = z
        per, ap, ang, _ = polygon(h)
        length = per + r * np.sum((np.pi - ang) - 2 / np.tan(ang / 2))
        area = ap - r * r * np.sum(1 / np.tan(ang / 2) - (np.pi - ang) / 2)
        ns, nz = abb_resultants(length / (2 * np.pi), lz, kuhn)
        return [w * r - ns, w * area / length - nz, (lz * w * area - gas) / gas]

    z = np.array([w0, ls0, lz0])
    out, h_prev = [], None
    for h in hs:
        steps = [h] if h_prev is None else np.linspace(h_prev, h, 21)[1:]
        for hh in steps:
            sol = optimize.root(res, z, args=(hh,), method="hybr", tol=1e-14)
            if not sol.success and np.max(np.abs(res(sol.x, hh))) > 1e-11:
                raise RuntimeError(f"polygon: hybrd failed at h = {hh}: {sol.message}")
            z = sol.x
        h_prev = h
        w, r, lz = z
        per, ap, ang, sides = polygon(h)
        length = per + r * np.sum((np.pi - ang) - 2 / np.tan(ang / 2))
        # flat length on side i: side minus the tangent lengths r cot(a/2) at its two corners
        cot = 1 / np.tan(ang / 2)
        flats = np.array([sides[i] - r * (cot[i - 1] + cot[i]) for i in range(len(sides))])
        out.append(dict(h=h, w=w, r=r, lambda_s=length / (2 * np.pi), lambda_z=lz,
                        area=ap - r * r * np.sum(cot - (np.pi - ang) / 2), forces=list(w * flats / np.pi)))
    return out
