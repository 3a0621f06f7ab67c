"""The packing study on a small box and a subset of targets; the full study is slow."""

import json

import pytest

from grainlab.cli import main
from grainlab.study import STUDY_COLUMNS, read_table, run_study


def test_small_study_writes_table_figures_summary(tmp_path):
    campaign, summary = run_study(
        tmp_path, workers=2, progress=False, overrides={"width": 0.02, "height": 0.04},
        irregular=(0.14, 0.2), hexagonal=(0.08, 0.12),
    )
    rows = read_table(tmp_path / "study.csv")
    assert list(rows[0])[: len(STUDY_COLUMNS)] == list(STUDY_COLUMNS)
    assert [(r["kind"], float(r["porosity_target"])) for r in rows] == [
        ("irregular", 0.14), ("irregular", 0.2), ("hexagonal", 0.08), ("hexagonal", 0.12)]
    assert rows[1]["status"] == "unjammed" and "stress-free" in rows[1]["note"]
    assert all(r["note"] for r in rows)
    for name in ("fig15_lambda_vs_coordination", "fig16_lambda_vs_porosity", "fig17_lambda_vs_anisotropy"):
        assert (tmp_path / f"{name}.png").exists() and (tmp_path / f"{name}.svg").exists()
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert saved["campaign_wall_time_s"] > 0 and saved["n_runs"] == 4
    assert "r2" in saved["fig17_fit"]


@pytest.mark.slow
def test_full_study_cli(tmp_path, capsys):
    assert main(["study", "--out", str(tmp_path), "--workers", "2", "--no-progress"]) == 0
    rows = read_table(tmp_path / "study.csv")
    assert len(rows) == 19
    assert all(r["status"] != "failed" for r in rows)
    hexagonal = [float(r["mean_stability_index"]) for r in rows if r["kind"] == "hexagonal"]
    irregular = [float(r["mean_stability_index"]) for r in rows if r["kind"] == "irregular"]
    assert max(hexagonal) < min(irregular)
