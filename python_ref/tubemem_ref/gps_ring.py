"""The GPS cross-section as the full closed ring (periodic P2 mesh), for any set of planes.

Same energy as `gps_section` (whose forms it reuses), on S in [0, 2 pi) with the dofs of S = 2 pi
identified with those of S = 0 (periodicity), so no symmetry is assumed. A closed ring that only
touches planes has three rigid-body modes (two translations, one rotation); they are removed by
Lagrange multipliers on the mean x, the mean y and the mean rotation of the nodes about the
origin; only the modes the planes do not hold are pinned (`rigid`). The multipliers are
returned: they must vanish (a pin that carries load would be a wrong constraint).
"""

import numpy as np
from skfem import Basis, ElementLineP2, ElementVector, Functional, MeshLine1

from .closed_form import gps_inflation
from .gps_section import GpsSection


class GpsRing(GpsSection):
    def __init__(self, kuhn=30.0, elements=128, penalty=1e5, intorder=8, rigid=(0, 1, 2), law=None):
        self.kuhn = kuhn
        self.law = law or ("abb", kuhn)
        # which rigid modes to pin: 0 mean x, 1 mean y, 2 mean rotation (tangential sliding)
        self.rigid = list(rigid)
        self.kappa = penalty
        mesh = MeshLine1.init_tensor(np.linspace(0.0, 2 * np.pi, elements + 1))
        self.basis = Basis(mesh, ElementVector(ElementLineP2(), 2), intorder=intorder)
        self.n = self.basis.N
        nd = self.basis.nodal_dofs
        # periodicity: the last vertex's dofs are the first vertex's
        keep = np.setdiff1d(np.arange(self.n), nd[:, -1])
        self.keep = keep
        self.t = np.zeros((self.n, len(keep)))
        self.t[keep, np.arange(len(keep))] = 1.0
        for c in range(2):
            self.t[nd[c, -1], np.where(keep == nd[c, 0])[0][0]] = 1.0
        self.fixed = np.array([], dtype=int)
        self.free = np.arange(self.n)

    def _rigid(self, q):
        """Constraint gradients (3 x reduced dofs): mean x, mean y, mean rotation."""
        comp = np.arange(self.n) % 2
        gx = np.where(comp == 0, 1.0, 0.0)
        gy = np.where(comp == 1, 1.0, 0.0)
        x0 = self.circle(1.0)  # reference positions
        rot = np.zeros(self.n)
        rot[comp == 0] = -x0[comp == 1]  # d(rotation) ~ -y dx + x dy
        rot[comp == 1] = x0[comp == 0]
        return np.array([gx @ self.t, gy @ self.t, rot @ self.t])[self.rigid]

    def solve(self, q, lz, planes, m4, tol=1e-11, max_iterations=60):
        """Newton on (reduced dofs, lambda_z, the rigid-mode multipliers); `m4` is the gas
        constant of the modelled part, here the whole ring: pass M (GpsSection passes M/4)."""
        t = self.t
        c = self._rigid(q)
        nr, nc = t.shape[1], len(self.rigid)
        mult = np.zeros(nc)
        x0 = t.T @ q / np.diag(t.T @ t)
        for it in range(max_iterations):
            res_full, jac_full, _ = self._full(q, lz, planes, m4)
            r = np.append(t.T @ res_full[:-1], res_full[-1])
            k = np.zeros((nr + 1, nr + 1))
            k[:nr, :nr] = t.T @ jac_full[:-1, :-1] @ t
            k[:nr, nr] = t.T @ jac_full[:-1, -1]
            k[nr, :nr] = k[:nr, nr]
            k[nr, nr] = jac_full[-1, -1]
            big = np.zeros((nr + 1 + nc, nr + 1 + nc))
            big[: nr + 1, : nr + 1] = k
            big[:nr, nr + 1:] = c.T
            big[nr + 1:, :nr] = c
            qr = t.T @ q / np.diag(t.T @ t)
            cons = c @ (qr - x0)
            rhs = -np.concatenate([r + np.append(c.T @ mult, 0.0), cons])
            step = np.linalg.solve(big, rhs)
            smax = np.abs(step[: nr + 1]).max()
            s = min(1.0, 0.2 / max(smax, 1e-300))
            q = q + s * (t @ step[:nr])
            lz = lz + s * step[nr]
            mult = mult + s * step[nr + 1:]
            full = np.abs(rhs).max()  # stationarity of the Lagrangian and the constraints
            if it == 0:
                r0 = max(1.0, full)
            if smax < tol and full < 1e-9 * r0:
                self.multipliers = mult
                return q, lz, it
        raise RuntimeError(f"GPS ring Newton did not converge at {planes}")

    def outputs(self, q, lz, planes, m):
        b = self.basis
        f = self._forms(lz, planes)
        uq = b.interpolate(q)
        a = f["area"].assemble(b, u=uq)
        length = Functional(lambda w_: np.sqrt(w_["u"].grad[0][0] ** 2 + w_["u"].grad[1][0] ** 2)).assemble(b, u=uq)
        forces = [f["contact_force"](k).assemble(b, u=uq) / lz / np.pi for k in range(len(planes))]
        return dict(w=m / (lz * a), lambda_s=length / (2 * np.pi), lambda_z=lz, area=a, forces=forces)


def squeeze(ls0, walls, hs, kuhn=30.0, elements=128, penalty=1e5, substeps=0.01, rigid=(0, 1, 2), law=None):
    """The full ring inflated to ls0 (closed form), gas closed in, walls(h) moved from h = ls0 to
    each h in `hs`; `rigid` selects the rigid modes that the walls do not hold."""
    law = law or ("abb", kuhn)
    ring = GpsRing(kuhn, elements, penalty, rigid=rigid, law=law)
    w0, lz0 = gps_inflation(ls0, law=law)
    m = w0 * lz0 * np.pi * ls0**2
    q, lz = ring.circle(ls0), lz0
    out, h_prev = [], ls0
    for h in hs:
        n = max(1, int(np.ceil((h_prev - h) / (substeps * ls0))))
        for hh in np.linspace(h_prev, h, n + 1)[1:]:
            q, lz, _ = ring.solve(q, lz, walls(hh), m)
        h_prev = h
        o = ring.outputs(q, lz, walls(h), m)
        o["h"] = h
        o["multipliers"] = ring.multipliers.copy()
        out.append(o)
    return out
