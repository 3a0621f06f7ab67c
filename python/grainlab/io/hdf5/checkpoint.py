"""The checkpoint ``checkpoint.h5`` a run resumes from: the engine's state bytes,
the protocol's state and optional arrays, each with its SHA-256, written
atomically (:func:`write_checkpoint`) and verified when read
(:func:`read_checkpoint`)."""

from __future__ import annotations

import hashlib
import io
import json
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.io.hdf5._layout import (
    _LIBVER,
    _STR,
    CHECKPOINT_FORMAT,
    CHECKPOINT_FORMAT_VERSION,
    _attr_str,
    _check_format,
    _check_name,
    _dumps,
    _grainlab_version,
    _now,
    _open_read,
)
from grainlab.io.hdf5.errors import CheckpointError
from grainlab.io.results import CHECKPOINT_FILE, write_bytes_atomic

__all__ = ["Checkpoint", "read_checkpoint", "write_checkpoint"]


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


def _read_checkpoint_v2(f: h5py.File, path: Path) -> Checkpoint:
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


#: Reader of each checkpoint layout version. A checkpoint is for resuming the run that
#: wrote it, not an archive: a new layout replaces the reader of the one before, whose
#: runs start again (:data:`_RETIRED_CHECKPOINT_VERSIONS`).
_CHECKPOINT_READERS_BY_VERSION: dict[int, Callable[[h5py.File, Path], Checkpoint]] = {
    2: _read_checkpoint_v2,
}
#: Checkpoint layout versions this grainlab no longer resumes, with what they lacked.
_RETIRED_CHECKPOINT_VERSIONS: dict[int, str] = {
    1: "it may lack the run's partial results file",
}


def _retired_version(f: h5py.File) -> int | None:
    """The file's checkpoint layout version when it is one this grainlab retired."""
    if _attr_str(f.attrs, "format", "") != CHECKPOINT_FORMAT:
        return None
    try:
        version = int(f.attrs.get("format_version"))
    except (TypeError, ValueError):
        return None
    return version if version in _RETIRED_CHECKPOINT_VERSIONS else None


def read_checkpoint(path: str | os.PathLike[str]) -> Checkpoint:
    """Load a checkpoint and verify its checksums.

    Raises
    ------
    CheckpointError
        Missing file, not a checkpoint, of a layout version this grainlab
        retired, truncated or corrupt (a checksum mismatch names the damaged
        part).
    UnsupportedVersionError
        Written by a newer grainlab (its ``format_version`` is named).
    """
    p = Path(path)
    if p.is_dir():
        p = p / CHECKPOINT_FILE
    f = _open_read(p, CheckpointError)
    try:
        retired = _retired_version(f)
        if retired is not None:
            raise CheckpointError(
                p, f"format_version {retired}: written by an earlier grainlab, which this one no longer resumes "
                f"({_RETIRED_CHECKPOINT_VERSIONS[retired]}); start the run again in a new folder",
            )
        version = _check_format(
            f, p, CHECKPOINT_FORMAT, _CHECKPOINT_READERS_BY_VERSION, CheckpointError
        )
        return _CHECKPOINT_READERS_BY_VERSION[version](f, p)
    finally:
        f.close()
