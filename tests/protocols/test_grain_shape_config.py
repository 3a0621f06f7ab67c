"""``sample.shape`` and ``sample.shape_parameter``: the grains' clump template from
the configuration, a template file read, and bad settings refused in one line
before any folder is made."""

from __future__ import annotations

import re

import numpy as np
import pytest

from grainlab import cli
from grainlab.io import FileFormatError
from grainlab.io.shape_file import read_shape_template
from grainlab.protocols.biaxial.config import resolve
from grainlab.protocols.config import grain_shape
from grainlab.shapes import shape_template


def test_the_configured_shape_is_the_shapes_template():
    config = resolve(overrides=["sample.shape=trimer", "sample.shape_parameter=0.3"])
    template = grain_shape(config.values)
    expected = shape_template("trimer", 0.3)
    assert template is not None and template.n_pebbles == 3
    np.testing.assert_array_equal(template.offsets, expected.offsets)
    assert grain_shape(resolve().values) is None  # disks, the default
    assert grain_shape(resolve(overrides=["sample.shape=rod", "sample.rod_pebbles=4",
                                          "sample.shape_parameter=0.2"]).values).n_pebbles == 4


def test_a_template_file_gives_its_pebbles_about_the_unions_centroid(tmp_path):
    path = tmp_path / "l_shape.csv"
    path.write_text("x, y, r\n0, 0, 1   # the corner\n1.5, 0, 1\n0, 1.5, 1\n")
    template = read_shape_template(path)
    assert template.n_pebbles == 3
    # about the union's centroid (the mean of the three by symmetry about the diagonal), R = 1
    assert abs(template.offsets[:, 0].mean() - template.offsets[:, 1].mean()) < 1e-12
    assert np.max(np.hypot(*template.offsets.T) + template.radii) == pytest.approx(1.0, rel=1e-12)
    assert grain_shape(resolve(overrides=[f"sample.shape={path}"]).values).n_pebbles == 3


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "no pebble"),
        ("# nothing here\n", "no pebble"),
        ("0, 0, 1\n1, 0, nan\n", ":2: a pebble needs a finite centre and a radius > 0"),
        ("0, 0, 1\n1, 0, -1\n", ":2: a pebble needs a finite centre and a radius > 0"),
        ("0, 0\n", ":1: expected three numbers x, y, r (m), got 2"),
        ("0, zero, 1\n", ":1: expected three numbers"),
    ],
)
def test_a_bad_template_file_is_refused_naming_the_line(tmp_path, text, message):
    path = tmp_path / "shape.csv"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=re.escape(message)):
        read_shape_template(path)


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        (["sample.shape=hexagon"], "sample.shape: 'hexagon' is not disk, dimer, trimer, rod or a template file "
                                   "(no such file)"),
        (["sample.shape=trimer", "sample.shape_parameter=0.8"], "sample.shape_parameter: a trimer's eta must be"),
        (["sample.shape_parameter=0.3"], "sample.shape_parameter: a disk has eta 0"),
        (["sample.shape=dimer", "sample.rod_pebbles=4"], "sample.rod_pebbles: only a rod takes it"),
        (["sample.shape=trimer", "sample.shape_parameter=0.3", "boundary.kind=outer_particles"],
         "boundary.kind: 'outer_particles' bonds the outermost grains into a chain"),
    ],
)
def test_bad_shape_settings_are_one_line_before_any_folder(tmp_path, capsys, settings, message):
    out = tmp_path / "run"
    argv = ["biaxial", "--quick", "--out", str(out)]
    for setting in settings:
        argv += ["--set", setting]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
    assert not out.exists()


def test_a_bad_template_file_in_the_configuration_names_the_file_and_line(tmp_path, capsys):
    path = tmp_path / "shape.csv"
    path.write_text("0, 0, 1\n1, 0, inf\n")
    out = tmp_path / "run"
    assert cli.main(["run", "oedometer", "--quick", "--out", str(out), "--set", f"sample.shape={path}"]) == 2
    err = capsys.readouterr().err.strip()
    assert f"{path}:2: a pebble needs a finite centre" in err and len(err.splitlines()) == 1, err
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.parametrize("command", ["oedometer", "simple_shear"])
def test_a_test_of_trimers_counts_its_grains_as_bodies(tmp_path, command):
    """Trimers of eta 0.3 through a whole test from the command line: the summary counts
    clumps (a third of the pebbles), the porosity each clump's union once (so it stays a
    porosity, where the pebbles' areas would count the clumps' own overlaps), and in
    simple shear the cell's stress control, reading branches between centroids, holds
    sigma_yy at its target."""
    import json

    out = tmp_path / "run"
    argv = ["run", command, "--quick", "--out", str(out), "--no-report",
            "--set", "sample.shape=trimer", "--set", "sample.shape_parameter=0.3"]
    assert cli.main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["shape"] == "trimer" and summary["shape_parameter"] == 0.3
    assert summary["n_particles"] == 3 * summary["n_grains"]
    assert 0.05 < summary["porosity_initial"] < 0.3
    series = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True)
    assert np.all(series["coordination_number"] > 2.0)  # contacts per clump, not per pebble
    if command == "simple_shear":
        sheared = series[series["shear_strain"] >= 0.1]
        assert abs(float(np.mean(sheared["normal_stress_pa"])) / 100.0e3 - 1.0) < 0.02
