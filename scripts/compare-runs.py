#!/usr/bin/env python3
"""Compare two tubemem run folders number by number: every numeric leaf of summary.json (matched
by key path; a string leaf must be equal) and every steps.csv field (matched by column name).
Prints the largest relative difference |a − b| / max(|a|, |b|) per file and exits 1 if it
exceeds --rtol (default 1e-12: a refactoring must leave the numbers unchanged to this level). Values below 1e-14 in
magnitude, N_sz and the penetration (differences of nearly equal numbers, of natural scale 1 in
R = μH = 1) and the summary's relative errors (scale 1) are compared absolutely.

    python3 scripts/compare-runs.py BEFORE_DIR AFTER_DIR [--rtol 1e-12]
"""
import csv, json, math, sys


def leaves(v, path=()):
    if isinstance(v, dict):
        for k, x in v.items():
            yield from leaves(x, path + (k,))
    elif isinstance(v, list):
        for i, x in enumerate(v):
            yield from leaves(x, path + (i,))
    else:
        yield path, v


ABS_ZERO = 1e-14
# Quantities that are differences of nearly equal numbers, compared absolutely on their natural
# scale, which is 1 in tubemem's units (R = 1, μH = 1): N_sz (zero by symmetry; what is left is
# round-off or discretization shear, ≪ N_s) and the penetration (position − plate, in R).
ABSOLUTE = {"n_sz", "penetration"}


def rel(a, b):
    """Relative difference; values below ABS_ZERO in magnitude (N_sz, which vanishes to
    round-off, ~1e-17) are compared absolutely, as CSVDiff's abs_zero does."""
    if a == b:
        return 0.0
    if max(abs(a), abs(b)) < ABS_ZERO:
        return 0.0
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def main():
    a_dir, b_dir = sys.argv[1], sys.argv[2]
    rtol = float(sys.argv[sys.argv.index("--rtol") + 1]) if "--rtol" in sys.argv else 1e-12
    ignore = {"case", "profile", "target", "error"}
    worst = 0.0
    a = dict(leaves(json.load(open(f"{a_dir}/summary.json"))))
    b = dict(leaves(json.load(open(f"{b_dir}/summary.json"))))
    n = 0
    where = None
    for k, va in a.items():
        if any(p in ignore for p in k if isinstance(p, str)):
            continue
        if k not in b:
            print(f"  summary.json: {'/'.join(map(str, k))} missing after")
            worst = math.inf
            continue
        vb = b[k]
        if isinstance(va, (int, float)) and isinstance(vb, (int, float)) and not isinstance(va, bool):
            # a relative error is itself a difference of nearly equal numbers: compare it
            # absolutely (its own scale is 1)
            if any(isinstance(p, str) and p.startswith("relative_error") for p in k) or k[-1] in ABSOLUTE:
                r = abs(float(va) - float(vb))
            else:
                r = rel(float(va), float(vb))
            n += 1
            if r > worst:
                worst, where = r, k
        elif va != vb:
            print(f"  summary.json: {'/'.join(map(str, k))}: {va!r} vs {vb!r}")
    print(f"  summary.json: {n} numbers, largest relative difference {worst:.2e} at {where}")
    ra = list(csv.DictReader(open(f"{a_dir}/steps.csv")))
    rb = list(csv.DictReader(open(f"{b_dir}/steps.csv")))
    sw, swhere = 0.0, None
    if len(ra) != len(rb):
        print(f"  steps.csv: {len(ra)} rows vs {len(rb)}")
        sw = math.inf
    for i, (x, y) in enumerate(zip(ra, rb)):
        for col, va in x.items():
            vb = y.get(col)
            if vb is None:
                print(f"  steps.csv: column {col} missing after")
                sw = math.inf
                continue
            if va == "" or vb == "":
                if va != vb:
                    print(f"  steps.csv row {i+2} {col}: {va!r} vs {vb!r}")
                    sw = math.inf
                continue
            r = abs(float(va) - float(vb)) if col in ABSOLUTE else rel(float(va), float(vb))
            if r > sw:
                sw, swhere = r, (i + 2, col)
    print(f"  steps.csv: {len(ra)} rows, largest relative difference {sw:.2e} at {swhere}")
    worst = max(worst, sw)
    sys.exit(0 if worst <= rtol else 1)


main()
