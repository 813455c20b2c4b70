import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def tubemem_exe():
    """Path of the tubemem binary (TUBEMEM_BIN, else target/release/tubemem, built if missing)."""
    exe = os.environ.get("TUBEMEM_BIN") or str(ROOT / "target" / "release" / "tubemem")
    if not pathlib.Path(exe).exists():
        subprocess.run(["cargo", "build", "--release", "-p", "tubemem-cli"], cwd=ROOT, check=True)
    return exe


@pytest.fixture(scope="session")
def tubemem(tubemem_exe):
    """Run the tubemem binary (TUBEMEM_BIN, else target/release/tubemem) and parse its JSON."""
    def run(*args):
        out = subprocess.run([tubemem_exe, *map(str, args)], capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    return run
