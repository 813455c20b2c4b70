"""Refinement study of the pressure-regulated squeeze (issue #62), from one command:

    python3 scripts/regulated-study.py [--bin target/release/tubemem] [--out runs/regulated]
        [--around 16,32,64,128] [--length 40]

Each run is `cases/squeeze_abb30_ls1.3_quad9_regulated.toml` (ABB N = 30, 9-node elements,
eighth model, contact edges tracked, λs* = 1.3 held while the plates close to ρ = 0.8) with
`around` varied, `along` = around × length/8 (the shipped case's element aspect) and the tube
`length` (in R; 40 by default, where the end effect at mid-span is below the 128-around error).
Columns: the final mid-span λs, λz, χ and force against the GPS section at the same ρ and the
same (held) pressure, FE/GPS − 1 signed; the largest penetration over the squeeze's steps (in
R); the squeeze's steps; the wall time; and p, the observed order log(e_coarse/e_fine)/log(2)
between consecutive meshes. Results go to OUT/table.md.
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
KEYS = ["lambda_s", "lambda_z", "chi", "force"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "tubemem"))
    ap.add_argument("--out", default=str(ROOT / "runs" / "regulated"))
    ap.add_argument("--around", default="16,32,64,128")
    ap.add_argument("--length", type=float, default=40.0)
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    text = CASE.read_text()
    rows = []
    for n in [int(v) for v in a.around.split(",")]:
        along = round(n * a.length / 8)
        case = (
            text.replace("around = 32", f"around = {n}")
            .replace("along = 80", f"along = {along}")
            .replace("length = 20.0", f"length = {a.length}")
        )
        path = out / f"around{n}.toml"
        path.write_text(case)
        run = out / f"around{n}"
        t0 = time.time()
        subprocess.run(
            [a.bin, "run", str(path), "--out", str(run), "--overwrite"],
            check=True,
            stdout=subprocess.DEVNULL,
        )
        wall = time.time() - t0
        stage = json.loads((run / "summary.json").read_text())["stages"][-1]
        err = stage["relative_error_vs_gps"]
        with open(run / "steps.csv") as f:
            pen = max(
                float(r["penetration"])
                for r in csv.DictReader(f)
                if r["stage"] == "2" and r["penetration"]
            )
        rows.append((n, [err[k] for k in KEYS], pen, stage["final"]["stage_steps"], wall))
    lines = [
        f"Regulated squeeze, L/R = {a.length:g}, 9-node, λs* = 1.3 held, ρ = 0.8: FE/GPS − 1 at the same ρ and pressure",
        "",
        "| around | λs | λz | χ | force | p (λs, λz, χ, force) | max penetration (R) | steps | time (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    prev = None
    for n, e, pen, steps, wall in rows:
        order = (
            ", ".join(f"{math.log(abs(p / c)) / math.log(2):.2f}" for p, c in zip(prev, e))
            if prev
            else ""
        )
        lines.append(
            f"| {n} | {e[0]:+.2e} | {e[1]:+.2e} | {e[2]:+.2e} | {e[3]:+.2e} | {order} | {pen:.1e} | {steps} | {wall:.1f} |"
        )
        prev = e
    table = "\n".join(lines) + "\n"
    (out / "table.md").write_text(table)
    print(table)


if __name__ == "__main__":
    main()
