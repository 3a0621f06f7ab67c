"""grainlab's HDF5 files: the results file ``run.h5`` and the checkpoint ``checkpoint.h5``.

The layouts are specified, group by group and attribute by attribute, in
``docs/file-formats.md``; this module is their reference implementation.

Results file (``format = "grainlab-results"``, ``format_version = 3``)
    :class:`ResultsWriter` creates it while a run goes on; :func:`read_results`
    loads it as a :class:`Results`. It holds the resolved configuration,
    the time series (one appendable float64 column per measurement), full
    :class:`~grainlab.snapshot.Snapshot` objects, a summary and wall time per
    phase. Version 2 adds the analysis group (:mod:`grainlab.io.hdf5.analysis`):
    products of the analysis stored with the run, added to a complete file by
    :func:`write_analysis`. Version 3 stores each snapshot's grains (rigid
    bodies: the grain of every particle, each grain's centroid and angle) one
    row per grain (:mod:`grainlab.io.hdf5.snapshot`).

Crash safety
    The writer works on ``run.h5.partial`` with root attribute
    ``status = "running"``; :meth:`ResultsWriter.finalize` sets
    ``status = "complete"``, closes and fsyncs the file and renames it to
    ``run.h5`` (:func:`os.replace`). A killed run therefore never leaves a
    ``run.h5`` that looks complete, and :meth:`ResultsWriter.resume` continues
    the partial file from a checkpoint. Readers refuse any file whose status
    is not ``"complete"`` unless called with ``allow_incomplete=True``.

Checkpoints (``format = "grainlab-checkpoint"``, ``format_version = 1``)
    :func:`write_checkpoint` stores the engine's opaque state bytes
    (:meth:`grainlab.Simulation.to_bytes`), the protocol's state as JSON and
    optional arrays, each with its SHA-256; the file is written to a
    temporary name, fsynced and renamed. :func:`read_checkpoint` verifies
    every checksum.

Versions
    Every reader dispatches on the file's ``format_version`` through a table
    of readers (``reader._READERS_BY_VERSION``,
    ``checkpoint._CHECKPOINT_READERS_BY_VERSION``); a later layout adds an
    entry and keeps the version-1 reader, so old files stay readable. A file
    newer than this grainlab raises :class:`UnsupportedVersionError` naming
    its version.

Modules
    ``_layout`` what both files share (format names and versions, the HDF5
    features used, name checks, JSON text and groups, opening a file with its
    format and version checked); ``errors`` the errors; ``snapshot`` one
    snapshot as a group and :func:`snapshot_name`; ``writer``
    :class:`ResultsWriter`; ``reader`` :func:`read_results` and
    :func:`read_hdf5_snapshot`; ``checkpoint`` the checkpoint. Every public
    name is imported from ``grainlab.io.hdf5`` itself.

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
