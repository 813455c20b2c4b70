#!/usr/bin/env bash
# Release-mode benchmark of whole FE cases: wall time of `tubemem run` (mesh, solve, all outputs)
# over repeated runs, with the per-stage steps and Newton iterations and the mid-span errors
# against GPS from summary.json.
#   scripts/bench-case.sh [CASE.toml] [RUNS]     (default: cases/squeeze_abb30_ls1.3_lr80.toml, 3)
set -euo pipefail
cd "$(dirname "$0")/.."
CASE=${1:-cases/squeeze_abb30_ls1.3_lr80.toml}
RUNS=${2:-3}
cargo build --release -q -p tubemem-cli
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for i in $(seq 1 "$RUNS"); do
  TIMEFORMAT="run $i: %2R s (wall)"
  time ./target/release/tubemem run "$CASE" --out "$OUT/run" --overwrite > /dev/null
done 2>&1
python3 - "$OUT/run/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
m = s["mesh"]
print(f"mesh: {m['elements']} elements, {m['equations']} equations ({m['symmetry']} model)")
for st in s["stages"]:
    f = st["final"]
    errs = ", ".join(f"{k} {100 * v:+.2f} %" for k, v in st["relative_error_vs_gps"].items())
    print(f"stage {st['index']} ({st['kind']}): {f['stage_steps']} steps, "
          f"{f['stage_newton_iterations']} Newton iterations; vs GPS: {errs}")
PY
