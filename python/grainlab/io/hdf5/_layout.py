"""What the results file and the checkpoint share: format names and versions, the
HDF5 features used, name checks, JSON text and JSON groups, root attributes, and
opening a file read-only with its format and version checked
(``docs/file-formats.md``)."""

from __future__ import annotations

import datetime
import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal

import h5py
import numpy as np

from grainlab._mapping import flatten_keys
from grainlab.io.hdf5.errors import ResultsFileError, UnsupportedVersionError
from grainlab.io.results import RESULTS_FILE, json_safe

#: Root attribute ``format`` of a results file.
FORMAT = "grainlab-results"
#: Layout version written by this grainlab: 2 adds the analysis group to version 1's layout,
#: 3 stores the snapshots' grains (rigid bodies) one row per grain.
FORMAT_VERSION = 3
#: Root attribute ``format`` of a checkpoint file.
CHECKPOINT_FORMAT = "grainlab-checkpoint"
#: Checkpoint layout version written by this grainlab: 2 is version 1 with a run's partial
#: results file always inside (the array ``results_partial``) and its protocol state free of
#: retired keys; a checkpoint of version 1 is refused (its run starts again).
CHECKPOINT_FORMAT_VERSION = 2
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
                f"({_grainlab_version()}) can read (it reads {expected} "
                f"version{'s' if len(readers) > 1 else ''} {known}); "
                "upgrade grainlab to read this file",
            )
        raise error(path, f"format_version {version} is unknown (known versions: {known})")
    return version
