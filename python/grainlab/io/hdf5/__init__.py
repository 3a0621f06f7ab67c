"""grainlab's HDF5 files: the results file ``run.h5`` and the checkpoint ``checkpoint.h5``.

The reference implementation of the layouts, crash safety and versions that
docs/file-formats.md specifies; every public name is imported from here.

Example
-------
>>> import tempfile, pathlib
>>> from grainlab.snapshot import Snapshot
>>> from grainlab.io.hdf5 import ResultsWriter, read_results, snapshot_name
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> snap = Snapshot.from_geometry([[0.0, 0.0], [2e-3, 0.0]], [1e-3, 1e-3], tolerance=1e-9)
>>> with ResultsWriter(folder / "run.h5", kind="biaxial") as out:
...     out.write_config({"sample": {"porosity": 0.12, "seed": 1}})
...     out.append_timeseries({"axial_strain": 0.0, "stress_ratio": 1.0},
...                           units={"axial_strain": "1", "stress_ratio": "1"})
...     out.append_timeseries({"axial_strain": 0.005, "stress_ratio": 2.5})
...     out.write_snapshot(snapshot_name(0.005), snap)
...     out.write_summary({"peak_stress_ratio": 2.5})
>>> res = read_results(folder / "run.h5")
>>> res.status, res.config["sample"]["porosity"], res.timeseries["stress_ratio"].tolist()
('complete', 0.12, [1.0, 2.5])
>>> res.snapshot_names, res.snapshot("strain_0.0050").n_contacts
(['strain_0.0050'], 1)
"""

from __future__ import annotations

from grainlab.io.hdf5._layout import (
    CHECKPOINT_FORMAT,
    CHECKPOINT_FORMAT_VERSION,
    FORMAT,
    FORMAT_VERSION,
    INTEGER_COLUMNS,
    PARTIAL_SUFFIX,
    Status,
)
from grainlab.io.hdf5.analysis import ANALYSIS_GROUP, AnalysisItem, write_analysis
from grainlab.io.hdf5.checkpoint import Checkpoint, read_checkpoint, write_checkpoint
from grainlab.io.hdf5.errors import (
    CheckpointError,
    IncompleteResultsError,
    ResultsFileError,
    UnsupportedVersionError,
)
from grainlab.io.hdf5.reader import Results, read_hdf5_snapshot, read_results, results_kind
from grainlab.io.hdf5.snapshot import SnapshotInfo, snapshot_name, snapshot_strain
from grainlab.io.hdf5.writer import ResultsWriter

__all__ = [
    "ANALYSIS_GROUP",
    "CHECKPOINT_FORMAT",
    "CHECKPOINT_FORMAT_VERSION",
    "FORMAT",
    "FORMAT_VERSION",
    "INTEGER_COLUMNS",
    "PARTIAL_SUFFIX",
    "AnalysisItem",
    "Checkpoint",
    "CheckpointError",
    "IncompleteResultsError",
    "Results",
    "ResultsFileError",
    "ResultsWriter",
    "SnapshotInfo",
    "Status",
    "UnsupportedVersionError",
    "read_checkpoint",
    "read_hdf5_snapshot",
    "read_results",
    "results_kind",
    "snapshot_name",
    "snapshot_strain",
    "write_analysis",
    "write_checkpoint",
]
