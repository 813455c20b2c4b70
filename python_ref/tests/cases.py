"""The small tube case shared by the Rust and Python tests (`cases/small_abb30_ls1.2.toml`:
L/R = 8, 16 around, 24 along, eighth model, inflated to lambda_s* = 1.2 in 4 steps), split into
its tables, and the squeeze stage the tests append."""
from pathlib import Path

SMALL = (Path(__file__).resolve().parents[2] / "cases" / "small_abb30_ls1.2.toml").read_text()
GEOMETRY = SMALL[: SMALL.index("[mesh]")]
GENERATED_MESH = SMALL[SMALL.index("[mesh]") : SMALL.index("[[stage]]")]
INFLATE = SMALL[SMALL.index("[[stage]]") :]
SQUEEZE = """
[[stage]]
kind = "squeeze"
target_rho = 1.0
steps = 4
"""
