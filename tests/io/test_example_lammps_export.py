"""examples/12_lammps_export.py: a small packing sheared in grainlab and, when it is
installed, in LAMMPS on 2 MPI processes from the exported deck."""

from __future__ import annotations

import contextlib
import io
import runpy
from pathlib import Path

import numpy as np

from grainlab.io.lammps_input import find_lammps

NAME = "12_lammps_export.py"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / NAME


def test_example_12_lammps_export(tmp_path):
    module = runpy.run_path(str(EXAMPLE), run_name="example")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        result = module["main"](tmp_path, disks=300, strain=0.1)
    assert (tmp_path / "in.grainlab").is_file() and (tmp_path / "data.grainlab").is_file()
    assert "not carried: the contacts' shear springs" in printed.getvalue()
    ours = result["grainlab"]
    assert ours.shape == (2, 2) and np.all(ours[:, 0] > 0.2)  # the shear mobilised friction
    if find_lammps() is None:
        assert "LAMMPS not found" in printed.getvalue()
        return
    # a shear strain of 0.1 is early: measured differences 0.009 (ratio) and 0.03 (Z)
    assert np.all(np.abs(result["lammps"] - ours) < [0.05, 0.08]), (ours, result["lammps"])
