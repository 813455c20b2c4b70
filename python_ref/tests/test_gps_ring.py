"""The GPS cross-section as the full closed ring (periodic P2 mesh, no symmetry assumed).

Sources: GPS flattening (eqs. 76-77) for two plates, and for a 60-degree V-groove closed by a
plate a hand calculation from the general GPS equations (55)-(60) (closed_form.gps_polygon:
the section is the walls' polygon with each corner replaced by a tangent arc of the common
radius r). Measured at kappa = 1e5: two plates, 128 elements, rho = 0.8: w -2.4e-5, lambda_s
+1.5e-5, lambda_z -5e-6, force -2.0e-4. V-groove, 96 elements: w, lambda_s, lambda_z, area
<= 3.6e-5; the force on each wall <= 3.5e-3 (its flat zone is only about two elements wide;
1.3e-3 at 192 elements). The rigid-mode multipliers are 4e-17 of the plate force for two
plates and at most 5.8e-5 of the largest wall force for the V-groove: about 1e-6 absolute, the
Newton tolerance (1e-9 of a first-iteration residual of ~1e3), so the pins carry no load. Bounds: 1e-4 for w, lambda_s, lambda_z, area (about 3x the
measured 3.6e-5, which is the penalty error at kappa = 1e5, falling as 1/kappa); 1e-3 for
the two-plate force, 5e-3 for the V-groove wall forces; 1e-4 for the multipliers over the
force (the solver-tolerance level above).
"""

import numpy as np

from tubemem_ref import closed_form as cf
from tubemem_ref import gps_ring


def rel(a, b):
    return abs(a / b - 1.0)


def test_full_ring_between_two_plates_matches_gps():
    walls = lambda h: [(0.0, -1.0, -h), (0.0, 1.0, -h)]
    r = gps_ring.squeeze(1.3, walls, [0.8], elements=128, penalty=1e5)[0]
    c = cf.gps_flattening(1.3, [0.8])[0]
    for k in ["w", "lambda_s", "lambda_z"]:
        assert rel(r[k], c[k]) < 1e-4, (k, r[k], c[k])
    assert rel(r["forces"][0], c["force"]) < 1e-3 and rel(r["forces"][1], c["force"]) < 1e-3
    assert np.abs(r["multipliers"]).max() < 1e-4 * r["forces"][0]


def test_v_groove_matches_the_hand_calculation():
    c60, s60 = np.cos(np.pi / 3), np.sin(np.pi / 3)
    walls = lambda h: [(0.0, -1.0, -h), (-s60, c60, -2.6 * c60), (s60, c60, -2.6 * c60)]
    ref = cf.gps_polygon(1.3, walls, [1.3, 1.2, 1.0])
    assert rel(ref[0]["r"], 1.3) < 1e-12  # the inflated circle is the triangle's incircle
    res = gps_ring.squeeze(1.3, walls, [1.2, 1.0], elements=96, penalty=1e5, rigid=(0, 2))
    for r, c in zip(res, ref[1:]):
        for k in ["w", "lambda_s", "lambda_z", "area"]:
            assert rel(r[k], c[k]) < 1e-4, (r["h"], k, r[k], c[k])
        for f, fc in zip(r["forces"], c["forces"]):
            assert rel(f, fc) < 5e-3, (r["h"], r["forces"], c["forces"])
        assert np.abs(r["multipliers"]).max() < 1e-4 * max(r["forces"])
