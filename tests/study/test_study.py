"""The packing study on a small box and a subset of targets; the full study is slow."""

import json

import pytest

from grainlab.cli import main
from grainlab.study import STUDY_COLUMNS, derive_seed, read_table, run_study, study_runs


def test_small_study_writes_table_figures_summary(tmp_path):
    small = {"width": 0.02, "height": 0.04}
    campaign, summary = run_study(
        tmp_path, workers=2, progress=False, overrides=small,
        irregular=(0.14, 0.2), hexagonal=(0.08, 0.12),
    )
    rows = read_table(tmp_path / "study.csv")
    assert list(rows[0])[: len(STUDY_COLUMNS)] == list(STUDY_COLUMNS)
    assert [(r["kind"], float(r["porosity_target"])) for r in rows] == [
        ("irregular", 0.14), ("irregular", 0.2), ("hexagonal", 0.08), ("hexagonal", 0.12)]
    assert all(r["note"] for r in rows)
    # every irregular packing bears load at its target: 0.14 frictionless, 0.2 (looser than the
    # frictionless expansion jams in this box) with the friction the search chose
    dense, loose = rows[0], rows[1]
    for row in (dense, loose):
        assert row["status"] == "ok"
        assert float(row["porosity"]) == pytest.approx(float(row["porosity_target"]), abs=1e-12)
        assert float(row["mean_wall_stress_pa"]) >= 1e5
        assert float(row["mechanical_coordination_number"]) >= 3.0
    assert float(dense["generation_friction"]) == 0.0 and dense["generation_expansions"] == "1"
    assert 0.0 < float(loose["generation_friction"]) <= 0.9
    assert 1e5 <= float(loose["mean_wall_stress_pa"]) <= 3e5
    trials = json.loads(loose["friction_search"])
    assert len(trials) == int(loose["generation_expansions"]) >= 3
    assert trials[0]["friction"] == 0.0 and trials[0]["outcome"] == "stress_free"
    assert trials[-1]["friction"] == float(loose["generation_friction"]) and trials[-1]["outcome"] == "in_band"
    assert f"generation friction {float(loose['generation_friction']):.4g}" in loose["note"]
    assert all(r["generation_friction"] == "nan" for r in rows[2:])  # lattices are not generated
    for name in ("fig15_lambda_vs_coordination", "fig16_lambda_vs_porosity", "fig17_lambda_vs_anisotropy"):
        assert (tmp_path / f"{name}.png").exists() and (tmp_path / f"{name}.svg").exists()
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert saved["campaign_wall_time_s"] > 0 and saved["n_runs"] == 4
    assert "r2" in saved["fig17_fit"] and "r2" in saved["fig17_fit_all"]
    assert saved["generation_friction"] == {"irregular_0.140": 0.0,
                                            "irregular_0.200": float(loose["generation_friction"])}
    assert saved["packing_params"]["generation_friction"] == "search"
    # both readings of lambda in the trends
    assert "all_lambda_vs_z_slope" in saved["trends"] and "all_lambda_all_vs_z_slope" in saved["trends"]

    # the fixed-friction variant of the same campaign seed: the same realisations, the old behaviour
    fixed_dir = tmp_path / "fixed0"
    run_study(fixed_dir, workers=1, progress=False, figures=False,
              overrides={**small, "generation_friction": 0.0},
              irregular=(0.14, 0.2), hexagonal=())
    fixed = read_table(fixed_dir / "study.csv")
    assert [r["seed"] for r in fixed] == [r["seed"] for r in rows[:2]]
    assert fixed[0]["mean_wall_stress_pa"] == dense["mean_wall_stress_pa"]  # bit for bit the same packing
    assert fixed[1]["status"] == "unjammed" and "stress-free" in fixed[1]["note"]
    assert float(fixed[1]["generation_friction"]) == 0.0 and fixed[1]["friction_search"] == ""


def test_study_runs_carry_the_generation_friction_and_share_seeds_across_variants():
    searched = study_runs(0)
    assert len(searched) == 19
    irregular = [r for r in searched if r.params["kind"] == "irregular"]
    hexagonal = [r for r in searched if r.params["kind"] == "hexagonal"]
    assert all(r.params["generation_friction"] == "search" for r in irregular)
    assert all("generation_friction" not in r.params for r in hexagonal)
    for value in (0.0, 0.9):
        fixed = study_runs(0, {"generation_friction": value})
        assert [r.seed for r in fixed] == [r.seed for r in searched]
        assert all(r.params["generation_friction"] == value for r in fixed if r.params["kind"] == "irregular")
    # the seeds are those of the campaign seed and the other parameters alone
    assert irregular[0].seed == derive_seed(0, "packing", {"kind": "irregular", "porosity": 0.08})
    assert study_runs(1)[0].seed != irregular[0].seed


@pytest.mark.parametrize(
    ("overrides", "field"),
    [
        ({"generation_friction": "searched"}, "generation_friction"),
        ({"generation_friction": -0.1}, "generation_friction"),
        ({"search_stress_max": 1e7}, "search_stress_max"),
        ({"search_stress_min": 4e5}, "search_stress_min"),
        ({"friction": 0.0}, "friction"),
    ],
)
def test_bad_study_overrides_are_refused_before_any_run(tmp_path, overrides, field):
    with pytest.raises(ValueError, match=field):
        run_study(tmp_path, workers=1, progress=False, overrides=overrides)
    assert not (tmp_path / "study.csv").exists()


def test_cli_generation_friction_option(tmp_path, capsys):
    assert main(["study", "--out", str(tmp_path), "--generation-friction", "lots", "--no-progress"]) == 2
    assert "--generation-friction" in capsys.readouterr().err
    assert not (tmp_path / "study.csv").exists()


@pytest.mark.slow
def test_full_study_cli(tmp_path, capsys):
    assert main(["study", "--out", str(tmp_path), "--workers", "2", "--no-progress"]) == 0
    rows = read_table(tmp_path / "study.csv")
    assert len(rows) == 19
    assert all(r["status"] == "ok" for r in rows)  # none failed, none unjammed
    irregular_rows = [r for r in rows if r["kind"] == "irregular"]
    assert all(float(r["mean_wall_stress_pa"]) >= 1e5 for r in irregular_rows)
    assert all(float(r["mechanical_coordination_number"]) >= 3.0 for r in irregular_rows)
    # frictionless where that jams (0.08 ... 0.14 at least), friction for the loose targets
    assert all(float(r["generation_friction"]) == 0.0 for r in irregular_rows[:7])
    assert all(float(r["generation_friction"]) > 0.0 for r in irregular_rows[8:])
    hexagonal = [float(r["mean_stability_index"]) for r in rows if r["kind"] == "hexagonal"]
    irregular = [float(r["mean_stability_index"]) for r in rows if r["kind"] == "irregular"]
    assert max(hexagonal) < min(irregular)
