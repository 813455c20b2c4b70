#!/usr/bin/env bash
# Time two tubemem binaries side by side: OLD and NEW run each case alternately N times (and the
# main job with MAIN=1); prints the median wall time per (case, binary).
#   OLD=/path/to/old/tubemem NEW=target/release/tubemem N=7 MAIN=1 \
#     bash scripts/compare-binaries.sh squeeze_abb30_ls1.3 inflate_abb30_ls1.3
set -euo pipefail
cd "$(dirname "$0")/.."
N=${N:-5}
# The main job runs in its own folder, so a relative OLD/NEW must be made absolute first.
OLD=$(realpath "$OLD"); NEW=$(realpath "$NEW")
work=$(mktemp -d)
for r in $(seq "$N"); do
  for b in old new; do
    bin=$OLD; [ "$b" = new ] && bin=$NEW
    for c in "$@"; do
      s=$(date +%s.%N); "$bin" run "cases/$c.toml" --out "$work/${b}_${c}_$r" >/dev/null 2>&1; e=$(date +%s.%N)
      echo "$b $c $(echo "$e - $s" | bc)"
    done
    if [ "${MAIN:-0}" = 1 ]; then
      mkdir -p "$work/mj_$b"; s=$(date +%s.%N); (cd "$work/mj_$b" && "$bin" >/dev/null 2>&1); e=$(date +%s.%N)
      echo "$b mainjob $(echo "$e - $s" | bc)"
    fi
  done
done | python3 -c '
import collections, statistics, sys
d = collections.defaultdict(list)
for line in sys.stdin:
    b, n, t = line.split()
    d[(n, b)].append(float(t))
for (n, b), v in sorted(d.items()):
    print(f"{n:32s} {b}: median {statistics.median(v):.3f} s  ({len(v)} runs)")
'
rm -rf "$work"
