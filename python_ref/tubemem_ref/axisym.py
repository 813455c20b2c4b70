"""Axisymmetric capped tube in scikit-fem, written from the membrane equations of the paper
(Sec. 2), independently of the Rust code.

The meridian of a closed tube of revolution — a cylinder of radius R = 1 and length L between two
hemispherical caps — is parametrized by its reference arc length S from the cap's pole (S = 0) to
the mid-span (S = pi/2 + L/2); by symmetry only this half is modelled. Fields r(S), z(S) are P2.

    lambda_1 = |d(r, z)/dS|  (meridional),  lambda_2 = r / R0(S)  (hoop)
    R0(S) = sin S on the cap, 1 on the cylinder
    Pi = int 2 pi R0 W(lambda_1, lambda_2) dS - p V,   V = pi int r^2 z' dS   (half tube: |V|)

Boundary conditions: r = 0 at the pole, z = 0 at mid-span (symmetry plane). The pressure p is
either prescribed (pressure control) or the Lagrange multiplier of a constraint (the mid-span
radius, as the paper controls its inflation), solved in one bordered Newton system with the
consistent tangent; or the pressure is prescribed, or the volume (control = "pressure" |
"stretch" | "volume" in `AxisymmetricTube.solve`). The mid-span values are lambda_s = r/R and lambda_z = lambda_1 there, and the
profiles along z give the end-cap boundary layer.
"""

import numpy as np
from skfem import Basis, BilinearForm, ElementLineP2, ElementVector, Functional, LinearForm, MeshLine1

from .gps_section import law_derivatives


class AxisymmetricTube:
    def __init__(self, length, kuhn=30.0, cap_elements=32, cylinder_elements=160, intorder=6, law=None):
        self.law = law or ("abb", kuhn)
        self.length = length
        sj = np.pi / 2
        nodes = np.concatenate([np.linspace(0.0, sj, cap_elements + 1),
                                np.linspace(sj, sj + length / 2, cylinder_elements + 1)[1:]])
        self.s_end = sj + length / 2
        self.basis = Basis(MeshLine1.init_tensor(nodes), ElementVector(ElementLineP2(), 2), intorder=intorder)
        nd = self.basis.nodal_dofs
        self.fixed = np.array([nd[0, 0], nd[1, -1]])  # r at the pole, z at mid-span
        self.free = np.setdiff1d(np.arange(self.basis.N), self.fixed)
        self.mid_r = nd[0, -1]

    def reference(self):
        s = self.basis.doflocs[0]
        comp = np.arange(self.basis.N) % 2
        q = np.zeros(self.basis.N)
        sj, half = np.pi / 2, self.length / 2
        cap = s <= sj
        r = np.where(cap, np.sin(np.minimum(s, sj)), 1.0)
        z = np.where(cap, half + np.cos(np.minimum(s, sj)), half - (s - sj))
        q[comp == 0] = r[comp == 0]
        q[comp == 1] = z[comp == 1]
        return q

    def _forms(self):
        law = self.law

        def geo(w):
            u = w["u"]
            s = w.x[0]
            r0 = np.where(s <= np.pi / 2, np.sin(np.minimum(s, np.pi / 2)), 1.0)
            dr, dz = u.grad[0][0], u.grad[1][0]
            l1 = np.sqrt(dr**2 + dz**2)
            l2 = u[0] / r0
            return r0, u[0], u[1], dr, dz, l1, l2

        @LinearForm
        def r_int(v, w):
            r0, r, z, dr, dz, l1, l2 = geo(w)
            _, w1, w2, _, _, _ = law_derivatives(l1, l2, law)
            return 2 * np.pi * r0 * (w1 / l1 * (dr * v.grad[0][0] + dz * v.grad[1][0]) + w2 * v[0] / r0)

        @BilinearForm
        def k_int(u, v, w):
            r0, r, z, dr, dz, l1, l2 = geo(w)
            _, w1, w2, w11, w12, w22 = law_derivatives(l1, l2, law)
            gu = dr * u.grad[0][0] + dz * u.grad[1][0]
            gv = dr * v.grad[0][0] + dz * v.grad[1][0]
            uv = u.grad[0][0] * v.grad[0][0] + u.grad[1][0] * v.grad[1][0]
            return 2 * np.pi * r0 * ((w11 / l1**2 - w1 / l1**3) * gu * gv + w1 / l1 * uv
                                     + w12 / (l1 * r0) * (gv * u[0] + gu * v[0]) + w22 / r0**2 * u[0] * v[0])

        @Functional
        def volume(w):
            _, r, z, dr, dz, _, _ = geo(w)
            return -np.pi * r**2 * dz  # z decreases from the pole to mid-span

        @LinearForm
        def d_volume(v, w):
            _, r, z, dr, dz, _, _ = geo(w)
            return -np.pi * (2 * r * dz * v[0] + r**2 * v.grad[1][0])

        @BilinearForm
        def d2_volume(u, v, w):
            _, r, z, dr, dz, _, _ = geo(w)
            return -np.pi * (2 * dz * u[0] * v[0] + 2 * r * (u[0] * v.grad[1][0] + v[0] * u.grad[1][0]))

        return r_int, k_int, volume, d_volume, d2_volume

    def solve_stretch(self, q, p, target, **kw):
        """The state whose mid-span radius is `target`, pressure as the multiplier."""
        return self.solve(q, p, ("stretch", target), **kw)

    def half_volume(self, q):
        _, _, volume, _, _ = self._forms()
        return volume.assemble(self.basis, u=self.basis.interpolate(q))

    def solve(self, q, p, control, tol=1e-11, max_iterations=60):
        """Newton for control = ("pressure", p) | ("stretch", mid-span radius) |
        ("volume", half-tube volume); the pressure is the Lagrange multiplier of the latter two."""
        b = self.basis
        r_int, k_int, volume, d_volume, d2_volume = self._forms()
        fr = self.free
        kind, value = control
        if kind == "pressure":
            p = value
        k_mid = int(np.where(fr == self.mid_r)[0][0])
        for it in range(max_iterations):
            uq = b.interpolate(q)
            g = d_volume.assemble(b, u=uq)
            fint = r_int.assemble(b, u=uq)
            res = (fint - p * g)[fr]
            kk = (k_int.assemble(b, u=uq) - p * d2_volume.assemble(b, u=uq)).toarray()[np.ix_(fr, fr)]
            n = len(fr)
            if kind == "pressure":
                step = np.append(np.linalg.solve(kk, -res), 0.0)
            else:
                jac = np.zeros((n + 1, n + 1))
                jac[:n, :n] = kk
                jac[:n, n] = -g[fr]
                if kind == "stretch":
                    jac[n, k_mid] = 1.0
                    c = q[self.mid_r] - value
                else:
                    jac[n, :n] = g[fr]
                    c = volume.assemble(b, u=uq) - value
                step = np.linalg.solve(jac, -np.append(res, c))
            t = min(1.0, 0.1 / max(np.abs(step[:-1]).max(), 1e-300))
            q = q.copy()
            q[fr] += t * step[:-1]
            p += t * step[-1]
            if np.abs(step).max() < tol and np.abs(res).max() < 1e-9 * max(1.0, np.abs(fint).max()):
                return q, p, it
        raise RuntimeError(f"axisymmetric Newton did not converge for {control}")

    def profile(self, q):
        """(z, lambda_s, lambda_z) at the mesh vertices on the cylinder and cap, from mid-span out."""
        nd = self.basis.nodal_dofs
        r, z = q[nd[0]], q[nd[1]]
        s = self.basis.mesh.p[0]
        r0 = np.where(s <= np.pi / 2, np.sin(np.minimum(s, np.pi / 2)), 1.0)
        ds = np.gradient(s)
        l1 = np.hypot(np.gradient(r), np.gradient(z)) / ds
        with np.errstate(divide="ignore", invalid="ignore"):
            l2 = np.where(r0 > 0, r / r0, np.nan)
        return z, l2, l1, s

    def midspan(self, q, p):
        uq = self.basis.interpolate(q)
        # lambda_z at mid-span from the P2 field's derivative at the last quadrature point
        dz = uq.grad[1][0][-1, -1]
        dr = uq.grad[0][0][-1, -1]
        return dict(w=p, lambda_s=q[self.mid_r], lambda_z=float(np.hypot(dr, dz)))


def inflate_to(length, target, kuhn=30.0, steps=6, law=None, **mesh):
    """Inflate the capped tube to mid-span stretch `target` (continuation in steps)."""
    tube = AxisymmetricTube(length, kuhn, law=law, **mesh)
    q, p = tube.reference(), 0.0
    for t in np.linspace(1.0, target, steps + 1)[1:]:
        q, p, _ = tube.solve_stretch(q, p, t)
    return tube, q, p


def inflate_volume(tube, q, p, v_target, dv, min_dv=1e-6, on_step=None):
    """Volume-controlled continuation of the half tube from (q, p) to `v_target`, with step
    halving on failure and growth after easy steps; `on_step(q, p)` sees every converged state."""
    v = tube.half_volume(q)
    while v < v_target - 1e-12:
        step = min(dv, v_target - v)
        try:
            q1, p1, it = tube.solve(q, p, ("volume", v + step))
        except (RuntimeError, np.linalg.LinAlgError):
            dv *= 0.5
            if dv < min_dv:
                raise
            continue
        q, p, v = q1, p1, v + step
        if on_step is not None:
            on_step(q, p)
        if it < 6:
            dv *= 1.5
    return q, p


def cap_tail_decay(length, lambda_s, distances=(3.0, 4.0), law=None, **mesh):
    """The decay of the cap's boundary layer of a uniform tube: inflate to mid-span stretch
    `lambda_s`, then (r(d) - r_mid) / (r(d + 1) - r_mid) at each distance d (in R, along the
    reference cylinder from the cap junction), the layer's factor of decay per R there; with
    the pressure. A tail that decays as exp(-k d) gives exp(k) at every d."""
    tube, q, p = inflate_to(length, lambda_s, law=law, **mesh)
    nd = tube.basis.nodal_dofs
    r, s = q[nd[0]], tube.basis.mesh.p[0]
    cyl = s >= np.pi / 2
    d, excess = s[cyl] - np.pi / 2, r[cyl] - r[cyl][-1]
    ratios = [float(np.interp(x, d, excess) / np.interp(x + 1.0, d, excess)) for x in distances]
    return ratios, p


def pressure_maximum(length, lo, hi, law=None, tol=1e-7, **mesh):
    """The pressure maximum of the capped tube's inflation, (lambda_s, p) at mid-span: golden
    section on p(lambda_s) over [lo, hi] (which must bracket it), each p from a mid-span
    stretch-controlled solve continued from the nearest solved state. The mid-span stretch grows
    monotonically through the maximum, so the stretch-controlled path passes it."""
    tube = AxisymmetricTube(length, law=law, **mesh)
    q, p = tube.reference(), 0.0
    for s in np.linspace(1.0, lo, 11)[1:]:
        q, p, _ = tube.solve_stretch(q, p, s)
    g = (np.sqrt(5.0) - 1.0) / 2.0
    a, b = lo, hi
    c, d = b - g * (b - a), a + g * (b - a)
    qc, pc, _ = tube.solve_stretch(q, p, c)
    qd, pd, _ = tube.solve_stretch(qc, pc, d)
    while b - a > tol:
        if pc > pd:
            b, d, qd, pd = d, c, qc, pc
            c = b - g * (b - a)
            qc, pc, _ = tube.solve_stretch(qd, pd, c)
        else:
            a, c, qc, pc = c, d, qd, pd
            d = a + g * (b - a)
            qd, pd, _ = tube.solve_stretch(qc, pc, d)
    return (c, pc) if pc > pd else (d, pd)
