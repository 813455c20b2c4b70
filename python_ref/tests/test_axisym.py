"""The scikit-fem axisymmetric capped tube (tubemem_ref.axisym) against the GPS closed form.

Sources: GPS free inflation (eq. 66) and the GPS limit point (closed_form.gps_limit_points).
Measured (ABB N = 30, lambda_s* = 1.3, mid-span stretch control, P2, 8 elements per R along):
the mid-span pressure differs from GPS by 1.03e-1, 7.0e-3, 1.32e-4, 5.35e-8 at L/R = 2, 5, 10, 20
(lambda_z: 2.25e-2, 1.5e-3, 2.8e-5, 1.1e-8): the end-cap effect dies out exponentially with L/R.
The issue asks for below 1e-4 at L/R = 20. The largest pressure along the mid-span-stretch path
is above the uniform GPS limit by 1.12e-3 at L/R = 20 and 1.12e-4 at L/R = 40 (33 s, not in CI):
a finite-length effect that vanishes as L grows; the test bounds it by 2e-3 at L/R = 20.
"""

import numpy as np

from tubemem_ref import axisym
from tubemem_ref import closed_form as cf


def test_axisymmetric_midspan_converges_to_gps():
    w, lz = cf.gps_inflation(1.3)
    errs = []
    for length in [5.0, 10.0, 20.0]:
        tube, q, p = axisym.inflate_to(length, 1.3, cylinder_elements=int(8 * length))
        m = tube.midspan(q, p)
        errs.append((abs(m["w"] / w - 1), abs(m["lambda_z"] / lz - 1)))
    assert errs[0] > errs[1] > errs[2], errs
    assert errs[2][0] < 1e-4 and errs[2][1] < 1e-4, errs


def test_axisymmetric_limit_point_pressure_is_the_gps_one():
    (lmax, wmax), _ = cf.gps_limit_points()
    tube, q, p = axisym.inflate_to(20.0, 1.55)
    best = (0.0, 0.0)
    for ls in np.arange(1.55, 1.66, 0.002):
        q, p, _ = tube.solve_stretch(q, p, ls)
        best = max(best, (p, ls))
    assert abs(best[0] / wmax - 1) < 2e-3, (best, wmax)
    assert abs(best[1] - lmax) < 0.03, (best, lmax)
