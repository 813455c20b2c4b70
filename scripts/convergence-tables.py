"""Convergence tables of the two membrane elements, inflation and contact, from one command:

    .venv/bin/python scripts/convergence-tables.py [--bin target/release/tubemem] [--out runs/convergence] [--quick]
        [--part squeeze,squeeze6,confine] [--variants augmented+track,...] [--confine-variants track,fit]

Every run is a case of the paper's tube (ABB N = 30, L/R = 20, eighth model unless said, along
= 2.5 × around) on each mesh of each element's family (4-node bilinear, 9-node biquadratic:
16, 32, 64, 128 around; --quick: 16, 32, 64). Errors are relative, FE/reference − 1, signed.

1. **Inflation and squeeze, λs* = 1.3 → ρ = 0.8** (`cases/squeeze_abb30_ls1.3_quad9.toml`
   varied only in the element and `around`), with each contact ingredient on its own:
   - `penalty`: the penalty alone at Gauss points (`contact_method = "penalty"`, penetration
     tolerance 1e-3), uniform mesh;
   - `augmented`: the default contact (augmented Lagrangian at the nodes, gap ≤ 1e-9 R),
     uniform mesh;
   - `augmented+fit`: the same on the mesh fitted once to the contact edge at the squeeze's end
     (`fit_contact_edge`);
   - `augmented+track`: the same with the node lines following the contact edges at every
     step (`track_contact_edge`), the shipped case;
   - `augmented-gauss+fit` (9-node, 16 and 32 around only): the augmented Lagrangian at the
     Gauss points, to show where it stalls.
   Columns: inflation ϖ, λz, N_z against GPS (eq. 66 at the FE's λs), the end-cap profile's
   largest |Δλs| against python_ref's scikit-fem axisymmetric tube (P2, 640 + 128 elements), and
   at the squeeze's end λs, λz, χ and the force against the GPS section under the FE's own
   mid-span pressure (eq. 76 without the gas law), the largest χ error over the squeeze's steps,
   the flat zone's max |p_c/ϖ − 1| at mid-span, the largest penetration over the squeeze's
   steps and the most multiplier updates in a step.
2. **Squeeze, λs* = 6 → ρ = 3** (`cases/squeeze_abb30_ls6.0.toml`, default contact, uniform).
3. **Confinement**: the channel and the V-groove (`cases/channel_abb30_ls1.3.toml`,
   `cases/vgroove_abb30_ls1.3.toml`, default contact; `track` as shipped, `fit` fitted once
   at the end), λs, λz and every wall's force
   against the section in the same walls under the FE's pressure: at the end (worst wall) and
   the worst over the steps where the walls carry a flat; and the V-groove at L/R = 40 (32 and
   64 around), to separate the end effect from the discretization.

p is the observed order log(e_coarse/e_fine)/log(n_fine/n_coarse) between consecutive meshes.
A run that fails is listed with its error. Results go to OUT/tables.md and OUT/tables.json.
"""

import argparse
import csv
import json
import math
import pathlib
import re
import subprocess
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python_ref"))
from tubemem_ref import axisym  # noqa: E402

LENGTH = 20.0
FAMILIES = {"quad4": [16, 32, 64, 128], "quad9": [16, 32, 64, 128]}
QUICK = {"quad4": [16, 32, 64], "quad9": [16, 32, 64]}


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))

    def num(v):
        try:
            return float(v)
        except (TypeError, ValueError):  # empty (no value at this step) or a label
            return np.nan
    return {k: np.array([num(r[k]) for r in rows]) for k in (rows[0] if rows else [])}


def reference_profile(cylinder_elements, cap_elements):
    tube, q, _ = axisym.inflate_to(LENGTH, 1.3, law=("abb", 30.0),
                                   cylinder_elements=cylinder_elements, cap_elements=cap_elements)
    z, ls, _, s = tube.profile(q)
    cyl = s >= np.pi / 2 - 1e-12
    z_ref = LENGTH / 2 - (s[cyl] - np.pi / 2)
    order = np.argsort(z_ref)
    return z_ref[order], ls[cyl][order]


def profile_error(run_dir, ref):
    """max |Δλs| of the inflation's end profile at the FE's rings (corner heights: vertices of
    the reference for every mesh of the families, so it is read there, not interpolated)."""
    summary = json.loads((run_dir / "summary.json").read_text())
    prof = read_csv(run_dir / summary["stages"][0]["profile"])
    sel = prof["z_ref"] >= -1e-12
    diff = prof["lambda_s"][sel] - np.interp(prof["z_ref"][sel], *ref)
    return float(np.abs(diff).max())


def case_text(base, element, around, mesh=None, stage=None, length=None):
    """A shipped case varied: its element and `around` (along = 2.5 × around), `mesh` keys set
    (None: removed), `stage` keys set on its last stage, and no checkpoints or VTU."""
    import tomllib
    t = tomllib.loads((ROOT / "cases" / base).read_text())
    t["mesh"].update({"element": element, "around": around, "along": int(2.5 * around)})
    for k, v in (mesh or {}).items():
        if v is None:
            t["mesh"].pop(k, None)
        else:
            t["mesh"][k] = v
    t["stage"][-1].update(stage or {})
    if length is not None:
        t["geometry"]["length"] = length
        t["mesh"]["along"] = int(2.5 * around * length / LENGTH)
    t["solver"] = {**t.get("solver", {}), "checkpoint_every": 0}
    t["output"] = {**t.get("output", {}), "vtu": "none"}
    return dumps(t)


def dumps(t):
    """TOML for the case tables used here (tables, arrays of tables, scalars, lists)."""
    def val(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, list):
            return "[" + ", ".join(val(x) for x in v) + "]"
        return repr(v)
    lines = []
    for k, v in t.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f"{a} = {val(b)}" for a, b in v.items()]
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines.append(f"[[{k}]]")
                subs = []
                for a, b in item.items():
                    if isinstance(b, list) and b and isinstance(b[0], dict):
                        subs.append((a, b))
                    else:
                        lines.append(f"{a} = {val(b)}")
                for a, b in subs:
                    for sub in b:
                        lines.append(f"[[{k}.{a}]]")
                        lines += [f"{c} = {val(d)}" for c, d in sub.items()]
    return "\n".join(lines) + "\n"


def run_one(binary, out, name, text):
    d = out / name
    out.mkdir(parents=True, exist_ok=True)
    case = d.with_suffix(".toml")
    case.write_text(text)
    t = time.perf_counter()
    p = subprocess.run([str(binary), "run", str(case), "--out", str(d), "--overwrite"],
                       capture_output=True, text=True)
    wall = time.perf_counter() - t
    print(f"{name}: {wall:.1f} s{'' if p.returncode == 0 else ' FAILED'}", file=sys.stderr)
    if p.returncode != 0:
        last = [l for l in p.stderr.strip().splitlines() if l.strip()]
        return d, wall, None, (last[-1] if last else f"exit {p.returncode}")
    return d, wall, json.loads((d / "summary.json").read_text()), None


def squeeze_row(d, s):
    """The squeeze's end against the section at the FE's pressure, and its steps' worst
    penetration, flat-zone pressure and multiplier updates."""
    st = read_csv(d / "steps.csv")
    sq = st["stage"] == st["stage"].max()
    last = np.where(sq)[0][-1]
    e = lambda q: float(st[q][last] / st[f"local_{q}"][last] - 1.0)
    aug = st["augmentations"][sq]
    with np.errstate(divide="ignore", invalid="ignore"):
        steps = st["chi"][sq] / st["local_chi"][sq] - 1.0
    steps = steps[np.isfinite(steps)]
    return {
        "sq_lambda_s": e("lambda_s"), "sq_lambda_z": e("lambda_z"),
        "sq_chi": e("chi"), "sq_force": e("force"),
        "sq_chi_steps": float(steps[np.argmax(np.abs(steps))]) if steps.size else math.nan,
        "flat_pressure": float(st["flat_pressure_deviation"][last]),
        "penetration": float(np.nanmax(st["penetration"][sq])),
        "updates": float(np.nanmax(aug)) if np.isfinite(aug).any() else math.nan,
    }


def confine_row(d, s):
    st = read_csv(d / "steps.csv")
    walls = read_csv(d / "walls.csv")
    sq = st["stage"] == st["stage"].max()
    last = np.where(sq)[0][-1]
    e = lambda q: float(st[q][last] / st[f"local_{q}"][last] - 1.0) if f"local_{q}" in st else math.nan
    sel = (walls["stage"] == st["stage"].max()) & (walls["local_force"] > 0)
    err = walls["force"][sel] / walls["local_force"][sel] - 1.0
    steps = walls["step"][sel]
    final = err[steps == steps.max()]
    summary_local = s["stages"][-1]["relative_error_vs_local"]
    return {
        "lambda_s": summary_local["lambda_s"], "lambda_z": summary_local["lambda_z"],
        "wall_force_end": float(final[np.argmax(np.abs(final))]),
        "wall_force_steps": float(err[np.argmax(np.abs(err))]),
        "penetration": float(np.nanmax(walls["penetration"][walls["stage"] == st["stage"].max()])),
        "updates": float(np.nanmax(st["augmentations"][sq])),
    }


def orders(errors, arounds):
    out = [None]
    for k in range(1, len(errors)):
        a, b = errors[k - 1], errors[k]
        ok = a is not None and b is not None and np.isfinite(a) and np.isfinite(b) and a != 0 and b != 0
        out.append(math.log(abs(a) / abs(b)) / math.log(arounds[k] / arounds[k - 1]) if ok else None)
    return out


def table(title, rows, cols, names, arounds_key="around"):
    lines = [f"**{title}**", ""]
    lines.append("| around | equations | wall s | " + " | ".join(f"{n} | p" for n in names) + " |")
    lines.append("|" + "---|" * (3 + 2 * len(names)))
    ok = [r for r in rows if r.get("error") is None]
    ps = {c: orders([r[c] for r in ok], [r[arounds_key] for r in ok]) for c in cols}
    k = 0
    for r in rows:
        if r.get("error") is not None:
            lines.append(f"| {r[arounds_key]} | {r.get('equations', '')} | {r['wall_s']:.2f} | failed: {r['error']} |")
            continue
        cells = [f"{r[arounds_key]}", f"{r['equations']}", f"{r['wall_s']:.2f}"]
        for c in cols:
            p = ps[c][k]
            v = r[c]
            no_order = c in ("penetration", "updates")
            cells += ["" if v is None or not np.isfinite(v) else (f"{v:.0f}" if c == "updates" else f"{v:+.2e}"),
                      "" if p is None or no_order else f"{p:.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
        k += 1
    lines.append("")
    return lines


UNIFORM = {"fit_contact_edge": None, "track_contact_edge": None}
FIT = {"fit_contact_edge": True, "track_contact_edge": None}
VARIANTS = {
    "penalty": (UNIFORM, {"contact_method": "penalty"}),
    "augmented": (UNIFORM, {}),
    "augmented+fit": (FIT, {}),
    "augmented+track": ({}, {}),
    "augmented-gauss+fit": (FIT, {"contact_points": "gauss"}),
}
CONFINE_VARIANTS = {"track": {}, "fit": FIT}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "target/release/tubemem"))
    ap.add_argument("--out", default=str(ROOT / "runs/convergence"))
    ap.add_argument("--quick", action="store_true", help="16, 32, 64 around only")
    ap.add_argument("--part", default="squeeze,squeeze6,confine",
                    help="which tables: squeeze, squeeze6, confine (comma-separated)")
    ap.add_argument("--variants", default=",".join(VARIANTS),
                    help="the squeeze's contact variants (comma-separated)")
    ap.add_argument("--elements", default="quad4,quad9", help="comma-separated")
    ap.add_argument("--confine-variants", default=",".join(CONFINE_VARIANTS),
                    help="the confinement's mesh variants: track, fit (comma-separated)")
    a = ap.parse_args(argv)
    parts = set(a.part.split(","))
    variants = {k: VARIANTS[k] for k in a.variants.split(",")}
    out = pathlib.Path(a.out)
    fams = {k: v for k, v in (QUICK if a.quick else FAMILIES).items() if k in a.elements.split(",")}
    ref = reference_profile(640, 128)
    ref_half = reference_profile(320, 64)
    ref_err = float(np.abs(np.interp(ref_half[0], *ref) - ref_half[1]).max())
    results = {"reference_profile_self_difference": ref_err, "squeeze": {}, "squeeze6": {}, "confine": {}}
    cmd = " ".join(["scripts/convergence-tables.py"] + (argv if argv is not None else sys.argv[1:]))
    lines = [f"Convergence tables (`{cmd}`): L/R = {LENGTH:g}, ABB N = 30, along = 2.5 × around.",
             "Errors are relative (FE/reference − 1) except the profile's (largest Δλs over the cylinder) and the",
             "penetration's (in R); p is the observed order between a mesh and the one before it.",
             f"The axisymmetric reference (640 + 128 P2 elements) differs from itself at half resolution by {ref_err:.1e} in λs.", ""]
    base = "squeeze_abb30_ls1.3_quad9.toml"
    sq_cols = ["sq_lambda_s", "sq_lambda_z", "sq_chi", "sq_force", "sq_chi_steps", "flat_pressure", "penetration",
               "updates"]
    sq_names = ["λs", "λz", "χ", "force", "χ, worst step", "max abs(p_c/ϖ − 1)", "max penetration", "updates/step"]
    inf_cols = ["w", "lambda_z", "n_z", "profile"]
    for element, arounds in (fams if "squeeze" in parts else {}).items():
        for variant, (mesh, stage) in variants.items():
            ns = arounds if variant != "augmented-gauss+fit" else ([16, 32] if element == "quad9" else [])
            rows = []
            for n in ns:
                d, wall, s, err = run_one(a.bin, out, f"sq13_{element}_{variant}_{n}",
                                          case_text(base, element, n, mesh, stage))
                row = {"around": n, "wall_s": wall, "error": err}
                if s is not None:
                    row["equations"] = s["mesh"]["equations"]
                    row.update(squeeze_row(d, s))
                    e_inf = s["stages"][0]["relative_error_vs_gps"]
                    row.update({"w": e_inf["w"], "lambda_z": e_inf["lambda_z"], "n_z": e_inf["n_z"],
                                "profile": profile_error(d, ref)})
                rows.append(row)
            if not rows:
                continue
            results["squeeze"].setdefault(element, {})[variant] = rows
            if variant == "augmented+track":
                lines += table(f"{element}: inflation to λs* = 1.3 (against GPS) and its end-cap profile",
                               rows, inf_cols, ["ϖ", "λz", "N_z", "profile max Δλs"])
            lines += table(f"{element}, squeeze to ρ = 0.8, {variant}: the end against the section at the FE's pressure",
                           rows, sq_cols, sq_names)
    for element, arounds in (fams if "squeeze6" in parts else {}).items():
        rows = []
        for n in arounds:
            d, wall, s, err = run_one(a.bin, out, f"sq6_{element}_{n}",
                                      case_text("squeeze_abb30_ls6.0.toml", element, n))
            row = {"around": n, "wall_s": wall, "error": err}
            if s is not None:
                row["equations"] = s["mesh"]["equations"]
                row.update(squeeze_row(d, s))
            rows.append(row)
        results["squeeze6"][element] = rows
        lines += table(f"{element}, λs* = 6 squeezed to ρ = 3 (default contact, uniform mesh)", rows, sq_cols, sq_names)
    c_cols = ["lambda_s", "lambda_z", "wall_force_end", "wall_force_steps", "penetration", "updates"]
    c_names = ["λs", "λz", "wall force, end", "wall force, worst step", "max penetration", "updates/step"]
    confine = [("channel_abb30_ls1.3.toml", "channel"), ("vgroove_abb30_ls1.3.toml", "V-groove")]
    for base, label in (confine if "confine" in parts else []):
        for element, arounds in fams.items():
            for variant, mesh in ((k, CONFINE_VARIANTS[k]) for k in a.confine_variants.split(",")):
                rows = []
                for n in arounds:
                    d, wall, s, err = run_one(a.bin, out, f"{label}_{element}_{variant}_{n}",
                                              case_text(base, element, n, mesh))
                    row = {"around": n, "wall_s": wall, "error": err}
                    if s is not None:
                        row["equations"] = s["mesh"]["equations"]
                        row.update(confine_row(d, s))
                    rows.append(row)
                results["confine"].setdefault(label, {}).setdefault(element, {})[variant] = rows
                lines += table(f"{element}, {label} ({variant}): the end against the section in the walls at the "
                               "FE's pressure", rows, c_cols, c_names)
    rows = []
    for n in ([32, 64] if "confine" in parts else []):
        d, wall, s, err = run_one(a.bin, out, f"V-groove_quad9_{n}_lr40",
                                  case_text("vgroove_abb30_ls1.3.toml", "quad9", n, length=40.0))
        row = {"around": n, "wall_s": wall, "error": err}
        if s is not None:
            row["equations"] = s["mesh"]["equations"]
            row.update(confine_row(d, s))
        rows.append(row)
    if rows:
        results["confine"]["V-groove L/R = 40"] = {"quad9": rows}
        lines += table("quad9, V-groove at L/R = 40 (along = 5 × around, tracked)", rows, c_cols, c_names)
    text = "\n".join(lines)
    print(text)
    out.mkdir(parents=True, exist_ok=True)
    (out / "tables.md").write_text(text + "\n")
    (out / "tables.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
