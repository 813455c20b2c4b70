"""Tests of the Python API (`import tubemem`, the PyO3 bindings in crates/py).

The closed-form values are checked against the independent scipy implementation in
python_ref (tubemem_ref.closed_form: the paper's formulas written out again and solved with
brentq / hybrd, not with the Rust Newton). Tolerance 1e-9 relative: both sides converge to
~1e-13, and 1e-9 is the bound the python_ref tests already hold the `tubemem` binary to.
"""

import csv
import math
import pathlib
import sys

import numpy as np
import pytest
from scipy import optimize

import tubemem
from tubemem_ref import closed_form as cf

ABB30 = {"model": "abb", "shear_modulus": 1.0, "kuhn": 30}
TOL = 1e-9

# the small tube shared with the python_ref tests (L/R = 8, 16 around, lambda_s* = 1.2), squeezed
# to rho = 1.0
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[3] / "python_ref" / "tests"))
from cases import SMALL, SQUEEZE  # noqa: E402

SMALL_CASE = SMALL + SQUEEZE
ROOT = pathlib.Path(__file__).resolve().parents[3]


def rel(a, b):
    return abs(a - b) / abs(b)


def test_module_docstring_and_stub():
    assert "ValueError" in tubemem.__doc__ and "TubememError" in tubemem.__doc__
    stub = pathlib.Path(__file__).resolve().parents[1] / "tubemem.pyi"
    text = stub.read_text()
    for name in ["gps_inflate", "gps_flatten", "run", "Run", "run_case", "TubememError"]:
        assert f" {name}" in text and hasattr(tubemem, name)


def test_module_metadata():
    assert tubemem.__version__
    assert issubclass(tubemem.TubememError, RuntimeError)
    assert "[[stage]]" in tubemem.default_case()


@pytest.mark.parametrize("ls", [1.1, 1.3, 2.0, 6.0])
def test_gps_inflation_matches_the_scipy_closed_form(ls):
    s = tubemem.gps_inflate(ls)
    w, lz = cf.gps_inflation(ls, 30.0)
    assert rel(s["w"], w) < TOL and rel(s["lambda_z"], lz) < TOL
    # the default material is the paper's ABB, N = 30
    assert s == tubemem.gps_inflate(ls, material=ABB30, hypothesis="GPS")
    p = tubemem.gps_inflate(ls, hypothesis="ps")
    assert p["lambda_z"] == 1.0 and rel(p["w"], cf.ps_inflation(ls, 30.0)) < TOL


def test_limit_points_match_the_scipy_closed_form():
    # the bounds of python_ref/tests/test_closed_form_vs_rust.py: limit points located to 1e-8 in
    # lambda_s by both sides, w at a stationary point to 1e-12; the Maxwell pressure inherits
    # ~1e-11 from quad's error estimate, held to 1e-9
    lim = tubemem.gps_limits()
    (lsmax, wmax), (lsmin, wmin) = cf.gps_limit_points(30.0)
    assert abs(lim["max"]["lambda_s"] - lsmax) < 1e-8 and rel(lim["max"]["w"], wmax) < 1e-12
    assert abs(lim["min"]["lambda_s"] - lsmin) < 1e-8 and rel(lim["min"]["w"], wmin) < 1e-12
    assert rel(lim["maxwell"]["w"], cf.gps_maxwell(30.0)[0]) < 1e-9
    assert tubemem.gps_limits(hypothesis="ps")["max"] is None


def test_flattening_matches_the_scipy_closed_form_and_the_local_section():
    ref = cf.gps_flattening(1.3, [1.0, 0.8], 30.0)
    curve = tubemem.gps_flattening_curve(1.3, 0.8, points=3)
    assert [round(r, 12) for r in curve["rho"]] == [1.3, 1.05, 0.8]
    for rho, r in zip([1.0, 0.8], ref):
        s = tubemem.gps_flatten(1.3, rho)
        for k in ["w", "lambda_s", "lambda_z", "chi", "force"]:
            assert rel(s[k], r[k]) < TOL, (rho, k)
        assert s["displacement"] == pytest.approx(1.3 - rho, abs=1e-14)
        # the section under the Boyle pressure is the same state (eq. 76 without 77's gas law)
        loc = tubemem.gps_section_at_pressure(rho, s["w"], (s["lambda_s"], s["lambda_z"]))
        assert rel(loc["chi"], s["chi"]) < TOL
    # PS is stiffer than GPS in the squeeze (paper Figs. 6-7)
    assert tubemem.gps_flatten(1.3, 0.8, hypothesis="ps")["force"] > curve["force"][-1]


def _between(ls, rho, law):
    """The section between plates at rho with hoop stretch ls (eqs. 76 with the pressure
    eliminated): N_z = (1 - rho/(2 ls)) N_s solved for lz by brentq; (w, lz)."""
    q = 1.0 - rho / (2.0 * ls)
    g = lambda lz: (lambda r: r[1] - q * r[0])(cf.resultants(ls, lz, law))
    lz = optimize.brentq(g, 0.5, 3.0, xtol=1e-15)
    return cf.resultants(ls, lz, law)[0] / rho, lz


def test_the_regulated_squeeze_and_the_critical_pressure_match_scipy():
    # issue #62: the pressure held at the inflated value, the section at rho = 0.8 found by
    # brentq on the explicit states (python_ref's resultants), not by the Rust Newton
    abb = ("abb", 30.0)
    w0 = cf.gps_inflation(1.3, 30.0)[0]
    s = tubemem.gps_flatten(1.3, 0.8, control="pressure")
    ls = optimize.brentq(lambda x: _between(x, 0.8, abb)[0] - w0, 1.0 + 1e-12, 3.0, xtol=1e-15)
    assert rel(s["w"], w0) < TOL
    assert rel(s["lambda_s"], ls) < TOL and rel(s["lambda_z"], _between(ls, 0.8, abb)[1]) < TOL
    assert rel(s["force"], w0 * (ls - 0.8)) < TOL
    # arrays of rho, and the closed gas refuses a pressure
    t = tubemem.gps_flatten(1.3, np.array([1.0, 0.8]), control="pressure")
    assert rel(t["lambda_s"][1], ls) < TOL
    # the gripper's stiffness -d(force)/d(2 rho) at the held pressure: a central difference of
    # the explicit force at rho +- 1e-4 (truncation ~1e-8 relative, the roots to 1e-15); bound 1e-7
    d = 1e-4
    f = lambda r: w0 * (optimize.brentq(lambda x: _between(x, r, abb)[0] - w0, 1.0 + 1e-12, 3.0, xtol=1e-15) - r)
    fd = -(f(0.8 + d) - f(0.8 - d)) / (4.0 * d)
    assert rel(s["stiffness"], fd) < 1e-7
    assert rel(t["stiffness"][1], s["stiffness"]) < TOL
    assert "stiffness" not in tubemem.gps_flatten(1.3, 0.8)  # closed gas: not this quantity
    with pytest.raises(ValueError, match="control"):
        tubemem.gps_flatten(1.3, 0.8, pressure=0.5)
    # neo-Hookean between fixed plates at rho = 0.8: the first maximum of w along the states,
    # by scipy's bounded minimization (xatol 1e-10: w is flat there, its value to ~1e-16)
    nh = {"model": "neo-hookean", "shear_modulus": 1.0}
    nh_law = ("mooney-rivlin", 0.0)
    m = optimize.minimize_scalar(
        lambda x: -_between(x, 0.8, nh_law)[0], bounds=(1.5, 3.0), method="bounded",
        options={"xatol": 1e-10},
    )
    c = tubemem.gps_critical_pressure(0.8, material=nh)
    assert rel(c["w"], -m.fun) < 1e-10
    # w is flat at its maximum: a rounding of 1e-16 in w moves the located maximum by about
    # sqrt(2e-16 w/|w''|) ~ 1e-8 (measured 2.4e-8); bound 1e-6
    assert abs(c["lambda_s"] - m.x) < 1e-6
    assert tubemem.gps_critical_pressure(0.8) is None  # ABB 30 locks first
    b = tubemem.gps_between_plates(0.8, 1.2, material=nh)
    ls_b = optimize.brentq(lambda x: _between(x, 0.8, nh_law)[0] - 1.2, 1.0 + 1e-9, m.x, xtol=1e-15)
    assert rel(b["lambda_s"], ls_b) < TOL
    with pytest.raises(ValueError, match="snaps"):
        tubemem.gps_between_plates(0.8, 1.5, material=nh)


def test_resultants_are_eq_58_and_take_any_material():
    # eq. (58) evaluated by two codes: agreement to rounding of a few operations, 1e-12
    n1, n2 = tubemem.resultants(1.3, 1.05)
    ns, nz = cf.abb_resultants(1.3, 1.05, 30.0)
    assert rel(n1, ns) < 1e-12 and rel(n2, nz) < 1e-12
    mr = {"model": "mooney-rivlin", "shear_modulus": 1.0, "alpha": 0.1}
    m1, m2 = tubemem.resultants(1.3, 1.05, material=mr)
    r1, r2 = cf.mr_resultants(1.3, 1.05, 0.1)
    # eqs. (86)-(87) are scaled by mu while eq. (83) as printed gives mu0 = mu (1 + alpha)
    # (README, "Mooney-Rivlin"): the ratio is scale-free
    assert rel(m1 / m2, r1 / r2) < 1e-12
    assert tubemem.gps_inflate(1.3, material=mr)["lambda_z"] == pytest.approx(
        cf.gps_inflation_mr(1.3, 0.1)[1], rel=TOL
    )


@pytest.mark.parametrize(
    "call, needle",
    [
        (lambda: tubemem.gps_inflate(0.5), "lambda_s"),
        (lambda: tubemem.gps_inflate(math.nan), "lambda_s"),
        (lambda: tubemem.gps_inflate(1.3, hypothesis="3d"), "hypothesis"),
        (lambda: tubemem.gps_flatten(1.3, 1.5), "rho"),
        (lambda: tubemem.gps_inflate(1.3, material={"model": "abb", "shear_modulus": 1.0, "kuhn": 0.5}), "kuhn"),
        (lambda: tubemem.gps_inflate(1.3, material={"model": "abb", "kuhn": 30}), "shear_modulus"),
        (lambda: tubemem.gps_inflate(1.3, material={"model": "rubber"}), "rubber"),
        (lambda: tubemem.resultants(9.0, 9.0), "locking"),  # I1 = 162 > 3N = 90
        (lambda: tubemem.gps_inflate(9.0), "locking"),  # beyond locking on the GPS path
        (lambda: tubemem.gps_flattening_curve(1.3, 0.8, points=1), "points"),
        # resource caps, checked before anything is allocated (no PanicException, no abort)
        (lambda: tubemem.gps_inflation_curve(2.0, points=2**62), "at most 10,000,000 points"),
        (lambda: tubemem.gps_inflation_curve(2.0, points=10**9), "at most 10,000,000 points"),
        (lambda: tubemem.gps_flattening_curve(1.3, 0.8, points=10**9), "at most 10,000,000 points"),
        # a NaN in a material dict is named as such, not as a JSON column
        (lambda: tubemem.gps_inflate(1.3, material={"model": "abb", "shear_modulus": 1.0, "kuhn": math.nan}), "not a finite number"),
        # complex values are refused, not truncated to their real parts (issue #25, class 5)
        (lambda: tubemem.gps_inflate(np.array([1.3 + 0.1j])), "complex"),
        (lambda: tubemem.gps_inflate(1.3 + 0j), "complex"),
        # arrays are capped like curves (issue #25, class 2)
        (lambda: tubemem.gps_inflate(np.full(10_000_001, 1.3)), "at most 10,000,000"),
        # a negative or huge point count is a ValueError naming it, not an OverflowError
        # (issue #25, class 6)
        (lambda: tubemem.gps_inflation_curve(1.5, points=-1), "points = -1: a curve needs at least 2"),
        (lambda: tubemem.gps_flattening_curve(1.3, 0.8, points=2**70), "at most 10,000,000 points"),
    ],
)
def test_bad_input_raises_value_error_naming_it(call, needle):
    with pytest.raises(ValueError, match=needle):
        call()


def test_run_case_text_writes_the_outputs_and_returns_the_summary(tmp_path):
    out = tmp_path / "run"
    s = tubemem.run_case_text(SMALL_CASE, str(out))
    assert [st["kind"] for st in s["stages"]] == ["inflate", "squeeze"]
    sq = s["stages"][1]
    assert sq["final"]["rho"] == 1.0
    # the summary returned is the one on disk, and its last row is the last steps.csv row
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert float(rows[-1]["force"]) == sq["final"]["force"]
    assert float(rows[-1]["gps_force"]) == sq["gps"]["force"]
    # the closed form in the summary is the API's closed form
    g = tubemem.gps_flatten(sq["final"]["initial_stretch"], 1.0)
    assert rel(sq["gps"]["force"], g["force"]) < 1e-12
    assert (out / "tube.pvd").exists()


def test_run_case_reads_a_file(tmp_path):
    case = tmp_path / "case.toml"
    case.write_text(SMALL)
    s = tubemem.run_case(str(case), str(tmp_path / "out"))
    assert s["case"] == str(case) and len(s["stages"]) == 1


def test_a_malformed_case_names_the_key(tmp_path):
    with pytest.raises(ValueError, match="kuhm"):
        tubemem.run_case_text(SMALL_CASE.replace("kuhn = 30", "kuhn = 30\nkuhm = 2"), str(tmp_path))


@pytest.mark.parametrize(
    "old, new, needle",
    [
        ("around = 16", "around = 60", "around"),  # not a multiple of 8: found when meshing
        ("kuhn = 30", "kuhn = 0.5", "kuhn"),
        ("target_rho = 1.0", "target_rho = 5.0", "target_rho"),  # above the tube: found at the stage
    ],
)
def test_the_exception_policy_bad_input_is_value_error_wherever_it_is_found(tmp_path, old, new, needle):
    with pytest.raises(ValueError, match=needle):
        tubemem.run_case_text(SMALL_CASE.replace(old, new), str(tmp_path / "o"))


def test_a_failing_run_raises_and_keeps_its_converged_steps(tmp_path):
    # N = 3 locks near lambda_s = 2.4 on the GPS path; the case asks for 3.0
    text = SMALL_CASE.replace("kuhn = 30", "kuhn = 3").replace("target_stretch = 1.2", "target_stretch = 3.0")
    out = tmp_path / "out"
    with pytest.raises(tubemem.TubememError, match="stage 1") as e:
        tubemem.run_case_text(text, str(out))
    assert "residual" in str(e.value) and "converged steps are in" in str(e.value)
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert len(rows) >= 2 and all(math.isfinite(float(r["w"])) for r in rows)


def test_progress_goes_to_a_callback_or_stays_silent(tmp_path, capfd):
    seen = []
    s = tubemem.run_case_text(SMALL, str(tmp_path / "cb"), progress=seen.append)
    assert [d["step"] for d in seen] == list(range(1, len(seen) + 1))
    assert seen[-1]["fraction"] == 1.0 and seen[-1]["lambda_s"] == s["stages"][0]["final"]["lambda_s"]
    # without a callback nothing is printed (the `tubemem` logger gets DEBUG records)
    tubemem.run_case_text(SMALL, str(tmp_path / "quiet"))
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_a_callback_that_raises_stops_the_run_and_is_raised(tmp_path):
    def stop(d):
        if d["step"] == 2:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        tubemem.run_case_text(SMALL.replace("steps = 4", "steps = 40"), str(tmp_path / "o"), progress=stop)
    rows = list(csv.DictReader(open(tmp_path / "o" / "steps.csv")))
    assert 2 <= len(rows) < 40
    assert '"interrupted"' in (tmp_path / "o" / "run.json").read_text()


def test_ctrl_c_interrupts_a_run_within_seconds_and_keeps_its_steps(tmp_path):
    """A Python process running a long case is sent SIGINT after its first steps: it raises
    KeyboardInterrupt within seconds (the run stops at its next Newton iteration), and every
    converged step is on disk with the run marked interrupted."""
    import os
    import signal
    import subprocess
    import time

    out = tmp_path / "run"
    # a finer mesh than SMALL's, so that the run is surely still going when the signal comes
    # (SMALL runs its 18 steps in 0.02 s; at 64 × 192 they take 0.68 s, `tubemem run`,
    # 2026-11-30)
    case = (
        SMALL.replace("steps = 4", "steps = 2000")
        .replace("around = 16", "around = 64")
        .replace("along = 24", "along = 192")
    )
    assert "around = 64" in case and "along = 192" in case
    # the child gets Python's own Ctrl-C handler, as an interactive session has: a process
    # started in the background (`cmd &` without job control, as a CI runner may do) inherits
    # SIGINT ignored, and Python then installs no KeyboardInterrupt handler at all (this test
    # failed so in two fresh-clone runs launched that way, 2026-11-30)
    script = (
        "import signal\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "import tubemem, sys\n"
        "try:\n"
        f"    tubemem.run_case_text({case!r}, {str(out)!r})\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
        "    sys.exit(3)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    t0 = time.time()
    while time.time() - t0 < 60:
        if (out / "steps.csv").exists() and len((out / "steps.csv").read_text().splitlines()) >= 4:
            break
        time.sleep(0.01)
    t1 = time.time()
    p.send_signal(signal.SIGINT)
    stdout, _ = p.communicate(timeout=30)
    assert p.returncode == 3 and "interrupted" in stdout
    assert time.time() - t1 < 5, "the prompt comes back within seconds"
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert len(rows) >= 3 and all(math.isfinite(float(r["w"])) for r in rows)
    assert '"interrupted"' in (out / "run.json").read_text()


def test_ctrl_c_interrupts_verify_within_a_second_and_keeps_its_report(tmp_path):
    """Issue #61: `tubemem.verify` had ignored Ctrl-C until every check had run, then lost the
    result. A process verifying a suite of long checks is sent SIGINT once the first check is
    running: it raises KeyboardInterrupt within a second (the checks stop at their next Newton
    iteration; the wait is polled every 50 ms), and results.json is written."""
    import os
    import signal
    import subprocess
    import time

    case = (
        SMALL.replace("steps = 4", "steps = 2000")
        .replace("around = 16", "around = 64")
        .replace("along = 24", "along = 192")
    )
    (tmp_path / "case.toml").write_text(case)
    suite = tmp_path / "suite.toml"
    suite.write_text(
        "".join(
            f'[[check]]\nname = "c{i}"\ncase = "case.toml"\nkind = "closed-form"\n'
            'tolerance.w = { value = 1.0, source = "test" }\n\n'
            for i in range(3)
        )
    )
    out = tmp_path / "v"
    script = (
        "import signal\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "import tubemem, sys\n"
        "try:\n"
        f"    tubemem.verify([{str(suite)!r}], out={str(out)!r}, jobs=1)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
        "    sys.exit(3)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    t0 = time.time()
    # the first check's run writes its steps: it is running
    while time.time() - t0 < 60 and not (out / "c0" / "run" / "steps.csv").exists():
        time.sleep(0.01)
    assert (out / "c0" / "run" / "steps.csv").exists()
    t1 = time.time()
    p.send_signal(signal.SIGINT)
    stdout, _ = p.communicate(timeout=30)
    elapsed = time.time() - t1
    assert p.returncode == 3 and "interrupted" in stdout, stdout
    assert elapsed < 1.0, f"{elapsed:.2f} s from Ctrl-C to the prompt"
    assert (out / "results.json").exists()


def test_the_closed_form_takes_arrays_and_agrees_with_the_scalar_calls():
    import numpy as np

    ls = np.array([[1.05, 1.3], [2.0, 4.0]])
    v = tubemem.gps_inflate(ls)
    assert set(v) == {"w", "lambda_s", "lambda_z", "n_s", "n_z"}
    for idx in np.ndindex(ls.shape):
        s = tubemem.gps_inflate(float(ls[idx]))
        for k in v:
            assert v[k].shape == ls.shape and v[k][idx] == s[k], (k, idx)
    rho = np.linspace(1.25, 0.8, 5)
    f = tubemem.gps_flatten(1.3, rho, hypothesis="ps")
    for i, r in enumerate(rho):
        s = tubemem.gps_flatten(1.3, float(r), hypothesis="ps")
        assert all(f[k][i] == s[k] for k in s)
    assert isinstance(v, tubemem.Table) and len(v) == 4 and "w" in v
    df = f.to_pandas()
    assert list(df.columns) == list(f) and len(df) == len(rho)
    np.testing.assert_array_equal(df["force"].to_numpy(), f["force"])
    with pytest.raises(KeyError, match="the columns are w, lambda_s"):
        v["pressure"]
    with pytest.raises(ValueError, match=r"stretch\[1\] = 0.5"):
        tubemem.gps_inflate(np.array([1.2, 0.5]))
    # a string is the wrong type (issue #61: "1.3" had been taken as 1.3)
    with pytest.raises(TypeError, match="a number or an array"):
        tubemem.gps_inflate("abc")


def test_run_returns_arrays_equal_to_steps_csv_and_takes_cases_as_dicts(tmp_path):
    import tomllib

    import numpy as np

    # a case as a dict of its tables equals the same case as TOML
    as_dict = tomllib.loads(SMALL_CASE)
    a = tubemem.run(as_dict, str(tmp_path / "dict"))
    b = tubemem.run(SMALL_CASE, str(tmp_path / "text"))
    for k in a.steps:
        np.testing.assert_array_equal(a.steps[k], b.steps[k])
    # the arrays are steps.csv, column by column (empty fields are NaN)
    rows = list(csv.DictReader(open(tmp_path / "dict" / "steps.csv")))
    assert len(rows) == len(a.steps["step"])
    for k in rows[0]:
        csv_col = np.array([float(r[k]) if r[k] else np.nan for r in rows])
        np.testing.assert_array_equal(a.steps[k], csv_col)
    assert a.summary["case"] == "case dict from Python" and b.summary["case"] == "case text from Python"
    # the same run but for its label and the hash of its text (the dict becomes its own TOML)
    assert {**a.summary, "case": "", "case_hash": ""} == {**b.summary, "case": "", "case_hash": ""}
    assert a.summary["stages"][1]["kind"] == "squeeze"
    assert a.vtu(0).name == "step_00000.vtu" and a.vtu(len(rows)).exists()
    with pytest.raises(ValueError, match="frame"):
        a.vtu(len(rows) + 1)
    assert "steps" in repr(a)
    df = a.to_pandas()
    assert list(df.columns) == list(a.steps) and len(df) == len(rows)
    np.testing.assert_array_equal(df["lambda_s"].to_numpy(), a.steps["lambda_s"])
    # the profiles: long form, every step's rings, equal to profiles/profiles.csv
    prof = list(csv.DictReader(open(tmp_path / "dict" / "profiles" / "profiles.csv")))
    assert list(a.profiles) == list(prof[0]) and len(a.profiles) == len(prof)
    for k in prof[0]:
        np.testing.assert_array_equal(a.profiles[k], np.array([float(r[k]) for r in prof]))
    pdf = a.profiles.to_pandas()
    assert set(pdf["row"]) == set(range(1, len(rows) + 1))
    # the mid-span ring of every step is that step's mid-span state; squeezed, it touches
    mid = pdf[pdf["z_ref"] == 0.0].set_index("row")
    np.testing.assert_array_equal(mid["lambda_s"].to_numpy(), a.steps["lambda_s"])
    sq = a.steps["rho"] == a.steps["rho"]  # squeeze rows (rho is NaN for inflation)
    np.testing.assert_array_equal(mid["contact_width"].to_numpy()[sq], a.steps["chi_geometric"][sq])
    np.testing.assert_array_equal(mid["contact_force"].to_numpy()[sq], a.steps["force"][sq])
    assert (mid["contact_width"].to_numpy()[sq] > 0).all() and (mid["contact_width"].to_numpy()[~sq] == 0).all()
    # a bad dict names its key
    bad = dict(as_dict, material={"model": "abb", "shear_modulus": 1.0, "kuhm": 3})
    with pytest.raises(ValueError, match="kuhm"):
        tubemem.run(bad, str(tmp_path / "bad"))


def test_cases_as_data_equal_the_toml(tmp_path):
    import tomllib

    tables = tomllib.loads(SMALL_CASE)
    a = tubemem.Case(**tables)
    b = tubemem.Case.from_dict(tables)
    c = tubemem.Case.from_toml(SMALL_CASE)
    assert a == b and a.to_dict() == tables and c.to_dict() == tables
    # a Case round-trips through its TOML, and runs like the TOML it came from
    assert tubemem.Case.from_toml(a.to_toml()) == a
    ra = tubemem.run(a, str(tmp_path / "a"))
    rc = tubemem.run(c, str(tmp_path / "c"))
    assert ra.summary["stages"][-1]["final"] == rc.summary["stages"][-1]["final"]
    # validation on construction, naming the table and key
    with pytest.raises(ValueError, match="length"):
        tubemem.Case(**dict(tables, geometry=dict(tables["geometry"], length=-1.0)))
    with pytest.raises(ValueError, match="kuhm"):
        tubemem.Case.from_dict(dict(tables, material={"model": "abb", "shear_modulus": 1.0, "kuhm": 3}))
    # a four-point L/R sweep is a loop over dicts
    lengths = [4.0, 6.0]
    cases = [tubemem.Case(**dict(tables, geometry={"radius": 1.0, "length": L})) for L in lengths]
    assert [tubemem.Case.to_dict(k)["geometry"]["length"] for k in cases] == lengths


def _sweep_cases():
    import tomllib

    tables = tomllib.loads(SMALL_CASE)
    lengths = [4.0, 6.0, 8.0]
    cases = [tubemem.Case(**dict(tables, geometry={"radius": 1.0, "length": L})) for L in lengths]
    # a member that fails (beyond the locking limit of N = 3) must not lose the others
    bad = dict(tables, material={"model": "abb", "shear_modulus": 1.0, "kuhn": 3})
    bad["stage"] = [dict(tables["stage"][0], target_stretch=3.0)]
    return cases + [tubemem.Case(**bad)], [{"L/R": L} for L in lengths] + [{"L/R": 8.0}]


def test_sweep_runs_in_local_processes_and_keeps_finished_runs(tmp_path):
    cases, params = _sweep_cases()
    df = tubemem.sweep(cases, str(tmp_path), params=params, workers=2)
    assert set(df["case"]) == {0, 1, 2, 3}
    ok = df[df["error"].isna()]
    assert set(ok["case"]) == {0, 1, 2}
    # one row per case and step, the last row of each case its final state (summary.json)
    for i in range(3):
        last = ok[ok["case"] == i].iloc[-1]
        import json

        summary = json.loads((tmp_path / f"case_{i:03d}" / "summary.json").read_text())
        assert last["w"] == summary["stages"][-1]["final"]["w"]
        assert last["L/R"] == [4.0, 6.0, 8.0][i] == summary["geometry"]["length"]
    failed = df[df["case"] == 3]
    assert len(failed) == 1 and "locking" in failed["error"].iloc[0]


def test_sweep_runs_from_a_plain_script_without_a_main_guard(tmp_path):
    # issue #24 item 1: called at module level, the sweep had spawned worker processes that
    # re-imported the script and died with BrokenProcessPool; it now runs on threads of this
    # process, and its progress callback sees every member once
    import subprocess
    import sys
    import textwrap

    script = tmp_path / "plain.py"
    script.write_text(textwrap.dedent(f"""
        import tomllib, tubemem
        tables = tomllib.loads({SMALL_CASE!r})
        cases = [tubemem.Case(**dict(tables, geometry={{"radius": 1.0, "length": L}})) for L in (4.0, 6.0)]
        seen = []
        df = tubemem.sweep(cases, {str(tmp_path / "out")!r}, workers=2, progress=seen.append)
        assert sorted(d["case"] for d in seen) == [0, 1], seen
        assert [d["done"] for d in seen] == [1, 2] and all(d["total"] == 2 for d in seen)
        assert df["error"].isna().all(), df["error"]
        print("rows", len(df))
    """))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "BrokenProcessPool" not in done.stderr
    assert done.stdout.startswith("rows ")


def test_sweep_arguments_are_checked_before_anything_runs(tmp_path):
    cases, params = _sweep_cases()
    with pytest.raises(ValueError, match=r"params has 1 entries for 4 cases"):
        tubemem.sweep(cases, str(tmp_path / "a"), params=params[:1])
    with pytest.raises(ValueError, match=r"workers=1 and processes=2"):
        tubemem.sweep(cases, str(tmp_path / "b"), workers=1, processes=2)
    with pytest.raises(ValueError, match=r"progress"):
        tubemem.sweep(cases, str(tmp_path / "c"), progress="bar")
    with pytest.raises(ValueError, match=r"cases\[1\]"):
        tubemem.sweep([cases[0], {"geometry": {"radius": -1.0}}], str(tmp_path / "d"))
    assert not any((tmp_path / d).exists() for d in "abcd")


def test_sweep_on_a_dask_local_cluster_equals_the_local_one(tmp_path):
    import dask.distributed as distributed  # in the test requirements: a missing one fails
    cases, params = _sweep_cases()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        df = tubemem.sweep(cases, str(tmp_path / "dask"), params=params, client=client)
    local = tubemem.sweep(cases, str(tmp_path / "local"), params=params, processes=2)
    cols = [c for c in local.columns if c not in ("error",)]
    assert df[cols].equals(local[cols])
    assert (df["error"].isna() == local["error"].isna()).all()


def test_curves_are_tables_of_arrays():
    import numpy as np

    c = tubemem.gps_inflation_curve(2.0, points=11)
    assert c.columns == ["w", "lambda_s", "lambda_z", "n_s", "n_z"] and len(c) == 11
    np.testing.assert_allclose(c["lambda_s"], np.linspace(1.0, 2.0, 11), rtol=0, atol=1e-15)
    # each row is the scalar closed form at that stretch (the curve continues from the previous
    # state, the scalar call starts afresh: both converge to rounding, 1e-12)
    for i in [3, 10]:
        s = tubemem.gps_inflate(float(c["lambda_s"][i]))
        assert abs(c["w"][i] / s["w"] - 1) < 1e-12
    assert list(c.to_pandas().columns) == c.columns
    assert "11 rows" in repr(c)


def test_progress_with_tqdm_or_a_clear_import_error(tmp_path, monkeypatch, capsys):
    """progress="tqdm" draws a tqdm bar over the stages (on stderr); without tqdm installed it
    is an ImportError that says how to get it, before anything runs."""
    pytest.importorskip("tqdm")
    tubemem.run(SMALL_CASE, str(tmp_path / "bar"), progress="tqdm")
    err = capsys.readouterr().err
    assert "tubemem" in err and "100%" in err and "2.0/2.0" in err and "stage 2 step 4" in err
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    with pytest.raises(ImportError, match="pip install tqdm"):
        tubemem.run(SMALL_CASE, str(tmp_path / "nobar"), progress="tqdm")
    assert not (tmp_path / "nobar" / "steps.csv").exists()
    with pytest.raises(ValueError, match="a callable"):
        tubemem.run(SMALL_CASE, str(tmp_path / "nobar2"), progress="bar")


def test_verify_returns_the_results_and_writes_a_junit_file_of_the_junit_structure(tmp_path):
    """tubemem.verify runs a suite (here: a reference check that must pass now that the
    scikit-fem references are installed, and a closed-form check that must fail), returns
    results.json's content, and junit.xml has the JUnit structure (testsuites > testsuite >
    testcase, with the attributes the JUnit schema requires, a <failure> with its message)."""
    import xml.etree.ElementTree as ET

    small = ROOT / "cases" / "small_abb30_ls1.2.toml"
    suite = tmp_path / "suite.toml"
    suite.write_text(f'''
[[check]]
name = "ref"
case = "{small}"
kind = "reference"
tolerance.profile = {{ value = 2e-3, source = "regression bound: 3.5 x the 5.7e-4 measured" }}
tolerance.w = {{ value = 2.1e-2, source = "16-gon factor 1.96e-2 + the end effect at L/R = 8" }}

[[check]]
name = "too-tight"
case = "{small}"
kind = "closed-form"
tolerance.w = {{ value = 1e-6, source = "a tolerance the 16-gon cannot meet" }}
''')
    out = tmp_path / "out"
    r = tubemem.verify([str(suite)], str(out))
    assert r["passed"] == 1 and r["failed"] == 1
    by = {c["name"]: c for c in r["checks"]}
    assert by["ref"]["status"] == "pass", by["ref"]["message"]
    prof = [m for m in by["ref"]["measures"] if m["quantity"] == "profile"][0]
    assert 1e-4 < prof["measured"] < 2e-3 and prof["source"].startswith("regression bound")
    assert by["too-tight"]["status"] == "fail" and "w: " in by["too-tight"]["message"]
    root = ET.parse(out / "junit.xml").getroot()
    assert root.tag == "testsuites"
    for ts in root:
        assert ts.tag == "testsuite"
        for a in ["name", "tests", "failures", "errors", "skipped", "time"]:
            assert a in ts.attrib, a
        assert int(ts.attrib["tests"]) == len(ts) == 2 and int(ts.attrib["failures"]) == 1
        for tc in ts:
            assert tc.tag == "testcase" and {"name", "classname", "time"} <= set(tc.attrib)
            float(tc.attrib["time"])
            for child in tc:
                assert child.tag in {"failure", "error", "skipped"}
                assert "message" in child.attrib
        fail = [tc for tc in ts if len(tc)][0]
        assert fail.attrib["name"] == "too-tight" and "16-gon cannot meet" in fail[0].attrib["message"]
    with pytest.raises(ValueError, match="has no `source`"):
        bad = tmp_path / "bad.toml"
        bad.write_text(f'[[check]]\nname = "x"\ncase = "{small}"\nkind = "gold"\ntolerance.w = {{ value = 1.0, source = "" }}\n')
        tubemem.verify([str(bad)], str(tmp_path / "bad"))


def test_an_arc_length_run_returns_its_critical_points_and_fronts(tmp_path):
    """The small tube inflated by arc length past its pressure maximum to λs* = 2: the located
    maximum is a row of `run.critical_points` equal to critical_points.csv and to summary.json,
    and the bulge fronts of every step are `run.fronts`, equal to fronts.csv."""
    import numpy as np

    text = SMALL.replace('control = "volume"', 'control = "arc-length"').replace(
        "target_stretch = 1.2", "target_stretch = 2.0"
    )
    r = tubemem.run(text, str(tmp_path / "arc"))
    cp = r.critical_points
    assert cp["kind"][0] == 1.0  # the pressure maximum
    assert cp["bracket"][0] <= 1e-8
    rows = list(csv.DictReader(open(tmp_path / "arc" / "critical_points.csv")))
    assert len(rows) == len(cp)
    for k in rows[0]:
        np.testing.assert_array_equal(cp[k], [float(x[k]) if x[k] else np.nan for x in rows])
    assert r.summary["stages"][0]["critical_points"][0]["w"] == cp["w"][0]
    # no converged step above the located maximum
    # (each step an equilibrium to Newton's 1e-9 relative residual: a few of those, 5e-9)
    assert np.all(r.steps["w"] <= cp["w"][0] * (1 + 5e-9))
    fr = r.fronts
    assert list(fr) == ["row", "stage", "step", "w", "volume", "front", "z_ref"]
    # the type stub has both
    stub = (pathlib.Path(__file__).resolve().parents[1] / "tubemem.pyi").read_text()
    assert "def critical_points(self) -> Table" in stub and "def fronts(self) -> Table" in stub
    if len(fr):
        on_disk = list(csv.DictReader(open(tmp_path / "arc" / "fronts.csv")))
        np.testing.assert_array_equal(fr["z_ref"], [float(x["z_ref"]) for x in on_disk])


def test_a_quad9_case_runs_through_the_api_and_writes_quad9_cells(tmp_path):
    """`[mesh] element = "quad9"` from a dict: the summary names the element, the VTU cells are
    meshio `quad9`, and the 4-node run of the same case has the 9-node pressure times the 16-gon
    factor 1/cos(π/16) (the flat facets' bias, 1.96e-2), to the two elements' remaining
    discretization errors: measured −1.2e-4 (the 9-node's is 2.5e-5 at 16 around,
    scripts/convergence-tables.py); bound 5e-4."""
    import math
    import tomllib

    import meshio

    d = tomllib.loads(SMALL)
    d9 = dict(d, mesh=dict(d["mesh"], element="quad9"))
    a = tubemem.run(d, str(tmp_path / "q4"))
    b = tubemem.run(d9, str(tmp_path / "q9"))
    assert b.summary["mesh"]["element"] == "quad9" and a.summary["mesh"]["element"] == "quad4"
    m = meshio.read(b.vtu(len(b.steps["step"])))
    assert [c.type for c in m.cells] == ["quad9"] and m.cells[0].data.shape == (b.summary["mesh"]["elements"], 9)
    ratio = a.steps["w"][-1] / b.steps["w"][-1] * math.cos(math.pi / 16)
    assert abs(ratio - 1.0) < 5e-4, ratio


def test_numpy_integers_and_strided_arrays_are_taken_as_numpy_users_pass_them():
    """Issue #25, class 6: `points` as np.int64 and a strided view (`a[::2]`) as the stretch
    array give what the plain int and the contiguous copy give."""
    a = np.linspace(1.1, 1.5, 5)
    strided = tubemem.gps_inflate(a[::2])["w"]
    np.testing.assert_array_equal(strided, tubemem.gps_inflate(np.ascontiguousarray(a[::2]))["w"])
    t = tubemem.gps_inflation_curve(1.5, points=np.int64(7)).to_pandas()
    assert len(t) == 7
    assert len(tubemem.gps_inflation_curve(1.5).to_pandas()) == 100
    with pytest.raises(TypeError, match="points = 2.5: an integer"):
        tubemem.gps_inflation_curve(1.5, points=2.5)


def test_case_validates_the_whole_plan_on_construction(tmp_path):
    """Issue #24 item 8: `tubemem.Case(...)` accepted a mesh the generator refuses and plates
    above the tube; both failed only in `run`, after a folder had been written."""
    import tomllib

    tables = tomllib.loads(SMALL_CASE)
    with pytest.raises(ValueError, match=r"mesh\.around = 30: elements around must be a multiple of 8"):
        tubemem.Case(**dict(tables, mesh=dict(tables["mesh"], around=30)))
    stages = [tables["stage"][0], dict(tables["stage"][1], target_rho=1.5)]
    with pytest.raises(ValueError, match=r"stage\[1\]\.target_rho = 1.5: the plates must close on the tube"):
        tubemem.Case(**dict(tables, stage=stages))
    # the material's own check names its key as the others do (it said `[material]: invalid
    # material parameter \`shear_modulus\``, the case file's style, in a dict's message)
    with pytest.raises(ValueError, match=r"case dict: material\.shear_modulus = -1: must be finite and > 0$"):
        tubemem.Case(**dict(tables, material=dict(tables["material"], shear_modulus=-1.0)))
    assert not any(tmp_path.iterdir())


def test_minor_defects_of_issue_24_item_13(tmp_path):
    """Issue #24 item 13: `to_pandas()` gives stage and step as integers (they were float64); a
    Case prints what it is (it printed "312 bytes of TOML"); with `vtu = "stage-end"` each VTU
    says which steps.csv row, stage and step it is (the frame numbers do not match the rows),
    and the VTUs and summary.json carry the version and the case hash (only run.json had them)."""
    import json

    import meshio

    text = SMALL_CASE + '\n[output]\nvtu = "stage-end"\n'
    case = tubemem.Case.from_toml(text)
    shown = repr(case)
    assert shown.startswith("<tubemem.Case: L/R = 8, hemisphere caps;") and "squeeze" in shown, shown
    r = tubemem.run(case, str(tmp_path / "run"))
    df = r.to_pandas()
    assert str(df["stage"].dtype) == "int64" and str(df["step"].dtype) == "int64"
    run_json = json.loads((tmp_path / "run" / "run.json").read_text())
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["case_hash"] == run_json["case_hash"] and summary["tubemem_version"] == run_json["tubemem"]
    steps = list(csv.DictReader(open(tmp_path / "run" / "steps.csv")))
    # frames: the reference state and the end of each of the two stages
    for k in range(3):
        m = meshio.read(r.vtu(k))
        fd = m.field_data
        row = int(fd["steps_csv_row"][0])
        assert bytes(fd["case_hash"]).decode() == run_json["case_hash"]
        assert bytes(fd["tubemem_version"]).decode() == run_json["tubemem"]
        if k == 0:
            assert row == 0 and int(fd["stage"][0]) == 0
            continue
        # the frame of stage k's end is the last steps.csv row of stage k
        last = max(i for i, s in enumerate(steps, start=1) if int(s["stage"]) == k)
        assert row == last, (k, row, last)
        assert int(fd["stage"][0]) == k and int(fd["step"][0]) == int(steps[last - 1]["step"])


def test_python_errors_name_dict_paths_and_arguments(tmp_path):
    """Issue #24 item 9: a misspelt dict key was reported at "line 19" of a TOML the user never
    wrote, a folder in the way asked for --overwrite, and a Mooney-Rivlin dict without alpha
    reported only the missing shear_modulus."""
    import tomllib

    tables = tomllib.loads(SMALL_CASE)
    with pytest.raises(ValueError) as e:
        tubemem.Case.from_dict(dict(tables, material={"model": "abb", "shear_modulus": 1.0, "kuhm": 3}))
    msg = str(e.value)
    assert "material.kuhm" in msg and "TOML" not in msg and "line" not in msg, msg
    with pytest.raises(ValueError) as e:
        tubemem.Case(**dict(tables, stage=[tables["stage"][0], {"kind": "squeeze", "target_roh": 0.9}]))
    assert "stage[1].target_roh" in str(e.value) and "TOML" not in str(e.value), str(e.value)
    with pytest.raises(ValueError, match=r"missing `shear_modulus` and `alpha`"):
        tubemem.Case(**dict(tables, material={"model": "mooney-rivlin"}))
    tubemem.run(tubemem.Case(**tables), str(tmp_path / "r"))
    with pytest.raises(ValueError) as e:
        tubemem.run(tubemem.Case(**tables), str(tmp_path / "r"))
    assert "overwrite=True" in str(e.value) and "--overwrite" not in str(e.value), str(e.value)


def test_units_reach_the_python_tables(tmp_path):
    """Issue #24 item 10: with `[units] system = "SI"` the Run's steps have the SI columns of
    steps.csv (p = w mu H / R, eq. 67), and its summary the scales."""
    import numpy as np

    text = (
        SMALL_CASE.replace("radius = 1.0", "radius = 0.005\nthickness = 0.0005")
        .replace("length = 8.0", "length = 0.04")
        .replace("shear_modulus = 1.0", "shear_modulus = 4.0e5")
        + '\n[units]\nsystem = "SI"\n'
    )
    r = tubemem.run(text, str(tmp_path / "si"))
    # three products in another order than the Rust side's: a few ulps apart, so 1e-14
    np.testing.assert_allclose(r.steps["pressure_pa"], r.steps["w"] * 4.0e5 * 0.0005 / 0.005, rtol=1e-14)
    assert r.summary["units"]["system"] == "SI"
    rows = list(csv.DictReader(open(tmp_path / "si" / "steps.csv")))
    np.testing.assert_array_equal(r.steps["pressure_pa"], [float(x["pressure_pa"]) for x in rows])


def test_material_objects_and_energies_written_as_text():
    """tubemem.Material: any law of the case files, validated on construction; the closed form
    takes it as material=; an energy written as text gives the built-in law's numbers (to
    1e-13 relative: the two derivative routes agree to round-off, crates/material's tests);
    bad laws are ValueErrors naming the parameter or the column."""
    gent = tubemem.Material("gent", shear_modulus=1.0, jm=50)
    text = tubemem.Material(model="invariants", energy="-(jm / 2) * ln(1 - (I1 - 3) / jm)",
                            parameters={"jm": 50}, shear_modulus=1.0)
    assert gent.to_dict() == {"model": "gent", "shear_modulus": 1.0, "jm": 50.0}
    assert tubemem.Material.from_dict(gent.to_dict()) == gent
    for ls in [1.1, 1.5, 2.5]:
        a, b = tubemem.gps_inflate(ls, material=gent), tubemem.gps_inflate(ls, material=text)
        assert abs(a["w"] / b["w"] - 1) < 1e-13 and abs(a["lambda_z"] / b["lambda_z"] - 1) < 1e-13
    assert tubemem.gps_limits(material=gent)["max"] is not None
    # the uniaxial nominal stress of an I1 law: P = 2 (l - l^-2) W'(I1), W' = 1/2 / (1 - (I1 - 3)/Jm)
    l = np.array([1.2, 2.0, 3.0])
    i1 = l**2 + 2 / l
    want = 2 * (l - l**-2) * 0.5 / (1 - (i1 - 3) / 50)
    assert np.allclose(gent.nominal_stress("uniaxial", l), want, rtol=1e-12)
    for kwargs, needle in [
        (dict(model="gent", shear_modulus=1.0), "jm"),
        (dict(model="yeoh", c10=0.0, c20=0.1), "c10"),
        (dict(model="invariants", energy="(I1 - 3)/2 * jn", parameters={"jm": 1}, shear_modulus=1), "column 14: unknown name `jn`"),
        (dict(model="principal", energy="-(l^2 - 1)", shear_modulus=1), "not positive definite"),
        (dict(model="ogden", mu=[1.0, -1.0], alpha=[2.0, 2.0]), "mu[1]"),
    ]:
        with pytest.raises(ValueError, match=None) as e:
            tubemem.Material(**kwargs)
        assert needle in str(e.value), (kwargs, str(e.value))
    # a Yeoh law with a negative coefficient is a law, stable over a range (issue #60 item 5):
    # a state beyond it is refused, naming the limit
    narrow = tubemem.Material("yeoh", c10=0.5, c20=-1.0)
    with pytest.raises(Exception, match="stable only for I1"):
        tubemem.gps_inflate(3.0, material=narrow)


def test_a_material_object_runs_in_a_case(tmp_path):
    gent = tubemem.Material("gent", shear_modulus=1.0, jm=50)
    case = tubemem.Case(geometry={"radius": 1.0, "length": 8.0}, material=gent,
                        mesh={"around": 16, "along": 24, "symmetry": "eighth"},
                        stage=[{"kind": "inflate", "control": "volume", "target_stretch": 1.2, "steps": 4}])
    r = tubemem.run(case, tmp_path / "gent")
    assert r.summary["material_spec"] == gent.to_dict()
    assert "Gent" in r.summary["material"]


def test_fit_takes_files_or_arrays_and_says_what_the_data_do_not_determine():
    """tubemem.fit on the shipped synthetic Yeoh data (examples/fit: the stated law with 1 %
    noise; python_ref/tubemem_ref/synthetic.py): every parameter within three standard errors;
    from arrays, noise-free Ogden data give the law back; SVK's Poisson ratio from a uniaxial
    test alone is reported as not determined (P = E l (l^2 - 1)/2 whatever nu)."""
    from tubemem_ref import synthetic
    ex = pathlib.Path(__file__).resolve().parents[3] / "examples" / "fit"
    r = tubemem.fit("yeoh", uniaxial=ex / "yeoh_synthetic_uniaxial.csv",
                    equibiaxial=str(ex / "yeoh_synthetic_equibiaxial.csv"),
                    pure_shear=ex / "yeoh_synthetic_pure_shear.csv")
    # the headers say MPa: the fit works in Pa
    assert r["stress_unit"] == "Pa" and r["converged"], r["stop_reason"]
    for p in r["parameters"]:
        assert abs(p["value"] - 1e6 * synthetic.YEOH[p["name"]]) <= 3 * p["std_error"], p
    assert isinstance(r["material"], tubemem.Material)
    with pytest.raises(ValueError, match="one unit per fit"):
        tubemem.fit("yeoh", uniaxial=ex / "yeoh_synthetic_uniaxial.csv",
                    equibiaxial=np.c_[[1.1, 1.2, 1.3], [0.01, 0.02, 0.03]])
    og = tubemem.Material("ogden", mu=[0.2, 0.002], alpha=[1.8, 5.0])
    l = np.linspace(1.05, 3.5, 20)
    r = tubemem.fit({"model": "ogden", "mu": [0.1, 0.01], "alpha": [2.0, 4.0]},
                    uniaxial=np.c_[l, og.nominal_stress("uniaxial", l)],
                    equibiaxial=(l[:12], og.nominal_stress("equibiaxial", l[:12])))
    got = r["material"].to_dict()
    assert np.allclose(got["mu"], [0.2, 0.002], rtol=1e-6) and np.allclose(got["alpha"], [1.8, 5.0], rtol=1e-6)
    svk = tubemem.Material("svk", young_modulus=3.0, poisson_ratio=0.3)
    rng = np.random.default_rng(1)
    l = np.linspace(1.01, 1.5, 15)
    p = svk.nominal_stress("uniaxial", l) + 1e-4 * rng.standard_normal(15)
    r = tubemem.fit({"model": "svk", "young_modulus": 2.0, "poisson_ratio": 0.2}, uniaxial=np.c_[l, p])
    assert any("poisson_ratio" in w for w in r["warnings"]), r["warnings"]
    with pytest.raises(ValueError, match="more points than parameters"):
        tubemem.fit("yeoh", uniaxial=([1.1, 1.2], [0.1, 0.2]))
    # a 2 × 2 array reads either way (issue #61): refused, with the tuple to give instead
    with pytest.raises(ValueError, match="2 × 2 array is ambiguous"):
        tubemem.fit("yeoh", uniaxial=np.c_[[1.1, 1.2], [0.1, 0.2]])
    with pytest.raises(ValueError, match="give test data"):
        tubemem.fit("yeoh")


def _ci_atlas():
    import pathlib
    return pathlib.Path(__file__).resolve().parents[3] / "atlas" / "ci.toml"


def test_atlas_on_a_dask_local_cluster_equals_the_local_one_bit_for_bit(tmp_path):
    """tubemem.atlas on a LocalCluster of 2 worker processes writes the same atlas.csv, runs.csv
    and atlas.json, byte for byte, as on threads of this process, and returns the same Dataset
    (dimensions lambda_s_star, rho, length_ratio), also written as atlas.nc."""
    import dask.distributed as distributed  # in the test requirements: a missing one fails
    import xarray as xr

    seen = []
    local = tubemem.atlas(_ci_atlas(), tmp_path / "local", workers=2, progress=seen.append)
    assert sorted(d["done"] for d in seen) == list(range(1, 7)) and all(d["error"] is None for d in seen)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = tubemem.atlas(_ci_atlas(), tmp_path / "dask", client=client)
    for name in ("atlas.csv", "runs.csv", "atlas.json"):
        assert (tmp_path / "local" / name).read_bytes() == (tmp_path / "dask" / name).read_bytes(), name
    assert local.identical(remote)
    assert dict(local.sizes) == {"lambda_s_star": 2, "rho": 4, "length_ratio": 3, "epsilon": 2}
    w = local["error_w"].sel(lambda_s_star=1.3, rho=0.8)
    assert w.dims == ("length_ratio",) and bool((w < 0).all())
    assert float(local["a_w"].sel(lambda_s_star=1.3, rho=0.8)) < 0
    assert (local["flag_w"] == "").all()
    back = xr.open_dataset(tmp_path / "local" / "atlas.nc", engine="scipy")
    assert float(back["min_length_ratio_force"].sel(lambda_s_star=1.3, rho=0.8, epsilon=1e-3)) == float(local["min_length_ratio_force"].sel(lambda_s_star=1.3, rho=0.8, epsilon=1e-3))
    back.close()
    # every member's folder keeps the case it ran
    assert (tmp_path / "dask" / "runs" / "ls1.3_lr40" / "case.toml").is_file()


def test_atlas_errors_name_the_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(_ci_atlas().read_text().replace("lengths =", "length ="))
    with pytest.raises(ValueError, match="length"):
        tubemem.atlas(bad, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_gps_history_matches_the_independent_dae_and_refuses_bad_input():
    """Issue #63: a squeeze-hold-release cycle from Python against tubemem_ref.visco (scipy
    DOP853 on the relaxed stresses; the bound 1e-8 of python_ref/tests/test_visco_vs_rust.py,
    the loop's area 1e-6); the free and plate steps in separate Tables (no NaN for a gap
    before the plates come); bad input is a ValueError naming the key."""
    from tubemem_ref import visco

    prony = [(0.3, 1.0), (0.2, 10.0)]
    r = tubemem.gps_history(prony, "stretch", 1.3, hold=200.0, material=ABB30, plates_to=1.0,
                            squeeze_time=3.0, plates_hold=5.0, release=True)
    assert r["error_estimate"] <= 1e-10 and r["touch"] == pytest.approx(1.3, abs=1e-12)
    free, plates = r["history"], r["plates"]
    assert "rho" not in free.columns and not np.isnan(plates["rho"]).any()
    times = [201.125, 203.0, 205.5, 209.5]
    ref, work = visco.program(("abb", 30.0), prony, "gps", [
        ("stretch", 1.3, 0.0), ("stretch", None, 200.0), ("plates-gas", 1.0, 3.0),
        ("plates-gas", None, 5.0), ("plates-gas", 1.3, 3.0)], times)
    t = np.asarray(plates["time"])
    for tt, w, ls, lz, rho, force in ref:
        i = int(np.argmin(abs(t - tt)))
        assert abs(t[i] - tt) < 1e-12 * tt
        for key, v in [("w", w), ("lambda_s", ls), ("lambda_z", lz), ("force", force)]:
            assert abs(plates[key][i] / v - 1) < 1e-8, (tt, key)
    assert abs(r["loop_area"] / work - 1) < 1e-6 and r["loop_closed"] is True
    # squeezed right after the inflation: the tube creeps wider, still pressed at the end
    u = tubemem.gps_history(prony, "stretch", 1.3, material=ABB30, plates_to=1.0,
                            squeeze_time=1.0, release=True, steps=64)
    assert u["loop_closed"] is False and u["plates"]["chi"][-1] > 0
    # a creep without plates: the plates Table is None, and g_infinity is reported
    c = tubemem.gps_history(prony, "pressure", 0.3, ramp=1.0, hold=20.0, material=ABB30)
    assert c["plates"] is None and c["loop_area"] is None and c["loop_closed"] is None
    assert c["g_infinity"] == pytest.approx(0.5)
    for kwargs, words in [
        (dict(prony=[(0.6, 1.0), (0.5, 2.0)], control="pressure", to=0.3), "g∞"),
        (dict(prony=prony, control="plates", to=0.3), "control"),
        (dict(prony=prony, control="stretch", to=1.3, plates_to=1.5), "first contact"),
        (dict(prony=prony, control="stretch", to=1.3, squeeze_time=2.0), "plates_to"),
    ]:
        with pytest.raises(ValueError, match=words):
            tubemem.gps_history(material=ABB30, **kwargs)
