"""Synthetic test data for `tubemem fit`, made from a stated law (no published data is shipped).

The nominal stresses of an incompressible law of I1 alone, W(I1), along the three standard
tests (Treloar's; e.g. Ogden, Non-Linear Elastic Deformations, 1984, sec. 7.2), written here
independently of the Rust code:

    uniaxial      l1 = l, l2 = l3 = l^(-1/2):   P = 2 (l - l^-2) W'(I1),  I1 = l^2 + 2/l
    equibiaxial   l1 = l2 = l, l3 = l^-2:       P = 2 (l - l^-5) W'(I1),  I1 = 2 l^2 + l^-4
    pure shear    l1 = l, l2 = 1, l3 = 1/l:     P = 2 (l - l^-3) W'(I1),  I1 = l^2 + 1 + l^-2

Run `python -m tubemem_ref.synthetic OUT_DIR` to write the shipped example files again.
"""

import sys
from pathlib import Path

import numpy as np

# the stated law: Yeoh, a soft silicone-like set of constants (synthetic, in MPa)
YEOH = dict(c10=0.012, c20=-3e-4, c30=2e-5)
# the tests: stretch ranges and point counts; noise: 1 % of each test's largest stress
TESTS = {"uniaxial": (1.0, 5.0, 25), "equibiaxial": (1.0, 3.0, 15), "pure_shear": (1.0, 4.0, 20)}
NOISE = 0.01
SEED = 2026


def yeoh_w1(i1, c10, c20, c30):
    x = i1 - 3.0
    return c10 + 2 * c20 * x + 3 * c30 * x * x


def nominal_stress(mode, l, w1):
    if mode == "uniaxial":
        return 2 * (l - l**-2) * w1(l**2 + 2 / l)
    if mode == "equibiaxial":
        return 2 * (l - l**-5) * w1(2 * l**2 + l**-4)
    if mode == "pure_shear":
        return 2 * (l - l**-3) * w1(l**2 + 1 + l**-2)
    raise ValueError(mode)


def write(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(SEED)
    w1 = lambda i1: yeoh_w1(i1, **YEOH)
    for mode, (lo, hi, n) in TESTS.items():
        l = np.linspace(lo, hi, n)
        p = nominal_stress(mode, l, w1)
        p = p + NOISE * np.max(np.abs(p)) * rng.standard_normal(n)
        lines = [
            f"# SYNTHETIC data, not a measurement: {mode} test of the Yeoh law C10 = {YEOH['c10']} MPa,",
            f"# C20 = {YEOH['c20']} MPa, C30 = {YEOH['c30']} MPa, with Gaussian noise of {NOISE:.0%} of the",
            f"# test's largest stress (seed {SEED}); written by python -m tubemem_ref.synthetic.",
            "stretch,nominal_stress_mpa",
        ] + [f"{a:.6f},{b:.8e}" for a, b in zip(l, p)]
        (out / f"yeoh_synthetic_{mode}.csv").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    write(sys.argv[1] if len(sys.argv) > 1 else "examples/fit")
