"""Factories of the reliability tests: a tiny biaxial configuration (about 200
grains, 0.2 % of shearing, about a second of simulation), fast stand-ins for the
figures, so that a test can stop a run anywhere and resume it in a few seconds,
the comparison of a resumed run with an uninterrupted one, and small CSV and
LAMMPS dump inputs."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np

#: A particles CSV of five disks, three kinds.
CSV = """\
id,x,y,radius,rotation,kind
1,0.0010,0.0010,0.0005,0.0,0
2,0.0019,0.0010,0.0005,0.1,0
3,0.0010,0.0019,0.0005,0.0,0
4,0.0019,0.0019,0.0004,0.0,1
5,0.0030,0.0015,0.0006,0.0,2
"""


def dump_frame(timestep: int, item: str, columns: str, rows: list[str]) -> str:
    """One frame of a LAMMPS text dump (``item``: ``ATOMS`` or ``ENTRIES``) in a 10 mm box periodic in x."""
    count = "ATOMS" if item == "ATOMS" else "ENTRIES"
    return (f"ITEM: TIMESTEP\n{timestep}\nITEM: NUMBER OF {count}\n{len(rows)}\nITEM: BOX BOUNDS pp ff pp\n"
            f"0.0 0.01\n0.0 0.01\n-0.001 0.001\nITEM: {item} {columns}\n" + "\n".join(rows) + "\n")


ATOM_COLUMNS = "id type x y z radius vx vy"
DUMP = dump_frame(0, "ATOMS", ATOM_COLUMNS, ["1 1 0.0002 0.0050 0 0.0005 0 0", "2 1 0.0096 0.0050 0 0.0005 0 0",
                                             "3 1 0.0050 0.0050 0 0.0005 0 0", "4 1 0.0050 0.0059 0 0.0005 0 0"])
DUMP += dump_frame(100, "ATOMS", ATOM_COLUMNS, ["4 1 0.0050 0.0060 0 0.0005 0.1 0.2", "3 1 0.0050 0.0050 0 0.0005 0 0",
                                                "2 1 0.0096 0.0050 0 0.0005 0 0", "1 1 0.0001 0.0050 0 0.0005 0 0"])

CONTACTS_CSV = """\
i,j,normal_force,shear_force
1,2,0.5,0.1
1,3,0.4,-0.1
2,4,0.3,0.0
"""

LOCAL_DUMP = dump_frame(100, "ENTRIES", "index c_ids[1] c_ids[2] c_pl[1] c_pl[2] c_pl[3] c_pl[4]",
                        ["1 1 2 0.0005 84.5 0.0 -2.0", "2 3 4 0.0010 8.45 1.0 0.0"])


#: ``--set`` overrides of the tiny run (uniform 0.5-1 mm grains in a 10 mm square).
TINY = [
    "sample.grading=uniform_by_number",
    "sample.d_min=0.5mm",
    "sample.d_max=1mm",
    "sample.width=10mm",
    "sample.height=10mm",
    "shear.final_strain=0.002",
    "shear.snapshot_strains=[0, 0.001]",
    "shear.strain_rate=20%/min",
    "run.threads=1",
]

TINY_TOML = """\
[sample]
grading = "uniform_by_number"
d_min = "0.5 mm"
d_max = "1 mm"
width = "10 mm"
height = "10 mm"

[shear]
final_strain = 0.002
snapshot_strains = [0, 0.001]
strain_rate = "20 %/min"

[run]
threads = 1
"""


def tiny_config(*extra: str):
    from grainlab.protocols.biaxial.config import resolve

    return resolve(overrides=[*TINY, *extra])


def fake_curves(timeseries, out, constant_volume=False):
    """Stands in for the macro-curve figures: one small file per run."""
    path = Path(out) / "fig08_stress_ratio.png"
    path.write_bytes(b"stand-in figure of %d records" % len(timeseries["axial_strain"]))
    return [path]


def fake_fabric_figures(run_dir, *args, **kwargs):
    """Stands in for the fabric figures: reads the finished run.h5 as they do."""
    from grainlab.io.hdf5 import read_results

    results = read_results(run_dir)  # refuses anything but a complete run.h5
    numbers = {"snapshots": results.snapshot_names}
    return SimpleNamespace(numbers=SimpleNamespace(summary=lambda: numbers))


def assert_same_run(reference: Path, other: Path, also_differing: set[str] | frozenset[str] = frozenset()) -> None:
    """``other`` is finished, with the reference's records, snapshots and summary, bit for bit
    (the summary but its wall times and the keys ``also_differing``)."""
    from grainlab.io.hdf5 import read_results

    a, b = read_results(reference), read_results(other)
    assert b.status == "complete"
    assert list(a.timeseries) == list(b.timeseries)
    for name in a.timeseries:
        np.testing.assert_array_equal(a.timeseries[name], b.timeseries[name], err_msg=name)
    assert a.snapshot_names == b.snapshot_names
    for name in a.snapshot_names:
        np.testing.assert_array_equal(a.snapshot(name).positions, b.snapshot(name).positions)
    assert (reference / "timeseries.csv").read_text() == (other / "timeseries.csv").read_text()
    sa, sb = (json.loads((p / "summary.json").read_text()) for p in (reference, other))
    timing = {"wall_time_s", "wall_time_by_phase_s", *also_differing}
    assert {k: v for k, v in sa.items() if k not in timing} == {k: v for k, v in sb.items() if k not in timing}
    assert not (other / "checkpoint.h5").exists() and not (other / "run.h5.partial").exists()
