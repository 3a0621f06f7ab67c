"""``grainlab reproduce --quick`` end to end on a shortened configuration: real runs,
claims with finite numbers in their physical ranges, the files in their documented form."""

from __future__ import annotations

import csv
import json
import math

import pytest

from grainlab.cli import main


@pytest.mark.slow
def test_quick_reproduction_writes_claims_in_range(tmp_path, capsys):
    out = tmp_path / "repro"
    argv = ["reproduce", "--quick", "--out", str(out), "--seeds", "3", "--workers", "2", "--no-progress",
            "--variants", "set:shear.final_strain=0.02", "lambda_raw:set:shear.final_strain=0.02",
            "study:width=0.02,height=0.04"]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "already finished" in printed and "claims (" in printed
    doc = json.loads((out / "claims.json").read_text())
    assert doc["seeds"] == [1, 2, 3] and doc["quick"] is True
    assert doc["variant"] == "set:shear.final_strain=0.02+study:width=0.02,height=0.04"
    rows = {r["id"]: r for r in doc["claims"]}
    assert len(rows) >= 15
    for r in doc["claims"]:
        assert r["verdict"] in ("reproduced", "not reproduced", "inconclusive")
        assert len(r["per_seed"]) == 3 and r["n"] <= 3
        for v in [r["mean"], *r["ci95"], *r["per_seed"]]:
            assert v is None or math.isfinite(v)
    # every seed has its macro numbers, and they are physical
    for key in ("peak_near_1.5", "z_initial", "a_isotropic", "initial_lambda_above_zero", "contraction_first"):
        assert rows[key]["n"] == 3, key
    assert all(0.0 < v <= 0.02 for v in rows["peak_near_1.5"]["per_seed"])
    assert all(2.5 < v < 4.5 for v in rows["z_initial"]["per_seed"])
    assert all(0.0 <= v < 0.2 for v in rows["a_isotropic"]["per_seed"])
    assert all(0.0 < v < 0.5 for v in rows["initial_lambda_above_zero"]["per_seed"])
    for key in ("lambda_locates_band", "lambda_field_locates_band", "initial_lambda_random"):
        assert all(v is None or 0.0 <= v <= 1.0 for v in rows[key]["per_seed"]), key
    # the study: hexagonal lattices are more stable than the random packings, every seed
    assert all(v < 0 for v in rows["hexagonal_more_stable"]["per_seed"])
    # the analysis-only variant read the same runs: the macro claims are the same numbers
    raw = {r["id"]: r for r in next(b for b in doc["variants"] if b["kind"] == "analysis")["claims"]}
    assert raw["peak_near_1.5"]["per_seed"] == rows["peak_near_1.5"]["per_seed"]
    assert raw["z_initial"]["per_seed"] == rows["z_initial"]["per_seed"]
    with open(out / "claims.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == sum(len(b["claims"]) for b in doc["variants"])
    html = (out / "reproduction.html").read_text()
    assert "<script" not in html and "data:image/png;base64," in html
    assert (out / "runs" / "set_shear.final_strain=0.02" / "seed-3" / "biaxial" / "run.h5").exists()
