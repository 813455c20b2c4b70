"""Convert any meshio-readable quadrilateral surface mesh (Gmsh .msh, VTU, ...) into the JSON mesh
that `tubemem run` reads through `[mesh] file = "..."`:

    {"nodes": [[x, y, z], ...], "quads": [[a, b, c, d], ...], "symmetry": "none", "plugs": []}

`quad` cells (4-node, bilinear) or `quad9` cells (9-node, biquadratic: corners, mid-sides of
edges 01 12 23 30, centre, which is meshio's and VTK's order) — one kind per mesh.

The tube axis must be z with the mid-span at z = 0; nodes are in the case's length unit (the run
divides them by [geometry] radius). Quads must be oriented counter-clockwise seen from outside;
tubemem checks that (and everything else) and names the offending element.

    python -m tubemem_ref.meshio_io IN.msh OUT.json [--symmetry eighth]
"""

import argparse
import json

import meshio
import numpy as np

SYMMETRIES = ("none", "half", "quarter", "eighth")


def quad_mesh(mesh):
    """(nodes (n, 3), cells (m, 4) or (m, 9)) of a meshio.Mesh: its `quad` or its `quad9` cells;
    any other surface cell type, or both kinds at once, is an error."""
    blocks = {"quad": [], "quad9": []}
    for block in mesh.cells:
        if block.type in blocks:
            blocks[block.type].append(np.asarray(block.data, dtype=np.int64))
        elif block.type in ("triangle", "triangle6", "quad8", "polygon"):
            raise ValueError(f"tubemem needs 4-node (quad) or 9-node (quad9) quadrilaterals; the mesh has '{block.type}' cells")
    kinds = [k for k, v in blocks.items() if v]
    if not kinds:
        raise ValueError("the mesh has no 'quad' or 'quad9' cells")
    if len(kinds) > 1:
        raise ValueError("the mesh mixes 'quad' and 'quad9' cells: one mesh has one kind of element")
    pts = np.asarray(mesh.points, dtype=float)
    if pts.shape[1] == 2:
        pts = np.column_stack([pts, np.zeros(len(pts))])
    return pts[:, :3], np.concatenate(blocks[kinds[0]])


def to_tubemem_json(source, out_path, symmetry="none", plugs=()):
    """Write `source` (a path or a meshio.Mesh) as a tubemem JSON mesh; returns (nodes, quads)."""
    if symmetry not in SYMMETRIES:
        raise ValueError(f"symmetry must be one of {SYMMETRIES}, not {symmetry!r}")
    mesh = meshio.read(source) if not isinstance(source, meshio.Mesh) else source
    nodes, quads = quad_mesh(mesh)
    doc = {
        "nodes": nodes.tolist(),
        "quads": quads.tolist(),
        "symmetry": symmetry,
        "plugs": [list(map(int, r)) for r in plugs],
    }
    with open(out_path, "w") as f:
        json.dump(doc, f)
    return nodes, quads


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source")
    ap.add_argument("out")
    ap.add_argument("--symmetry", default="none", choices=SYMMETRIES)
    a = ap.parse_args(argv)
    nodes, quads = to_tubemem_json(a.source, a.out, a.symmetry)
    print(f"wrote {a.out}: {len(nodes)} nodes, {len(quads)} quads, symmetry {a.symmetry}")


if __name__ == "__main__":
    main()
