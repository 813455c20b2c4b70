#!/usr/bin/env python3
"""Report cycles between the top-level modules of each crate under crates/, and between the
files of each module folder.

A module M depends on N when a line of M's code (comments and doc comments left out) names
`crate::N` or `use super::N` from a direct child, or `use crate::{N, ...}`. The crate root
(lib.rs) is left out: it declares every module. Inside a module folder D, each file (and each
subfolder, as one unit) depends on a sibling N when its code names `super::N` (or `use
super::{N, ...}`) or `crate::<D's path>::N`; the folder's mod.rs is left out, as the crate root
is. Exits 1 if any crate or folder has a cycle.
"""
import re
import sys
from pathlib import Path

root = Path(__file__).resolve().parent.parent / "crates"


def code_lines(path):
    for line in path.read_text().splitlines():
        s = line.strip()
        if s.startswith("//"):
            continue
        yield line.split("//")[0] if "\"" not in line else line


def modules(src):
    mods = {}
    for p in sorted(src.glob("*.rs")):
        if p.name in ("lib.rs", "main.rs"):
            continue
        mods[p.stem] = [p]
    for d in sorted(x for x in src.iterdir() if x.is_dir()):
        mods.setdefault(d.name, []).extend(sorted(d.rglob("*.rs")))
    return mods


def deps(files, names, me):
    out = set()
    for f in files:
        for line in code_lines(f):
            for m in re.finditer(r"crate::(\w+)", line):
                out.add(m.group(1))
            for m in re.finditer(r"use crate::\{([^}]*)\}", line):
                out.update(x.strip().split("::")[0] for x in m.group(1).split(","))
    return {d for d in out if d in names and d != me}


def sccs(graph):
    index, low, stack, on, out, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return out


bad = False
for crate in sorted(p for p in root.iterdir() if (p / "src").is_dir()):
    mods = modules(crate / "src")
    graph = {m: deps(files, mods, m) for m, files in mods.items()}
    for comp in sccs(graph):
        bad = True
        edges = [f"{a}→{b}" for a in comp for b in sorted(graph[a]) if b in comp]
        print(f"{crate.name}: cycle among {', '.join(comp)} ({'; '.join(edges)})")

def file_deps(unit, names, modpath):
    """The siblings that the files of `unit` (a file, or every file of a subfolder) name."""
    out = set()
    for f in unit:
        for line in code_lines(f):
            for m in re.finditer(r"super::(\w+)", line):
                out.add(m.group(1))
            for m in re.finditer(r"use super::\{([^}]*)\}", line):
                out.update(x.strip().split("::")[0] for x in m.group(1).split(","))
            for m in re.finditer(r"crate::" + re.escape(modpath) + r"::(\w+)", line):
                out.add(m.group(1))
    return out & names


for crate in sorted(p for p in root.iterdir() if (p / "src").is_dir()):
    src = crate / "src"
    for d in sorted(x for x in src.rglob("*") if x.is_dir()):
        units = {p.stem: [p] for p in d.glob("*.rs") if p.name != "mod.rs"}
        for sub in (x for x in d.iterdir() if x.is_dir()):
            units[sub.name] = sorted(sub.rglob("*.rs"))
        modpath = d.relative_to(src).as_posix().replace("/", "::")
        names = set(units)
        graph = {n: file_deps(files, names, modpath) - {n} for n, files in units.items()}
        for comp in sccs(graph):
            bad = True
            edges = [f"{a}→{b}" for a in comp for b in sorted(graph[a]) if b in comp]
            print(f"{crate.name}::{modpath}: file cycle among {', '.join(comp)} ({'; '.join(edges)})")
if not bad:
    print("no module cycles, and no cycles between the files of a module")
sys.exit(1 if bad else 0)
