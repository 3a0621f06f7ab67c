"""The study report on a real small study; ``grainlab study`` writes it at the end."""

from __future__ import annotations

import functools
import html
import json
import re
import shutil

import pytest
from report_factories import STUDY_OVERRIDES, STUDY_TARGETS
from report_helpers import check_self_contained

import grainlab.commands.study as study_command
from grainlab._html import fmt
from grainlab.cli import main
from grainlab.report import write_report
from grainlab.report.study import STUDY_FIGURES, gather_study
from grainlab.study import read_table, run_study


def _text(path) -> str:
    raw = re.sub(r'src="data:[^"]*"', "", path.read_text(encoding="utf-8"))
    raw = re.sub(r"<style>.*?</style>", " ", raw, flags=re.S)
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", raw)))


@pytest.fixture(scope="module")
def study_report(small_study, tmp_path_factory):
    folder = tmp_path_factory.mktemp("study-report") / "study"
    shutil.copytree(small_study, folder)
    write_report(folder)
    return folder


def test_study_report_shows_the_table_figures_and_times(study_report):
    rows = read_table(study_report / "study.csv")
    summary = json.loads((study_report / "summary.json").read_text())
    r = gather_study(study_report)
    assert len(r.rows) == len(rows) == 3
    assert [float(t) for t in r.irregular] == list(STUDY_TARGETS["irregular"])
    assert [float(t) for t in r.hexagonal] == list(STUDY_TARGETS["hexagonal"])
    assert r.params["width"] == STUDY_OVERRIDES["width"] and r.params["friction"] == 0.9
    assert "recorded by the study" in r.params_source
    assert set(r.figures) == set(STUDY_FIGURES)
    text = _text(study_report / "report.html")
    for row in rows:
        assert row["name"] in text and row["status"] in text
        assert fmt(float(row["mean_stability_index"]), 4) in text
    assert fmt(summary["campaign_wall_time_s"], 4) in text
    fit = summary["fig17_fit"]
    assert f"slope {fmt(fit['slope'], 4)}" in text
    # the paper's claims, each with the study's evidence
    assert [c[0] for c in r.claims] == ["λ against Z (Fig. 15)", "hexagonal against irregular",
                                        "λ against porosity (Fig. 16)", "λ against anisotropy a (Fig. 17)"]
    assert check_self_contained(study_report / "report.html") == ["png"] * 3


def test_study_rerun_is_python_when_the_cli_cannot_say_it(study_report):
    r = gather_study(study_report)
    assert r.rerun_command.startswith("from grainlab.study import run_study")
    assert '"width": 0.02' in r.rerun_command and "irregular=(0.14,)" in r.rerun_command
    calls = []
    code = r.rerun_command.split("\n", 1)[1]  # the call, with a stand-in for run_study
    exec(code, {"run_study": lambda *args, **kwargs: calls.append((args, kwargs))})
    (out,), kwargs = calls[0]
    assert out == f"{study_report.resolve()}-rerun"
    assert kwargs == {"seed": 0, "workers": 2, "overrides": STUDY_OVERRIDES, **STUDY_TARGETS}


def test_table_alone_still_reports_and_draws_the_figures(small_study, tmp_path):
    folder = tmp_path / "bare"
    folder.mkdir()
    shutil.copy(small_study / "study.csv", folder / "study.csv")
    path = write_report(folder)
    assert {p.name for p in folder.glob("fig1*.png")} == {f"{k}.png" for k in STUDY_FIGURES}
    text = _text(path)
    assert "no summary.json" in text and "reconstructed" in text
    assert check_self_contained(path) == ["png"] * 3


def test_grainlab_study_writes_the_report_unless_told_not_to(small_study, tmp_path, monkeypatch, capsys):
    # the CLI runs the paper's 19 packings; here it resumes the small study, whose runs are finished
    small = functools.partial(run_study, overrides=STUDY_OVERRIDES, **STUDY_TARGETS)
    monkeypatch.setattr(study_command, "run_study", small)
    for flag, expected in (([], True), (["--no-report"], False)):
        out = tmp_path / f"study{len(flag)}"
        shutil.copytree(small_study, out)
        assert main(["study", "--out", str(out), "--no-progress", "--workers", "2", *flag]) == 0
        assert (out / "report.html").exists() is expected
        printed = capsys.readouterr().out
        assert ("report " + str(out / "report.html") in printed) is expected
