"""Runs per minute of a small case (the atlas's and the sweeps' regime), in-process through the
Python API and as separate `tubemem run` processes:

    .venv/bin/python scripts/bench-small-runs.py [CASE] [N]     (default cases/small_abb30_ls1.2.toml, 40)

The first in-process run is reported apart (it pays the one-time costs); the rest give the
median. Compare two builds by running it with each build's interpreter, interleaved.
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time

import tubemem

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
case_path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "cases", "small_abb30_ls1.2.toml")
n = int(sys.argv[2]) if len(sys.argv) > 2 else 40
exe = os.environ.get("TUBEMEM", os.path.join(ROOT, "target", "release", "tubemem"))

with tempfile.TemporaryDirectory() as tmp:
    case = tubemem.Case.read(case_path)
    t = []
    for _ in range(n):
        s = time.perf_counter()
        tubemem.run(case, os.path.join(tmp, "py"), overwrite=True)
        t.append(time.perf_counter() - s)
    m = statistics.median(t[1:])
    print(f"in-process: first {t[0] * 1e3:.1f} ms, then median {m * 1e3:.2f} ms = {60 / m:.0f} runs/min")
    t = []
    for _ in range(n):
        s = time.perf_counter()
        subprocess.run([exe, "run", case_path, "--out", os.path.join(tmp, "cli"), "--overwrite"],
                       capture_output=True, check=True)
        t.append(time.perf_counter() - s)
    m = statistics.median(t)
    print(f"processes:  median {m * 1e3:.2f} ms = {60 / m:.0f} runs/min ({exe})")
