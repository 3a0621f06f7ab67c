"""Reading the results file ``run.h5``: :func:`read_results` (a :class:`Results`),
:func:`read_hdf5_snapshot` (one snapshot, for :func:`grainlab.io.read_snapshot`),
each through the reader of the file's layout version."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from grainlab.io.hdf5._layout import (
    _STATUSES,
    FORMAT,
    _attr_str,
    _check_format,
    _open_read,
    _partial_of,
    _read_json,
    _resolve_results_path,
)
from grainlab.io.hdf5.analysis import AnalysisItem, read_analysis_item, read_analysis_versions
from grainlab.io.hdf5.errors import IncompleteResultsError, ResultsFileError
from grainlab.io.hdf5.snapshot import (
    SnapshotInfo,
    _read_snapshot_group_v1,
    _read_snapshot_group_v3,
    _snapshot_infos_v1,
)
from grainlab.io.walls import WallGeometry, read_wall_group
from grainlab.snapshot import Snapshot

__all__ = ["Results", "read_hdf5_snapshot", "read_results"]


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
    #: The ``/cracks`` table, ``column -> (n_cracks,)`` (empty for a run without cement;
    #: docs/file-formats.md).
    cracks: dict[str, NDArray[Any]]
    #: The snapshots in the order written.
    snapshots: tuple[SnapshotInfo, ...]
    #: All root attributes of the file (including ``error`` of a failed run).
    attrs: dict[str, Any] = field(default_factory=dict)
    #: The analysis products stored in the file, ``product -> version`` (empty in
    #: version-1 files and before any is stored; :mod:`grainlab.io.hdf5.analysis`).
    analysis_versions: dict[str, int] = field(default_factory=dict)
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
            return reader.read_snapshot(_snapshot_group(f, info.name, self.path), self.path)

    def analysis(self, product: str, item: str) -> AnalysisItem | None:
        """The stored ``item`` (a snapshot's name) of the analysis ``product``, or None
        when the file does not hold it (read from the file now, not when loaded)."""
        if product not in self.analysis_versions:
            return None
        with _open_results(self.path, self._allow_incomplete) as (f, _reader):
            return read_analysis_item(f, product, item)

    @contextlib.contextmanager
    def analysis_reader(self) -> Iterator[Callable[[str, str], AnalysisItem | None]]:
        """Reads many stored analysis items with the file opened once: yields
        ``read(product, item)``, :meth:`analysis` within the block."""
        with _open_results(self.path, self._allow_incomplete) as (f, _reader):
            versions = self.analysis_versions

            def read(product: str, item: str) -> AnalysisItem | None:
                return read_analysis_item(f, product, item) if product in versions else None

            yield read

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
    #: Reads one snapshot group.
    read_snapshot: Callable[[h5py.Group, Path], Snapshot]


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
    cracks: dict[str, NDArray[Any]] = {}
    if "cracks" in f:
        g = f["cracks"]
        n_cracks = int(g.attrs.get("n_rows", 0))
        cracks = {str(c): np.asarray(g[str(c)][:n_cracks]) for c in g.attrs["columns"]}
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
        cracks=cracks,
        snapshots=_snapshot_infos_v1(f),
        attrs=attrs,
        analysis_versions=read_analysis_versions(f),
        _allow_incomplete=allow_incomplete,
    )


def _snapshot_group(f: h5py.File, name: str, path: Path) -> h5py.Group:
    group = f.get("snapshots")
    if group is None or name not in group:
        raise ResultsFileError(path, f"no snapshot named {name!r}")
    return group[name]


#: Reader of each results layout version. A new layout adds an entry; old ones stay.
_READERS_BY_VERSION: dict[int, _LayoutReader] = {
    1: _LayoutReader(_read_results_v1, _snapshot_infos_v1, _read_snapshot_group_v1),
    # version 2 is version 1 and the analysis group, which version 1 files do not have
    2: _LayoutReader(_read_results_v1, _snapshot_infos_v1, _read_snapshot_group_v1),
    # version 3 is version 2 with the snapshots' grains one row per grain
    3: _LayoutReader(_read_results_v1, _snapshot_infos_v1, _read_snapshot_group_v3),
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


def results_kind(path: str | os.PathLike[str]) -> str:
    """The ``kind`` of a results file (the protocol that wrote it: ``"biaxial"``,
    ``"oedometer"``, ...), read from its attributes alone; the reader's errors as
    :func:`read_results` raises them, but for an unfinished run, whose kind is read too."""
    with _open_results(path, True) as (f, _):
        return _attr_str(f.attrs, "kind", "")


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
        return reader.read_snapshot(_snapshot_group(f, info.name, Path(f.filename)), Path(f.filename))
