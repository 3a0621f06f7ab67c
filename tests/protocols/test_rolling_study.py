"""docs/biaxial.md's rolling-resistance table is tests/data/rolling/rolling_study.json's,
and that file's numbers follow from its runs (friction angles of the stress ratios,
means and deviations over the seeds)."""

from __future__ import annotations

import json
import math
import statistics
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
STUDY = json.loads((ROOT / "tests" / "data" / "rolling" / "rolling_study.json").read_text())


def test_the_docs_quote_the_study():
    text = (ROOT / "docs" / "biaxial.md").read_text()
    for t in STUDY["by_rolling_friction"]:
        row = (f"| {t['rolling_friction']:g} | {t['peak_friction_angle_deg']:.1f} ± {t['peak_friction_angle_deg_sd']:.1f} | "
               f"{t['residual_friction_angle_deg']:.1f} ± {t['residual_friction_angle_deg_sd']:.1f} | "
               f"{100 * t['axial_strain_at_peak']:.2f} | {100 * t['final_volumetric_strain']:.2f} |")
        assert row in text, row


def test_the_study_is_its_runs():
    assert sorted({r["rolling_friction"] for r in STUDY["runs"]}) == [0.0, 0.05, 0.1, 0.2]
    for run in STUDY["runs"]:
        for kind in ("peak", "residual"):
            ratio = run[f"{kind}_stress_ratio"]
            assert run[f"{kind}_friction_angle_deg"] == pytest.approx(
                math.degrees(math.asin((ratio - 1) / (ratio + 1))), rel=1e-12)
    for t in STUDY["by_rolling_friction"]:
        group = [r for r in STUDY["runs"] if r["rolling_friction"] == t["rolling_friction"]]
        assert t["seeds"] == len(group) == 3
        values = [r["peak_friction_angle_deg"] for r in group]
        assert t["peak_friction_angle_deg"] == pytest.approx(statistics.fmean(values), rel=1e-12)
        assert t["peak_friction_angle_deg_sd"] == pytest.approx(statistics.stdev(values), rel=1e-12)
    # mu_r = 0, seed 1 is the default run: the README's peak
    default = next(r for r in STUDY["runs"] if r["rolling_friction"] == 0.0 and r["seed"] == 1)
    assert default["peak_stress_ratio"] == 3.0093591071656127
