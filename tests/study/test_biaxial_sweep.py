"""A sweep whose base is a test (the biaxial test, the oedometer) runs end to end, one row per run."""

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


def test_an_oedometer_sweep_runs_each_friction_into_its_own_folder(tmp_path):
    plan = tmp_path / "plan.toml"
    plan.write_text(
        'base = "oedometer"\nquick = true\n[fixed]\n"oedometer.vertical_stresses" = ["400 kPa", "800 kPa"]\n'
        '[vary.material]\nfriction = [0.3, 0.9]\n'
    )
    out = tmp_path / "out"
    assert main(["sweep", str(plan), "--out", str(out), "--workers", "1", "--no-progress"]) == 0
    with open(out / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["material.friction"] for r in rows] == ["0.3", "0.9"] and all(r["status"] == "ok" for r in rows)
    k0 = [float(r["k0_loading"]) for r in rows]
    assert k0[0] > k0[1] > 0  # more grain friction, less lateral stress: K0 falls
    assert (out / "runs" / "run_0001" / "oedometer" / "run.h5").exists()


def test_a_plan_of_an_unknown_test_names_the_known_ones(tmp_path, capsys):
    plan = tmp_path / "plan.toml"
    plan.write_text('base = "triaxial"\n')
    assert main(["sweep", str(plan), "--out", str(tmp_path / "out")]) == 2
    assert "base: expected one of 'packing', 'biaxial', 'brazilian', 'crushing', 'cyclic', 'oedometer', 'simple_shear', 'ucs', got 'triaxial'" in capsys.readouterr().err
