"""Output folders: one that cannot be written is refused with one line before any
work; a run never overwrites files that another run (or the user) put in its
folder; outputs get the mode the umask asks for, like any file the user writes."""

from __future__ import annotations

import json
import os
import stat
import subprocess

import pytest

from grainlab.cli import main
from grainlab.io.hdf5 import ResultsWriter, write_checkpoint
from grainlab.io.results import (
    ensure_output_folder,
    write_bytes_atomic,
    write_json_atomic,
    write_text_atomic,
)
from grainlab.study.campaign import write_table


@pytest.fixture
def read_only_folder(tmp_path):
    """A read-only tmpfs (root only; skipped where mounting is not allowed)."""
    folder = tmp_path / "read-only"
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m,ro", "tmpfs", str(folder)],
                             capture_output=True, check=False)
    if mounted.returncode != 0:
        pytest.skip("cannot mount a tmpfs here")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=False)


def _one_line(capsys, *needles: str) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, err
    return err


@pytest.mark.parametrize("case", ["a file", "under a file", "in /proc", "in /proc/self"])
def test_an_unwritable_out_is_refused_with_one_line(tmp_path, capsys, case):
    (tmp_path / "notes.txt").write_text("mine")
    out = {"a file": tmp_path / "notes.txt", "under a file": tmp_path / "notes.txt" / "run",
           "in /proc": "/proc/grainlab-run", "in /proc/self": "/proc/self/grainlab-run"}[case]
    assert main(["biaxial", "--quick", "--out", str(out), "--no-progress"]) == 2
    _one_line(capsys, "grainlab biaxial: error: --out:", str(out))
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_a_read_only_file_system_is_refused_with_one_line(read_only_folder, capsys):
    assert main(["biaxial", "--quick", "--out", str(read_only_folder), "--no-progress"]) == 2
    _one_line(capsys, "cannot write in", "Read-only file system")
    assert main(["biaxial", "--quick", "--out", str(read_only_folder / "run"), "--no-progress"]) == 2
    _one_line(capsys, "cannot create the folder", "Read-only file system")


def test_analyze_and_export_refuse_a_file_as_out(tmp_path, capsys, tiny_reference):
    (tmp_path / "p.csv").write_text("id,x,y,radius\n1,0,0,0.5\n2,1,0,0.5\n")
    (tmp_path / "taken").write_text("mine")
    assert main(["analyze", str(tmp_path / "p.csv"), "--out", str(tmp_path / "taken")]) == 2
    _one_line(capsys, "grainlab analyze: error: --out:", "is a file, not a folder")
    assert main(["export", str(tiny_reference), "--vtk", "--out", str(tmp_path / "taken")]) == 2
    _one_line(capsys, "grainlab export: error: --out:", "is a file, not a folder")
    assert (tmp_path / "taken").read_text() == "mine"


def test_ensure_output_folder_makes_missing_parents_and_says_what_is_wrong(tmp_path):
    assert ensure_output_folder(tmp_path / "a" / "b").is_dir()
    (tmp_path / "f").write_text("")
    with pytest.raises(ValueError, match=r"--folder: .*/f/x: .*/f is a file, not a folder"):
        ensure_output_folder(tmp_path / "f" / "x", option="--folder")
    with pytest.raises(ValueError, match="does not exist"):
        ensure_output_folder(tmp_path / "missing", create=False)
    assert not (tmp_path / "missing").exists()


def test_demo_refuses_a_folder_with_another_runs_outputs(tmp_path, capsys, tiny_reference):
    import shutil

    run = tmp_path / "biaxial"
    shutil.copytree(tiny_reference, run)
    before = {p.name: p.read_bytes() for p in run.iterdir()}
    assert main(["demo", "--out", str(run), "--n-side", "3", "--no-progress"]) == 2
    _one_line(capsys, "timeseries.csv exists and was not written by this run")
    assert {p.name: p.read_bytes() for p in run.iterdir()} == before


def test_biaxial_refuses_a_folder_with_another_summary_or_timeseries(tmp_path, capsys):
    for name in ("summary.json", "timeseries.csv"):
        folder = tmp_path / name.replace(".", "-")
        folder.mkdir()
        (folder / name).write_text("someone else's")
        assert main(["biaxial", "--quick", "--out", str(folder), "--no-progress"]) == 2
        _one_line(capsys, f"{folder / name} exists and was not written by this run")
        assert (folder / name).read_text() == "someone else's"
        assert sorted(p.name for p in folder.iterdir()) == [name]  # no run started


@pytest.mark.parametrize("umask", [0o022, 0o077])
def test_outputs_get_the_mode_the_umask_asks_for(tmp_path, umask):
    expected = 0o666 & ~umask
    old = os.umask(umask)
    try:
        paths = [
            write_text_atomic(tmp_path / "timeseries.csv", "a\n1\n"),
            write_json_atomic(tmp_path / "summary.json", {"a": 1}),
            write_bytes_atomic(tmp_path / "state.bin", b"\x00"),
            write_table(tmp_path / "study.csv", [{"name": "run_0000", "porosity": 0.12}]),
            write_checkpoint(tmp_path / "checkpoint.h5", b"engine", {"phase": "shear"}),
        ]
        for buffered in (False, True):
            with ResultsWriter(tmp_path / f"run-{buffered}.h5", buffered=buffered) as writer:
                writer.write_summary({"a": 1})
            paths.append(writer.path)
    finally:
        os.umask(old)
    for path in paths:
        assert stat.S_IMODE(path.stat().st_mode) == expected, (path.name, oct(path.stat().st_mode))
    assert json.loads((tmp_path / "summary.json").read_text()) == {"a": 1}
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize("case", ["negative radius", "truncated HDF5"])
def test_analyze_of_refused_input_leaves_no_folder(tmp_path, capsys, case):
    if case == "negative radius":
        source = tmp_path / "p.csv"
        source.write_text("id,x,y,radius\n1,0,0,-1\n2,1,0,0.5\n")
        needle = "column 'radius': -1 is not > 0"
    else:
        source = tmp_path / "run.h5"
        source.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(92))  # an HDF5 signature, cut short
        needle = "cannot be read as HDF5"
    out = tmp_path / "new" / "analysis"
    assert main(["analyze", str(source), "--out", str(out)]) == 2
    _one_line(capsys, "grainlab analyze: error:", needle)
    assert not (tmp_path / "new").exists()  # nothing created before the input was accepted
    assert sorted(p.name for p in tmp_path.iterdir()) == [source.name]


def test_analyze_refuses_an_out_it_cannot_create_before_reading(tmp_path, capsys):
    source = tmp_path / "p.csv"
    source.write_text("id,x,y,radius\n1,0,0,-1\n")  # would be refused too, but --out is checked first
    assert main(["analyze", str(source), "--out", "/proc/grainlab-analysis/out"]) == 2
    _one_line(capsys, "grainlab analyze: error: --out:", "cannot create the folder")
