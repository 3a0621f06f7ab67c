"""The cyclic biaxial test on the runner: the platens turn exactly at +/- the
amplitude and bring the axial strain back to 0 at each cycle's end, the sample is
in compression at +A and in extension at -A under the held confining pressure,
the records and snapshots fall where the plan says, a stopped run resumes to the
same bits (mid-cycle and across a turn included), the command line writes the
report, and bad input is one line before any work."""

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
from grainlab.columns import AXIAL_STRAIN, CYCLE, CYCLIC, STRAIN_PATH, STRESS_RATIO
from grainlab.io.hdf5 import read_results
from grainlab.protocols.cyclic import CyclicProtocol
from grainlab.protocols.cyclic.outputs import cycle_table
from grainlab.protocols.cyclic.protocol import cycle_plan, snapshot_name_of
from grainlab.protocols.registry import resolve_config
from grainlab.report import detect_kind

AMPLITUDE = 0.002
# two cycles of +/-0.2 % on the quick sample, a checkpoint at every record: a few seconds
SMALL = [f"cyclic.strain_amplitude={AMPLITUDE}", "cyclic.cycles=2", "run.threads=1", "run.checkpoint_interval=1e-6"]


@pytest.fixture(scope="module")
def config():
    return resolve_config("cyclic", overrides=SMALL, quick=True)


@pytest.fixture(scope="module")
def straight(tmp_path_factory, config):
    out = tmp_path_factory.mktemp("cyclic") / "run"
    runner.run_protocol(CyclicProtocol(config), out)
    return out


def test_the_plan_turns_at_odd_quarters_and_names_its_snapshots():
    final, turns, snapshots = cycle_plan(0.005, 3)
    assert final == pytest.approx(0.06)
    assert turns == pytest.approx([0.005, 0.015, 0.025, 0.035, 0.045, 0.055])
    name = snapshot_name_of(0.005)
    assert [name(s) for s in snapshots] == [
        "start", "cycle_001_compression", "cycle_001_extension", "cycle_001_end", "cycle_002_end",
        "cycle_003_compression", "cycle_003_extension", "cycle_003_end"]


def test_the_axial_strain_turns_at_the_amplitude_and_returns_to_zero(straight, config):
    ts = read_results(straight / "run.h5").timeseries
    eps, cycle, path = ts[AXIAL_STRAIN], ts[CYCLE], ts[STRAIN_PATH]
    height_tolerance = 1e-6  # the platens move a whole number of steps
    assert eps.max() == pytest.approx(AMPLITUDE, abs=height_tolerance)
    assert eps.min() == pytest.approx(-AMPLITUDE, abs=height_tolerance)
    assert path[-1] == pytest.approx(4 * AMPLITUDE * 2, rel=1e-6)
    # the axial strain is the triangle wave of the path: up, down, up
    expected = np.where(path <= AMPLITUDE, path, np.where(path <= 3 * AMPLITUDE, 2 * AMPLITUDE - path,
                                                           path - 4 * AMPLITUDE))
    first = cycle <= 1 + 1e-6
    np.testing.assert_allclose(eps[first], expected[first], atol=2e-6)
    ends = [int(np.argmin(np.abs(cycle - k))) for k in (1, 2)]
    np.testing.assert_allclose(eps[ends], 0.0, atol=height_tolerance)


def test_compression_at_plus_a_and_extension_at_minus_a(straight, config):
    results = read_results(straight / "run.h5")
    ts = results.timeseries
    assert ts["confining_pressure_pa"] == pytest.approx(config["consolidation.pressure"])
    for row in cycle_table(ts):
        assert row["stress_ratio_compression"] > 1.2  # the axial stress above the confining pressure
        assert row["stress_ratio_extension"] < 0.85  # and below it
        assert row["axial_strain_compression"] == pytest.approx(AMPLITUDE, abs=1e-6)
        assert row["axial_strain_extension"] == pytest.approx(-AMPLITUDE, abs=1e-6)
    assert results.snapshot_names == ["start", "cycle_001_compression", "cycle_001_extension", "cycle_001_end",
                                      "cycle_002_compression", "cycle_002_extension", "cycle_002_end"]
    assert [results.snapshot(n).axial_strain for n in results.snapshot_names[1:3]] == pytest.approx(
        [AMPLITUDE, -AMPLITUDE], abs=1e-6)
    assert list(ts) == [str(c) for c in CYCLIC]


@pytest.mark.parametrize("checkpoints", [3, 9, 20])
def test_a_stopped_run_resumes_to_the_same_bits(straight, tmp_path, monkeypatch, config, checkpoints):
    """Stopped after the boundary stage, after the first turn and in the first extension."""
    stop_and_resume(CyclicProtocol(config), tmp_path / "run", checkpoints, monkeypatch)
    assert_same_run(straight, tmp_path / "run")


def test_the_command_line_writes_the_report(tmp_path, capsys):
    out = tmp_path / "cyclic"
    assert main(["run", "cyclic", "--quick", "--out", str(out), "--no-progress", "--set", "cyclic.cycles=1",
                 "--set", "cyclic.strain_amplitude=0.2 %"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("grainlab cyclic: ") and "1 cycles of +/-0.20 %" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary["cycles"]) == 1
    assert detect_kind(out) == (out, "cyclic")
    page = (out / "report.html").read_text()
    assert "The cycles" in page and "data:image/png;base64," in page
    assert "grainlab run cyclic --out" in page and "cyclic.strain_amplitude=0.002" in page
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert header == [str(c) for c in CYCLIC]
    assert STRESS_RATIO in header


@pytest.mark.parametrize(("override", "message"), [
    ("cyclic.strain_amplitude=0.2", "cyclic.strain_amplitude: 0.2 is out of range"),
    ("cyclic.strain_amplitude=0.001", "less than four record intervals"),
    ("cyclic.cycles=0", "cyclic.cycles"),
    ("shear.final_strain=0.1", "unknown configuration key 'shear.final_strain'"),
])
def test_bad_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    assert main(["run", "cyclic", "--quick", "--out", str(out), "--set", override]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_the_example_prints_each_cycle(tmp_path):
    example = Path(__file__).resolve().parents[2] / "examples" / "10_cyclic.py"
    printed = subprocess.run([sys.executable, str(example), str(tmp_path / "run")], check=True,
                             capture_output=True, text=True).stdout
    lines = printed.splitlines()
    assert [line.split(":")[0] for line in lines[:-1]] == ["cycle 1", "cycle 2", "cycle 3"]
    assert lines[-1].startswith("grainlab cyclic: 563 grains") and "3 cycles of +/-0.30 %" in lines[-1]


DOCS = Path(__file__).resolve().parents[2] / "docs" / "protocols.md"
DEFAULT = Path(__file__).resolve().parents[2] / "tests" / "data" / "cyclic" / "default_summary.json"


def test_the_docs_quote_the_default_runs_summary():
    """docs/protocols.md's default run (line and cycle table) is tests/data/cyclic's summary."""
    s = json.loads(DEFAULT.read_text())
    text = DOCS.read_text()
    line = next(x for x in text.splitlines() if x.startswith("grainlab cyclic: 3518"))
    first, last = s["cycles"][0], s["cycles"][-1]
    assert line.split("; ")[:-1] == [
        f"grainlab cyclic: {s['n_particles']} grains, porosity {s['porosity_initial']:.3f}",
        f"5 cycles of +/-0.50 %: sigma1/sigma3 at +A {first['stress_ratio_compression']:.2f} -> "
        f"{last['stress_ratio_compression']:.2f}, volumetric strain {100 * last['volumetric_strain']:.3f} %, "
        f"Z {s['coordination_number_initial']:.2f} -> {last['coordination_number']:.2f}"]
    for c in s["cycles"]:
        row = (f"| {c['cycle']} | {c['stress_ratio_compression']:.3f} | {c['stress_ratio_extension']:.3f} | "
               f"{100 * c['volumetric_strain']:.4f} | {c['coordination_number']:.3f} | "
               f"{c['mean_stability_index']:.4f} | {c['anisotropy']:.3f} |")
        assert row in text, row
    assert s["strain_amplitude"] == 0.005 and len(s["cycles"]) == 5


@pytest.mark.slow
def test_the_quick_default_run_is_the_one_docs_protocols_md_prints(tmp_path, capsys):
    # 5 cycles of +/-0.5 % on the quick sample: about 45 s
    assert main(["run", "cyclic", "--quick", "--out", str(tmp_path / "cyclic"), "--no-progress", "--no-report"]) == 0
    printed = capsys.readouterr().out.splitlines()[0]
    quoted = next(line for line in DOCS.read_text().splitlines() if line.startswith("grainlab cyclic: 563"))
    assert printed.split("; ")[:-1] == quoted.split("; ")[:-1], (printed, quoted)


# stress control: two cycles of q = +/-30 kPa on the quick sample, a checkpoint at every record
STRESS = ["cyclic.control=stress", "cyclic.stress_amplitude=30 kPa", "cyclic.cycles=2", "run.threads=1",
          "run.checkpoint_interval=1e-6"]


@pytest.fixture(scope="module")
def stress_config():
    return resolve_config("cyclic", overrides=STRESS, quick=True)


@pytest.fixture(scope="module")
def stress_run(tmp_path_factory, stress_config):
    out = tmp_path_factory.mktemp("cyclic_stress") / "run"
    runner.run_protocol(CyclicProtocol(stress_config), out)
    return out


def test_stress_control_turns_where_the_deviator_reaches_the_amplitude(stress_run):
    """The platens turn at q = +/-A_q: the rule is asked every 100 steps, so a turn
    overshoots by at most what 100 steps add (a few per cent of A_q here)."""
    ts = {k: np.asarray(v, dtype=np.float64) for k, v in read_results(stress_run / "run.h5").timeseries.items()}
    q = ts["axial_stress_pa"] - ts["confining_pressure_pa"]
    cycle = ts[CYCLE]
    quarters = np.round(4 * cycle).astype(int)
    first = np.flatnonzero(np.diff(quarters) > 0) + 1  # the record of each event
    assert list(quarters[first]) == list(range(1, 9))
    turns = first[(quarters[first] % 4 == 1) | (quarters[first] % 4 == 3)]
    np.testing.assert_allclose(np.abs(q[turns]), 30e3, rtol=0.05)
    assert np.all(q[turns][::2] > 0) and np.all(q[turns][1::2] < 0)
    ends = first[quarters[first] % 4 == 0]
    assert np.all(np.abs(q[ends]) < 0.1 * 30e3)
    summary = json.loads((stress_run / "summary.json").read_text())
    assert len(summary["cycles"]) == 2 and summary["stopped_at_strain_limit"] is False
    assert summary["cycles"][0]["stress_ratio_compression"] == pytest.approx(1.3, rel=0.05)
    names = read_results(stress_run / "run.h5").snapshot_names
    assert names == ["start", "cycle_001_compression", "cycle_001_extension", "cycle_001_end",
                     "cycle_002_compression", "cycle_002_extension", "cycle_002_end"]


@pytest.mark.parametrize("checkpoints", [4, 12])
def test_a_stopped_stress_controlled_run_resumes_to_the_same_bits(stress_run, tmp_path, monkeypatch, stress_config,
                                                                   checkpoints):
    stop_and_resume(CyclicProtocol(stress_config), tmp_path / "run", checkpoints, monkeypatch)
    assert_same_run(stress_run, tmp_path / "run")


def test_a_sample_that_cannot_carry_the_cycles_stops_at_the_strain_limit(tmp_path):
    """q = +/-90 kPa at sigma_3 = 100 kPa: extension to sigma_1 = 10 kPa is beyond these disks'
    strength in extension; the loading ends where the axial strain reaches the limit."""
    config = resolve_config("cyclic", overrides=["cyclic.control=stress", "cyclic.stress_amplitude=90 kPa",
                                                 "cyclic.cycles=2", "cyclic.strain_limit=0.5 %", "run.threads=1"],
                            quick=True)
    result = runner.run_protocol(CyclicProtocol(config), tmp_path / "run")
    s = result.summary
    assert s["stopped_at_strain_limit"] is True and len(s["cycles"]) < 2
    eps = np.asarray(read_results(tmp_path / "run" / "run.h5").timeseries[AXIAL_STRAIN])
    assert np.abs(eps).max() >= 0.005 and np.abs(eps).max() < 0.0055
    assert "the axial strain reached +/-0.5 %" in result.one_line()


@pytest.mark.parametrize(("override", "message"), [
    ("cyclic.stress_amplitude=150 kPa", "cyclic.stress_amplitude: 150 kPa reaches beyond the sample"),
    ("cyclic.strain_amplitude=0.01", "cyclic.strain_amplitude: a stress-controlled test turns at"),
])
def test_bad_stress_control_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    assert main(["run", "cyclic", "--quick", "--out", str(out), "--set", "cyclic.control=stress", "--set",
                 "cyclic.stress_amplitude=50 kPa", "--set", override]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_stress_control_needs_its_amplitude_and_strain_control_refuses_it(tmp_path, capsys):
    for args, message in ((["--set", "cyclic.control=stress"], "cyclic.stress_amplitude: give the deviator"),
                          (["--set", "cyclic.stress_amplitude=50 kPa"], "only used with cyclic.control = 'stress'")):
        assert main(["run", "cyclic", "--quick", "--out", str(tmp_path / "never"), *args]) != 0
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1, err


def test_a_saved_stress_controlled_configuration_reads_back(stress_config):
    """A checkpoint stores every key; reading it back must not refuse the defaults it holds."""
    protocol = CyclicProtocol(stress_config)
    assert protocol.resolve_saved(protocol.config_dict()) == protocol.config_dict()


STRESS_QUICK = Path(__file__).resolve().parents[2] / "tests" / "data" / "cyclic" / "stress_quick_summary.json"


def test_the_docs_quote_the_stress_controlled_run():
    """docs/protocols.md's stress-controlled run (line and table) is tests/data/cyclic's summary."""
    s = json.loads(STRESS_QUICK.read_text())
    text = DOCS.read_text()
    line = next(x for x in text.splitlines() if x.startswith("grainlab cyclic: 563 grains") and "q +/-" in x)
    first, last = s["cycles"][0], s["cycles"][-1]
    assert line.split("; ")[:-1] == [
        f"grainlab cyclic: {s['n_particles']} grains, porosity {s['porosity_initial']:.3f}",
        f"5 cycles of q +/-{s['stress_amplitude_pa'] / 1e3:.1f} kPa: sigma1/sigma3 at +A "
        f"{first['stress_ratio_compression']:.2f} -> {last['stress_ratio_compression']:.2f}, volumetric strain "
        f"{100 * last['volumetric_strain']:.3f} %, Z {s['coordination_number_initial']:.2f} -> "
        f"{last['coordination_number']:.2f}"]
    for c in s["cycles"]:
        row = (f"| {c['cycle']} | {100 * c['axial_strain_compression']:.4f} | {100 * c['axial_strain_extension']:.4f} | "
               f"{100 * c['volumetric_strain']:.4f} | {c['coordination_number']:.3f} | "
               f"{c['mean_stability_index']:.4f} | {c['anisotropy']:.3f} |")
        assert row in text, row
    assert s["control"] == "stress" and len(s["cycles"]) == 5
