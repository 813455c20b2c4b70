"""Convergence tables of the two membrane elements, from one command:

    .venv/bin/python scripts/convergence-tables.py [--bin target/release/tubemem] [--out runs/convergence]

For each element (4-node bilinear, 9-node biquadratic) and each mesh of its family (elements
around n, along 2.5 n, eighth model of the L/R = 20 capped tube, ABB N = 30), one run of the
case "inflate to λs* = 1.3, then squeeze to ρ = 0.8" (the shipped squeeze case, with the
penalty's penetration tolerance lowered from 1e-3 to 1e-4: the flat zone sits about that much
inside the plate, an error of that order in χ and the force; 1e-5 is out of reach of the 9-node
element on coarse meshes, whose 3 × 3 Gauss-point penalty then over-constrains the contact edge
and the squeeze stalls at 16 around), and prints:

1. inflation: the mid-span ϖ, λz, N_z against GPS (eq. 66, at the FE's mid-span λs);
2. squeeze: the mid-span λs, λz, χ and force against the GPS section under the FE's own
   mid-span pressure (eq. 76 without the gas law: the local mechanics, free of the end effect
   that acts through the gas): λs and λz the worst of the squeeze's steps (signed), χ and the
   force at its end, ρ = 0.8 (in the first contact steps χ is small and its relative error
   large on every mesh);
3. the end-cap profile: the largest |Δλs| over the cylinder against python_ref's scikit-fem
   axisymmetric tube (P2, refined: 640 cylinder and 128 cap elements; its own error is printed,
   from the same reference at half the resolution);

with the observed order p = log(e_coarse/e_fine)/log(n_fine/n_coarse) between consecutive
meshes, and the wall time and equation count of each run. Results go to OUT/tables.md and
OUT/tables.json as well.
"""

import argparse
import json
import math
import pathlib
import subprocess
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python_ref"))
from tubemem_ref import axisym  # noqa: E402

LENGTH = 20.0
CASE = """
[geometry]
radius = 1.0
length = {length}
thickness = 0.01
caps = "hemisphere"

[material]
model = "abb"
shear_modulus = 1.0
kuhn = 30

[mesh]
around = {around}
along = {along}
symmetry = "eighth"
element = "{element}"

[solver]
checkpoint_every = 0

[output]
vtu = "none"

[[stage]]
kind = "inflate"
control = "volume"
target_stretch = 1.3
steps = 6

[[stage]]
kind = "squeeze"
target_rho = 0.8
penetration_tolerance = 1e-4
steps = 10
"""

FAMILIES = {"quad4": [16, 32, 64, 128], "quad9": [16, 32, 64]}
QUICK = {"quad4": [16, 32, 64], "quad9": [16, 32]}


def read_csv(path):
    import csv
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    def num(v):
        try:
            return float(v)
        except ValueError:  # empty (no value at this step) or a label
            return np.nan
    return {k: np.array([num(r[k]) for r in rows]) for k in rows[0]}


def reference_profile(cylinder_elements, cap_elements):
    tube, q, _ = axisym.inflate_to(LENGTH, 1.3, law=("abb", 30.0),
                                   cylinder_elements=cylinder_elements, cap_elements=cap_elements)
    z, ls, _, s = tube.profile(q)
    cyl = s >= np.pi / 2 - 1e-12
    z_ref = LENGTH / 2 - (s[cyl] - np.pi / 2)
    order = np.argsort(z_ref)
    return z_ref[order], ls[cyl][order]


def profile_error(run_dir, ref):
    """max |Δλs| at the FE's rings (corner heights: multiples of the reference's vertex spacing
    for every mesh of the families, so the reference is read at its vertices, not
    interpolated)."""
    summary = json.loads((run_dir / "summary.json").read_text())
    prof = read_csv(run_dir / summary["stages"][0]["profile"])
    sel = prof["z_ref"] >= -1e-12
    diff = prof["lambda_s"][sel] - np.interp(prof["z_ref"][sel], *ref)
    return float(np.abs(diff).max())


def run_one(binary, out, element, around):
    d = out / f"{element}_{around}"
    case = d.with_suffix(".toml")
    out.mkdir(parents=True, exist_ok=True)
    case.write_text(CASE.format(length=LENGTH, around=around, along=int(2.5 * around), element=element))
    t = time.perf_counter()
    subprocess.run([str(binary), "run", str(case), "--out", str(d), "--overwrite"],
                   check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t
    return d, wall, json.loads((d / "summary.json").read_text())


def worst_squeeze_errors(run_dir):
    """The signed error of largest magnitude over the squeeze's steps, per quantity, against
    the section at the FE's own pressure (steps.csv's local_* columns)."""
    st = read_csv(run_dir / "steps.csv")
    sq = st["stage"] == 2
    out = {}
    for q in ["lambda_s", "lambda_z"]:
        e = st[q][sq] / st[f"local_{q}"][sq] - 1.0
        out[q] = float(e[np.nanargmax(np.abs(e))])
    return out


def orders(errors, arounds):
    out = [None]
    for k in range(1, len(errors)):
        a, b = abs(errors[k - 1]), abs(errors[k])
        out.append(math.log(a / b) / math.log(arounds[k] / arounds[k - 1]) if a > 0 and b > 0 else None)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "target/release/tubemem"))
    ap.add_argument("--out", default=str(ROOT / "runs/convergence"))
    ap.add_argument("--quick", action="store_true", help="three meshes per element instead of four")
    a = ap.parse_args(argv)
    out = pathlib.Path(a.out)
    fams = QUICK if a.quick else FAMILIES
    ref = reference_profile(640, 128)
    ref_half = reference_profile(320, 64)
    # at the half-resolution reference's vertices, which are vertices of the fine one (no
    # interpolation error between them)
    ref_err = float(np.abs(np.interp(ref_half[0], *ref) - ref_half[1]).max())
    results = {"reference_profile_self_difference": ref_err, "elements": {}}
    lines = [f"Convergence tables (`{' '.join(['scripts/convergence-tables.py'] + (argv or sys.argv[1:]))}`): "
             f"L/R = {LENGTH:g}, eighth model, along = 2.5 × around, ABB N = 30.",
             "Errors are relative (FE/reference − 1) except the profile's, which is the largest Δλs over the cylinder;",
             "p is the observed order between a mesh and the one before it.",
             f"The axisymmetric reference (640 + 128 P2 elements) differs from itself at half resolution by {ref_err:.1e} in λs.", ""]
    for element, arounds in fams.items():
        rows = []
        for n in arounds:
            d, wall, s = run_one(a.bin, out, element, n)
            inf, sq = s["stages"][0], s["stages"][1]
            e_inf = inf["relative_error_vs_gps"]
            e_sq = {**sq["relative_error_vs_gps_at_fe_pressure"], **worst_squeeze_errors(d)}
            rows.append({
                "around": n, "equations": s["mesh"]["equations"], "wall_s": wall,
                "w": e_inf["w"], "lambda_z": e_inf["lambda_z"], "n_z": e_inf["n_z"],
                "sq_lambda_s": e_sq["lambda_s"], "sq_lambda_z": e_sq["lambda_z"],
                "sq_chi": e_sq["chi"], "sq_force": e_sq["force"],
                "profile": profile_error(d, ref),
            })
            print(f"{element} {n} around: {s['mesh']['equations']} equations, {wall:.2f} s", file=sys.stderr)
        cols = ["w", "lambda_z", "n_z", "sq_lambda_s", "sq_lambda_z", "sq_chi", "sq_force", "profile"]
        ps = {c: orders([r[c] for r in rows], arounds) for c in cols}
        results["elements"][element] = {"rows": rows, "orders": ps}
        names = ["ϖ", "λz", "N_z", "sq. λs", "sq. λz", "sq. χ", "sq. force", "profile max Δλs"]
        lines.append(f"**{element}**")
        lines.append("")
        lines.append("| around | equations | wall s | " + " | ".join(f"{nm} | p" for nm in names) + " |")
        lines.append("|" + "---|" * (3 + 2 * len(names)))
        for k, r in enumerate(rows):
            cells = [f"{r['around']}", f"{r['equations']}", f"{r['wall_s']:.2f}"]
            for c in cols:
                p = ps[c][k]
                cells += [f"{r[c]:+.2e}", "" if p is None else f"{p:.2f}"]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    text = "\n".join(lines)
    print(text)
    out.mkdir(parents=True, exist_ok=True)
    (out / "tables.md").write_text(text + "\n")
    (out / "tables.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
