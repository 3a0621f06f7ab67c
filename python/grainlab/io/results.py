r"""Files of a results folder published atomically: a crash never leaves half a file.

Each file goes to a temporary name in its folder, is fsynced and renamed with
:func:`os.replace` (docs/file-formats.md, "Crash safety").

Example
-------
>>> import tempfile, pathlib
>>> from grainlab.io.results import write_json_atomic, write_text_atomic
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_text_atomic(folder / "timeseries.csv", "axial_strain,q\n0.0,0.0\n").name
'timeseries.csv'
>>> (folder / "timeseries.csv").read_text().splitlines()[0]
'axial_strain,q'
>>> write_json_atomic(folder / "summary.json", {"peak": 1.5, "missing": float("nan")}).name
'summary.json'
>>> (folder / "summary.json").read_text()
'{\n  "peak": 1.5,\n  "missing": null\n}\n'
"""

from __future__ import annotations

import contextlib
import csv
import errno
import fcntl
import io
import json
import math
import os
import secrets
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "timeseries_csv",
    "CHECKPOINT_FILE",
    "SHEAR_START_FILE",
    "RESULTS_FILE",
    "atomic_path",
    "check_output_folder",
    "FolderBusyError",
    "ensure_output_folder",
    "fsync_directory",
    "fsync_file",
    "is_disk_full",
    "json_safe",
    "refuse_overwrite",
    "write_bytes_atomic",
    "write_json_atomic",
    "write_text_atomic",
    "writer_lock",
]

#: Name of the results file of a run folder.
RESULTS_FILE = "run.h5"
#: Name of the checkpoint file of a run folder.
CHECKPOINT_FILE = "checkpoint.h5"
#: The engine state at the start of a periodic simple shear's shearing, kept in its folder
#: (:meth:`Simulation.save`): ``grainlab export DIR --lammps`` shears it in LAMMPS.
SHEAR_START_FILE = "shear_start.state"


def fsync_file(path: str | os.PathLike[str]) -> None:
    """Flush a closed file's content to the storage device (``fsync``)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def fsync_directory(path: str | os.PathLike[str]) -> None:
    """Make a rename inside folder ``path`` durable (``fsync`` of the folder).

    A no-op where folders cannot be opened (Windows).
    """
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Context manager: a temporary path to write, published as ``path`` on success.

    The temporary file is created empty in ``path``'s folder. When the block
    ends without an exception the file is fsynced and renamed over ``path``
    (:func:`os.replace`) and the folder is fsynced; on an exception the
    temporary file is removed and ``path`` is left as it was.

    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.bin"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_bytes(b"\\x00\\x01")
    >>> target.read_bytes()
    b'\\x00\\x01'
    """
    final = Path(path)
    folder = final.parent
    tmp = _create_temporary(folder, final.name)
    try:
        yield tmp
        fsync_file(tmp)
        os.replace(tmp, final)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise
    fsync_directory(folder)


def _create_temporary(folder: Path, name: str) -> Path:
    """An empty new file ``.NAME.XXXXXXXX.tmp`` in ``folder``, created exclusively
    with mode ``0666`` so that the umask applies as to any ordinary file
    (``tempfile.mkstemp`` would create it ``0600`` whatever the umask)."""
    for _ in range(100):
        tmp = folder / f".{name}.{secrets.token_hex(4)}.tmp"
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise FileExistsError(f"{folder}: no free temporary name for {name}")  # pragma: no cover


def _write_atomic(path: str | os.PathLike[str], write: Callable[[Path], Any]) -> Path:
    final = Path(path)
    with atomic_path(final) as tmp:
        write(tmp)
    return final


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file, fsync, rename); returns ``path``."""
    return _write_atomic(path, lambda tmp: tmp.write_bytes(bytes(data)))


def write_text_atomic(path: str | os.PathLike[str], text: str, *, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (temporary file, fsync, rename); returns ``path``.

    Line endings are written as given (no newline translation), so a file
    written on Windows is byte-identical to one written on Linux.
    """
    data = text.encode(encoding)
    return _write_atomic(path, lambda tmp: tmp.write_bytes(data))


def timeseries_csv(timeseries: Mapping[str, Any]) -> str:
    """A time series (column -> 1-D array, all of one length) as CSV text: a header of
    the column names, then one row per record, each value as Python's ``repr`` of
    the float (exact: it reads back to the same bits)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    names = list(timeseries)
    writer.writerow(names)
    for row in zip(*(timeseries[k] for k in names), strict=True):
        writer.writerow([repr(float(v)) for v in row])
    return buffer.getvalue()


def json_safe(value: Any, *, nan: str = "null", where: str = "value") -> Any:
    """``value`` as plain JSON types, recursively: the one sanitiser of grainlab's JSON.

    NumPy scalars and arrays become numbers and lists, tuples lists, paths
    strings; dict keys must be strings. Non-finite
    floats become None with ``nan="null"`` (strict JSON, for files other
    programs read) or stay as they are with ``nan="keep"`` (Python's ``NaN`` /
    ``Infinity`` tokens, for grainlab's own HDF5 attributes, which round-trip).
    Any other type (and a key that is not a string) raises TypeError, an
    array of strings or objects ValueError, naming ``where``.

    >>> json_safe({"a": float("nan"), "b": (1, 2.5), "c": [float("inf")]})
    {'a': None, 'b': [1, 2.5], 'c': [None]}
    >>> json_safe({"a": float("nan")}, nan="keep")
    {'a': nan}
    """
    if nan not in ("null", "keep"):
        raise ValueError(f"nan: 'null' or 'keep', got {nan!r}")
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        x = float(value)
        return None if nan == "null" and not math.isfinite(x) else x
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "biuf":
            raise ValueError(f"{where}: cannot store an array of dtype {value.dtype} as JSON")
        return json_safe(value.tolist(), nan=nan, where=where)
    if isinstance(value, list | tuple):
        return [json_safe(v, nan=nan, where=f"{where}[{k}]") for k, v in enumerate(value)]
    if isinstance(value, Mapping):
        out: dict[str, Any] = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"{where}: key {k!r} is not a string (JSON keys are strings)")
            out[k] = json_safe(v, nan=nan, where=f"{where}[{k!r}]")
        return out
    raise TypeError(
        f"{where}: cannot store a value of type {type(value).__name__} as JSON (allowed: None, bool, "
        "int, float, str, paths, lists, tuples and dicts of them, NumPy numbers and arrays)"
    )


def write_json_atomic(path: str | os.PathLike[str], value: Any, *, indent: int | None = 2) -> Path:
    """Write ``value`` as strict JSON (UTF-8) to ``path`` atomically; returns ``path``.

    NaN and infinities, which JSON cannot represent, are written as ``null``;
    NumPy scalars and arrays are written as numbers and lists. A trailing
    newline ends the file.
    """
    text = json.dumps(json_safe(value), indent=indent, ensure_ascii=False, allow_nan=False)
    return write_text_atomic(path, text + "\n")


# ---- output folders ------------------------------------------------------------


def _nearest_existing(folder: Path, option: str) -> Path | None:
    """``folder`` or its nearest ancestor that exists (None when none does); ``ValueError``
    naming ``option`` when that is a file rather than a folder."""
    for parent in (folder, *folder.parents):
        if parent.exists() or parent.is_symlink():
            if not parent.is_dir():
                where = f"{folder}" if parent == folder else f"{folder}: {parent}"
                raise ValueError(f"{option}: {where} is a file, not a folder")
            return parent
    return None


def ensure_output_folder(path: str | os.PathLike[str], *, option: str = "--out", create: bool = True) -> Path:
    """The folder ``path``, made if needed (``create``), checked to be a folder
    this process can write into; returns it.

    Raises ``ValueError`` naming ``option`` and the path, before any work,
    when ``path`` is a file, lies under a file, cannot be created or written
    (permissions, a read-only or pseudo file system such as ``/proc``), or,
    with ``create=False``, does not exist.

    >>> import tempfile, pathlib
    >>> base = pathlib.Path(tempfile.mkdtemp())
    >>> ensure_output_folder(base / "runs" / "a").is_dir()
    True
    >>> (base / "notes.txt").write_text("x")
    1
    >>> ensure_output_folder(base / "notes.txt")
    Traceback (most recent call last):
    ...
    ValueError: --out: .../notes.txt is a file, not a folder
    """
    folder = Path(path)
    _nearest_existing(folder, option)
    if not folder.is_dir():
        if not create:
            raise ValueError(f"{option}: {folder} does not exist")
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise ValueError(f"{option}: cannot create the folder {folder} ({_reason(error)})") from None
    try:
        probe = _create_temporary(folder, "write-test")
    except OSError as error:
        raise ValueError(f"{option}: cannot write in {folder} ({_reason(error)})") from None
    with contextlib.suppress(OSError):
        probe.unlink()
    return folder


def check_output_folder(path: str | os.PathLike[str], *, option: str = "--out") -> Path:
    """``path`` checked as :func:`ensure_output_folder` checks it, but created by no one:
    an existing folder must be writable, a missing one must lie under a writable folder
    (its nearest existing ancestor). A command calls this before reading its input and
    :func:`ensure_output_folder` once the input is accepted, so that input it refuses
    leaves no empty folder behind. Raises ``ValueError`` naming ``option``.

    >>> import tempfile, pathlib
    >>> base = pathlib.Path(tempfile.mkdtemp())
    >>> check_output_folder(base / "runs" / "a") == base / "runs" / "a", (base / "runs").exists()
    (True, False)
    """
    import tempfile

    folder = Path(path)
    parent = _nearest_existing(folder, option)
    if parent is None:
        return folder
    try:  # a probe that is removed at once: it tells permissions, read-only and pseudo file systems
        if parent == folder:
            probe = _create_temporary(folder, "write-test")
            with contextlib.suppress(OSError):
                probe.unlink()
        else:
            os.rmdir(tempfile.mkdtemp(prefix=".grainlab-", dir=parent))
    except OSError as error:
        what = f"write in {folder}" if parent == folder else f"create the folder {folder}"
        raise ValueError(f"{option}: cannot {what} ({_reason(error)})") from None
    return folder


def refuse_overwrite(folder: str | os.PathLike[str], names: Iterable[str], *, why: str) -> None:
    """Raise ``ValueError`` naming the first of ``names`` (file names or glob
    patterns) that exists in ``folder``; ``why`` says whose folder it is, e.g.
    ``"grainlab demo writes its own"``.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> refuse_overwrite(folder, ["summary.json"], why="grainlab demo writes its own")
    >>> _ = (folder / "summary.json").write_text("{}")
    >>> refuse_overwrite(folder, ["summary.json"], why="grainlab demo writes its own")
    Traceback (most recent call last):
    ...
    ValueError: --out: .../summary.json exists and was not written by this run (grainlab demo writes its own); ...
    """
    root = Path(folder)
    for name in names:
        found = sorted(root.glob(name)) if any(c in name for c in "*?[") else [root / name]
        for path in found:
            if path.exists():
                raise ValueError(
                    f"--out: {path} exists and was not written by this run ({why}); grainlab does not "
                    "overwrite it: choose another folder or move the file away"
                )


def is_disk_full(error: BaseException) -> bool:
    """True when ``error`` (or an error it was raised from) is a full disk or
    an exhausted quota: ``ENOSPC``/``EDQUOT``, also as reported inside an
    HDF5 library message (``errno = 28``)."""
    codes = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)}
    seen: set[int] = set()
    current: BaseException | None = error
    while current is not None and id(current) not in seen:
        seen.add(id(current))
        if isinstance(current, OSError) and current.errno in codes:
            return True
        text = str(current)
        if "No space left on device" in text or "Disk quota exceeded" in text:
            return True
        current = current.__cause__ or current.__context__
    return False


def _reason(error: OSError) -> str:
    return error.strerror or str(error)


class FolderBusyError(ValueError):
    """Another process is writing the results folder (:func:`writer_lock`): refused
    before any work, as bad input is (the command line exits with code 2)."""


@contextlib.contextmanager
def writer_lock(folder: str | os.PathLike[str], *, option: str = "--out") -> Iterator[Path]:
    """Hold the one-writer lock of the existing results ``folder`` while the block runs.

    The lock is an exclusive ``flock`` on the folder itself (no lock file is
    left in it): a second process that asks for it while the first holds it
    gets :class:`FolderBusyError` at once, naming the folder. The kernel
    releases it when the holder closes it or dies, however it dies, so a killed
    run leaves no stale lock and ``--resume`` can continue it. Locks are
    per open file: the same process taking it twice is refused as well.
    """
    path = Path(folder)
    fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderBusyError(
                f"{option}: {path} is being written by another grainlab run; wait for it to end or "
                "choose another folder"
            ) from None
        yield path
    finally:
        os.close(fd)
