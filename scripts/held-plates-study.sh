#!/usr/bin/env bash
# The inflation between fixed plates (issue #62): the shipped case's last stage continued by
# arc length past the FE's pressure maximum, on finer meshes and longer tubes; prints the
# located maximum against the closed form's critical pressure ϖc(ρ = 0.8) for each.
# Usage: scripts/held-plates-study.sh [out-dir]   (about 12 min on 2 cores)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$(mktemp -d)}"
mkdir -p "$out"
bin="$here/target/release/tubemem"
[ -x "$bin" ] || cargo build --release -p tubemem-cli --manifest-path "$here/Cargo.toml"
base="$here/cases/inflate_nh_between_plates_quad9.toml"
echo "around along L/R  located maximum"
for v in "16 40 20" "32 80 20" "64 160 20" "32 160 40" "32 320 80"; do
  set -- $v
  case_file="$out/held_$1_$3.toml"
  sed -e "s/^around = 32/around = $1/" -e "s/^along = 80/along = $2/" \
      -e "s/^length = 20.0/length = $3.0/" "$base" |
    python3 -c 'import sys; s=sys.stdin.read(); i=s.rindex("control = \"pressure\"\ntarget_pressure = 1.3"); print(s[:i]+"control = \"arc-length\"\ntarget_pressure = 1.5"+s[i+len("control = \"pressure\"\ntarget_pressure = 1.3"):], end="")' \
    > "$case_file"
  "$bin" run "$case_file" --out "$out/run_$1_$3" > "$out/log_$1_$3.txt" 2>&1 || true
  echo "$v  $(grep '◆' "$out/log_$1_$3.txt" | head -1 | sed 's/.*load maximum) //')"
done
