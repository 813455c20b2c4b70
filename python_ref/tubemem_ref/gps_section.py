"""GPS cross-section of a translation-invariant membrane with closed gas and frictionless
penalty contact, in scikit-fem — written from the paper's equations, independently of the Rust
code.

Model (R = 1, μH = 1; energies per unit *reference* length along the axis):

    Π(x, y, λz) = ∫_Γ W(λs(S), λz) dS − M ln(λz A) + (κ/2) Σ_planes ∫_Γ ⟨−g⟩² dS

with the ring's current position (x(S), y(S)) on the reference arc length S, λs = |dx/dS|,
A = ½∮(x y' − y x') dS the enclosed area, M = ϖ* λz* A* Boyle's constant (eq. 60), g the gap
to each plane. λz is one global unknown: stationarity in λz gives ∫ ∂W/∂λz dS = M/λz = p A, which
is exactly the end-cap axial balance ∮ N_z ds = p A of eq. (37) (N_z ds = (1/λs) ∂W/∂λz λs dS).
Nothing assumes the stadium shape: it comes out of the solution.

Discretization: P2 Lagrange fields x, y (`ElementVector(ElementLineP2(), 2)`) on a quarter of the
ring, S ∈ [0, π/2], with the symmetry conditions y = 0 at S = 0 and x = 0 at S = π/2 (the
symmetry planes pass through the origin, so the quarter's (1/2)∫(x y' − y x') is a quarter of
the area). Newton with the consistent tangent, assembled from one `LinearForm` / `BilinearForm`
per term; the gas term's rank-one part and the λz border are added as dense blocks.

Laws: `law=("abb", 𝒩)` (eq. 19, the default with `kuhn`) or `("mooney-rivlin", α)` (eq. 85;
α = 0 is neo-Hookean), through `law_derivatives`.
"""

import numpy as np
from skfem import Basis, BilinearForm, ElementLineP2, ElementVector, Functional, LinearForm, MeshLine1

from .closed_form import gps_inflation


def law_derivatives(l1, l2, law):
    """W(λ1, λ2) and W_1, W_2, W_11, W_12, W_22 for law = ("abb", 𝒩) (eq. 21) or
    ("mooney-rivlin", α) (eq. 85; α = 0 is neo-Hookean)."""
    kind, param = law
    if kind == "abb":
        return abb_derivatives(l1, l2, param)
    if kind == "mooney-rivlin":
        a = param
        i1 = l1**2 + l2**2 + 1 / (l1 * l2) ** 2
        i2 = 1 / l1**2 + 1 / l2**2 + (l1 * l2) ** 2
        i1_1, i1_2 = 2 * l1 - 2 / (l1**3 * l2**2), 2 * l2 - 2 / (l1**2 * l2**3)
        i1_11, i1_22, i1_12 = 2 + 6 / (l1**4 * l2**2), 2 + 6 / (l1**2 * l2**4), 4 / (l1**3 * l2**3)
        i2_1, i2_2 = -2 / l1**3 + 2 * l1 * l2**2, -2 / l2**3 + 2 * l1**2 * l2
        i2_11, i2_22, i2_12 = 6 / l1**4 + 2 * l2**2, 6 / l2**4 + 2 * l1**2, 4 * l1 * l2
        h = 0.5
        return (h * ((i1 - 3) + a * (i2 - 3)), h * (i1_1 + a * i2_1), h * (i1_2 + a * i2_2),
                h * (i1_11 + a * i2_11), h * (i1_12 + a * i2_12), h * (i1_22 + a * i2_22))
    raise ValueError(f"unknown law {kind!r}")


def abb_derivatives(ls, lz, kuhn):
    """W(λs, λz) of eq. (21) and its derivatives W_s, W_z, W_ss, W_sz, W_zz (arrays)."""
    n = kuhn
    k = n * (3 - 3 * n) / (1 - 3 * n)
    i1 = ls**2 + lz**2 + 1 / (ls * lz) ** 2
    d = i1 - 3 * n
    f0 = k * ((i1 - 3) / (6 * n) - np.log(d / (3 - 3 * n)))
    f1 = k * (1 / (6 * n) - 1 / d)
    f2 = k / d**2
    i_s = 2 * ls - 2 / (ls**3 * lz**2)
    i_z = 2 * lz - 2 / (ls**2 * lz**3)
    i_ss = 2 + 6 / (ls**4 * lz**2)
    i_zz = 2 + 6 / (ls**2 * lz**4)
    i_sz = 4 / (ls**3 * lz**3)
    return (f0, f1 * i_s, f1 * i_z, f2 * i_s**2 + f1 * i_ss, f2 * i_s * i_z + f1 * i_sz, f2 * i_z**2 + f1 * i_zz)


def plates(h):
    """The top plate y = h of a symmetric squeeze (the quarter model sees only it): (nx, ny, d)
    with gap g = nx x + ny y − d ≥ 0 allowed."""
    return [(0.0, -1.0, -h)]


def square_channel(h):
    """A square channel |x| ≤ h, |y| ≤ h: the quarter model sees x = h and y = h."""
    return [(0.0, -1.0, -h), (-1.0, 0.0, -h)]


class GpsSection:
    """The quarter cross-section in frictionless contact with planes (nx, ny, d), gap
    g = nx x + ny y − d, all parallel to the axis."""

    def __init__(self, kuhn=30.0, elements=64, penalty=1e4, intorder=8, law=None):
        self.kuhn = kuhn
        self.law = law or ("abb", kuhn)
        self.kappa = penalty
        mesh = MeshLine1.init_tensor(np.linspace(0.0, np.pi / 2, elements + 1))
        self.basis = Basis(mesh, ElementVector(ElementLineP2(), 2), intorder=intorder)
        self.n = self.basis.N
        nd = self.basis.nodal_dofs
        # y = 0 at S = 0 (on the x axis), x = 0 at S = π/2 (on the y axis)
        self.fixed = np.array([nd[1, 0], nd[0, -1]])
        self.free = np.setdiff1d(np.arange(self.n), self.fixed)

    # --- the state -------------------------------------------------------------------------
    def circle(self, radius):
        """Dof vector of a circle of the given radius."""
        s = self.basis.doflocs[0]
        q = np.zeros(self.n)
        comp = np.arange(self.n) % 2  # ElementVector interleaves the components
        q[comp == 0] = radius * np.cos(s[comp == 0])
        q[comp == 1] = radius * np.sin(s[comp == 1])
        return q

    def _forms(self, lz, planes):
        kappa, law = self.kappa, self.law

        def gaps(x, y):
            return [(nx, ny, nx * x + ny * y - d) for nx, ny, d in planes]

        def geo(w):
            u = w["u"]
            gx, gy = u.grad[0][0], u.grad[1][0]
            return u[0], u[1], gx, gy, np.sqrt(gx**2 + gy**2)


        @Functional
        def area(w):
            x, y, gx, gy, _ = geo(w)
            return 0.5 * (x * gy - y * gx)

        @Functional
        def w_z(w):
            _, _, _, _, ls = geo(w)
            return law_derivatives(ls, lz, law)[2]

        @Functional
        def w_zz(w):
            _, _, _, _, ls = geo(w)
            return law_derivatives(ls, lz, law)[5]

        def contact_force(k):
            nx0, ny0, d0 = planes[k]

            @Functional
            def force(w):
                x, y, _, _, _ = geo(w)
                return kappa * np.maximum(d0 - nx0 * x - ny0 * y, 0.0)

            return force

        @LinearForm
        def r_membrane(v, w):
            _, y, gx, gy, ls = geo(w)
            ws = law_derivatives(ls, lz, law)[1]
            x = w["u"][0]
            out = ws / ls * (gx * v.grad[0][0] + gy * v.grad[1][0])
            for nx, ny, g in gaps(x, y):
                out = out - kappa * np.maximum(-g, 0.0) * (nx * v[0] + ny * v[1])
            return out

        @LinearForm
        def d_area(v, w):
            x, y, gx, gy, _ = geo(w)
            return 0.5 * (v[0] * gy + x * v.grad[1][0] - v[1] * gx - y * v.grad[0][0])

        @LinearForm
        def k_membrane_lz(v, w):
            _, _, gx, gy, ls = geo(w)
            wsz = law_derivatives(ls, lz, law)[4]
            return wsz / ls * (gx * v.grad[0][0] + gy * v.grad[1][0])

        @BilinearForm
        def k_membrane(u, v, w):
            _, y, gx, gy, ls = geo(w)
            _, ws, _, wss, _, _ = law_derivatives(ls, lz, law)
            gu = gx * u.grad[0][0] + gy * u.grad[1][0]
            gv = gx * v.grad[0][0] + gy * v.grad[1][0]
            uv = u.grad[0][0] * v.grad[0][0] + u.grad[1][0] * v.grad[1][0]
            x = w["u"][0]
            out = (wss / ls**2 - ws / ls**3) * gu * gv + ws / ls * uv
            for nx, ny, g in gaps(x, y):
                out = out + kappa * (g < 0) * (nx * u[0] + ny * u[1]) * (nx * v[0] + ny * v[1])
            return out

        @BilinearForm
        def d2_area(u, v, w):
            return 0.5 * (u[0] * v.grad[1][0] + v[0] * u.grad[1][0]
                          - u[1] * v.grad[0][0] - v[1] * u.grad[0][0])

        return dict(area=area, w_z=w_z, w_zz=w_zz, contact_force=contact_force,
                    r_membrane=r_membrane, d_area=d_area, k_membrane_lz=k_membrane_lz,
                    k_membrane=k_membrane, d2_area=d2_area)

    def _full(self, q, lz, planes, m):
        """Residual and Jacobian in all dofs and λz (before constraints); m is the gas constant
        of the modelled part (M/4 for the quarter, M for the full ring)."""
        b = self.basis
        f = self._forms(lz, planes)
        uq = b.interpolate(q)
        a = f["area"].assemble(b, u=uq)
        da = f["d_area"].assemble(b, u=uq)
        r = f["r_membrane"].assemble(b, u=uq) - m / a * da
        r_lz = f["w_z"].assemble(b, u=uq) - m / lz
        k = f["k_membrane"].assemble(b, u=uq).toarray()
        k += m / a**2 * np.outer(da, da) - m / a * f["d2_area"].assemble(b, u=uq).toarray()
        k_lz = f["k_membrane_lz"].assemble(b, u=uq)
        k_zz = f["w_zz"].assemble(b, u=uq) + m / lz**2
        n = self.n
        jac = np.zeros((n + 1, n + 1))
        jac[:n, :n] = k
        jac[:n, n] = k_lz
        jac[n, :n] = k_lz
        jac[n, n] = k_zz
        return np.append(r, r_lz), jac, a

    def residual_jacobian(self, q, lz, planes, m4):
        """Residual and Jacobian in the unknowns (free dofs, λz); m4 = M/4 (quarter)."""
        res, jac, a = self._full(q, lz, planes, m4)
        keep = np.append(self.free, self.n)
        return res[keep], jac[np.ix_(keep, keep)], a

    def solve(self, q, lz, planes, m4, tol=1e-11, max_iterations=50):
        """Newton from (q, λz) against `planes`; returns (q, λz, iterations)."""
        for it in range(max_iterations):
            res, jac, _ = self.residual_jacobian(q, lz, planes, m4)
            scale = max(1.0, np.abs(res).max())
            step = np.linalg.solve(jac, -res)
            t = 1.0
            # keep λz positive and the ring from folding (|step| limited to 0.2 R)
            smax = np.abs(step).max()
            if smax > 0.2:
                t = 0.2 / smax
            q = q.copy()
            q[self.free] += t * step[:-1]
            lz = lz + t * step[-1]
            if np.abs(step).max() < tol and np.abs(res).max() < 1e-9 * scale:
                return q, lz, it
        raise RuntimeError(f"GPS section Newton did not converge at {planes} (residual {np.abs(res).max():.2e})")

    def outputs(self, q, lz, planes, m4):
        """ϖ, λs, λz and, per plane, the force per unit current length over π (for a plate of
        the symmetric squeeze: the whole plate, i.e. twice the quarter's)."""
        b = self.basis
        f = self._forms(lz, planes)
        uq = b.interpolate(q)
        a = f["area"].assemble(b, u=uq)
        w = m4 / (lz * a)  # p = M/(λz A), quarter quantities
        length = Functional(lambda w_: np.sqrt(w_["u"].grad[0][0] ** 2 + w_["u"].grad[1][0] ** 2)).assemble(b, u=uq)
        forces = [2.0 * f["contact_force"](k).assemble(b, u=uq) / lz / np.pi for k in range(len(planes))]
        return dict(w=w, lambda_s=length / (np.pi / 2), lambda_z=lz, area=4.0 * a, forces=forces,
                    force=forces[0], chi=forces[0] / w)


def squeeze(ls0, rhos, kuhn=30.0, elements=64, penalty=1e4, substeps=0.05, walls=plates, law=None):
    """Inflate exactly to λs* (the closed-form inflated circle is the model's equilibrium under
    that pressure), close the gas in, and move the walls `walls(h)` from h = λs* to each ρ in
    `rhos` (decreasing); list of outputs (with `rho` and the largest penetration)."""
    law = law or ("abb", kuhn)
    sec = GpsSection(kuhn, elements, penalty, law=law)
    w0, lz0 = gps_inflation(ls0, law=law)
    m4 = w0 * lz0 * np.pi * ls0**2 / 4.0
    q, lz = sec.circle(ls0), lz0
    out, h_prev = [], ls0
    for rho in rhos:
        n = max(1, int(np.ceil((h_prev - rho) / (substeps * ls0))))
        for h in np.linspace(h_prev, rho, n + 1)[1:]:
            q, lz, _ = sec.solve(q, lz, walls(h), m4)
        h_prev = rho
        o = sec.outputs(q, lz, walls(rho), m4)
        o["rho"] = rho
        o["penetration"] = float(max(np.max(q[0::2]) - rho if len(walls(rho)) > 1 else 0.0, np.max(q[1::2]) - rho))
        out.append(o)
    return out
