"""grainlab's HDF5 files: the results file ``run.h5`` and the checkpoint ``checkpoint.h5``.

The layouts are specified, group by group and attribute by attribute, in
``docs/file-formats.md``; this module is their reference implementation.

Results file (``format = "grainlab-results"``, ``format_version = 1``)
    :class:`ResultsWriter` creates it while a run goes on; :func:`read_results`
    loads it as a :class:`Results`. It holds the resolved configuration,
    the time series (one appendable float64 column per measurement), full
    :class:`~grainlab.snapshot.Snapshot` objects, a summary and wall time per
    phase.

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
    Every reader dispatches on the file's ``format_version`` through
    :data:`_READERS_BY_VERSION`; a later layout adds an entry and keeps the
    version-1 reader, so old files stay readable. A file newer than this
    grainlab raises :class:`UnsupportedVersionError` naming its version.

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

import contextlib
import datetime
import hashlib
import io
import json
import math
import os
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any, Literal, Self

import h5py
import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab._mapping import flatten_keys
from grainlab.io._table import FileFormatError
from grainlab.io.results import (
    CHECKPOINT_FILE,
    RESULTS_FILE,
    fsync_directory,
    fsync_file,
    json_safe,
    write_bytes_atomic,
)
from grainlab.io.walls import WallGeometry, read_wall_group, write_wall_group
from grainlab.snapshot import Snapshot

__all__ = [
    "CHECKPOINT_FORMAT",
    "CHECKPOINT_FORMAT_VERSION",
    "FORMAT",
    "FORMAT_VERSION",
    "PARTIAL_SUFFIX",
    "Checkpoint",
    "CheckpointError",
    "IncompleteResultsError",
    "Results",
    "ResultsFileError",
    "ResultsWriter",
    "SnapshotInfo",
    "UnsupportedVersionError",
    "read_checkpoint",
    "read_hdf5_snapshot",
    "read_results",
    "snapshot_name",
    "write_checkpoint",
]

#: Root attribute ``format`` of a results file.
FORMAT = "grainlab-results"
#: Layout version written by this grainlab.
FORMAT_VERSION = 1
#: Root attribute ``format`` of a checkpoint file.
CHECKPOINT_FORMAT = "grainlab-checkpoint"
#: Checkpoint layout version written by this grainlab.
CHECKPOINT_FORMAT_VERSION = 1
#: Suffix of the file a running writer works on (``run.h5.partial``).
PARTIAL_SUFFIX = ".partial"

Status = Literal["running", "complete", "failed"]
_STATUSES = ("running", "complete", "failed")

# Lowest and highest HDF5 file-format features used: 1.8 structures (dense
# attribute storage, creation order), readable by HDF5 >= 1.8 (MATLAB R2011+).
_LIBVER = ("v108", "v108")
_TIMESERIES_CHUNK = 1024
#: Time series columns stored as int64 (the rest float64): the engine step count.
INTEGER_COLUMNS = ("step",)
_STR = h5py.string_dtype("utf-8")

# Units of the snapshot datasets and of well-known per-particle / per-contact fields.
_SNAPSHOT_UNITS = {
    "positions": "m",
    "radii": "m",
    "ids": "",
    "rotations": "rad",
    "kind": "",
    "contact_i": "",
    "contact_j": "",
    "normal_force": "N",
    "shear_force": "N",
    "contact_normal": "",
    "contact_point": "m",
    "box": "m",
}
_FIELD_UNITS = {
    "overlap": "m",
    "velocity": "m/s",
    "force": "N",
    "angular_velocity": "rad/s",
    "torque": "N m",
    "displacement": "m",
}


# ----------------------------------------------------------------------------- errors
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


# ------------------------------------------------------------------------------ names
def snapshot_name(axial_strain: float, *, digits: int = 4, prefix: str = "strain") -> str:
    """A stable snapshot name from an axial strain (a fraction, not percent).

    ``f"{prefix}_{axial_strain:.{digits}f}"``, with ``-0`` written as ``0``.
    Two strains that round to the same name give the same name, which
    :meth:`ResultsWriter.write_snapshot` refuses unless ``overwrite=True``.

    >>> snapshot_name(0.005), snapshot_name(0.015), snapshot_name(0.1)
    ('strain_0.0050', 'strain_0.0150', 'strain_0.1000')
    >>> snapshot_name(-1e-9), snapshot_name(0.00705, digits=5)
    ('strain_0.0000', 'strain_0.00705')
    """
    value = float(axial_strain)
    if not math.isfinite(value):
        raise ValueError(f"axial_strain: must be finite, got {value!r}")
    if not 0 <= int(digits) <= 12:
        raise ValueError(f"digits: must be in 0..12, got {digits!r}")
    text = f"{value:.{int(digits)}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return f"{prefix}_{text}"


def _check_name(what: str, name: str) -> str:
    if not isinstance(name, str) or not name or name in {".", ".."} or "/" in name:
        raise ValueError(
            f"{what}: {name!r} is not a valid name (a non-empty string without '/', "
            "not '.' or '..')"
        )
    return name


# ------------------------------------------------------------------------------- JSON
def _dumps(value: Any, where: str) -> str:
    # NaN / inf are kept as the tokens NaN / Infinity (Python's json), so they round-trip.
    return json.dumps(json_safe(value, nan="keep", where=where), ensure_ascii=False, allow_nan=True)


def _write_text(group: h5py.Group, name: str, text: str) -> None:
    if name in group:
        del group[name]
    group.create_dataset(name, data=text, dtype=_STR)


def _read_text(dataset: h5py.Dataset) -> str:
    value = dataset.asstr()[()]
    return value if isinstance(value, str) else str(value)


def _readable_attr(value: Any) -> Any:
    """An HDF5 attribute value for a JSON leaf, or None when it has no simple form."""
    if isinstance(value, bool):
        return np.bool_(value)
    if isinstance(value, int):
        return np.int64(value) if -(2**63) <= value < 2**63 else None
    if isinstance(value, float):
        return np.float64(value)
    if isinstance(value, str):
        return value
    if isinstance(value, list) and 0 < len(value) <= 1024:
        if all(isinstance(v, str) for v in value):
            return np.array(value, dtype=_STR)
        if all(isinstance(v, bool) for v in value):
            return np.array(value, dtype=bool)
        if all(isinstance(v, int) and not isinstance(v, bool) for v in value):
            try:
                return np.array(value, dtype=np.int64)
            except OverflowError:
                return None
        if all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
            return np.array(value, dtype=np.float64)
    return None


def _write_json_group(group: h5py.Group, value: Mapping[str, Any], where: str) -> None:
    """``group/json`` holds ``value`` exactly; group attributes give a readable, flat view."""
    if not isinstance(value, Mapping):
        raise TypeError(f"{where}: expected a dict, got {type(value).__name__}")
    plain = json_safe(value, nan="keep", where=where)
    text = json.dumps(plain, ensure_ascii=False, allow_nan=True)
    for key in list(group.attrs):
        del group.attrs[key]
    _write_text(group, "json", text)
    for key, leaf in flatten_keys(plain).items():
        attr = _readable_attr(leaf)
        if key and attr is not None:
            group.attrs[key] = attr


def _read_json(group: h5py.Group | None, path: Path) -> Any:
    if group is None or "json" not in group:
        return {}
    try:
        return json.loads(_read_text(group["json"]))
    except json.JSONDecodeError as error:
        raise ResultsFileError(path, f"{group.name}/json: not valid JSON ({error})") from None


# --------------------------------------------------------------------------- helpers
def _now() -> str:
    return datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")


def _grainlab_version() -> str:
    try:
        import grainlab

        return str(grainlab.__version__)
    except (ImportError, AttributeError):  # the engine may be missing in a pure-Python checkout
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("grainlab")
        except PackageNotFoundError:
            return "unknown"


def _attr_str(attrs: h5py.AttributeManager, key: str, default: str = "") -> str:
    value = attrs.get(key, default)
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace")
    return str(value)


def _resolve_results_path(path: str | os.PathLike[str]) -> Path:
    p = Path(path)
    return p / RESULTS_FILE if p.is_dir() else p


def _partial_of(final: Path) -> Path:
    return final.with_name(final.name + PARTIAL_SUFFIX)


def _open_read(path: Path, error: type[ResultsFileError] = ResultsFileError) -> h5py.File:
    """Open an HDF5 file read-only, turning library errors into a clear message."""
    if not path.exists():
        raise error(path, "file not found")
    if path.is_dir():
        raise error(path, "is a directory, not a file")
    try:
        return h5py.File(path, "r")
    except OSError as first:
        if "lock" in str(first).lower():
            # A writer in another process holds the lock (a running run): read anyway.
            try:
                return h5py.File(path, "r", locking=False)
            except OSError:
                pass
        raise error(
            path, f"cannot be read as HDF5: the file is truncated or corrupt ({first})"
        ) from None


def _check_format(
    f: h5py.File,
    path: Path,
    expected: str,
    readers: Mapping[int, Any],
    error: type[ResultsFileError],
) -> int:
    fmt = _attr_str(f.attrs, "format", "")
    if fmt != expected:
        if fmt in (FORMAT, CHECKPOINT_FORMAT):
            what = "a results file" if fmt == FORMAT else "a checkpoint"
            use = "read_results" if fmt == FORMAT else "read_checkpoint"
            raise error(path, f"is {what} (format {fmt!r}), not {expected!r}; use {use}()")
        found = f"format {fmt!r}" if fmt else "no 'format' attribute"
        raise error(path, f"not a grainlab file of format {expected!r} ({found})")
    raw = f.attrs.get("format_version")
    try:
        version = int(raw)
    except (TypeError, ValueError):
        raise error(path, f"format_version: missing or not an integer ({raw!r})") from None
    if version not in readers:
        known = ", ".join(str(v) for v in sorted(readers))
        if version > max(readers):
            raise UnsupportedVersionError(
                path,
                f"format_version {version} is newer than this grainlab "
                f"({_grainlab_version()}) can read (it reads {expected} version {known}); "
                "upgrade grainlab to read this file",
            )
        raise error(path, f"format_version {version} is unknown (known versions: {known})")
    return version


# ------------------------------------------------------------------ snapshot <-> group
def _write_array(
    group: h5py.Group,
    name: str,
    data: ArrayLike,
    *,
    units: str | None,
    compression: str | None,
    where: str,
) -> None:
    a = np.asarray(data)
    if a.dtype.kind not in "biuf":
        raise ValueError(f"{where}: cannot store dtype {a.dtype} (numbers or booleans only)")
    kwargs: dict[str, Any] = {}
    if compression and a.size:
        kwargs.update(compression=compression, shuffle=True)
    ds = group.create_dataset(name, data=a, **kwargs)
    if units is not None:
        ds.attrs["units"] = units


def _write_snapshot_group(
    group: h5py.Group, snapshot: Snapshot, *, compression: str | None, step: int | None
) -> None:
    def put(name: str, value: ArrayLike | None) -> None:
        if value is not None:
            _write_array(
                group,
                name,
                value,
                units=_SNAPSHOT_UNITS[name],
                compression=compression,
                where=f"snapshot.{name}",
            )

    metadata = _dumps(dict(snapshot.metadata), "snapshot.metadata")
    for name in ("positions", "radii", "ids", "rotations", "kind", "contact_i", "contact_j"):
        put(name, getattr(snapshot, name))
    for name in ("normal_force", "shear_force", "contact_normal", "contact_point", "box"):
        put(name, getattr(snapshot, name))
    for owner in ("contact_fields", "particle_fields"):
        sub = group.create_group(owner, track_order=True)
        for key, value in getattr(snapshot, owner).items():
            _check_name(f"snapshot.{owner}", key)
            _write_array(
                sub,
                key,
                value,
                units=_FIELD_UNITS.get(key),
                compression=compression,
                where=f"snapshot.{owner}[{key!r}]",
            )
    _write_text(group, "metadata", metadata)
    group.attrs["n_particles"] = np.int64(snapshot.n_particles)
    group.attrs["n_contacts"] = np.int64(snapshot.n_contacts)
    group.attrs["periodic"] = np.array(snapshot.periodic, dtype=np.int8)
    if snapshot.time is not None:
        group.attrs["time"] = np.float64(snapshot.time)
    if snapshot.axial_strain is not None:
        group.attrs["axial_strain"] = np.float64(snapshot.axial_strain)
    if step is not None:
        group.attrs["step"] = np.int64(step)


def _read_snapshot_group_v1(group: h5py.Group, path: Path) -> Snapshot:
    def get(name: str) -> NDArray[Any] | None:
        return group[name][()] if name in group else None

    def fields(owner: str) -> dict[str, NDArray[Any]]:
        if owner not in group:
            return {}
        sub = group[owner]
        return {key: sub[key][()] for key in sub}

    try:
        metadata = json.loads(_read_text(group["metadata"])) if "metadata" in group else {}
    except json.JSONDecodeError as error:
        raise ResultsFileError(path, f"{group.name}/metadata: not valid JSON ({error})") from None
    attrs = group.attrs
    periodic = tuple(bool(p) for p in attrs.get("periodic", (0, 0)))
    try:
        return Snapshot(
            positions=group["positions"][()],
            radii=group["radii"][()],
            ids=get("ids"),
            rotations=get("rotations"),
            kind=get("kind"),
            contact_i=get("contact_i"),
            contact_j=get("contact_j"),
            normal_force=get("normal_force"),
            shear_force=get("shear_force"),
            contact_normal=get("contact_normal"),
            contact_point=get("contact_point"),
            contact_fields=fields("contact_fields"),
            particle_fields=fields("particle_fields"),
            box=get("box"),
            periodic=periodic,  # type: ignore[arg-type]
            time=float(attrs["time"]) if "time" in attrs else None,
            axial_strain=float(attrs["axial_strain"]) if "axial_strain" in attrs else None,
            metadata=metadata,
        )
    except KeyError as error:
        raise ResultsFileError(path, f"{group.name}: missing dataset ({error})") from None
    except ValueError as error:
        raise ResultsFileError(path, f"{group.name}: invalid snapshot ({error})") from None


# ----------------------------------------------------------------------------- writer
class ResultsWriter:
    """Writes a results file ``run.h5`` while a run goes on.

    The writer works on ``PATH.partial`` (root attribute ``status =
    "running"``) and flushes after every call, so a killed run leaves a
    partial file that :meth:`resume` can continue. :meth:`finalize` marks the
    file complete and renames it to ``PATH`` atomically. Used as a context
    manager, a block that ends normally finalizes; a block that raises marks
    the partial file ``"failed"`` (with the error message) and does not
    rename it (``KeyboardInterrupt`` leaves it ``"running"``, resumable).

    With ``buffered=True`` the file is built in memory and reaches the disk
    only whole, through :meth:`publish`, :meth:`close` and :meth:`finalize`,
    each an atomic write of the complete file (:func:`write_bytes_atomic`):
    the HDF5 library never writes the disk itself, so a kill or a full disk
    can never leave a damaged ``PATH.partial`` (a full disk is a plain
    ``OSError`` from that write, and the file on disk stays the last one
    published). The biaxial test writes this way and publishes at every checkpoint.

    Parameters
    ----------
    path
        The final results file (usually ``RUN_DIR/run.h5``), or a run folder.
    kind
        What the run is, e.g. ``"biaxial"``, ``"study"``, ``"consolidation"``.
    overwrite
        Replace an existing ``PATH`` / ``PATH.partial``; without it an
        existing one raises :class:`FileExistsError`.
    compression
        HDF5 filter for snapshot arrays (``"gzip"``, ``"lzf"``) or None (default).
    buffered
        Build the file in memory and write it to disk only whole (above).

    Notes
    -----
    Time series columns are fixed by the first :meth:`define_timeseries`,
    :meth:`append_timeseries` or :meth:`append_rows`; later records must
    have exactly the same columns. A snapshot group is complete once its
    ``index`` attribute exists (written last); readers ignore groups without it.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        kind: str = "run",
        overwrite: bool = False,
        compression: str | None = None,
        buffered: bool = False,
    ) -> None:
        final = _resolve_results_path(path)
        partial = _partial_of(final)
        if not isinstance(kind, str) or not kind:
            raise ValueError(f"kind: must be a non-empty string, got {kind!r}")
        for p in (final, partial):
            if p.exists():
                if not overwrite:
                    raise FileExistsError(
                        f"{p}: exists; pass overwrite=True to replace it, or "
                        "ResultsWriter.resume() to continue a partial run"
                    )
                p.unlink()
        buffer = io.BytesIO() if buffered else None
        f = h5py.File(buffer if buffered else partial, "w", libver=_LIBVER, track_order=True)
        try:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = np.int64(FORMAT_VERSION)
            f.attrs["grainlab_version"] = _grainlab_version()
            f.attrs["created"] = _now()
            f.attrs["kind"] = kind
            f.attrs["status"] = "running"
            _write_json_group(f.create_group("config"), {}, "config")
            ts = f.create_group("timeseries", track_order=True)
            ts.attrs["n_rows"] = np.int64(0)
            f.create_group("snapshots", track_order=True).attrs["n_written"] = np.int64(0)
            _write_json_group(f.create_group("summary"), {}, "summary")
            f.flush()
        except BaseException:
            f.close()
            raise
        self._init(f, final, compression, buffer)
        if buffered:
            self._publish_or_close()

    def _init(self, f: h5py.File, final: Path, compression: str | None, buffer: io.BytesIO | None = None) -> None:
        self._file: h5py.File | None = f
        self._final = final
        self._partial = _partial_of(final)
        self._compression = compression
        self._buffer = buffer

    def _publish_or_close(self) -> None:
        try:
            self.publish()
        except BaseException:
            self._f.close()
            self._file = None
            raise

    @classmethod
    def resume(
        cls,
        path: str | os.PathLike[str],
        *,
        timeseries_rows: int | None = None,
        snapshots: Iterable[str] | None = None,
        compression: str | None = None,
        buffered: bool = False,
        image: bytes | None = None,
    ) -> ResultsWriter:
        """Reopen the partial file of a killed run to continue writing it.

        ``timeseries_rows`` cuts the time series back to that many rows (the
        count saved with the checkpoint the run resumes from); ``snapshots``,
        when given, keeps only the snapshots with these names (those written
        after the checkpoint are dropped, to be written again). The status
        goes back to ``"running"``. ``buffered``: continue in memory (see the
        class); ``image``: the file's bytes to continue from instead of
        ``PATH.partial`` (see :meth:`restore`).
        """
        final = _resolve_results_path(path)
        partial = _partial_of(final)
        if image is None and not partial.exists():
            if final.exists():
                raise FileExistsError(f"{final}: the run is already finalized; nothing to resume")
            raise FileNotFoundError(f"{partial}: no partial results file to resume")
        buffer = None
        try:
            if buffered or image is not None:
                buffer = io.BytesIO(partial.read_bytes() if image is None else bytes(image))
                f = h5py.File(buffer, "r+")
            else:
                f = h5py.File(partial, "r+")
        except OSError as error:
            raise ResultsFileError(
                partial,
                f"cannot be reopened: the file is truncated or corrupt ({error}); "
                "start the results file again from the checkpoint",
            ) from None
        try:
            version = _check_format(f, partial, FORMAT, _READERS_BY_VERSION, ResultsFileError)
            if version != FORMAT_VERSION:
                raise ResultsFileError(
                    partial,
                    f"format_version {version}: only files of version {FORMAT_VERSION} "
                    "can be continued by this grainlab",
                )
            writer = cls.__new__(cls)
            writer._init(f, final, compression, buffer if buffered else None)
        except BaseException:
            f.close()
            raise
        if timeseries_rows is not None:
            writer.truncate_timeseries(timeseries_rows)
        group = f["snapshots"]
        if snapshots is not None:
            keep = set(snapshots)
            for name in list(group):
                if name not in keep:
                    del group[name]
        for name in list(group):  # half-written groups of the killed run
            if "index" not in group[name].attrs:
                del group[name]
        writer.set_status("running")
        if buffered:
            writer._publish_or_close()
        elif image is not None:  # continued on disk: the image becomes the partial file
            assert buffer is not None  # the image was opened in memory
            f.flush()
            data = buffer.getvalue()
            f.close()
            write_bytes_atomic(partial, data)
            writer._init(h5py.File(partial, "r+"), final, compression)
        return writer

    # ------------------------------------------------------------ properties
    @property
    def path(self) -> Path:
        """The final file name (``run.h5``), which exists once finalized."""
        return self._final

    @property
    def partial_path(self) -> Path:
        """The file written while the run goes on (``run.h5.partial``)."""
        return self._partial

    @property
    def closed(self) -> bool:
        """True after :meth:`close` or :meth:`finalize`."""
        return self._file is None

    @property
    def _f(self) -> h5py.File:
        if self._file is None:
            raise ValueError(f"{self._partial}: the results writer is closed")
        return self._file

    @property
    def columns(self) -> list[str]:
        """Time series column names, in order."""
        ts = self._f["timeseries"]
        return [str(c) for c in ts.attrs.get("columns", [])] if "columns" in ts.attrs else []

    @property
    def n_rows(self) -> int:
        """Number of time series rows written."""
        return int(self._f["timeseries"].attrs["n_rows"])

    def read_timeseries(self) -> dict[str, NDArray[np.float64]]:
        """The time series written so far, column by column."""
        ts = self._f["timeseries"]
        n = self.n_rows if "n_rows" in ts.attrs else 0
        return {name: np.asarray(ts[name][:n], dtype=np.float64) for name in self.columns}

    @property
    def snapshot_names(self) -> list[str]:
        """Names of the snapshots written, in the order written."""
        return [info[0] for info in _snapshot_order(self._f["snapshots"])]

    # ---------------------------------------------------------------- writes
    def flush(self) -> None:
        """Hand everything written so far to the operating system (a buffered
        writer: to its memory; :meth:`publish` writes it to disk)."""
        self._f.flush()

    def write_config(self, config: Mapping[str, Any]) -> None:
        """Store the resolved configuration (replaces any earlier one).

        ``config`` is a dict of str keys whose values are None, bool, int,
        float, str, lists and dicts of those (NumPy numbers and arrays are
        converted, tuples become lists). Stored exactly as JSON in
        ``/config/json``; scalar and simple-list leaves also appear as
        attributes of ``/config`` named by their dotted path.
        """
        _write_json_group(self._f["config"], config, "config")
        self.flush()

    def write_summary(self, summary: Mapping[str, Any]) -> None:
        """Store the run's summary (replaces any earlier one); same rules as :meth:`write_config`."""
        _write_json_group(self._f["summary"], summary, "summary")
        self.flush()

    def write_phases(self, phases: Mapping[str, float]) -> None:
        """Store the wall-clock time of each phase, ``name -> seconds`` (replaces any earlier)."""
        names = [_check_name("phases", str(k)) for k in phases]
        seconds = np.array([float(v) for v in phases.values()], dtype=np.float64)
        if np.any(~np.isfinite(seconds)) or np.any(seconds < 0):
            raise ValueError(f"phases: wall times must be finite and >= 0 s, got {dict(phases)}")
        if "phases" in self._f:
            del self._f["phases"]
        g = self._f.create_group("phases", track_order=True)
        g.create_dataset("name", data=np.array(names, dtype=_STR), dtype=_STR)
        g.create_dataset("wall_time", data=seconds).attrs["units"] = "s"
        self.flush()

    def define_timeseries(self, units: Mapping[str, str]) -> None:
        """Declare time series columns (``name -> units``, in order) before any row.

        Columns already defined only get their units updated; a new column
        after rows were written raises ``ValueError``.
        """
        ts = self._f["timeseries"]
        existing = self.columns
        new = [_check_name("timeseries column", str(c)) for c in units if c not in existing]
        if new and self.n_rows:
            raise ValueError(
                f"timeseries: cannot add columns {new} after {self.n_rows} rows were written "
                f"(columns are {existing})"
            )
        for name in new:
            ts.create_dataset(
                name,
                shape=(0,),
                maxshape=(None,),
                dtype=np.int64 if name in INTEGER_COLUMNS else np.float64,
                chunks=(_TIMESERIES_CHUNK,),
            )
        for name, unit in units.items():
            ts[name].attrs["units"] = str(unit)
        if new:
            ts.attrs["columns"] = np.array(existing + new, dtype=_STR)
        self.flush()

    def append_timeseries(
        self, record: Mapping[str, float], *, units: Mapping[str, str] | None = None
    ) -> None:
        """Append one row, ``column -> value`` (converted to float64; NaN allowed)."""
        self.append_rows({k: [v] for k, v in record.items()}, units=units)

    def append_rows(
        self, columns: Mapping[str, ArrayLike], *, units: Mapping[str, str] | None = None
    ) -> None:
        """Append a batch of rows given column-wise (``column -> 1D values``, same length).

        The first call defines the columns (with ``units``, default ``""``,
        dimensionless or unknown); later calls must give exactly those columns.
        The columns of :data:`INTEGER_COLUMNS` (``step``) are stored as int64
        and must hold whole numbers.
        """
        data: dict[str, NDArray[np.float64]] = {}
        for name, values in columns.items():
            try:
                a = np.asarray(values, dtype=np.float64)
            except (TypeError, ValueError) as error:
                raise ValueError(f"timeseries[{name!r}]: not numbers ({error})") from None
            if a.ndim != 1:
                raise ValueError(f"timeseries[{name!r}]: expected 1D values, got shape {a.shape}")
            if name in INTEGER_COLUMNS:
                if not np.all(np.isfinite(a) & (a == np.round(a))):
                    raise ValueError(f"timeseries[{name!r}]: the engine step must be a whole number, got {a}")
                a = a.astype(np.int64)
            data[str(name)] = a
        lengths = {len(a) for a in data.values()}
        if len(lengths) > 1:
            shown = {k: len(a) for k, a in data.items()}
            raise ValueError(f"timeseries: columns of different lengths {shown}")
        existing = self.columns
        if not existing:
            wanted = {k: "" for k in data}
            wanted.update(units or {})
            self.define_timeseries(wanted)
            existing = self.columns
        elif units:
            self.define_timeseries(units)
        missing = [c for c in existing if c not in data]
        extra = [c for c in data if c not in existing]
        if missing or extra:
            raise ValueError(
                f"timeseries: record columns differ from the file's {existing}: "
                f"missing {missing}, unexpected {extra}"
            )
        n_new = lengths.pop() if lengths else 0
        if n_new == 0:
            return
        ts = self._f["timeseries"]
        start = self.n_rows
        for name in existing:
            ds = ts[name]
            ds.resize((start + n_new,))
            ds[start:] = data[name]
        ts.attrs["n_rows"] = np.int64(start + n_new)  # last: marks the rows complete
        self.flush()

    def truncate_timeseries(self, n_rows: int) -> None:
        """Keep only the first ``n_rows`` rows (used when resuming from a checkpoint)."""
        n_rows = int(n_rows)
        if not 0 <= n_rows <= self.n_rows:
            raise ValueError(f"timeseries_rows: must be in [0, {self.n_rows}], got {n_rows}")
        ts = self._f["timeseries"]
        for name in self.columns:
            ts[name].resize((n_rows,))
        ts.attrs["n_rows"] = np.int64(n_rows)
        self.flush()

    def write_snapshot(
        self,
        name: str,
        snapshot: Snapshot,
        *,
        step: int | None = None,
        overwrite: bool = False,
        walls: WallGeometry | None = None,
    ) -> None:
        """Store ``snapshot`` completely as ``/snapshots/<name>``.

        ``name`` is any string without ``/`` (see :func:`snapshot_name`);
        ``step`` is the engine step count (default ``snapshot.metadata["step"]``
        when that is an integer), which ``read_snapshot(..., timestep=N)`` selects by.
        ``walls``, the run's walls at that instant
        (:meth:`WallGeometry.from_simulation <grainlab.io.walls.WallGeometry.from_simulation>`),
        are stored as ``/snapshots/<name>/walls`` and read back by :meth:`Results.walls`.
        """
        _check_name("snapshot name", name)
        if not isinstance(snapshot, Snapshot):
            raise TypeError(f"snapshot: expected a Snapshot, got {type(snapshot).__name__}")
        if step is None:
            meta_step = snapshot.metadata.get("step")
            if isinstance(meta_step, int | np.integer) and not isinstance(meta_step, bool):
                step = int(meta_step)
        group = self._f["snapshots"]
        if name in group:
            if not overwrite:
                raise ValueError(
                    f"snapshot name: {name!r} already written (pass overwrite=True to replace it)"
                )
            del group[name]
        g = group.create_group(name, track_order=True)
        try:
            _write_snapshot_group(g, snapshot, compression=self._compression, step=step)
            if walls is not None:
                write_wall_group(g.create_group("walls", track_order=True), walls)
        except BaseException:
            del group[name]
            raise
        index = int(group.attrs.get("n_written", 0))
        g.attrs["index"] = np.int64(index)  # last: marks the group complete
        group.attrs["n_written"] = np.int64(index + 1)
        self.flush()

    def set_status(self, status: Status, *, error: str | None = None) -> None:
        """Set the root ``status`` to ``"running"`` or ``"failed"`` (with an ``error`` message).

        ``"complete"`` is set only by :meth:`finalize`.
        """
        if status not in ("running", "failed"):
            raise ValueError(
                f"status: {status!r} is not allowed here (use 'running' or 'failed'; "
                "finalize() marks a run 'complete')"
            )
        self._f.attrs["status"] = status
        if error is not None:
            self._f.attrs["error"] = str(error)
        elif "error" in self._f.attrs and status == "running":
            del self._f.attrs["error"]
        self.flush()

    def close(self) -> None:
        """Flush and close without finalizing: ``run.h5.partial`` stays, resumable
        (a buffered writer publishes it first).

        The writer counts as closed even when the flush or the publication
        fails (a full disk): the error is raised once and a second ``close``
        does nothing.
        """
        f = self._file
        if f is None:
            return
        try:
            if self._buffer is not None:
                self.publish()
            else:
                f.flush()
        finally:
            self._file = None
            f.close()

    def publish(self) -> bytes:
        """Make ``run.h5.partial`` on disk the complete file as it stands, and
        return its bytes (for a checkpoint to carry; :meth:`restore` continues
        from them). A buffered writer writes its memory atomically; an
        unbuffered one closes the file, reads it and reopens it. Writing goes on.
        """
        f = self._f
        f.flush()
        if self._buffer is not None:
            data = self._buffer.getvalue()
            write_bytes_atomic(self._partial, data)
            return data
        self._file = None
        f.close()
        try:
            data = self._partial.read_bytes()
        finally:
            self._file = h5py.File(self._partial, "r+")
        return data

    @classmethod
    def restore(
        cls,
        path: str | os.PathLike[str],
        image: bytes,
        *,
        compression: str | None = None,
        buffered: bool = False,
    ) -> ResultsWriter:
        """Continue the results file from ``image`` (from :meth:`publish`), which
        becomes ``run.h5.partial`` (written atomically): the file exactly as it
        was when the image was taken, whatever happened to ``run.h5.partial``
        since (a kill during a write, a full disk, the file deleted). An
        existing ``run.h5`` is left alone.
        """
        return cls.resume(path, compression=compression, buffered=buffered, image=image)

    def finalize(self, status: Literal["complete", "failed"] = "complete") -> Path:
        """Mark the run ``status``, close, fsync and rename ``run.h5.partial`` to ``run.h5``.

        Returns the final path. After this the writer is closed.
        """
        if status not in ("complete", "failed"):
            raise ValueError(f"status: must be 'complete' or 'failed', got {status!r}")
        f = self._f
        f.attrs["status"] = status
        f.attrs["finished"] = _now()
        if self._buffer is not None:  # the final file written whole, then the partial one removed
            f.flush()
            data = self._buffer.getvalue()
            self._file = None
            f.close()
            write_bytes_atomic(self._final, data)
            self._partial.unlink(missing_ok=True)
            fsync_directory(self._final.parent)
            return self._final
        self.close()
        fsync_file(self._partial)
        os.replace(self._partial, self._final)
        fsync_directory(self._final.parent)
        return self._final

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if self._file is None:
            return
        if exc is None:
            self.finalize()
        elif isinstance(exc, Exception):
            try:
                self.set_status("failed", error=f"{type(exc).__name__}: {exc}")
            finally:
                self.close()
        else:
            self.close()

    def __repr__(self) -> str:
        state = "closed" if self.closed else f"{self.n_rows} rows"
        return f"ResultsWriter({str(self._partial)!r}, {state})"


# ----------------------------------------------------------------------------- reader
@dataclass(frozen=True)
class SnapshotInfo:
    """What a results file says about one of its snapshots, without loading it."""

    #: Group name under ``/snapshots``.
    name: str
    #: Position in the order written (0 first).
    index: int
    #: Simulated time, s (None if not recorded).
    time: float | None
    #: Axial strain, compression positive, a fraction (None if not recorded).
    axial_strain: float | None
    #: Engine step count (None if not recorded).
    step: int | None
    #: Number of particles N.
    n_particles: int
    #: Number of contacts Nc (particle–particle and wall).
    n_contacts: int


def _snapshot_order(group: h5py.Group) -> list[tuple[str, int]]:
    out = []
    for name in group:
        index = group[name].attrs.get("index")
        if index is not None:
            out.append((name, int(index)))
    return sorted(out, key=lambda item: item[1])


def _snapshot_infos_v1(f: h5py.File) -> tuple[SnapshotInfo, ...]:
    if "snapshots" not in f:
        return ()
    group = f["snapshots"]
    infos = []
    for name, index in _snapshot_order(group):
        a = group[name].attrs
        infos.append(
            SnapshotInfo(
                name=name,
                index=index,
                time=float(a["time"]) if "time" in a else None,
                axial_strain=float(a["axial_strain"]) if "axial_strain" in a else None,
                step=int(a["step"]) if "step" in a else None,
                n_particles=int(a.get("n_particles", group[name]["positions"].shape[0])),
                n_contacts=int(a.get("n_contacts", 0)),
            )
        )
    return tuple(infos)


@dataclass(frozen=True)
class Results:
    """A results file loaded by :func:`read_results`.

    Everything but the snapshots is loaded; :meth:`snapshot` reads one
    snapshot from the file on demand.
    """

    #: The file read.
    path: Path
    #: Layout version of the file.
    format_version: int
    #: grainlab version that wrote it.
    grainlab_version: str
    #: When the file was created (ISO 8601, UTC).
    created: str
    #: What the run is (``"biaxial"``, ...).
    kind: str
    #: ``"complete"``, or ``"running"`` / ``"failed"`` when read with ``allow_incomplete``.
    status: str
    #: The resolved configuration, as written.
    config: dict[str, Any]
    #: Time series: ``column -> (n_rows,) float64`` (``step``: int64), columns in order.
    timeseries: dict[str, NDArray[np.float64]]
    #: Units of each time series column (``""`` when dimensionless or unknown).
    timeseries_units: dict[str, str]
    #: The run's summary, as written.
    summary: dict[str, Any]
    #: Wall time per phase, ``name -> s`` (empty when not recorded).
    phases: dict[str, float]
    #: The snapshots in the order written.
    snapshots: tuple[SnapshotInfo, ...]
    #: All root attributes of the file (including ``error`` of a failed run).
    attrs: dict[str, Any] = field(default_factory=dict)
    _allow_incomplete: bool = field(default=False, repr=False)

    @property
    def snapshot_names(self) -> list[str]:
        """Snapshot names in the order written."""
        return [s.name for s in self.snapshots]

    def __repr__(self) -> str:
        from grainlab._repr import results_repr

        return results_repr(self)

    def _repr_html_(self) -> str:
        from grainlab._repr import results_html

        return results_html(self)

    def snapshot(self, name: str | int | None = None) -> Snapshot:
        """Load a snapshot: by name, by position in the order written (``-1`` the last), or the last."""
        info = _select(self.path, self.snapshots, name, None)
        with _open_results(self.path, self._allow_incomplete) as (f, reader):
            return reader.read_snapshot(f, info.name, self.path)

    def walls(self, name: str | int | None = None) -> WallGeometry | None:
        """The walls stored with a snapshot (selected as by :meth:`snapshot`), or None if none were."""
        info = _select(self.path, self.snapshots, name, None)
        with _open_results(self.path, self._allow_incomplete) as (f, _reader):
            group = f["snapshots"][info.name]
            return read_wall_group(group["walls"]) if "walls" in group else None


@dataclass(frozen=True)
class _LayoutReader:
    """How to read one layout version of the results file."""

    read_results: Callable[[h5py.File, Path, bool], Results]
    list_snapshots: Callable[[h5py.File], tuple[SnapshotInfo, ...]]
    read_snapshot: Callable[[h5py.File, str, Path], Snapshot]


def _read_results_v1(f: h5py.File, path: Path, allow_incomplete: bool) -> Results:
    ts_group = f.get("timeseries")
    timeseries: dict[str, NDArray[np.float64]] = {}
    units: dict[str, str] = {}
    if ts_group is not None:
        n_rows = int(ts_group.attrs.get("n_rows", 0))
        names = [str(c) for c in ts_group.attrs["columns"]] if "columns" in ts_group.attrs else []
        for name in names:
            if name not in ts_group:
                raise ResultsFileError(path, f"/timeseries: column {name!r} is listed but missing")
            ds = ts_group[name]
            if ds.shape[0] < n_rows:
                raise ResultsFileError(
                    path,
                    f"/timeseries/{name}: {ds.shape[0]} values, fewer than n_rows = {n_rows}",
                )
            integral = ds.dtype.kind in "iu"  # the engine step (INTEGER_COLUMNS)
            timeseries[name] = np.asarray(ds[:n_rows], dtype=np.int64 if integral else np.float64)
            units[name] = _attr_str(ds.attrs, "units", "")
    phases: dict[str, float] = {}
    if "phases" in f:
        g = f["phases"]
        names = [str(n) for n in g["name"].asstr()[()]]
        phases = dict(zip(names, (float(s) for s in g["wall_time"][()]), strict=True))
    attrs = {
        k: (v.decode() if isinstance(v, bytes) else v.item() if isinstance(v, np.generic) else v)
        for k, v in f.attrs.items()
    }
    return Results(
        path=path,
        format_version=int(f.attrs["format_version"]),
        grainlab_version=_attr_str(f.attrs, "grainlab_version"),
        created=_attr_str(f.attrs, "created"),
        kind=_attr_str(f.attrs, "kind"),
        status=_attr_str(f.attrs, "status"),
        config=_read_json(f.get("config"), path),
        timeseries=timeseries,
        timeseries_units=units,
        summary=_read_json(f.get("summary"), path),
        phases=phases,
        snapshots=_snapshot_infos_v1(f),
        attrs=attrs,
        _allow_incomplete=allow_incomplete,
    )


def _read_snapshot_v1(f: h5py.File, name: str, path: Path) -> Snapshot:
    group = f.get("snapshots")
    if group is None or name not in group:
        raise ResultsFileError(path, f"no snapshot named {name!r}")
    return _read_snapshot_group_v1(group[name], path)


#: Reader of each results layout version. A new layout adds an entry; old ones stay.
_READERS_BY_VERSION: dict[int, _LayoutReader] = {
    1: _LayoutReader(_read_results_v1, _snapshot_infos_v1, _read_snapshot_v1),
}


@contextlib.contextmanager
def _open_results(
    path: str | os.PathLike[str], allow_incomplete: bool
) -> Iterator[tuple[h5py.File, _LayoutReader]]:
    """Open a results file, check format, version and status; yield ``(file, reader)``."""
    p = _resolve_results_path(path)
    partial = _partial_of(p)
    if not p.exists() and partial.exists():
        if not allow_incomplete:
            raise IncompleteResultsError(
                p,
                f"file not found, but {partial.name} exists: the run did not finish "
                "(still running, killed or failed; a killed run can be resumed); pass "
                "allow_incomplete=True to read the partial file",
            )
        p = partial
    f = _open_read(p)
    try:
        version = _check_format(f, p, FORMAT, _READERS_BY_VERSION, ResultsFileError)
        status = _attr_str(f.attrs, "status", "")
        if status not in _STATUSES:
            raise ResultsFileError(
                p, f"status: unknown value {status!r} (expected one of {list(_STATUSES)})"
            )
        if status != "complete" and not allow_incomplete:
            if status == "running":
                why = (
                    "the run is incomplete (status 'running': still running, or killed "
                    "before it finished)"
                )
            else:
                error = _attr_str(f.attrs, "error", "")
                why = f"the run failed (status 'failed'{': ' + error if error else ''})"
            raise IncompleteResultsError(
                p, f"{why}; pass allow_incomplete=True to read what it wrote"
            )
        try:
            yield f, _READERS_BY_VERSION[version]
        except (OSError, KeyError) as error:  # damaged, or caught mid-write by a live reader
            raise ResultsFileError(
                p,
                f"cannot be read: the file is corrupt, or is being written ({error!r})",
            ) from None
    finally:
        f.close()


def read_results(path: str | os.PathLike[str], *, allow_incomplete: bool = False) -> Results:
    """Load a results file (``run.h5``, or a run folder containing one).

    Raises
    ------
    IncompleteResultsError
        The file's ``status`` is not ``"complete"``, or only ``run.h5.partial``
        exists, unless ``allow_incomplete=True`` (which then reads the
        partial file when ``run.h5`` does not exist).
    UnsupportedVersionError
        The file was written by a newer grainlab (its ``format_version`` is named).
    ResultsFileError
        Missing, truncated or corrupt file, or not a grainlab results file.
    """
    with _open_results(path, allow_incomplete) as (f, reader):
        return reader.read_results(f, Path(f.filename), allow_incomplete)


def _select(
    path: Path,
    infos: tuple[SnapshotInfo, ...],
    snapshot: str | int | None,
    timestep: int | None,
) -> SnapshotInfo:
    if not infos:
        raise ResultsFileError(path, "the results file holds no snapshots")
    if snapshot is not None and timestep is not None:
        raise ValueError("snapshot / timestep: give one or the other, not both")
    if timestep is not None:
        hits = [s for s in infos if s.step == int(timestep)]
        if hits:
            return hits[-1]
        steps = [s.step for s in infos if s.step is not None]
        if not steps:
            raise ValueError(
                f"timestep: no snapshot in {path} records its engine step; select by name "
                f"(snapshot=...), one of {[s.name for s in infos][:20]}"
            )
        raise ValueError(
            f"timestep: no snapshot at step {timestep} in {path} (steps: {steps[:20]})"
        )
    if snapshot is None:
        return infos[-1]
    if isinstance(snapshot, str):
        for s in infos:
            if s.name == snapshot:
                return s
        names = [s.name for s in infos]
        more = f" ... ({len(names)} in all)" if len(names) > 20 else ""
        raise ValueError(f"snapshot: no snapshot {snapshot!r} in {path}; names: {names[:20]}{more}")
    if isinstance(snapshot, int | np.integer) and not isinstance(snapshot, bool):
        k = int(snapshot)
        if not -len(infos) <= k < len(infos):
            raise ValueError(
                f"snapshot: index {k} out of range for {len(infos)} snapshots in {path}"
            )
        return infos[k]
    raise TypeError(f"snapshot: expected a name, an index or None, got {type(snapshot).__name__}")


def read_hdf5_snapshot(
    path: str | os.PathLike[str],
    *,
    snapshot: str | int | None = None,
    timestep: int | None = None,
    allow_incomplete: bool = False,
    contacts: str | os.PathLike[str] | None = None,
    tolerance: float = 0.0,
    columns: Mapping[str, str] | None = None,
    boundary_types: Iterable[int] = (),
) -> Snapshot:
    """One snapshot of a results file; the reader :func:`grainlab.io.read_snapshot` uses.

    Selection: ``snapshot`` by name (``"strain_0.0150"``) or by position in
    the order written (``0`` the first, ``-1`` the last); or ``timestep``,
    the engine step count recorded with the snapshot (CLI ``--timestep``);
    default the last snapshot written. Contacts are stored in the file, so
    ``contacts``, ``tolerance``, ``columns`` and ``boundary_types`` do not
    apply and raise ``ValueError`` when given.
    """
    p = Path(path)
    if contacts is not None:
        raise ValueError("contacts: a grainlab results file carries its contacts; no contacts file")
    if tolerance:
        raise ValueError("tolerance: a grainlab results file carries its contacts; not detected")
    if columns:
        raise ValueError("contact columns: only apply to LAMMPS local dumps")
    if len(tuple(boundary_types)):
        raise ValueError("boundary types: only apply to LAMMPS dumps (run.h5 stores 'kind')")
    with _open_results(p, allow_incomplete) as (f, reader):
        info = _select(p, reader.list_snapshots(f), snapshot, timestep)
        return reader.read_snapshot(f, info.name, Path(f.filename))


# ------------------------------------------------------------------------- checkpoints
@dataclass(frozen=True)
class Checkpoint:
    """A checkpoint loaded (and verified) by :func:`read_checkpoint`."""

    #: The file read.
    path: Path
    #: The engine's opaque state, for :meth:`grainlab.Simulation.from_bytes`.
    engine_state: bytes
    #: The protocol's state (phase, step counts, next record strain, ...).
    protocol_state: dict[str, Any]
    #: Optional arrays saved with it.
    arrays: dict[str, NDArray[Any]]
    #: Layout version of the file.
    format_version: int
    #: grainlab version that wrote it.
    grainlab_version: str
    #: When it was written (ISO 8601, UTC).
    created: str


def _sha256(data: bytes | NDArray[Any]) -> str:
    if isinstance(data, np.ndarray):
        data = np.ascontiguousarray(data).tobytes()
    return hashlib.sha256(data).hexdigest()


def write_checkpoint(
    path: str | os.PathLike[str],
    engine_state: bytes,
    protocol_state: Mapping[str, Any],
    *,
    arrays: Mapping[str, ArrayLike] | None = None,
) -> Path:
    """Write a checkpoint atomically (temporary file, fsync, rename); returns its path.

    Parameters
    ----------
    path
        ``checkpoint.h5`` (or a run folder, which gets one).
    engine_state
        :meth:`grainlab.Simulation.to_bytes`; stored as a uint8 dataset with its SHA-256.
    protocol_state
        JSON-able dict (same rules as :meth:`ResultsWriter.write_config`),
        stored exactly with its SHA-256.
    arrays
        Optional named numeric arrays (e.g. the time series rows so far),
        each stored bitwise with its SHA-256.
    """
    p = Path(path)
    if p.is_dir():
        p = p / CHECKPOINT_FILE
    if not isinstance(engine_state, bytes | bytearray | memoryview):
        raise TypeError(f"engine_state: expected bytes, got {type(engine_state).__name__}")
    state = bytes(engine_state)
    if not isinstance(protocol_state, Mapping):
        raise TypeError(f"protocol_state: expected a dict, got {type(protocol_state).__name__}")
    protocol_text = _dumps(protocol_state, "protocol_state")
    prepared: dict[str, NDArray[Any]] = {}
    for name, value in (arrays or {}).items():
        _check_name("arrays", name)
        a = np.ascontiguousarray(value)
        if a.dtype.kind not in "biuf":
            raise ValueError(f"arrays[{name!r}]: cannot store dtype {a.dtype} (numbers only)")
        prepared[name] = a
    # built in memory and written whole: the HDF5 library never writes the disk,
    # so a full disk is a plain OSError and leaves the previous checkpoint intact
    buffer = io.BytesIO()
    with h5py.File(buffer, "w", libver=_LIBVER, track_order=True) as f:
        f.attrs["format"] = CHECKPOINT_FORMAT
        f.attrs["format_version"] = np.int64(CHECKPOINT_FORMAT_VERSION)
        f.attrs["grainlab_version"] = _grainlab_version()
        f.attrs["created"] = _now()
        ds = f.create_dataset("engine_state", data=np.frombuffer(state, dtype=np.uint8))
        ds.attrs["sha256"] = _sha256(state)
        ds = f.create_dataset("protocol_state", data=protocol_text, dtype=_STR)
        ds.attrs["sha256"] = _sha256(protocol_text.encode("utf-8"))
        g = f.create_group("arrays", track_order=True)
        for name, a in prepared.items():
            g.create_dataset(name, data=a).attrs["sha256"] = _sha256(a)
    write_bytes_atomic(p, buffer.getvalue())
    return p


def _read_checkpoint_v1(f: h5py.File, path: Path) -> Checkpoint:
    def verify(name: str, data: bytes | NDArray[Any], ds: h5py.Dataset) -> None:
        stored = _attr_str(ds.attrs, "sha256", "")
        actual = _sha256(data)
        if stored != actual:
            raise CheckpointError(
                path,
                f"{name}: checksum mismatch (stored sha256 {stored[:16] or 'missing'}..., "
                f"computed {actual[:16]}...): the checkpoint is corrupt; resume from an "
                "earlier checkpoint or start the run again",
            )

    try:
        ds = f["engine_state"]
        state = np.asarray(ds[()], dtype=np.uint8).tobytes()
        verify("engine_state", state, ds)
        ds = f["protocol_state"]
        raw = ds[()]
        text_bytes = raw if isinstance(raw, bytes) else str(raw).encode("utf-8")
        verify("protocol_state", text_bytes, ds)
        arrays: dict[str, NDArray[Any]] = {}
        if "arrays" in f:
            for name in f["arrays"]:
                ds = f["arrays"][name]
                a = ds[()]
                verify(f"arrays/{name}", np.asarray(a), ds)
                arrays[name] = a
    except KeyError as error:
        raise CheckpointError(path, f"missing dataset ({error})") from None
    except OSError as error:  # a damaged data block the library cannot read
        raise CheckpointError(
            path, f"cannot read the data: the file is corrupt ({error})"
        ) from None
    try:
        protocol_state = json.loads(text_bytes.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise CheckpointError(path, f"protocol_state: not valid JSON ({error})") from None
    return Checkpoint(
        path=path,
        engine_state=state,
        protocol_state=protocol_state,
        arrays=arrays,
        format_version=int(f.attrs["format_version"]),
        grainlab_version=_attr_str(f.attrs, "grainlab_version"),
        created=_attr_str(f.attrs, "created"),
    )


#: Reader of each checkpoint layout version.
_CHECKPOINT_READERS_BY_VERSION: dict[int, Callable[[h5py.File, Path], Checkpoint]] = {
    1: _read_checkpoint_v1,
}


def read_checkpoint(path: str | os.PathLike[str]) -> Checkpoint:
    """Load a checkpoint and verify its checksums.

    Raises
    ------
    CheckpointError
        Missing file, not a checkpoint, truncated or corrupt (a checksum
        mismatch names the damaged part).
    UnsupportedVersionError
        Written by a newer grainlab (its ``format_version`` is named).
    """
    p = Path(path)
    if p.is_dir():
        p = p / CHECKPOINT_FILE
    f = _open_read(p, CheckpointError)
    try:
        version = _check_format(
            f, p, CHECKPOINT_FORMAT, _CHECKPOINT_READERS_BY_VERSION, CheckpointError
        )
        return _CHECKPOINT_READERS_BY_VERSION[version](f, p)
    finally:
        f.close()
