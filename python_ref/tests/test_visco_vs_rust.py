"""`tubemem gps history` (the recursive QLV update with step doubling to an error estimate
of 1e-10) against the independent DAE integration of tubemem_ref.visco (scipy DOP853 in the
relaxed stresses, rtol 1e-12). Bound 1e-8 relative, the issue's: the Rust side's own error is
at most 1e-10 by its estimate, the scipy side's changes by less than 1e-9 from rtol 1e-10 to
1e-12 (test_reference_is_converged); measured at most 3.9e-10 over the three histories."""

import csv

import pytest

from tubemem_ref import visco

ABB = ("--material", "abb", "--kuhn", "30")
PRONY = [(0.3, 1.0), (0.2, 10.0)]


def rel(a, b):
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def rust_rows(tubemem_exe, tmp_path, args):
    import subprocess

    path = tmp_path / "h.csv"
    out = subprocess.run([tubemem_exe, "gps", "history", *map(str, args), "--csv", str(path)],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    with open(path) as f:
        return {float(r["time"]): r for r in csv.DictReader(f)}


CASES = [
    # (law flags, law tuple, hypothesis, control, to, ramp, hold, times); the times are on
    # every step grid of 8 or more steps per segment (ramp or hold × k/8)
    (ABB, ("abb", 30.0), "gps", "pressure", 0.3, 1.0, 20.0, [0.5, 1.0, 3.5, 6.0, 21.0]),
    (("--material", "neo-hookean"), ("mooney-rivlin", 0.0), "ps", "pressure", 0.25, 2.0, 30.0,
     [2.0, 5.75, 17.0, 32.0]),
    (ABB, ("abb", 30.0), "gps", "volume", 1.3**2 * 1.05, 2.0, 30.0, [1.0, 2.0, 9.5, 32.0]),
]


@pytest.mark.parametrize("flags,law,hyp,control,to,ramp,hold,times", CASES)
def test_history_matches_the_independent_dae(tubemem_exe, tmp_path, flags, law, hyp, control,
                                             to, ramp, hold, times):
    rows = rust_rows(tubemem_exe, tmp_path, [
        *flags, "--hypothesis", hyp, "--prony", "0.3:1,0.2:10", "--control", control,
        "--to", to, "--ramp", ramp, "--hold", hold])
    ref = visco.history(law, PRONY, hyp, control, to, ramp, hold, times)
    for t, w, ls, lz in ref:
        # the step ends t0 + i·Δt: the one at t to rounding (a time on the step grid)
        near = min(rows, key=lambda k: abs(k - t))
        assert abs(near - t) < 1e-12 * max(1.0, t), (t, near)
        r = rows[near]
        for key, v in [("w", w), ("lambda_s", ls), ("lambda_z", lz)]:
            assert rel(float(r[key]), v) < 1e-8, (t, key, float(r[key]), v)


def test_reference_is_converged():
    """The scipy side at rtol 1e-12 and 1e-10 differs by far less than the 1e-8 bound."""
    a = visco.history(("abb", 30.0), PRONY, "gps", "pressure", 0.3, 1.0, 20.0, [21.0])
    b = visco.history(("abb", 30.0), PRONY, "gps", "pressure", 0.3, 1.0, 20.0, [21.0],
                      rtol=1e-10, atol=1e-12)
    assert all(rel(x, y) < 1e-9 for x, y in zip(a[0][1:], b[0][1:]))


CYCLES = [
    # inflated by a jump to lambda_s = 1.3, held 200 (20 tau_2); plates from first contact to
    # rho = 1.0 in 3, held 5, released to first contact in 3 (times on the step grid)
    ("gas", "gps"), ("pressure", "gps"), ("gas", "ps"),
]


@pytest.mark.parametrize("supply,hyp", CYCLES)
def test_squeeze_hold_release_matches_the_independent_dae(tubemem_exe, tmp_path, supply, hyp):
    """States to 1e-8 as the free histories (measured at most 1.1e-10); the loop's area to 1e-6
    relative: Rust's error estimate bounds its error by 1e-10 absolute, 1.7e-7 of the
    smallest area here (6.1e-4); measured 1.8e-8 to 7.0e-8."""
    import subprocess

    path = tmp_path / "c.csv"
    out = subprocess.run([
        tubemem_exe, "gps", "history", *ABB, "--hypothesis", hyp, "--prony", "0.3:1,0.2:10",
        "--control", "stretch", "--to", "1.3", "--hold", "200", "--plates-to", "1.0",
        "--squeeze-time", "3", "--plates-hold", "5", "--release", "--supply", supply,
        "--csv", str(path), "--json"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    import json
    summary = json.loads(out.stdout)
    with open(path) as f:
        rows = {float(r["time"]): r for r in csv.DictReader(f)}
    times = [201.125, 203.0, 205.5, 209.5]
    ref, work = visco.program(("abb", 30.0), PRONY, hyp, [
        ("stretch", 1.3, 0.0), ("stretch", None, 200.0), (f"plates-{supply}", 1.0, 3.0),
        (f"plates-{supply}", None, 5.0), (f"plates-{supply}", 1.3, 3.0)], times)
    assert len(ref) == len(times)
    for t, w, ls, lz, rho, force in ref:
        near = min(rows, key=lambda k: abs(k - t))
        assert abs(near - t) < 1e-12 * t, (t, near)
        r = rows[near]
        assert rel(float(r["rho"]), rho) < 1e-12
        for key, v in [("w", w), ("lambda_s", ls), ("lambda_z", lz), ("force", force)]:
            assert rel(float(r[key]), v) < 1e-8, (t, key, float(r[key]), v)
    # the force-gap loop: Rust's trapezoids over its steps against quad on the dense solution
    assert summary["loop_area"] > 0 and rel(summary["loop_area"], work) < 1e-6, (summary["loop_area"], work)
