"""Sweep plans: parsing, ranges, grid and zip, errors that name the key; the CLI."""

import pytest

from grainlab.cli import main
from grainlab.study import read_table
from grainlab.study.plan import PlanError, parse_plan

GOOD = """
base = "packing"
seed = 3
[fixed]
width = 0.02
height = 0.04
[vary]
porosity = [0.14, 0.18]
generation_friction = { start = 0.0, stop = 0.4, num = 3 }
"""


def test_grid_and_ranges():
    plan = parse_plan(GOOD)
    runs = plan.runs()
    assert len(runs) == 6
    assert runs[0].labels == {"porosity": 0.14, "generation_friction": 0.0}
    assert runs[-1].labels == {"porosity": 0.18, "generation_friction": 0.4}
    assert runs[0].params["width"] == 0.02
    assert len({r.seed for r in runs}) == 6


def test_zip_and_step_range():
    plan = parse_plan(GOOD.replace('seed = 3', 'seed = 3\nmode = "zip"').replace(
        "{ start = 0.0, stop = 0.4, num = 3 }", "{ start = 0.0, stop = 0.1, step = 0.1 }"))
    assert [r.labels["generation_friction"] for r in plan.runs()] == [0.0, 0.1]


def test_biaxial_plan_keys_and_units(tmp_path):
    plan = parse_plan('base = "biaxial"\nquick = true\n[vary.consolidation]\npressure = ["100 kPa", "200 kPa"]\n')
    runs = plan.runs()
    assert [r.params["consolidation.pressure"] for r in runs] == ["100 kPa", "200 kPa"]
    assert runs[0].params["quick"] is True


@pytest.mark.parametrize(
    ("text", "key"),
    [
        ('mode = "grid"', "base"),
        ('base = "triaxial"', "base"),
        ('base = "packing"\nmode = "cross"', "mode"),
        ('base = "packing"\nseed = -1', "seed"),
        ('base = "packing"\nwhat = 1', "what"),
        ('base = "packing"\n[vary]\nporosity = []', "vary.porosity"),
        ('base = "packing"\n[vary]\nporosity = [0.1, 1.2]', "porosity"),
        ('base = "packing"\n[vary]\nporosity = { start = 0.1 }', "vary.porosity"),
        ('base = "packing"\n[vary]\nporosity = { start = 0.1, stop = 0.2 }', "vary.porosity"),
        ('base = "packing"\n[vary]\nporosity = { start = 0.1, stop = 0.2, num = 0 }', "vary.porosity.num"),
        ('base = "packing"\n[vary]\nporosityy = [0.1]', "porosityy"),
        ('base = "packing"\n[fixed]\nwidth = -1.0', "width"),
        ('base = "packing"\n[fixed]\nkind = "square"', "kind"),
        ('base = "packing"\nmode = "zip"\n[vary]\nporosity = [0.1, 0.2]\nwidth = [0.02]', "mode 'zip'"),
        ('base = "packing"\n[fixed]\nporosity = 0.1\n[vary]\nporosity = [0.1]', "porosity"),
        ('base = "biaxial"\n[vary]\n"sample.porosity" = [0.12, 2.0]', "sample.porosity"),
        ('base = "biaxial"\n[vary]\n"sample.poro" = [0.12]', "sample.poro"),
        ('base = "biaxial"\nconfig = "missing.toml"', "config"),
        ('base = "packing"\nquick = true', "quick"),
        ("base = ", "not valid TOML"),
    ],
)
def test_errors_name_the_key(text, key):
    with pytest.raises(PlanError, match=key.replace(".", r"\.").replace("(", r"\(")):
        parse_plan(text)


def test_sweep_cli(tmp_path, capsys):
    plan = tmp_path / "plan.toml"
    plan.write_text(
        'base = "packing"\nmode = "zip"\n[fixed]\nwidth = 0.02\nheight = 0.04\n'
        '[vary]\nkind = ["hexagonal", "irregular"]\nporosity = [0.13, 0.2]\n'
    )
    out = tmp_path / "out"
    assert main(["sweep", str(plan), "--out", str(out), "--workers", "2", "--no-progress"]) == 0
    rows = read_table(out / "sweep.csv")
    assert [r["kind"] for r in rows] == ["hexagonal", "irregular"]
    assert list(rows[0])[:3] == ["name", "kind", "porosity"]
    assert (out / "plan.toml").exists()
    assert "2 run, 0 already finished" in capsys.readouterr().out
    assert main(["sweep", str(plan), "--out", str(out), "--no-progress"]) == 0
    assert "0 run, 2 already finished" in capsys.readouterr().out


def test_sweep_cli_bad_plan(tmp_path, capsys):
    plan = tmp_path / "plan.toml"
    plan.write_text('base = "packing"\n[vary]\nporosity = [1.5]\n')
    assert main(["sweep", str(plan), "--out", str(tmp_path / "o"), "--no-progress"]) == 2
    assert "porosity" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
