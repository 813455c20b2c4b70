"""Refinement study of the pressure-regulated squeeze (issue #62), from one command:

    python3 scripts/regulated-study.py [--bin target/release/tubemem] [--out runs/regulated]
        [--around 16,32,64,128] [--length 40]

Each run is `cases/squeeze_abb30_ls1.3_quad9_regulated.toml` (ABB N = 30, 9-node elements,
eighth model, contact edges tracked, λs* = 1.3 held while the plates close to ρ = 0.8) with
`around` varied, `along` = around × length/8 (the shipped case's element aspect) and the tube
`length` (in R; 40 by default, where the end effect at mid-span is below the 128-around error).
Columns: the final mid-span λs, λz, χ and force against the GPS section at the same ρ and the
same (held) pressure, FE/GPS − 1 signed; the flat zone's contact pressure against ϖ at the
end (the largest |p_c/ϖ − 1| over its interior at mid-span: in a flat zone p_c = ϖ exactly);
the largest penetration over the squeeze's steps (in R); the squeeze's steps; the wall time; and p, the observed order log(e_coarse/e_fine)/log(2)
between consecutive meshes. Results go to OUT/table.md.

    python3 scripts/regulated-study.py --channel [--around 16,32,64,128] [--length 20]

runs the regulated channel instead (`cases/channel_abb30_ls1.3_regulated.toml`: four walls
moved in from 1.35 R to 1.1 R with the pressure held): the final mid-span λs and λz against the
GPS section in the same walls at the same pressure, the worst wall's force at the end and over
the steps (walls.csv), the largest penetration; results to OUT/channel.md.

    python3 scripts/regulated-study.py --lengths 6,8,10,12,16,20,40,80 [--around 32]

instead measures the end effect: the same case at each length (along = 4 × L/R, the shipped
element length), its mid-span errors against GPS less those of the longest tube (same element
size at mid-span, so the discretization error cancels and what is left is the caps'), and the
least-squares fit ln|e| = a − k L/R over the lengths where |e| > 1e-12. Results go to
OUT/end_effect.md.
"""

import argparse
import csv
import json
import math
import pathlib
import subprocess
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
CASE = ROOT / "cases" / "squeeze_abb30_ls1.3_quad9_regulated.toml"
CHANNEL = ROOT / "cases" / "channel_abb30_ls1.3_regulated.toml"
KEYS = ["lambda_s", "lambda_z", "chi", "force"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "tubemem"))
    ap.add_argument("--out", default=str(ROOT / "runs" / "regulated"))
    ap.add_argument("--around", default="16,32,64,128")
    ap.add_argument("--length", type=float, default=40.0)
    ap.add_argument("--lengths", default=None)
    ap.add_argument("--channel", action="store_true")
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    if a.channel:
        return channel(a, out, CHANNEL.read_text())
    text = CASE.read_text()
    if a.lengths:
        return end_effect(a, out, text)
    rows = []
    for n in [int(v) for v in a.around.split(",")]:
        t0 = time.time()
        stage, run = run_variant(a, out, text, f"around{n}", n, a.length)
        wall = time.time() - t0
        err = stage["relative_error_vs_gps"]
        with open(run / "steps.csv") as f:
            squeeze = [r for r in csv.DictReader(f) if r["stage"] == "2"]
        pen = max(float(r["penetration"]) for r in squeeze if r["penetration"])
        # the flat zone's contact pressure against ϖ at the end (max |p_c/ϖ − 1| over the
        # flat zone's interior at mid-span; empty where no element lies wholly in contact)
        flat = squeeze[-1]["flat_pressure_deviation"]
        flat = float(flat) if flat else float("nan")
        rows.append((n, [err[k] for k in KEYS] + [flat], pen, stage["final"]["stage_steps"], wall))
    lines = [
        f"Regulated squeeze, L/R = {a.length:g}, 9-node, λs* = 1.3 held, ρ = 0.8: FE/GPS − 1 at the same ρ and pressure",
        "",
        "| around | λs | λz | χ | force | flat p_c/ϖ − 1 | p (λs, λz, χ, force) | max penetration (R) | steps | time (s) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    prev = None
    for n, e, pen, steps, wall in rows:
        lines.append(
            f"| {n} | {e[0]:+.2e} | {e[1]:+.2e} | {e[2]:+.2e} | {e[3]:+.2e} | {e[4]:.1e} | {order(prev, e[:4])} | {pen:.1e} | {steps} | {wall:.1f} |"
        )
        prev = e[:4]
    table = "\n".join(lines) + "\n"
    (out / "table.md").write_text(table)
    print(table)


def run_variant(a, out, text, name, n, length):
    """The shipped case with `n` around, `length` (in R) and along = n·length/8 (the shipped
    element aspect), run into OUT/name: its last stage's summary and its folder."""
    # the contact edges take the 32-around tube's node lines (the shipped case's
    # edge_fit_around), so 32, 64 and 128 around are nested; a coarser mesh takes its own
    if n < 32:
        text = text.replace("edge_fit_around = 32\n", "")
    case = (
        text.replace("\naround = 32\n", f"\naround = {n}\n")
        .replace("along = 80", f"along = {round(n * length / 8)}")
        .replace("length = 20.0", f"length = {length}")
    )
    path = out / f"{name}.toml"
    path.write_text(case)
    run = out / name
    subprocess.run(
        [a.bin, "run", str(path), "--out", str(run), "--overwrite"],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    return json.loads((run / "summary.json").read_text())["stages"][-1], run


def order(prev, cur):
    """The observed orders between two meshes' errors (halved element size)."""
    if not prev:
        return ""
    return ", ".join(f"{math.log(abs(p / c)) / math.log(2):.2f}" for p, c in zip(prev, cur))


def channel(a, out, text):
    rows = []
    for n in [int(v) for v in a.around.split(",")]:
        t0 = time.time()
        stage, run = run_variant(a, out, text, f"channel{n}", n, a.length)
        wall = time.time() - t0
        err = stage["relative_error_vs_local"]
        worst_end = max((w["force_error_vs_local"] for w in stage["walls"]), key=abs)
        with open(run / "walls.csv") as f:
            ws = [r for r in csv.DictReader(f) if r["stage"] == "2" and r["local_force"]]
        # the worst step where the walls carry a flat (contact length above zero)
        worst_step = max(
            (float(r["force"]) / float(r["local_force"]) - 1.0
             for r in ws if float(r["local_contact_length"]) > 0.0),
            key=abs,
        )
        pen = max(float(r["penetration"]) for r in ws)
        rows.append((n, [err["lambda_s"], err["lambda_z"], worst_end, worst_step], pen,
                     stage["final"]["stage_steps"], wall))
    lines = [
        f"Regulated channel, L/R = {a.length:g}, 9-node, λs* = 1.3 held, walls 1.35 → 1.1 R: FE/GPS − 1 in the same walls at the same pressure",
        "",
        "| around | λs | λz | wall force (end, worst wall) | wall force (worst step) | p | max penetration (R) | steps | time (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    prev = None
    for n, e, pen, steps, wall in rows:
        lines.append(
            f"| {n} | {e[0]:+.2e} | {e[1]:+.2e} | {e[2]:+.2e} | {e[3]:+.2e} | {order(prev, e)} | {pen:.1e} | {steps} | {wall:.1f} |"
        )
        prev = e
    table = "\n".join(lines) + "\n"
    (out / "channel.md").write_text(table)
    print(table)


def end_effect(a, out, text):
    # one mesh: the --around given, or 32 when it is the list of the refinement study
    ns = [int(v) for v in a.around.split(",")]
    n = ns[0] if len(ns) == 1 else 32
    lengths = [float(v) for v in a.lengths.split(",")]
    errs = {}
    for length in lengths:
        stage, _ = run_variant(a, out, text, f"length{length:g}", n, length)
        errs[length] = [stage["relative_error_vs_gps"][k] for k in KEYS[:3]]
    ref = errs[max(lengths)]
    lines = [
        f"End effect of the regulated squeeze at mid-span ({n} around, 9-node, λs* = 1.3 held, ρ = 0.8): FE/GPS − 1 less the L/R = {max(lengths):g} tube's",
        "",
        "| L/R | λs | λz | χ |",
        "|---|---|---|---|",
    ]
    pts = []
    for length in lengths:
        d = [e - r for e, r in zip(errs[length], ref)]
        lines.append(f"| {length:g} | {d[0]:+.2e} | {d[1]:+.2e} | {d[2]:+.2e} |")
        if length < max(lengths) and abs(d[0]) > 1e-12:
            pts.append((length, math.log(abs(d[0]))))
    if len(pts) >= 2:
        mx = sum(p[0] for p in pts) / len(pts)
        my = sum(p[1] for p in pts) / len(pts)
        k = -sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
        lines += [
            "",
            f"Fit over {len(pts)} lengths: |e(λs)| ≈ {math.exp(my + k * mx):.3g} · exp(−{k:.3f} L/R), "
            f"i.e. exp(−{2 * k:.2f} d/R) in the distance d = L/2 from mid-span to a cap junction",
        ]
    table = "\n".join(lines) + "\n"
    (out / "end_effect.md").write_text(table)
    print(table)


if __name__ == "__main__":
    main()
