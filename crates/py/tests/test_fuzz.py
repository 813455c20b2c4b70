"""Fuzz of the Python API (issue #61): random and hostile arguments to the closed form, the
material, the fit, case dicts and runs. The property: every call returns finite numbers, or
raises TubememError, ValueError or TypeError with a message that is not empty, holds no `nan`
unless the input did, and quotes at most a short excerpt of the input. Anything else (an
AttributeError, a SystemError, a panic, a crash of the interpreter, a hang) fails.

In the test command: 150 inputs from a fixed seed (a few seconds). The long run:
`TUBEMEM_PY_FUZZ_SECONDS=1800 TUBEMEM_PY_FUZZ_SEED=… .venv/bin/python -m pytest
crates/py/tests/test_fuzz.py -s` (prints how many inputs it ran, by kind and outcome).
"""

import math
import os
import random
import re
import time

import numpy as np

import tubemem

ALLOWED = (tubemem.TubememError, ValueError, TypeError)
# a message line longer than this quotes too much of its input (tubemem cuts echoed input to
# its first 800 and last 200 characters, MAX_MESSAGE_LINE = 1200 in crates/material)
LONGEST_LINE = 1260


def hostile_number(r):
    # half ordinary (so that calls reach the solvers), half hostile
    if r.random() < 0.5:
        return r.uniform(1.0, 2.0)
    return r.choice(
        [
            r.uniform(0.5, 3.0),
            r.uniform(1.0, 2.0),
            0,
            -1.5,
            1e-300,
            1e308,
            float("nan"),
            float("inf"),
            "1.3",
            True,
            None,
            np.int64(2),
            np.float32(1.2),
            1 + 2j,
            [1.2, 1.3],
            np.array([1.1, float("nan")]),
            np.array(["a"]),
            {},
        ]
    )


def energy(r, depth=0):
    leaves = ["(I1 - 3)", "(I2 - 3)", "I1", "0", "1e150", "1e-300", str(r.uniform(0.01, 5))]
    if depth > 3 or r.random() < 0.3:
        return r.choice(leaves)
    a, b = energy(r, depth + 1), energy(r, depth + 1)
    return r.choice(
        [
            f"({a} + {b})",
            f"({a} - {b})",
            f"{a} * {b}",
            f"{a} / {b}",
            f"{a}^{r.randint(0, 4)}",
            f"exp({a})",
            f"ln({a})",
            f"sqrt({a})",
            f"tanh({a})",
        ]
    )


def material(r):
    return r.choice(
        [
            None,
            None,
            {"model": "abb", "shear_modulus": 1.0, "kuhn": 30},
            {"model": "abb", "shear_modulus": 1.0, "kuhn": hostile_number(r)},
            {"model": "mooney-rivlin", "shear_modulus": 1.0, "alpha": hostile_number(r)},
            {"model": "neo-hookean", "shear_modulus": hostile_number(r)},
            {"model": "invariants", "shear_modulus": 1.0, "energy": energy(r)},
            {"model": "invariants", "shear_modulus": 1.0, "energy": "(I1 - 3) / 2 + 0.1 * (I1 - 3)^2"},
            {"model": "invariants", "shear_modulus": 1.0, "energy": "+".join(["(I1-3)"] * 30000)},
            {"model": "invariants", "shear_modulus": 1.0, "energy": "(" * 500 + "I1" + ")" * 500},
            {"model": "rubber"},
            {"model": "abb", "kuhn": 30, "shear_modulus": 1.0, "extra": 1},
            "neo-hookean",
            "yeoh",
            42,
        ]
    )


def fit_data(r):
    n = r.randint(0, 8)
    stretch = np.sort(np.array([r.uniform(1.0, 3.0) for _ in range(n)]))
    exact = 0.3e6 * (stretch - 1 / stretch**2)
    return r.choice(
        [
            np.column_stack([stretch, exact]) if n else np.zeros((0, 2)),
            (stretch, exact),
            (stretch, exact * (1 + 0j)),
            np.array([[1.1, 2.0], [1.2, 3.0]]),
            np.array([["1.1", "x"]]),
            np.column_stack([stretch, exact * float("nan")]) if n else None,
            [[1.0, 0.0], [1.5, 1e300], [2.0, 2e300]],
            "no-such-file.csv",
            hostile_number(r),
        ]
    )


def maybe(r, good, hostile):
    """`good` four times in five, else `hostile`."""
    return good if r.random() < 0.8 else hostile


def case_dict(r):
    d = {
        "geometry": {"radius": maybe(r, r.uniform(0.5, 2.0), hostile_number(r)), "length": 6.0},
        "material": maybe(r, {"model": "abb", "shear_modulus": 1.0, "kuhn": 30}, material(r))
        or {"model": "neo-hookean", "shear_modulus": 1.0},
        "mesh": {
            "around": maybe(r, 8, r.choice([16, 7, 0, np.int64(8), "8", 2**70])),
            "along": maybe(r, 4, r.choice([6, -1, 1.5])),
            "symmetry": maybe(r, "eighth", r.choice(["quarter", "sixteenth"])),
        },
        "stage": [
            {
                "kind": "inflate",
                "control": maybe(r, r.choice(["volume", "pressure"]), "nonsense"),
                "target_stretch": maybe(r, r.uniform(1.05, 1.5), hostile_number(r)),
                "target_pressure": maybe(r, r.uniform(0.1, 0.7), hostile_number(r)),
                "steps": maybe(r, r.choice([1, 2]), 0),
            }
        ],
        "output": {"vtu": "none"},
    }
    if r.random() < 0.3:
        d["stage"].append({"kind": "squeeze", "target_rho": maybe(r, 0.9, hostile_number(r))})
    if r.random() < 0.1:
        d["nonsense"] = {"x": 1}
    # drop one control's other target so that some dicts are valid
    st = d["stage"][0]
    st.pop("target_pressure" if st["control"] != "pressure" else "target_stretch")
    return d


def finite(v):
    if isinstance(v, dict):
        return all(finite(x) for x in v.values())
    if isinstance(v, (list, tuple)):
        return all(finite(x) for x in v)
    if isinstance(v, tubemem.Table):
        return all(finite(v[k]) for k in v)
    if isinstance(v, np.ndarray):
        return v.dtype.kind not in "fc" or bool(np.all(np.isfinite(v)))
    if isinstance(v, float):
        return math.isfinite(v)
    return True


def call(r, kind, tmp):
    """The arguments drawn for `kind`, and the call on them."""
    if kind == "inflate":
        a = (hostile_number(r), material(r), r.choice(["gps", "ps", "x"]))
        return a, lambda: tubemem.gps_inflate(*a)
    if kind == "flatten":
        a = (hostile_number(r), hostile_number(r), material(r))
        return a, lambda: tubemem.gps_flatten(*a)
    if kind == "curve":
        a = (hostile_number(r), r.choice([2, 5, 0, 10**9, "5"]), material(r))
        return a, lambda: tubemem.gps_inflation_curve(a[0], points=a[1], material=a[2])
    if kind == "material":
        a = (material(r) or {}, hostile_number(r), hostile_number(r))

        def f():
            m = tubemem.Material.from_dict(a[0])
            return [m.resultants(a[1], a[2]), m.to_dict()]

        return a, f
    if kind == "fit":
        a = (r.choice(["neo-hookean", "yeoh", "mooney-rivlin", material(r)]), fit_data(r))
        starts = r.choice([1, 2, 0, -1])
        return (a, starts), lambda: tubemem.fit(a[0], uniaxial=a[1], starts=starts)
    if kind == "run":
        d = case_dict(r)
        out = tmp / f"run{r.randint(0, 10**9)}"
        return d, lambda: tubemem.run(d, out).summary
    raise AssertionError(kind)


def check_message(e, shown):
    msg = str(e)
    assert msg.strip(), f"empty {type(e).__name__} for {shown}"
    # a NaN is a missing check upstream, unless it is the user's own value or the message
    # says that this value is what is wrong ("… is NaN, not a finite number")
    nan = re.compile(r"\bnan\b", re.IGNORECASE)
    explained = "not a finite number" in msg or "not finite" in msg
    assert not nan.search(msg) or nan.search(shown) or explained, f"NaN in `{msg}` for {shown}"
    longest = max(len(line) for line in msg.splitlines())
    assert longest <= LONGEST_LINE, f"a message line of {longest} characters for {shown[:300]}"


def test_no_python_input_crashes_or_returns_nonsense(tmp_path):
    seconds = float(os.environ.get("TUBEMEM_PY_FUZZ_SECONDS", "0"))
    cases = 150 if seconds == 0 else 10**9
    seed = int(os.environ.get("TUBEMEM_PY_FUZZ_SEED", "61"))
    r = random.Random(seed)
    kinds = ["inflate", "flatten", "curve", "material", "fit", "run"]
    counts = {k: [0, 0] for k in kinds}  # accepted, refused
    t0 = time.monotonic()
    ran = 0
    while ran < cases and (seconds == 0 or time.monotonic() - t0 < seconds):
        kind = r.choice(kinds)
        ran += 1
        args, f = call(r, kind, tmp_path)
        shown = f"{kind} input {ran} (seed {seed}): {args!r}"
        started = time.monotonic()
        try:
            v = f()
        except ALLOWED as e:
            check_message(e, shown)
            counts[kind][1] += 1
        else:
            assert finite(v), f"{shown} returned a non-finite value: {v}"
            counts[kind][0] += 1
        # a run of a small case, or a closed-form call, takes well under 10 s (issue #25's limit)
        assert time.monotonic() - started < 10.0, f"{kind} input {ran} took over 10 s"
    total = sum(a + b for a, b in counts.values())
    print(
        f"python fuzz: {total} inputs in {time.monotonic() - t0:.1f} s: "
        + ", ".join(f"{k} {a} accepted / {b} refused" for k, (a, b) in counts.items())
    )
    assert total == ran
