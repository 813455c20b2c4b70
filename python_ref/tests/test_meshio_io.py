"""meshio round trips into `tubemem run`: the reference mesh of a run, written by tubemem as VTU,
read by meshio, passed through Gmsh's .msh format and converted to tubemem JSON, gives the same
run as the generated mesh. The nodes are the same, in the same order, but the coordinates pass
through two text formats, which may round the last digit (measured: results differ by 2e-15
relative), so the runs must agree to 1e-12. Bad meshes are refused with a clear message."""

import subprocess

import meshio
import numpy as np
import pytest

from cases import GENERATED_MESH, GEOMETRY
from cases import INFLATE as STAGE
from tubemem_ref import meshio_io, runs





def run(exe, case_text, folder):
    folder.mkdir(parents=True, exist_ok=True)
    case = folder / "case.toml"
    case.write_text(case_text)
    return subprocess.run([exe, "run", str(case), "--out", str(folder / "out")], capture_output=True, text=True)


@pytest.mark.parametrize("element,cell", [("quad4", "quad"), ("quad9", "quad9")])
def test_gmsh_round_trip_reproduces_the_generated_run(tmp_path, tubemem_exe, element, cell):
    mesh = GENERATED_MESH + f'element = "{element}"\n'
    gen = run(tubemem_exe, GEOMETRY + mesh + STAGE, tmp_path / "gen")
    assert gen.returncode == 0, gen.stderr
    ref = meshio.read(tmp_path / "gen/out/vtu/step_00000.vtu")
    assert list(ref.cells_dict) == [cell]
    meshio.write(tmp_path / "ref.msh", meshio.Mesh(ref.points, [(cell, ref.cells_dict[cell])]), file_format="gmsh22")
    (tmp_path / "user").mkdir()
    nodes, quads = meshio_io.to_tubemem_json(tmp_path / "ref.msh", tmp_path / "user/mesh.json", symmetry="eighth")
    assert quads.shape == ref.cells_dict[cell].shape
    usr = run(tubemem_exe, GEOMETRY + '[mesh]\nfile = "mesh.json"\n' + STAGE, tmp_path / "user")
    assert usr.returncode == 0, usr.stderr
    a, b = runs.read_steps(tmp_path / "gen/out"), runs.read_steps(tmp_path / "user/out")
    for k in ["w", "lambda_s", "lambda_z", "n_s", "n_z", "volume"]:
        np.testing.assert_allclose(b[k], a[k], rtol=1e-12, atol=1e-14)


def test_bad_meshes_are_refused(tmp_path, tubemem_exe):
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    with pytest.raises(ValueError, match="triangle"):
        meshio_io.to_tubemem_json(meshio.Mesh(pts, [("triangle", [[0, 1, 2]])]), tmp_path / "t.json")
    with pytest.raises(ValueError, match="mixes"):
        meshio_io.to_tubemem_json(meshio.Mesh(np.zeros((9, 3)), [("quad", [[0, 1, 2, 3]]), ("quad9", [list(range(9))])]), tmp_path / "m.json")
    gen = run(tubemem_exe, GEOMETRY + GENERATED_MESH + STAGE, tmp_path / "gen")
    assert gen.returncode == 0, gen.stderr
    ref = meshio.read(tmp_path / "gen/out/vtu/step_00000.vtu")
    quads = ref.cells_dict["quad"].copy()
    quads[7] = quads[7][[0, 3, 2, 1]]  # invert element 7
    (tmp_path / "bad").mkdir()
    meshio_io.to_tubemem_json(meshio.Mesh(ref.points, [("quad", quads)]), tmp_path / "bad/mesh.json", symmetry="eighth")
    out = run(tubemem_exe, GEOMETRY + '[mesh]\nfile = "mesh.json"\n' + STAGE, tmp_path / "bad")
    assert out.returncode != 0 and "panicked" not in out.stderr
    assert "inverted" in out.stderr and "element 7" in out.stderr, out.stderr
