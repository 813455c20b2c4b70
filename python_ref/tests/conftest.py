import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def tubemem():
    """Run the tubemem binary (TUBEMEM_BIN, else target/release/tubemem) and parse its JSON."""
    exe = os.environ.get("TUBEMEM_BIN") or str(ROOT / "target" / "release" / "tubemem")
    if not pathlib.Path(exe).exists():
        subprocess.run(["cargo", "build", "--release", "-p", "tubemem-cli"], cwd=ROOT, check=True)

    def run(*args):
        out = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    return run
