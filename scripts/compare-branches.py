"""Pressure at equal volume on two runs' paths: the symmetric branch against the branch a
`branch = "follow-stable"` run switched to (README, "Bulging").

    python3 scripts/compare-branches.py SYMMETRIC_RUN SWITCHED_RUN

For each run, the steps.csv rows past the pressure maximum (volume rising along them) give the
pressure as a piecewise-linear function of the enclosed volume; on the volumes both runs cover,
it prints the largest |ϖ_switched/ϖ_symmetric − 1|, where it is, and each run's plateau
(smallest pressure past the maximum) and its negative-pivot counts under volume control.
"""
import csv
import sys

import numpy as np


def path(run):
    with open(f"{run}/steps.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    w = np.array([float(r["w"]) for r in rows])
    v = np.array([float(r["volume"]) for r in rows])
    neg = [r["negative_pivots_volume"] for r in rows]
    k = int(np.argmax(w))
    # past the maximum: keep the steps where the volume rises (a monotone piece to interpolate)
    keep = [k]
    for i in range(k + 1, len(v)):
        if v[i] > v[keep[-1]]:
            keep.append(i)
    return w, v, neg, np.array(keep)


def main(sym, sw):
    ws, vs, ns, ks = path(sym)
    ww, vw, nw, kw = path(sw)
    lo, hi = max(vs[ks].min(), vw[kw].min()), min(vs[ks].max(), vw[kw].max())
    grid = np.linspace(lo, hi, 400)
    ps = np.interp(grid, vs[ks], ws[ks])
    pw = np.interp(grid, vw[kw], ww[kw])
    d = pw / ps - 1.0
    i = int(np.argmax(np.abs(d)))
    print(f"volumes compared: {lo:.1f} to {hi:.1f} (400 points)")
    print(f"largest |ϖ_switched/ϖ_symmetric − 1| = {abs(d[i]):.3e} at V = {grid[i]:.1f}")
    print(f"mean (ϖ_switched/ϖ_symmetric − 1) = {d.mean():+.3e}")
    for name, w, neg, k in [("symmetric", ws, ns, ks), ("switched", ww, nw, kw)]:
        past = w[k[0]:]
        counts = [int(n) for n in neg[k[0]:] if n != ""]
        print(f"{name}: plateau min ϖ = {past.min():.9f}; steps past the maximum with negative "
              f"pivots under volume control: {sum(c > 0 for c in counts)} of {len(counts)}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
