"""A full disk stops a biaxial run with one clear line (exit code 1), keeps the
last checkpoint intact, and the run resumes to the uninterrupted run's results
once space is freed: the error injected into the writers, and for real on a
small tmpfs (where this test may mount one)."""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

import pytest
from reliability_factories import TINY_TOML, assert_same_run, tiny_config

import grainlab.protocols.biaxial as biaxial
import grainlab.protocols.biaxial.outputs as outputs
import grainlab.protocols.runner as runner
from grainlab.cli import main
from grainlab.io.hdf5 import ResultsWriter, read_checkpoint, read_results
from grainlab.io.results import is_disk_full


def _full(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


def _full_at(function, n):
    calls = {"n": 0}

    def writing(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] >= n:  # the disk stays full
            _full()
        return function(*args, **kwargs)

    return writing


@pytest.mark.parametrize(
    ("where", "target", "n"),
    [
        ("a record", (ResultsWriter, "append_timeseries"), 3),
        ("a snapshot", (ResultsWriter, "write_snapshot"), 2),
        ("the final checkpoint", (runner, "write_checkpoint"), 4),
        ("the figures", (outputs, "_figures"), 1),
    ],
)
def test_a_full_disk_stops_with_one_line_and_the_run_resumes(tmp_path, monkeypatch, capsys, fast_figures,
                                                             tiny_reference, where, target, n):
    (tmp_path / "tiny.toml").write_text(TINY_TOML)
    out = tmp_path / "run"
    args = ["biaxial", "--config", str(tmp_path / "tiny.toml"), "--out", str(out), "--no-progress", "--no-report"]
    owner, name = target
    with monkeypatch.context() as patch:
        patch.setattr(owner, name, _full_at(getattr(owner, name), n))
        assert main(args) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "the disk is full" in err and "continue with --resume" in err, err
    checkpoint = read_checkpoint(out / "checkpoint.h5")  # intact: its checksums verify
    assert checkpoint.protocol_state["phase"] in ("shear", "done")
    if (out / "run.h5.partial").exists():
        partial = read_results(out, allow_incomplete=True)
        assert partial.status == "failed" and partial.attrs["error"] == "no space left on device"
    assert main([*args, "--resume"]) == 0
    assert_same_run(tiny_reference, out)


def test_disk_full_is_told_apart_from_other_write_errors():
    assert is_disk_full(OSError(errno.ENOSPC, "No space left on device"))
    assert is_disk_full(OSError(errno.EDQUOT, "Disk quota exceeded"))
    # h5py's own wording of the C library's failure
    assert is_disk_full(OSError("Can't synchronously write data (file write failed: errno = 28, "
                                "error message = 'No space left on device')"))
    try:
        try:
            _full()
        except OSError as error:
            raise RuntimeError("closing failed") from error
    except RuntimeError as chained:
        assert is_disk_full(chained)
    assert not is_disk_full(OSError(errno.EACCES, "Permission denied"))
    assert not is_disk_full(ValueError("no space here"))


#: Runs the tiny test with stand-in figures and fills the disk while it shears.
FILLING = """\
import os, sys
sys.path.insert(0, {tests!r})
import reliability_factories as stand_ins
import grainlab.postprocess.figures as figures
import grainlab.protocols.biaxial.outputs as outputs
import grainlab.protocols.biaxial.records as records
from grainlab.cli import main

outputs._figures = stand_ins.fake_curves
figures.fabric_figures = stand_ins.fake_fabric_figures
measure, calls = records.measure, []

def filling_measure(*args, **kwargs):
    calls.append(1)
    if len(calls) == 3:  # the disk fills up while the run shears
        fd = os.open({filler!r}, os.O_WRONLY | os.O_CREAT)
        try:
            while True:
                os.write(fd, bytes(65536))
        except OSError:
            os.close(fd)
    return measure(*args, **kwargs)

records.measure = filling_measure
sys.exit(main(sys.argv[1:]))
"""


@pytest.fixture
def small_disk(tmp_path):
    """A 4 MB tmpfs at tmp_path/disk (root only; skipped where mounting is not allowed)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(disk)], capture_output=True,
                             check=False)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.decode(errors='replace').strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_a_really_full_disk_stops_cleanly_and_the_run_resumes(tmp_path, small_disk, fast_figures, tiny_reference):
    (tmp_path / "tiny.toml").write_text(TINY_TOML)
    filler = small_disk / "filler"
    script = tmp_path / "filling.py"
    script.write_text(FILLING.format(tests=str(Path(__file__).parent), filler=str(filler)))
    out = small_disk / "run"
    args = ["biaxial", "--config", str(tmp_path / "tiny.toml"), "--out", str(out), "--no-progress", "--no-report"]
    stopped = subprocess.run([sys.executable, str(script), *args], capture_output=True, text=True, timeout=300,
                             check=False)
    assert filler.stat().st_size > 0
    # one line, no traceback, no error report of the HDF5 library, no crash at exit
    assert stopped.returncode == 1, stopped.stderr
    assert stopped.stderr.count("\n") == 1 and "the disk is full" in stopped.stderr, stopped.stderr
    assert "HDF5" not in stopped.stderr and "Exception ignored" not in stopped.stderr
    read_checkpoint(out / "checkpoint.h5")
    assert not any(name.endswith(".tmp") for name in os.listdir(out))  # no half-written temporary file left
    filler.unlink()  # space freed
    biaxial.run_biaxial(tiny_config(), out, resume=True, progress=False)
    assert_same_run(tiny_reference, out)
