"""A sweep whose base is the biaxial test runs end to end, one row per run."""

from __future__ import annotations

import csv

import pytest

from grainlab.cli import main


@pytest.mark.slow
def test_biaxial_sweep_runs_each_test_into_its_own_folder(tmp_path):
    plan = tmp_path / "plan.toml"
    plan.write_text(
        'base = "biaxial"\nquick = true\n[fixed]\n"shear.final_strain" = 0.006\n"shear.strain_rate" = "20 %/min"\n'
        '"shear.snapshot_strains" = [0.0, 0.005]\n[vary]\n"sample.seed" = [1, 2]\n'
    )
    out = tmp_path / "out"
    assert main(["sweep", str(plan), "--out", str(out), "--workers", "2", "--no-progress"]) == 0
    with open(out / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["sample.seed"] for r in rows] == ["1", "2"]
    assert all(r["status"] == "ok" for r in rows)
    # different samples, each a real biaxial run with its own results
    assert rows[0]["coordination_number_initial"] != rows[1]["coordination_number_initial"]
    for k in range(2):
        assert (out / "runs" / f"run_000{k}" / "biaxial" / "run.h5").exists()
