"""examples/03_custom_sample.py runs and prints where its sample is."""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "03_custom_sample.py"


def test_example_prints_porosities_coordination_and_stress(capsys):
    module = runpy.run_path(str(EXAMPLE), run_name="example")
    result = module["main"]()
    out = capsys.readouterr().out
    for text in ("porosity nominal", "porosity overlap-corrected", "coordination number", "mean wall stress"):
        assert text in out
    assert result["porosity"] == pytest.approx(0.14, abs=1e-12)
    assert result["porosity_overlap_corrected"] >= result["porosity"]
    assert 3.0 < result["coordination_number"] < 5.0
    assert result["mean_wall_stress_pa"] > 0
    assert abs(result["lattice_porosity"] - 0.14) < 0.01
