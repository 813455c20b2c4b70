"""Reader of tubemem run folders: steps.csv, summary.json and the VTU series (via meshio)."""

import csv
import json
import pathlib
import xml.etree.ElementTree as ET

import meshio
import numpy as np


def read_steps(run_dir):
    """steps.csv as a dict of numpy arrays (one entry per column); empty fields (the contact
    columns of inflation rows) are NaN."""
    with open(pathlib.Path(run_dir) / "steps.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) if r[k] != "" else np.nan for r in rows]) for k in rows[0]} if rows else {}


def read_summary(run_dir):
    return json.loads((pathlib.Path(run_dir) / "summary.json").read_text())


def read_series(run_dir):
    """[(time, meshio.Mesh)] in the order of tube.pvd."""
    run_dir = pathlib.Path(run_dir)
    root = ET.parse(run_dir / "tube.pvd").getroot()
    return [(float(ds.get("timestep")), meshio.read(run_dir / ds.get("file")))
            for ds in root.iter("DataSet")]
