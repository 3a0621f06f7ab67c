"""Writing the results file ``run.h5``: :class:`ResultsWriter`, crash-safe
(a partial file while the run goes on, renamed when it is complete),
buffered in memory or not, resumable from a checkpoint."""

from __future__ import annotations

import io
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from types import TracebackType
from typing import Any, Literal, Self

import h5py
import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.io.hdf5._layout import (
    _LIBVER,
    _STR,
    _TIMESERIES_CHUNK,
    FORMAT,
    FORMAT_VERSION,
    INTEGER_COLUMNS,
    Status,
    _check_format,
    _check_name,
    _grainlab_version,
    _now,
    _partial_of,
    _resolve_results_path,
    _write_json_group,
)
from grainlab.io.hdf5.errors import ResultsFileError
from grainlab.io.hdf5.reader import _READERS_BY_VERSION
from grainlab.io.hdf5.snapshot import _snapshot_order, _write_snapshot_group
from grainlab.io.results import fsync_directory, fsync_file, write_bytes_atomic
from grainlab.io.walls import WallGeometry, write_wall_group
from grainlab.snapshot import Snapshot

__all__ = ["ResultsWriter"]


class ResultsWriter:
    """Writes a results file ``run.h5`` while a run goes on, on ``PATH.partial`` until
    :meth:`finalize` publishes ``PATH`` atomically (the context manager, :meth:`resume`
    and ``buffered``: docs/file-formats.md, "Crash safety").

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
        Build the file in memory and write it to disk only whole.

    Notes
    -----
    Time series columns are fixed by the first :meth:`define_timeseries`,
    :meth:`append_timeseries` or :meth:`append_rows`; later records must
    have exactly the same columns. A snapshot group is complete once its
    ``index`` attribute exists (written last).
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

    def _init(
        self, f: h5py.File, final: Path, compression: str | None, buffer: io.BytesIO | None = None
    ) -> None:
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

    def read_timeseries(self, columns: Sequence[str] | None = None) -> dict[str, NDArray[np.float64]]:
        """The time series written so far, column by column (only ``columns``, when given)."""
        ts = self._f["timeseries"]
        n = self.n_rows if "n_rows" in ts.attrs else 0
        return {name: np.asarray(ts[name][:n], dtype=np.float64) for name in (columns or self.columns)}

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

    def append_cracks(self, columns: Mapping[str, ArrayLike], units: Mapping[str, str]) -> None:
        """Append rows to the ``/cracks`` table (``column -> 1D values``, one row per
        broken bond; the first call sets the columns and their ``units``, later calls
        give the same columns)."""
        data = {str(k): np.asarray(v) for k, v in columns.items()}
        if len({a.shape for a in data.values()}) > 1 or any(a.ndim != 1 for a in data.values()):
            raise ValueError(f"cracks: expected 1D columns of one length, got { {k: a.shape for k, a in data.items()} }")
        g = self._f.require_group("cracks")
        if "columns" not in g.attrs:
            for name, a in data.items():
                g.create_dataset(_check_name("cracks column", name), shape=(0,), maxshape=(None,), dtype=a.dtype,
                                 chunks=(_TIMESERIES_CHUNK,)).attrs["units"] = str(units.get(name, ""))
            g.attrs["columns"] = np.array(list(data), dtype=_STR)
            g.attrs["n_rows"] = np.int64(0)
        existing = [str(c) for c in g.attrs["columns"]]
        if sorted(existing) != sorted(data):
            raise ValueError(f"cracks: columns {sorted(data)} differ from the file's {existing}")
        start = int(g.attrs["n_rows"])
        n_new = len(next(iter(data.values()))) if data else 0
        for name in existing:
            g[name].resize((start + n_new,))
            g[name][start:] = data[name]
        g.attrs["n_rows"] = np.int64(start + n_new)  # last: marks the rows complete
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
                    raise ValueError(
                        f"timeseries[{name!r}]: the engine step must be a whole number, got {a}"
                    )
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
