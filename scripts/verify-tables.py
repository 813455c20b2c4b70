"""Print the README's verification table from a `tubemem verify` results.json:

    python3 scripts/verify-tables.py runs/verify-paper/results.json

One row per check (name, kind, status, the measures with their tolerances, wall time), then the
total wall time. Nothing is typed by hand: the README pastes this output.
"""

import json
import sys


def fmt(v):
    if v is None:
        return "—"
    if v == 0 or 1e-3 <= abs(v) < 1e4:
        return f"{v:.4g}"
    return f"{v:.2e}"


def main(path):
    r = json.load(open(path))
    print("| check | kind | status | measured (tolerance) | time |")
    print("|---|---|---|---|---|")
    for c in r["checks"]:
        parts = []
        for m in c["measures"]:
            if m["tolerance"] is None:
                parts.append(f"{m['quantity']} {fmt(m['measured'])}")
            else:
                op = "≥" if m.get("at_least") else "≤"
                parts.append(f"{m['quantity']} {fmt(m['measured'])} ({op} {fmt(m['tolerance'])})")
        if c["kind"] == "end-effect" and c["status"] == "pass":
            parts.insert(0, c["message"])
        cell = ("; ".join(parts) or c["message"]).replace("|", "\\|")
        print(f"| {c['name']} | {c['kind']} | {c['status']} | {cell} | {c['seconds']:.1f} s |")
    print(f"\n{r['verdict'].rstrip('.')} (wall time {r['seconds']:.1f} s).")


if __name__ == "__main__":
    main(sys.argv[1])
