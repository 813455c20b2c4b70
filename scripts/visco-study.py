"""The viscoelastic GPS closed form's own accuracy and the squeeze cycle's loop (issue #63),
from one command:

    python3 scripts/visco-study.py [--bin target/release/tubemem] [--out runs/visco]

Writes OUT/visco.md with three tables, every run a `tubemem gps history` (ABB N = 30, Prony
g = (0.3, 0.2), tau = (1, 10)):

1. the observed temporal order: the end state with 32, 64, 128, 256 fixed steps per segment
   (`--steps`) against 16384, for a ramped creep (pressure 0 -> 0.3 over 1, held 20: a smooth
   history) and a squeeze-hold-release cycle (inflated to lambda_s = 1.3 and held 200; plates to
   rho = 1.0 in 3, held 5, released in 3, gas closed: contact begins at a segment's start and
   ends inside a step);
2. the error estimate's honesty: `--tolerance` 1e-6, 1e-8, 1e-10 on the cycle, the steps taken,
   the estimate, and the true error against a 65536-step run;
3. the force-gap loop's area (the plates' work over the cycle) against the squeeze time T,
   without a hold and with the plates held 5 at rho = 1.0 (tolerance 1e-9).
"""

import argparse
import json
import math
import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parent.parent
LAW = ["--material", "abb", "--kuhn", "30", "--prony", "0.3:1,0.2:10"]
CREEP = ["--control", "pressure", "--to", "0.3", "--ramp", "1", "--hold", "20"]


def cycle(t=3.0, hold=5.0):
    extra = ["--plates-hold", str(hold)] if hold > 0 else []
    return ["--control", "stretch", "--to", "1.3", "--hold", "200", "--plates-to", "1.0",
            "--squeeze-time", str(t), *extra, "--release"]


def run(binary, args):
    out = subprocess.run([binary, "gps", "history", *LAW, *args, "--json"], check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "tubemem"))
    ap.add_argument("--out", default=str(ROOT / "runs" / "visco"))
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    lines = ["Observed temporal order of the GPS DAE (end state against 16384 steps per segment; "
             "p between consecutive step counts)", "",
             "| history | steps | λs error | p | λz or loop-area error | p |", "|---|---|---|---|---|---|"]
    for name, args, key in [("creep (smooth)", CREEP, "lambda_z"), ("squeeze–hold–release", cycle(), "loop_area")]:
        ref = run(a.bin, [*args, "--steps", "16384"])
        prev = None
        for n in [32, 64, 128, 256]:
            s = run(a.bin, [*args, "--steps", str(n)])
            e = (abs(s["lambda_s"] - ref["lambda_s"]), abs(s[key] - ref[key]))
            p = ["", ""] if prev is None else [f"{math.log2(prev[i] / e[i]):.2f}" for i in range(2)]
            label = "λz" if key == "lambda_z" else "loop area"
            lines.append(f"| {name} | {n} | {e[0]:.2e} | {p[0]} | {e[1]:.2e} ({label}) | {p[1]} |")
            prev = e
    lines += ["", "The error estimate against the true error (squeeze–hold–release cycle, against 65536 steps)", "",
              "| tolerance | steps per segment | estimate | true error (λs, ϖ, λz, force, loop area) |", "|---|---|---|---|"]
    ref = run(a.bin, [*cycle(), "--steps", "65536"])
    for tol in ["1e-6", "1e-8", "1e-10"]:
        s = run(a.bin, [*cycle(), "--tolerance", tol])
        true = max(abs(s[k] - ref[k]) for k in ["lambda_s", "w", "lambda_z", "force", "loop_area"])
        lines.append(f"| {tol} | {s['steps_per_segment']} | {s['error_estimate']:.2e} | {true:.2e} |")
    lines += ["", "The force–gap loop's area (the plates' work per plate and unit length over the cycle, πμHR) against the squeeze time T (τ₁ = 1, τ₂ = 10)", "",
              "| T | loop area, no hold | loop area, held 5 at ρ = 1.0 |", "|---|---|---|"]
    for t in [0.001, 0.1, 0.3, 1, 3, 10, 30, 100, 1000, 10000]:
        s0 = run(a.bin, [*cycle(t, 0.0), "--tolerance", "1e-9"])
        s5 = run(a.bin, [*cycle(t), "--tolerance", "1e-9"])
        lines.append(f"| {t:g} | {s0['loop_area']:.4e} | {s5['loop_area']:.4e} |")
    text = "\n".join(lines) + "\n"
    (out / "visco.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
