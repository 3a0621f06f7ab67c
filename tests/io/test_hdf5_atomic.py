"""Crash safety: status, rename at finalize, killed writers, truncated files, resume, atomic text."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from grainlab.io import read_snapshot
from grainlab.io.hdf5 import (
    IncompleteResultsError,
    ResultsFileError,
    ResultsWriter,
    read_results,
)
from grainlab.io.results import atomic_path, write_json_atomic, write_text_atomic
from grainlab.snapshot import Snapshot

TWO_DISKS = Snapshot.from_geometry([[0.0, 0.0], [2e-3, 0.0]], [1e-3, 1e-3], tolerance=1e-9)


def run_child(code: str, *args: str, **kwargs) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code), *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **kwargs,
    )


def test_finalize_renames_partial_to_run_h5(tmp_path):
    out = ResultsWriter(tmp_path / "run.h5", kind="biaxial")
    assert out.partial_path == tmp_path / "run.h5.partial"
    out.append_timeseries({"axial_strain": 0.0})
    assert out.partial_path.exists() and not (tmp_path / "run.h5").exists()
    assert out.finalize() == tmp_path / "run.h5"
    assert out.closed and not out.partial_path.exists()
    res = read_results(tmp_path)
    assert res.status == "complete" and "finished" in res.attrs
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"]


def test_unfinalized_run_is_refused_until_asked(tmp_path):
    out = ResultsWriter(tmp_path / "run.h5", kind="biaxial")
    out.append_rows({"axial_strain": [0.0, 1e-3], "q": [0.0, 5.0]})
    out.write_snapshot("strain_0.0010", TWO_DISKS)
    # a reader while the writer is open (same process) sees what was flushed
    live = read_results(tmp_path, allow_incomplete=True)
    assert live.status == "running" and live.timeseries["q"].tolist() == [0.0, 5.0]
    out.close()  # a crash: no finalize
    with pytest.raises(
        IncompleteResultsError, match=r"run.h5.partial exists: the run did not finish"
    ):
        read_results(tmp_path)
    with pytest.raises(IncompleteResultsError, match="allow_incomplete=True"):
        read_snapshot(tmp_path / "run.h5.partial")
    with pytest.raises(IncompleteResultsError, match="status 'running'"):
        read_results(tmp_path / "run.h5.partial")
    res = read_results(tmp_path / "run.h5", allow_incomplete=True)
    assert res.status == "running" and res.path.name == "run.h5.partial"
    assert res.snapshot().n_contacts == 1


def test_exception_marks_failed_and_interrupt_leaves_running(tmp_path):
    with pytest.raises(RuntimeError, match="boom"), ResultsWriter(tmp_path / "run.h5") as out:
        out.append_timeseries({"t": 1.0})
        raise RuntimeError("boom")
    assert not (tmp_path / "run.h5").exists()
    with pytest.raises(IncompleteResultsError, match=r"status 'failed': RuntimeError: boom"):
        read_results(tmp_path / "run.h5.partial")
    assert read_results(tmp_path, allow_incomplete=True).attrs["error"] == "RuntimeError: boom"

    other = tmp_path / "other"
    other.mkdir()
    with pytest.raises(KeyboardInterrupt), ResultsWriter(other) as out:
        raise KeyboardInterrupt
    assert read_results(other, allow_incomplete=True).status == "running"


def test_finalized_failed_run_needs_allow_incomplete(tmp_path):
    out = ResultsWriter(tmp_path / "run.h5")
    out.set_status("failed", error="SimulationUnstableError: overlap")
    out.finalize("failed")
    with pytest.raises(IncompleteResultsError, match="the run failed .*overlap"):
        read_results(tmp_path / "run.h5")
    assert read_results(tmp_path / "run.h5", allow_incomplete=True).status == "failed"


def test_overwrite_removes_the_old_complete_file_first(tmp_path):
    with ResultsWriter(tmp_path / "run.h5") as out:
        out.write_summary({"old": True})
    with pytest.raises(FileExistsError):
        ResultsWriter(tmp_path / "run.h5")
    out = ResultsWriter(tmp_path / "run.h5", overwrite=True)
    # no stale complete run.h5 beside the new run's partial file
    assert not (tmp_path / "run.h5").exists()
    out.close()
    with pytest.raises(FileExistsError, match="resume"):
        ResultsWriter(tmp_path / "run.h5")


def test_truncated_file_gives_a_clear_error(tmp_path):
    with ResultsWriter(tmp_path / "run.h5") as out:
        out.append_rows({"t": np.arange(5000.0)})
        out.write_snapshot("s", TWO_DISKS)
    path = tmp_path / "run.h5"
    size = path.stat().st_size
    with open(path, "r+b") as fh:
        fh.truncate(size // 2)
    with pytest.raises(
        ResultsFileError, match="run.h5: cannot be read as HDF5: the file is truncated"
    ):
        read_results(path)
    with pytest.raises(ResultsFileError, match="truncated or corrupt"):
        read_snapshot(path)
    path.write_bytes(b"")
    with pytest.raises(ValueError, match="run.h5"):
        read_snapshot(path)


KILLED_WRITER = """
import os, signal, sys
from grainlab.io.hdf5 import ResultsWriter
from grainlab.snapshot import Snapshot
out = ResultsWriter(sys.argv[1], kind="biaxial")
out.write_config({"seed": 1})
for k in range(5):
    out.append_timeseries({"axial_strain": k * 1e-3, "q": float(k)})
out.write_snapshot("strain_0.0000", Snapshot([[0.0, 0.0]], [1e-3]))
out.write_snapshot("strain_0.0040", Snapshot([[0.0, 0.0]], [2e-3]))
os.kill(os.getpid(), signal.SIGKILL)
"""


def test_killed_process_leaves_only_a_partial_file_that_resumes(tmp_path):
    child = run_child(KILLED_WRITER, str(tmp_path / "run.h5"))
    child.communicate(timeout=120)
    assert child.returncode == -signal.SIGKILL
    assert not (tmp_path / "run.h5").exists()
    with pytest.raises(IncompleteResultsError):
        read_results(tmp_path)
    seen = read_results(tmp_path, allow_incomplete=True)
    assert seen.timeseries["q"].tolist() == [0, 1, 2, 3, 4]
    assert seen.snapshot_names == ["strain_0.0000", "strain_0.0040"]

    # resume from a checkpoint taken after 3 records and the first snapshot
    out = ResultsWriter.resume(tmp_path, timeseries_rows=3, snapshots=["strain_0.0000"])
    assert out.n_rows == 3 and out.snapshot_names == ["strain_0.0000"]
    out.append_rows({"axial_strain": [3e-3, 4e-3], "q": [30.0, 40.0]})
    out.write_snapshot("strain_0.0040", Snapshot([[0.0, 0.0]], [3e-3]))
    out.finalize()
    res = read_results(tmp_path)
    assert res.status == "complete" and res.config == {"seed": 1}
    assert res.timeseries["q"].tolist() == [0, 1, 2, 30, 40]
    assert res.snapshot_names == ["strain_0.0000", "strain_0.0040"]
    assert res.snapshot("strain_0.0040").radii.tolist() == [3e-3]
    with pytest.raises(FileExistsError, match="already finalized"):
        ResultsWriter.resume(tmp_path)


def test_resume_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="no partial results file"):
        ResultsWriter.resume(tmp_path / "run.h5")
    out = ResultsWriter(tmp_path)
    out.append_timeseries({"t": 0.0})
    out.close()
    with pytest.raises(ValueError, match=r"timeseries_rows: must be in \[0, 1\], got 2"):
        ResultsWriter.resume(tmp_path, timeseries_rows=2)
    (tmp_path / "run.h5.partial").write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    with pytest.raises(
        ResultsFileError, match="truncated or corrupt.*start the results file again"
    ):
        ResultsWriter.resume(tmp_path)


KEEPS_APPENDING = """
import sys
from grainlab.io.hdf5 import ResultsWriter
out = ResultsWriter(sys.argv[1], kind="biaxial")
k = 0
while True:
    out.append_rows({"a": [float(k)] * 7, "b": [float(-k)] * 7})
    if k == 3:
        print("ready", flush=True)
    k += 1
"""


@pytest.mark.parametrize("delay_s", [0.0, 0.05, 0.2])
def test_kill_during_appends_never_leaves_a_complete_looking_file(tmp_path, delay_s):
    import time

    child = run_child(KEEPS_APPENDING, str(tmp_path / "run.h5"))
    assert child.stdout.readline().strip() == "ready"
    # while the writer runs (and holds its lock), a reader can look at the partial file;
    # HDF5 has no concurrent-read guarantee, so a read that meets a write is retried
    for _ in range(50):
        try:
            live = read_results(tmp_path, allow_incomplete=True)
            break
        except ResultsFileError:
            time.sleep(0.01)
    else:
        pytest.fail("the partial file of a running writer could not be read in 50 tries")
    assert live.status == "running" and len(live.timeseries["a"]) >= 28
    time.sleep(delay_s)
    child.send_signal(signal.SIGKILL)
    child.communicate(timeout=60)
    assert not (tmp_path / "run.h5").exists()
    try:
        res = read_results(tmp_path, allow_incomplete=True)
    except ResultsFileError:
        return  # the kill hit an HDF5 write: unreadable, but never complete-looking
    assert res.status == "running"
    n = len(res.timeseries["a"])
    assert n % 7 == 0 and n >= 28
    np.testing.assert_array_equal(res.timeseries["a"], -res.timeseries["b"])


# --------------------------------------------------------------------------- text
def test_write_text_atomic_replaces_whole_files(tmp_path):
    path = tmp_path / "timeseries.csv"
    assert write_text_atomic(path, "a,b\r\n1,2\r\n") == path
    assert path.read_bytes() == b"a,b\r\n1,2\r\n"
    write_text_atomic(str(path), "é\n")
    assert path.read_text(encoding="utf-8") == "é\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["timeseries.csv"]


def test_failed_atomic_write_keeps_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "summary.json"
    write_json_atomic(path, {"v": 1})
    with pytest.raises(RuntimeError, match="disk full"), atomic_path(path) as tmp:
        tmp.write_text('{"v": 2, "trunc')
        raise RuntimeError("disk full")
    assert json.loads(path.read_text()) == {"v": 1}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


def test_write_json_atomic_is_strict_json(tmp_path):
    path = write_json_atomic(
        tmp_path / "summary.json",
        {"peak": float("nan"), "n": np.int64(3), "x": np.array([1.5, np.inf]), "name": "σ₃"},
    )
    text = path.read_text(encoding="utf-8")
    assert "NaN" not in text and "Infinity" not in text and "σ₃" in text
    assert json.loads(text) == {"peak": None, "n": 3, "x": [1.5, None], "name": "σ₃"}


def test_killed_text_writer_leaves_the_old_file(tmp_path):
    path = tmp_path / "big.txt"
    write_text_atomic(path, "old\n")
    code = """
    import os, signal, sys
    from grainlab.io import results
    def die(p):
        open(p, "w").write("half")
        os.kill(os.getpid(), signal.SIGKILL)
    results.fsync_file = die
    results.write_text_atomic(sys.argv[1], "new\\n" * 1000)
    """
    child = run_child(code, str(path))
    child.communicate(timeout=60)
    assert child.returncode == -signal.SIGKILL
    assert path.read_text() == "old\n"
    leftovers = [p.name for p in tmp_path.iterdir() if p.name != "big.txt"]
    assert all(name.startswith(".big.txt.") and name.endswith(".tmp") for name in leftovers)
    assert os.path.getsize(path) == 4


def test_a_buffered_writer_reaches_the_disk_only_whole(tmp_path):
    out = ResultsWriter(tmp_path / "run.h5", kind="biaxial", buffered=True)
    on_disk = out.partial_path.read_bytes()  # published at once: a complete, empty run
    assert read_results(tmp_path, allow_incomplete=True).timeseries == {}
    out.append_rows({"axial_strain": [0.0, 1e-3], "q": [0.0, 5.0]})
    out.write_snapshot("strain_0.0010", TWO_DISKS)
    assert out.partial_path.read_bytes() == on_disk  # nothing reached the disk yet
    image = out.publish()
    assert out.partial_path.read_bytes() == image
    live = read_results(tmp_path, allow_incomplete=True)
    assert live.timeseries["q"].tolist() == [0.0, 5.0] and live.snapshot_names == ["strain_0.0010"]
    out.append_timeseries({"axial_strain": 2e-3, "q": 6.0})
    # the partial file damaged or deleted after the image was taken: restore continues from the image
    out.close()
    out.partial_path.write_bytes(image[: len(image) // 3])
    again = ResultsWriter.restore(tmp_path / "run.h5", image, buffered=True)
    assert again.n_rows == 2 and again.snapshot_names == ["strain_0.0010"]
    out.partial_path.unlink()
    again.append_timeseries({"axial_strain": 2e-3, "q": 7.0})
    again.finalize()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"]
    res = read_results(tmp_path)
    assert res.status == "complete" and res.timeseries["q"].tolist() == [0.0, 5.0, 7.0]


def test_an_unbuffered_writer_publishes_and_restores_too(tmp_path):
    out = ResultsWriter(tmp_path / "run.h5", kind="biaxial")
    out.append_timeseries({"axial_strain": 0.0, "q": 1.0})
    image = out.publish()  # closed, read and reopened: writing goes on
    out.append_timeseries({"axial_strain": 1e-3, "q": 2.0})
    out.close()
    restored = ResultsWriter.restore(tmp_path, image)
    assert restored.n_rows == 1
    restored.finalize()
    assert read_results(tmp_path).timeseries["q"].tolist() == [1.0]


def test_a_buffered_writer_that_fails_publishes_its_status(tmp_path):
    with pytest.raises(RuntimeError), ResultsWriter(tmp_path, buffered=True) as out:
        out.append_timeseries({"axial_strain": 0.0})
        raise RuntimeError("the engine blew up")
    res = read_results(tmp_path, allow_incomplete=True)
    assert res.status == "failed" and res.attrs["error"] == "RuntimeError: the engine blew up"
    assert res.timeseries["axial_strain"].tolist() == [0.0]


def test_a_full_disk_keeps_the_published_file_and_the_old_checkpoint(tmp_path, monkeypatch):
    import errno

    import grainlab.io.hdf5 as hdf5
    from grainlab.io.hdf5 import checkpoint, writer

    out = ResultsWriter(tmp_path, buffered=True)
    out.append_timeseries({"axial_strain": 0.0})
    image = out.publish()
    hdf5.write_checkpoint(tmp_path / "checkpoint.h5", b"state 1", {"phase": "shear", "rows": 1})
    out.append_timeseries({"axial_strain": 1e-3})

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(writer, "write_bytes_atomic", full)
    monkeypatch.setattr(checkpoint, "write_bytes_atomic", full)
    with pytest.raises(OSError, match="No space left"):
        out.publish()
    with pytest.raises(OSError, match="No space left"):
        hdf5.write_checkpoint(tmp_path / "checkpoint.h5", b"state 2", {"phase": "shear", "rows": 2})
    with pytest.raises(OSError, match="No space left"):
        out.close()
    assert out.closed
    monkeypatch.undo()
    assert out.partial_path.read_bytes() == image
    assert hdf5.read_checkpoint(tmp_path).protocol_state == {"phase": "shear", "rows": 1}
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
