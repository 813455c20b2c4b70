"""The Rust closed form for any set of walls (`tubemem gps confine`, crates/gps/src/confine.rs)
against the independent references of python_ref, for the same planes:

* a square channel |x|, |y| <= 1.1 from lambda_s* = 1.3: the scikit-fem quarter section with
  penalty contact (gps_section, kappa = 1e5) and the hand calculation closed_form.gps_square_channel;
* a 60-degree V-groove closed by a plate at h = 1.2 and 1.0: the periodic full ring (gps_ring,
  96 elements, kappa = 1e5) and the polygon hand calculation closed_form.gps_polygon.

The planes of python_ref are (nx, ny, d) with nx x + ny y >= d; tubemem's are n.x <= d, so
(nx, ny, d) -> (-nx, -ny, -d). Bounds: against the hand calculations 1e-9 (both solve to 1e-10
or better); against the penalty models 1e-4 for w, lambda_s, lambda_z and area (their penalty
error at kappa = 1e5: 3.6e-5 measured in test_gps_ring.py) and 5e-3 for the wall forces (the
ring's flat zones are two elements wide: 3.5e-3 measured there).
"""

import numpy as np
import pytest

from tubemem_ref import closed_form as cf
from tubemem_ref import gps_ring, gps_section

ABB = ("--material", "abb", "--kuhn", "30")


def rel(a, b):
    return abs(a / b - 1.0)


def planes_args(planes):
    args = []
    for nx, ny, d in planes:
        args += ["--plane", f"{float(-nx)!r},{float(-ny)!r},{float(-d)!r}"]
    return args


def test_square_channel(tubemem):
    h = 1.1
    quarter = gps_section.square_channel(h)
    full = quarter + [(0.0, 1.0, -h), (1.0, 0.0, -h)]
    s = tubemem("gps", "confine", *ABB, "--initial-stretch", 1.3, *planes_args(full), "--json")
    assert s["regime"] == "polygon"
    hand = cf.gps_square_channel(1.3, [h])[0]
    for k in ["w", "lambda_s", "lambda_z", "area"]:
        assert rel(s[k], hand[k]) < 1e-9, (k, s[k], hand[k])
    assert rel(s["r"], hand["r"]) < 1e-9
    for wall in s["walls"]:
        assert rel(wall["force"], hand["force"]) < 1e-9
    sec = gps_section.squeeze(1.3, [h], elements=64, penalty=1e5, walls=gps_section.square_channel)[0]
    for k in ["w", "lambda_s", "lambda_z", "area"]:
        assert rel(s[k], sec[k]) < 1e-4, (k, s[k], sec[k])
    for f in sec["forces"]:
        assert rel(s["walls"][0]["force"], f) < 5e-3


@pytest.mark.parametrize("h", [1.2, 1.0])
def test_v_groove(tubemem, h):
    c60, s60 = np.cos(np.pi / 3), np.sin(np.pi / 3)
    walls = lambda hh: [(0.0, -1.0, -hh), (-s60, c60, -2.6 * c60), (s60, c60, -2.6 * c60)]
    s = tubemem("gps", "confine", *ABB, "--initial-stretch", 1.3, *planes_args(walls(h)), "--json")
    hand = cf.gps_polygon(1.3, walls, [1.3, h])[1]
    for k in ["w", "lambda_s", "lambda_z", "area", "r"]:
        assert rel(s[k], hand[k]) < 1e-9, (k, s[k], hand[k])
    for wall, f in zip(s["walls"], hand["forces"]):
        assert rel(wall["force"], f) < 1e-9, (wall, f)
    ring = gps_ring.squeeze(1.3, walls, [h], elements=96, penalty=1e5, rigid=(0, 2))[0]
    for k in ["w", "lambda_s", "lambda_z", "area"]:
        assert rel(s[k], ring[k]) < 1e-4, (k, s[k], ring[k])
    for wall, f in zip(s["walls"], ring["forces"]):
        assert rel(wall["force"], f) < 5e-3, (wall, f)
