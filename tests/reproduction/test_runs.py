"""The runs of a reproduction: variants, their folders, seeds, bad input before any work,
and resuming (a second call reruns nothing)."""

from __future__ import annotations

import json

import pytest

from grainlab.cli import main
from grainlab.protocols.biaxial.config import FIELDS
from grainlab.reproduction.runs import (
    PLAN_FILE,
    ReproductionPlan,
    parse_variant,
    plan_from_args,
    snapshot_strains,
    variant_folder,
)


def test_the_default_strain_rate_is_the_papers():
    assert FIELDS["shear.strain_rate"].default == pytest.approx(0.02 / 60.0)


def test_snapshots_every_quarter_percent_to_2_then_every_percent():
    s = snapshot_strains(0.10)
    assert s[:3] == [0.0, 0.0025, 0.005] and 0.007 in s and 0.009 in s and 0.015 in s
    assert [x for x in s if x > 0.02] == pytest.approx([0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10])
    assert snapshot_strains(0.045)[-1] == 0.045


def test_variants_by_name():
    assert parse_variant("boundary_b").overrides == {"boundary.kind": "outer_particles"}
    rate = parse_variant("rate=1 %/min")
    assert rate.name == "rate=1%/min" and rate.overrides["shear.strain_rate"] == pytest.approx(0.01 / 60)
    assert variant_folder(rate.name) == "rate=1pct_per_min"
    study = parse_variant("study:generation_friction=0.9")
    assert study.kind == "study" and study.overrides == {"generation_friction": 0.9}
    raw = parse_variant("lambda_raw")
    assert raw.kind == "analysis" and raw.source == "paper" and raw.analysis == {"boundary_contacts": "raw"}
    assert parse_variant("lambda_raw:boundary_b").source == "boundary_b"
    reading = parse_variant("lambda:slots=nearest,deviation=per_contact")
    assert reading.kind == "analysis" and reading.source == "paper"
    assert reading.analysis == {"lambda_slots": "nearest", "lambda_deviation": "per_contact"}
    on_study = parse_variant("lambda: deviation=per_contact :study:generation_friction=0")
    assert on_study.name == "lambda:deviation=per_contact:study:generation_friction=0"
    assert on_study.source == "study:generation_friction=0" and on_study.analysis == {"lambda_deviation": "per_contact"}
    assert parse_variant("lambda:anchor=mean:rate=1 %/min").source == "rate=1%/min"
    studied = ReproductionPlan.build(2, [on_study.name])
    assert [v.name for v in studied.variants] == ["study:generation_friction=0", on_study.name]
    assert [studied.reads(v) for v in studied.variants] == ["study", "study"]
    assert len(studied.runs()) == 2 * 19  # the study's packings, measured again: nothing of its own
    band = parse_variant("band:displacement")
    assert band.kind == "analysis" and band.source == "paper" and band.analysis == {"band": "displacement"}
    plan = ReproductionPlan.build(2, ["band:final", "lambda:anchor=mean"])
    assert [v.name for v in plan.variants] == ["paper", "band:final", "lambda:anchor=mean"]
    assert len(plan.runs()) == 2  # the analysis variants run nothing of their own


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("nonsense", "unknown variant 'nonsense'"),
        ("rate=2%/fortnight", "unknown unit"),
        ("rate=auto", "give a rate with a unit"),
        ("study:friction_of_the_moon=1", "unknown packing parameter"),
        ("set:sample.porosity=1.5", "sample.porosity"),
        ("set:porosity", "key=value"),
        ("lambda_raw:study", "reads a biaxial variant"),
        ("lambda:slots=sideways", "slots must be one of angular, list, nearest"),
        ("lambda:colour=red", "unknown lambda option 'colour'"),
        ("lambda:anchor=mean:lambda_raw", "lambda reads a biaxial or study variant's runs"),
        ("lambda:anchor=mean:nonsense", "unknown variant 'nonsense'"),
        ("band:strain", "band:displacement, band:lambda or band:final"),
        ("band:eyeballed", "band:displacement, band:lambda or band:final"),
    ],
)
def test_bad_variants_name_the_problem(name, message):
    with pytest.raises(ValueError, match=message):
        parse_variant(name)


def test_same_sample_in_every_variant_and_shared_runs():
    plan = ReproductionPlan.build(3, ["lambda_raw", "rate=2%/min", "rate=1%/min", "boundary_b"])
    names = [v.name for v in plan.variants]
    assert names[0] == "paper"  # the runs lambda_raw reads are added
    assert plan.variant("rate=2%/min").source == "paper"  # the paper's rate: its runs
    runs = plan.runs()
    assert [r.name for r in runs] == [f"{v}/seed-{k}" for v in ("paper", "rate=1pct_per_min", "boundary_b")
                                      for k in (1, 2, 3)]
    seeds = {r.name: r.params["sample.seed"] for r in runs}
    assert seeds["paper/seed-2"] == seeds["boundary_b/seed-2"] == 2
    config = plan.biaxial_config(plan.variant("boundary_b"), 2)
    assert config["boundary.kind"] == "outer_particles" and config["shear.snapshot_strains"] == snapshot_strains(0.1)
    assert config["shear.strain_rate"] == pytest.approx(0.02 / 60)


def test_quick_is_small_and_short():
    plan = plan_from_args(None, None, True)
    assert plan.seeds == (1, 2, 3)
    config = plan.biaxial_config(plan.variant("paper"), 1)
    assert config["sample.width"] == 0.03 and config["shear.final_strain"] == 0.05
    study = [r for r in plan.runs() if r.kind == "packing"]
    assert len(study) == 3 * 19 and study[0].params["width"] == 0.03


def test_a_folder_keeps_its_variants_seeds_and_mode(tmp_path):
    ReproductionPlan.build(2, ["paper"], quick=True).save(tmp_path)
    assert plan_from_args(None, None, None, tmp_path) == ReproductionPlan.build(2, ["paper"], quick=True)
    merged = plan_from_args(3, ["boundary_b"], None, tmp_path)
    assert [v.name for v in merged.variants] == ["paper", "boundary_b"] and merged.seeds == (1, 2, 3)
    assert merged.quick
    with pytest.raises(ValueError, match="--quick"):
        plan_from_args(3, ["paper"], False, tmp_path)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--seeds", "1"], "--seeds"),
        (["--variants", "nonsense"], "--variants"),
        (["--workers", "0"], "--workers"),
        (["--workers", "2", "--scheduler", "tcp://localhost:1"], "--workers/--scheduler"),
        (["--variants", "paper", "paper"], "given twice"),
        (["--claims-only"], "holds no reproduction"),
    ],
)
def test_bad_input_fails_before_any_work(tmp_path, capsys, argv, message):
    out = tmp_path / "never"
    assert main(["reproduce", "--out", str(out), "--no-progress", *argv]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_an_out_that_is_a_file_is_refused(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    assert main(["reproduce", "--out", str(tmp_path / "file"), "--no-progress"]) == 2
    assert "is a file" in capsys.readouterr().err


@pytest.mark.slow
def test_a_second_call_reruns_nothing_and_claims_only_recomputes(tmp_path, capsys):
    out = tmp_path / "repro"
    argv = ["reproduce", "--out", str(out), "--quick", "--seeds", "2", "--workers", "1", "--no-progress",
            "--variants", "set:shear.final_strain=0.0025"]
    assert main(argv) == 0
    first = capsys.readouterr().out
    assert "2 runs (2 run, 0 already finished, 0 failed)" in first
    saved = json.loads((out / PLAN_FILE).read_text())
    assert saved == {"seeds": [1, 2], "variants": ["set:shear.final_strain=0.0025"], "quick": True}
    h5 = out / "runs" / "set_shear.final_strain=0.0025" / "seed-1" / "biaxial" / "run.h5"
    stamp = h5.stat().st_mtime_ns
    assert main(argv) == 0
    assert "2 runs (0 run, 2 already finished, 0 failed)" in capsys.readouterr().out
    assert h5.stat().st_mtime_ns == stamp
    (out / "claims.json").unlink()
    assert main(["reproduce", "--out", str(out), "--claims-only", "--no-progress", "--workers", "1"]) == 0
    doc = json.loads((out / "claims.json").read_text())
    assert doc["variant"] == "set:shear.final_strain=0.0025" and doc["seeds"] == [1, 2]
    assert len(doc["claims"]) >= 15
