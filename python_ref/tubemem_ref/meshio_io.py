"""Convert any meshio-readable quadrilateral surface mesh (Gmsh .msh, VTU, ...) into the JSON mesh
that `tubemem run` reads through `[mesh] file = "..."`:

    {"nodes": [[x, y, z], ...], "quads": [[a, b, c, d], ...], "symmetry": "none", "plugs": []}

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
    """(nodes (n, 3), quads (m, 4)) of a meshio.Mesh; any other surface cell type is an error."""
    quads = []
    for block in mesh.cells:
        if block.type == "quad":
            quads.append(np.asarray(block.data, dtype=np.int64))
        elif block.type in ("triangle", "triangle6", "quad8", "quad9", "polygon"):
            raise ValueError(f"tubemem needs bilinear quadrilaterals; the mesh has '{block.type}' cells")
    if not quads:
        raise ValueError("the mesh has no 'quad' cells")
    pts = np.asarray(mesh.points, dtype=float)
    if pts.shape[1] == 2:
        pts = np.column_stack([pts, np.zeros(len(pts))])
    return pts[:, :3], np.concatenate(quads)


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
