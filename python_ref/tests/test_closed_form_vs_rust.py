"""The Rust closed form (tubemem gps ...) against the independent Python one.

Tolerances: both sides converge their nonlinear solves to ~1e-14; the flattening system has a
condition number of order 1e2 and hybrd stops at tol = 1e-14, so states agree to 1e-9 relative.
Limit points are located to 1e-8 in lambda_s by both sides (bisection on the slope to that
width), so they are compared at 1e-8.
"""

import pytest

from tubemem_ref import closed_form as cf

ABB = ("--material", "abb", "--kuhn", "30")


def rel(a, b):
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


@pytest.mark.parametrize("ls", [1.05, 1.3, 1.6, 2.5, 4.0, 6.0, 7.4])
def test_gps_and_ps_inflation(tubemem, ls):
    g = tubemem("gps", "inflate", *ABB, "--hypothesis", "gps", "--stretch", ls, "--json")
    w, lz = cf.gps_inflation(ls)
    assert rel(g["w"], w) < 1e-10 and rel(g["lambda_z"], lz) < 1e-10
    p = tubemem("gps", "inflate", *ABB, "--hypothesis", "ps", "--stretch", ls, "--json")
    assert rel(p["w"], cf.ps_inflation(ls)) < 1e-10 and p["lambda_z"] == 1.0


@pytest.mark.parametrize("ls0,rhos", [(1.3, [1.1, 0.8, 0.65]), (6.0, [5.0, 4.0, 3.0])])
def test_gps_flattening(tubemem, ls0, rhos):
    ref = cf.gps_flattening(ls0, rhos)
    for r in ref:
        s = tubemem("gps", "flatten", *ABB, "--initial-stretch", ls0, "--rho", r["rho"], "--json")
        for k in ["w", "lambda_s", "lambda_z", "chi", "force"]:
            assert rel(s[k], r[k]) < 1e-9, (k, s[k], r[k])


LAWS = {"mooney-rivlin": ("--material", "mooney-rivlin", "--alpha", "0.1"), "neo-hookean": ("--material", "neo-hookean")}


@pytest.mark.parametrize("name,law", [("mooney-rivlin", ("mooney-rivlin", 0.1)), ("neo-hookean", ("mooney-rivlin", 0.0))])
def test_other_laws_inflation_and_flattening(tubemem, name, law):
    """The references for any law: Mooney-Rivlin and neo-Hookean inflation (GPS, PS) and GPS
    flattening from 1.3 (Python eqs. 86-87 against the Rust law code), same tolerances."""
    for ls in [1.1, 1.3, 1.6]:
        g = tubemem("gps", "inflate", *LAWS[name], "--hypothesis", "gps", "--stretch", ls, "--json")
        w, lz = cf.gps_inflation(ls, law=law)
        assert rel(g["w"], w) < 1e-10 and rel(g["lambda_z"], lz) < 1e-10
        p = tubemem("gps", "inflate", *LAWS[name], "--hypothesis", "ps", "--stretch", ls, "--json")
        assert rel(p["w"], cf.ps_inflation(ls, law=law)) < 1e-10
    for r in cf.gps_flattening(1.3, [1.1, 0.8], law=law):
        s = tubemem("gps", "flatten", *LAWS[name], "--initial-stretch", 1.3, "--rho", r["rho"], "--json")
        for k in ["w", "lambda_s", "lambda_z", "chi", "force"]:
            assert rel(s[k], r[k]) < 1e-9, (k, s[k], r[k])


def test_limit_points_and_maxwell(tubemem):
    lim = tubemem("gps", "limits", *ABB, "--json")
    (lmax, wmax), (lmin, wmin) = cf.gps_limit_points()
    assert abs(lim["max"]["lambda_s"] - lmax) < 1e-8
    assert abs(lim["min"]["lambda_s"] - lmin) < 1e-8
    assert rel(lim["max"]["w"], wmax) < 1e-12 and rel(lim["min"]["w"], wmin) < 1e-12
    wm, l1, l3 = cf.gps_maxwell()
    m = lim["maxwell"]
    # quad's error estimate is ~1e-12 of the area; the Maxwell pressure inherits ~1e-11.
    assert rel(m["w"], wm) < 1e-9, (m["w"], wm)
    assert abs(m["lambda_s_lower"] - l1) < 1e-7 and abs(m["lambda_s_upper"] - l3) < 1e-7


# The law library: each law's case-file table (given to the binary as --law) and its Python
# law. The Python resultants are written from each published energy by hand (closed_form.
# law_resultants); the Rust side computes them through its (tr C, det C) derivatives, its
# inverse Langevin Newton and its separable-law series. Same tolerances as above.
LIBRARY = {
    "yeoh": 'model = "yeoh", c10 = 0.5, c20 = -0.01, c30 = 0.001',
    "gent": 'model = "gent", shear_modulus = 1.0, jm = 50',
    "gent-gent": 'model = "gent-gent", shear_modulus = 1.0, jm = 50, c2 = 0.2',
    "arruda-boyce": 'model = "arruda-boyce", shear_modulus = 1.0, kuhn = 8',
    "ogden": 'model = "ogden", mu = [6.3, 0.012, -0.1], alpha = [1.3, 5.0, -2.0]',
    "svk": 'model = "saint-venant-kirchhoff", young_modulus = 2.9998, poisson_ratio = 0.4999',
    "svk-0.3": 'model = "saint-venant-kirchhoff", young_modulus = 2.6, poisson_ratio = 0.3',
}


def _law(text):
    import tomllib
    return cf.law_of_spec(tomllib.loads("m = {" + text + "}")["m"])


@pytest.mark.parametrize("name", sorted(LIBRARY))
def test_law_library_inflation_and_flattening(tubemem, name):
    text = LIBRARY[name]
    law = _law(text)
    for ls in [1.05, 1.3, 1.6, 2.2]:
        g = tubemem("gps", "inflate", "--law", text, "--hypothesis", "gps", "--stretch", ls, "--json")
        w, lz = cf.gps_inflation(ls, law=law)
        assert rel(g["w"], w) < 1e-10 and rel(g["lambda_z"], lz) < 1e-10, (ls, g, w, lz)
        p = tubemem("gps", "inflate", "--law", text, "--hypothesis", "ps", "--stretch", ls, "--json")
        assert rel(p["w"], cf.ps_inflation(ls, law=law)) < 1e-10
    for r in cf.gps_flattening(1.3, [1.1, 0.8], law=law):
        s = tubemem("gps", "flatten", "--law", text, "--initial-stretch", 1.3, "--rho", r["rho"], "--json")
        for k in ["w", "lambda_s", "lambda_z", "chi", "force"]:
            assert rel(s[k], r[k]) < 1e-9, (k, s[k], r[k])


@pytest.mark.parametrize("name", sorted(LIBRARY))
def test_law_library_pressure_maximum(tubemem, name):
    """The GPS pressure maximum where the law has one (Python: a scan and a bounded Brent
    search on w(ls), to 1e-12 in ls), and none where it has none (a scan to ls = 4 and the Rust
    scan agree)."""
    text = LIBRARY[name]
    ref = cf.gps_pressure_maximum(law=_law(text))
    lim = tubemem("gps", "limits", "--law", text, "--json")
    if ref is None:
        assert lim["max"] is None, lim
        return
    ls, wm, _ = ref
    assert lim["max"] is not None, (name, ref)
    assert abs(lim["max"]["lambda_s"] - ls) < 1e-7, (lim["max"], ls)
    assert rel(lim["max"]["w"], wm) < 1e-12, (lim["max"], wm)


def test_fit_recovers_the_stated_law_of_the_shipped_synthetic_data(tubemem):
    """`tubemem fit` on examples/fit (made by tubemem_ref.synthetic from a stated Yeoh law with
    1 % noise): every parameter within three reported standard errors of the stated value, and
    the data files are the generator's (written again and compared)."""
    import pathlib
    import tempfile
    from tubemem_ref import synthetic
    root = pathlib.Path(__file__).resolve().parents[2]
    ex = root / "examples" / "fit"
    with tempfile.TemporaryDirectory() as d:
        synthetic.write(d)
        for f in ex.glob("*.csv"):
            assert (pathlib.Path(d) / f.name).read_text() == f.read_text(), f.name
    r = tubemem("fit", "--law", "yeoh", "--uniaxial", ex / "yeoh_synthetic_uniaxial.csv",
                "--equibiaxial", ex / "yeoh_synthetic_equibiaxial.csv",
                "--pure-shear", ex / "yeoh_synthetic_pure_shear.csv", "--json")
    # the files' headers say MPa: the fit works in Pa
    assert r["converged"], r["stop_reason"]
    for p in r["parameters"]:
        truth = 1e6 * synthetic.YEOH[p["name"]]
        assert abs(p["value"] - truth) <= 3 * p["std_error"], (p, truth)
        assert p["determined"], p
