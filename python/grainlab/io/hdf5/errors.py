"""The errors of grainlab's HDF5 files (all :class:`grainlab.io.FileFormatError`, a ``ValueError``)."""

from __future__ import annotations

import os
from pathlib import Path

from grainlab.io._table import FileFormatError

__all__ = [
    "CheckpointError",
    "IncompleteResultsError",
    "ResultsFileError",
    "UnsupportedVersionError",
]


class ResultsFileError(FileFormatError):
    """A grainlab HDF5 file that cannot be read: missing, corrupt, or not of the expected kind."""

    def __init__(self, path: str | os.PathLike[str], problem: str) -> None:
        super().__init__(Path(path), None, problem)


class IncompleteResultsError(ResultsFileError):
    """A results file whose ``status`` is not ``"complete"`` (pass ``allow_incomplete=True``)."""


class UnsupportedVersionError(ResultsFileError):
    """A file whose ``format_version`` this grainlab cannot read (written by a newer one)."""


class CheckpointError(ResultsFileError):
    """A checkpoint that is missing, corrupt (checksum mismatch) or of an unknown format."""
