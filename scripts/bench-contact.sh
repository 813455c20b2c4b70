#!/usr/bin/env bash
# The contact's cost, side by side in one run: each shipped contact case as shipped (the default
# augmented Lagrangian at the nodes), with `contact_method = "penalty"` on its contact stages
# (the penalty alone at the Gauss points, the same meshes: tracked or fitted as shipped) and,
# where the node lines track the contact edge, fitted once at the end instead (`fit_contact_edge`,
# its locating solve included) and on the uniform mesh, alternated N times; with OLD=path, also
# the case as it was shipped before issue #23's contact (git revision OLD_REV, default a90e174)
# run by that binary. Prints the median wall time per (case, variant) and the augmented/penalty
# ratio.
#   N=5 bash scripts/bench-contact.sh
#   OLD=/path/to/old/tubemem N=5 bash scripts/bench-contact.sh
set -euo pipefail
cd "$(dirname "$0")/.."
N=${N:-5}
NEW=${NEW:-target/release/tubemem}
CASES=${CASES:-"squeeze_abb30_ls1.3_quad9 squeeze_abb30_ls1.3 squeeze_abb30_ls6.0 channel_abb30_ls1.3 vgroove_abb30_ls1.3"}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for c in $CASES; do
  cp "cases/$c.toml" "$work/$c.aug.toml"
  # the penalty alone on every contact stage, the rest unchanged
  python3 - "cases/$c.toml" "$work/$c.pen.toml" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
out = re.sub(r'(\nkind = "(squeeze|confine)"\n)', r'\1contact_method = "penalty"\n', text)
open(sys.argv[2], "w").write(out)
PY
  # the tracked cases also fitted once at the end, and uniform
  if grep -q "^track_contact_edge = true" "cases/$c.toml"; then
    sed 's/^track_contact_edge = true/fit_contact_edge = true/' "cases/$c.toml" > "$work/$c.fit.toml"
    sed 's/^track_contact_edge = true//' "cases/$c.toml" > "$work/$c.uni.toml"
  fi
  if [ -n "${OLD:-}" ]; then git show "${OLD_REV:-a90e174}:cases/$c.toml" > "$work/$c.old.toml" 2>/dev/null || rm -f "$work/$c.old.toml"; fi
done
for r in $(seq "$N"); do
  for c in $CASES; do
    for v in aug fit uni pen old; do
      f="$work/$c.$v.toml"; [ -f "$f" ] || continue
      bin=$NEW; [ "$v" = old ] && bin=$OLD
      s=$(date +%s.%N); "$bin" run "$f" --out "$work/out_${c}_$v" --overwrite >/dev/null 2>&1 || echo "FAILED $c $v" >&2; e=$(date +%s.%N)
      echo "$v $c $(echo "$e - $s" | bc)"
    done
  done
done | python3 -c '
import collections, statistics, sys
d = collections.defaultdict(list)
for line in sys.stdin:
    v, c, t = line.split()
    d[(c, v)].append(float(t))
names = {"aug": "augmented (shipped)", "fit": "augmented, fitted at the end", "uni": "augmented, uniform",
         "pen": "penalty, same mesh", "old": "before (a90e174)"}
for c in dict.fromkeys(k[0] for k in d):
    m = {v: statistics.median(d[(c, v)]) for v in ("aug", "fit", "uni", "pen", "old") if (c, v) in d}
    cells = ", ".join(f"{names[v]} {t:.3f} s" for v, t in m.items())
    ratio = m["aug"] / m["pen"] if "pen" in m else float("nan")
    runs = len(d[(c, "aug")])
    print(f"{c:28s} {cells}; augmented/penalty {ratio:.2f} ({runs} runs each)")
'
