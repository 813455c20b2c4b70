"""The squeeze's L/R table with `tubemem.sweep`: the shipped case (ABB 𝒩 = 30, λs* = 1.3, gas
closed in, squeezed to ρ = 0.8, 64 around, 8 elements per R along) at L/R = 5, 10, 20, 40, run
once in one local process and once on a Dask LocalCluster of 2 workers; prints the mid-span ϖ
and plate force against the GPS flattening at ρ = 0.8, and both wall times.

    .venv/bin/python crates/py/examples/sweep_lr.py [OUT_DIR]

On a real cluster, pass `client=dask.distributed.Client("tcp://scheduler:8786")` instead: the
workers need `tubemem` installed (`pip install ./crates/py`) and a shared OUT_DIR.
"""

import pathlib
import sys
import tempfile
import time
import tomllib

import dask.distributed as distributed

import tubemem

def main():
    ROOT = pathlib.Path(__file__).resolve().parents[3]
    base = tomllib.loads((ROOT / "cases" / "squeeze_abb30_ls1.3.toml").read_text())
    lengths = [5.0, 10.0, 20.0, 40.0]
    cases = []
    for L in lengths:
        t = dict(base)
        t["geometry"] = dict(base["geometry"], length=L)
        t["mesh"] = dict(base["mesh"], along=int(8 * L))
        cases.append(tubemem.Case(**t))
    params = [{"L/R": L} for L in lengths]
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(tempfile.mkdtemp())

    t0 = time.perf_counter()
    serial = tubemem.sweep(cases, str(out / "serial"), params=params, processes=1)
    t_serial = time.perf_counter() - t0
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        t0 = time.perf_counter()
        dask = tubemem.sweep(cases, str(out / "dask"), params=params, client=client)
        t_dask = time.perf_counter() - t0

    last = dask[dask["step"] == dask.groupby("case")["step"].transform("max")].sort_values("case")
    print("| L/R | ϖ FE | ϖ GPS | FE − GPS | force FE | force GPS | FE − GPS |")
    print("|---|---|---|---|---|---|---|")
    for _, r in last.iterrows():
        print(
            f"| {r['L/R']:g} | {r['w']:.5f} | {r['gps_w']:.5f} | {100 * (r['w'] / r['gps_w'] - 1):+.2f} % "
            f"| {r['force']:.5f} | {r['gps_force']:.5f} | {100 * (r['force'] / r['gps_force'] - 1):+.2f} % |"
        )
    same = serial.drop(columns="error").equals(dask.drop(columns="error"))
    print(f"\nwall time: one process {t_serial:.1f} s, Dask LocalCluster (2 workers) {t_dask:.1f} s; results identical: {same}")


# the guard matters: Dask starts its worker processes by importing this file again
if __name__ == "__main__":
    main()
