"""examples/02_analyze_snapshot.py runs and finds the band it imposes."""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "02_analyze_snapshot.py"


def test_example_runs_and_reports_the_imposed_band(capsys):
    module = runpy.run_path(str(EXAMPLE), run_name="example")
    summary = module["main"]()
    out = capsys.readouterr().out
    assert "mean lambda" in out and "shear band" in out
    assert abs(summary["band_angle_deg"] - 35.0) < 2.0
    mean_d = 1.0e-3 * (0.48 + 0.54)  # mean diameter of the example's packing
    assert summary["band_thickness_m"] == pytest.approx(6e-3, abs=mean_d)
    assert 3.0 < summary["Z"] < 4.5
    assert 0.0 < summary["mean_lambda"] < 0.5
