"""Mid-span λs and λz of a CalculiX run of a `tubemem export` deck (plain Python, no numpy).

    python3 scripts/ccx_midspan.py DECK.inp RESULTS.dat

The deck's node sets MIDSPAN (the ring at z = 0) and NEXT (the next ring of element corners)
are printed by *NODE PRINT at the end of each step; the last print of each is read. λs is the
length ratio of the MIDSPAN polygon (as tubemem's 4-node extraction), λz the mean stretch of
the meridian segments from each MIDSPAN node to the NEXT node at the same angle (the axial
stretch at ΔZ/2, as tubemem's). Prints one JSON object {"lambda_s": …, "lambda_z": …}.
"""

import json
import math
import re
import sys


def read_nodes(deck):
    text = open(deck).read()
    block = text.split("*NODE, NSET=NALL\n", 1)[1].split("*", 1)[0]
    nodes = {}
    for line in block.strip().splitlines():
        f = [v.strip() for v in line.split(",")]
        nodes[int(f[0])] = tuple(float(v) for v in f[1:4])
    return nodes


def last_prints(dat):
    text = open(dat).read()
    pat = re.compile(r"displacements \(vx,vy,vz\) for set (\w+) and time\s+(\S+)\s*\n\s*\n((?:\s*\d+(?:\s+\S+){3}\s*\n)+)")
    out, times = {}, {}
    for name, time, body in pat.findall(text):
        out[name] = {int(l.split()[0]): tuple(float(v) for v in l.split()[1:4]) for l in body.strip().splitlines()}
        times[name] = float(time)
    for name, t in times.items():
        if t < 1.0 - 1e-9:
            raise SystemExit(f"{dat}: the last print of {name} is at time {t} of the step, not 1: CalculiX stopped before the end of the load step")
    return out


def main(deck, dat):
    x0 = read_nodes(deck)
    u = last_prints(dat)
    if "MIDSPAN" not in u or "NEXT" not in u:
        raise SystemExit(f"{dat}: no *NODE PRINT of MIDSPAN and NEXT (did CalculiX finish the step?)")
    cur = {n: tuple(a + b for a, b in zip(x0[n], d)) for s in u.values() for n, d in s.items()}
    ang = lambda n: math.atan2(x0[n][1], x0[n][0])
    ring = sorted(u["MIDSPAN"], key=ang)
    dist = lambda p, q: math.dist(p, q)
    length = sum(dist(cur[a], cur[b]) for a, b in zip(ring, ring[1:]))
    ref = sum(dist(x0[a], x0[b]) for a, b in zip(ring, ring[1:]))
    nxt = {round(ang(n), 9): n for n in u["NEXT"]}
    lz = [dist(cur[n], cur[nxt[round(ang(n), 9)]]) / dist(x0[n], x0[nxt[round(ang(n), 9)]]) for n in ring]
    print(json.dumps({"lambda_s": length / ref, "lambda_z": sum(lz) / len(lz)}))


if __name__ == "__main__":
    main(*sys.argv[1:3])
