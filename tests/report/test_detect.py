"""``grainlab report DIR`` refuses what it cannot report on, clearly and before any work."""

from __future__ import annotations

import pytest

from grainlab.cli import main
from grainlab.io.hdf5 import ResultsWriter
from grainlab.report import ReportError, detect_kind, write_report


def _refused(capsys, folder, *fragments: str) -> None:
    assert main(["report", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("grainlab report: error: ")
    for fragment in fragments:
        assert fragment in err
    if folder.is_dir():
        assert not (folder / "report.html").exists()


def test_missing_folder(tmp_path, capsys):
    _refused(capsys, tmp_path / "nowhere", "no such folder")


def test_empty_folder_is_neither_kind(tmp_path, capsys):
    _refused(capsys, tmp_path, "neither a biaxial results folder", "study.csv")
    assert list(tmp_path.iterdir()) == []


def test_a_plain_file_is_refused(tmp_path, capsys):
    f = tmp_path / "notes.txt"
    f.write_text("hello")
    _refused(capsys, f, "not a folder")


def test_unfinished_run_says_how_to_finish_it(tmp_path, capsys):
    writer = ResultsWriter(tmp_path / "run.h5", kind="biaxial")
    writer.close()  # stays run.h5.partial
    _refused(capsys, tmp_path, "has not finished", "--resume")


def test_sweep_folder_points_to_a_run_that_exists(tmp_path, capsys):
    (tmp_path / "sweep.csv").write_text("name,status\nrun_0003,ok\n")
    _refused(capsys, tmp_path, "sweep folder", "packing runs, which have no report", "sweep.csv", "result.json")
    (tmp_path / "runs" / "run_0003" / "biaxial").mkdir(parents=True)
    (tmp_path / "runs" / "run_0003" / "biaxial" / "run.h5").write_bytes(b"")
    _refused(capsys, tmp_path, "sweep folder", f"grainlab report {tmp_path / 'runs' / 'run_0003' / 'biaxial'}")


def test_results_of_another_kind_are_refused(tmp_path, capsys):
    with ResultsWriter(tmp_path / "run.h5", kind="consolidation") as writer:
        writer.append_rows({"axial_strain": [0.0, 0.01]})
    _refused(capsys, tmp_path, "a run of kind 'consolidation', which grainlab report does not cover")


def test_a_table_that_is_not_a_study_is_refused(tmp_path, capsys):
    (tmp_path / "study.csv").write_text("a,b\n1,2\n")
    _refused(capsys, tmp_path, "not a study table")


def test_detect_kind_takes_the_folder_or_its_file(tmp_path):
    (tmp_path / "study.csv").write_text("kind\n")
    assert detect_kind(tmp_path) == (tmp_path, "study")
    assert detect_kind(tmp_path / "study.csv") == (tmp_path, "study")
    with pytest.raises(ReportError):
        write_report(tmp_path / "missing")
    assert issubclass(ReportError, ValueError)
