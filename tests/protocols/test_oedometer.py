"""The oedometer (K0) test: the second protocol on the runner. Its physics (side
walls that do not move, each load step at its stress, the walls' stresses equal
to the grains' Love-Weber stress at equilibrium, K below 1 on loading and
growing with the overconsolidation ratio on unloading), its resume to the same
bits from any checkpoint, its command line, report and bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

import grainlab.protocols.runner as runner
from grainlab.cli import main
from grainlab.columns import OEDOMETER
from grainlab.io.hdf5 import read_results
from grainlab.protocols.config import ConfigError
from grainlab.protocols.oedometer import (
    K0_FROM_STRESS_RATIO,
    OedometerProtocol,
    k0_loading,
    load_path,
)
from grainlab.protocols.registry import PROTOCOLS, resolve_config
from grainlab.report import detect_kind

# three load steps up, two down: a few seconds on the quick sample
PATH = ["oedometer.vertical_stresses=[200 kPa, 400 kPa, 800 kPa, 400 kPa, 100 kPa]", "run.threads=1",
        "run.checkpoint_interval=1e-6"]  # a checkpoint at every load step


@pytest.fixture(scope="module")
def config():
    return resolve_config("oedometer", overrides=PATH, quick=True)


@pytest.fixture(scope="module")
def straight(tmp_path_factory, config):
    out = tmp_path_factory.mktemp("oedometer") / "run"
    runner.run_protocol(OedometerProtocol(config), out)
    return out


def test_the_records_are_the_schemas_columns_one_per_load_step(straight, config):
    results = read_results(straight / "run.h5")
    assert results.kind == "oedometer" and list(results.timeseries) == [str(c) for c in OEDOMETER]
    ts = results.timeseries
    np.testing.assert_array_equal(ts["target_vertical_stress_pa"], load_path(config))
    assert results.snapshot_names == [f"load_{k:02d}" for k in range(len(load_path(config)))]
    # each step ends within the tolerance of its target
    assert np.all(np.abs(ts["vertical_stress_pa"] / ts["target_vertical_stress_pa"] - 1) < 0.01)


def test_the_side_walls_stay_put_and_the_sample_compresses_then_swells(straight):
    results = read_results(straight / "run.h5")
    walls = [results.walls(name) for name in results.snapshot_names]
    for name in ("left", "right", "bottom"):
        k = walls[0].names.index(name)
        for w in walls[1:]:
            np.testing.assert_array_equal(np.r_[w.a[k], w.b[k]], np.r_[walls[0].a[k], walls[0].b[k]], err_msg=name)
    ts = results.timeseries
    # width fixed: the area strain is the axial strain
    np.testing.assert_allclose(ts["volumetric_strain"], ts["axial_strain"], rtol=1e-12, atol=1e-15)
    strain = ts["axial_strain"]
    assert strain[0] == 0.0 and np.all(np.diff(strain[:4]) > 0) and np.all(np.diff(strain[3:]) < 0)
    assert np.all(np.diff(ts["void_ratio"][:4]) < 0)


def test_the_walls_stresses_are_the_grains_love_weber_stress_at_equilibrium(straight):
    ts = read_results(straight / "run.h5").timeseries
    np.testing.assert_allclose(ts["love_weber_yy_pa"], ts["vertical_stress_pa"], rtol=0.02)
    np.testing.assert_allclose(ts["love_weber_xx_pa"], ts["horizontal_stress_pa"], rtol=0.02)
    assert np.all(np.abs(ts["love_weber_xy_pa"]) < 0.02 * ts["vertical_stress_pa"])


def test_a_trimer_samples_love_weber_stress_is_the_walls_with_levers_from_the_centroids(tmp_path):
    """A clump's contacts act about its centroid: with each pebble's own centre as the
    lever's origin the clumps' internal forces are missed (about 30 % too low here)."""
    config = resolve_config("oedometer", overrides=["oedometer.vertical_stresses=[200 kPa, 400 kPa]",
                                                    "run.threads=1", "sample.shape=trimer",
                                                    "sample.shape_parameter=0.3"], quick=True)
    runner.run_protocol(OedometerProtocol(config), tmp_path / "run")
    ts = read_results(tmp_path / "run" / "run.h5").timeseries
    np.testing.assert_allclose(ts["love_weber_yy_pa"], ts["vertical_stress_pa"], rtol=0.005)
    np.testing.assert_allclose(ts["love_weber_xx_pa"], ts["horizontal_stress_pa"], rtol=0.005)


def test_k_on_loading_and_unloading(straight, config):
    ts = read_results(straight / "run.h5").timeseries
    k, ocr = ts["lateral_stress_ratio"], ts["overconsolidation_ratio"]
    np.testing.assert_allclose(k, ts["horizontal_stress_pa"] / ts["vertical_stress_pa"], rtol=1e-15)
    assert abs(k[0] - 1.0) < 0.02  # isotropically consolidated, friction just on
    assert np.all(np.diff(k[:4]) < 0) and 0.1 < k[3] < 1.0  # loading: towards K0
    assert np.all(ocr[:4] == 1.0) and np.all(np.diff(ocr[3:]) > 0)
    assert np.all(np.diff(k[3:]) > 0)  # unloading: K grows with the OCR
    summary = read_results(straight / "run.h5").summary
    # the module's rule: the slope of sigma_h on sigma_v over 400 and 800 kPa (>= 4 sigma_0)
    assert K0_FROM_STRESS_RATIO == 4.0
    expected = np.polyfit(ts["vertical_stress_pa"][2:4], ts["horizontal_stress_pa"][2:4], 1)[0]
    assert summary["k0_loading"] == pytest.approx(expected, rel=1e-12)
    assert summary["k0_loading"] == pytest.approx(k0_loading(ts, config["consolidation.pressure"]), rel=1e-15)
    assert summary["k0_jaky"] is None
    assert [u["overconsolidation_ratio"] for u in summary["unloading"]] == pytest.approx(list(ocr[4:]))


@pytest.mark.parametrize("checkpoints", [2, 3, 6])
def test_a_stopped_run_resumes_to_the_same_bits(straight, tmp_path, monkeypatch, config, checkpoints):
    stop_and_resume(OedometerProtocol(config), tmp_path / "run", checkpoints, monkeypatch)
    assert_same_run(straight, tmp_path / "run")


def test_the_command_line_runs_it_with_its_report_as_cli_md_prints(tmp_path, capsys):
    out = tmp_path / "oedo"
    assert main(["run", "oedometer", "--quick", "--out", str(out), "--no-progress",
                 "--set", "oedometer.friction_angle=30deg"]) == 0
    printed = capsys.readouterr().out.splitlines()[0]
    quoted = " ".join((Path(__file__).resolve().parents[2] / "docs" / "cli.md").read_text().split())
    line = printed.split("; ")  # all but the wall time and folder, as docs/cli.md quotes them
    assert "; ".join(line[:-1]) in quoted, printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["k0_jaky"] == pytest.approx(0.5, rel=1e-12) and summary["friction_angle_deg"] == pytest.approx(30)
    for step in summary["unloading"]:
        assert step["mayne_kulhawy"] == pytest.approx(0.5 * step["overconsolidation_ratio"] ** 0.5, rel=1e-12)
    assert detect_kind(out) == (out, "oedometer")
    page = (out / "report.html").read_text()
    assert "K0 on first loading" in page and "Mayne" in page and "data:image/png;base64," in page
    assert f"{summary['k0_loading']:.3g}" in page
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert header == [str(c) for c in OEDOMETER]


@pytest.mark.parametrize(("override", "message"), [
    ("oedometer.vertical_stresses=[200 kPa, -5 kPa]", "oedometer.vertical_stresses: -5000 is out of range"),
    ("oedometer.vertical_stresses=[]", "give at least one vertical stress"),
    ("oedometer.friction_angle=95deg", "oedometer.friction_angle"),
    ("shear.strain_rate=0.01", "unknown configuration key 'shear.strain_rate'"),
])
def test_bad_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    assert main(["run", "oedometer", "--quick", "--out", str(out), "--set", override]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_load_path_keeps_its_order_and_the_registry_knows_it():
    config = resolve_config("oedometer", overrides=["oedometer.vertical_stresses=[1 MPa, 200 kPa, 300 kPa]"])
    assert config["oedometer.vertical_stresses"] == [1e6, 2e5, 3e5]
    assert set(PROTOCOLS) == {"biaxial", "brazilian", "crushing", "cyclic", "oedometer", "simple_shear", "ucs"}
    with pytest.raises(ConfigError, match="unknown configuration key"):
        resolve_config("oedometer", overrides=["boundary.kind=membrane"])


def test_the_example_prints_k_at_each_step_and_k0_beside_jaky(tmp_path):
    example = Path(__file__).resolve().parents[2] / "examples" / "09_oedometer.py"
    printed = subprocess.run([sys.executable, str(example), str(tmp_path / "run")], check=True,
                             capture_output=True, text=True).stdout
    lines = printed.splitlines()
    steps = [line for line in lines if line.startswith("sigma_v")]
    stresses = [float(line.split()[1]) for line in steps]
    assert stresses == pytest.approx([100, 200, 400, 800, 400, 200, 100], rel=0.01)
    assert "(Jaky 0.500)" in lines[-1] and "K0 " in lines[-1]


@pytest.mark.slow
def test_the_default_run_is_the_one_docs_protocols_md_prints(tmp_path, capsys):
    # the paper-scale sample (3,518 grains): about 30 s
    assert main(["run", "oedometer", "--out", str(tmp_path / "oedometer"), "--no-progress", "--no-report",
                 "--set", "oedometer.friction_angle=30.1 deg"]) == 0
    printed = capsys.readouterr().out.splitlines()[0]
    docs = Path(__file__).resolve().parents[2] / "docs" / "protocols.md"
    quoted = next(line for line in docs.read_text().splitlines() if line.startswith("grainlab oedometer: 3518"))
    assert printed.split("; ")[:-1] == quoted.split("; ")[:-1], (printed, quoted)


def test_the_viewer_draws_the_oedometer_curve_of_sigma_v(straight):
    from grainlab.viewer.data import viewer_data

    data = viewer_data(straight / "run.h5")
    assert (data["curve"]["x"], data["curve"]["y"]) == ("axial_strain", "vertical_stress_pa")
    assert data["curve"]["n"] == len(read_results(straight / "run.h5").timeseries["step"])


def test_each_snapshot_carries_the_load_steps_stresses_as_its_scalars(straight):
    results = read_results(straight / "run.h5")
    ts = results.timeseries
    for k, info in enumerate(results.snapshots):
        snap = results.snapshot(info.name)
        assert snap.scalars["vertical_stress_pa"] == ts["vertical_stress_pa"][k] == info.scalars["vertical_stress_pa"]
        assert snap.scalars["horizontal_stress_pa"] == ts["horizontal_stress_pa"][k]
        assert snap.axial_strain == ts["axial_strain"][k] == info.axial_strain
