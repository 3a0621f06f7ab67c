"""A biaxial run stopped anywhere (at each phase boundary, while shearing, while
its outputs are written) finishes with ``--resume`` with the same records,
snapshots and summary as an uninterrupted run, bit for bit; a rerun without
``--resume`` is refused and says to use it (docs/file-formats.md, crash safety)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from reliability_factories import TINY_TOML, assert_same_run, tiny_config

import grainlab.postprocess.figures as figures
import grainlab.protocols.biaxial as biaxial
import grainlab.protocols.biaxial.outputs as outputs
import grainlab.protocols.biaxial.records as records
import grainlab.protocols.runner as runner
import grainlab.protocols.specimen as specimen
from grainlab.cli import main
from grainlab.io.hdf5 import (
    CheckpointError,
    ResultsWriter,
    read_results,
    write_checkpoint,
)


class Stop(KeyboardInterrupt):
    """A kill of the run at a chosen point (what Ctrl-C raises)."""


def _after(function, n=1):
    """``function`` that stops the run right after its ``n``-th call returns."""
    calls = {"n": 0}

    def stopping(*args, **kwargs):
        result = function(*args, **kwargs)
        calls["n"] += 1
        if calls["n"] == n:
            raise Stop(function.__name__)
        return result

    return stopping


def _before(function, n=1):
    """``function`` that stops the run at its ``n``-th call, before it does anything."""
    calls = {"n": 0}

    def stopping(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == n:
            raise Stop(function.__name__)
        return function(*args, **kwargs)

    return stopping


def _stop_at(monkeypatch, where: str) -> None:
    if where == "generation":
        monkeypatch.setattr(specimen, "generate", _after(specimen.generate))
    elif where.startswith("checkpoint "):  # 1 generated, 2 consolidated, 3 boundary installed, 4 sheared
        monkeypatch.setattr(runner, "write_checkpoint", _after(write_checkpoint, int(where.split()[1])))
    elif where == "shearing":
        monkeypatch.setattr(records, "measure", _before(records.measure, 3))
    elif where == "summary":
        monkeypatch.setattr(ResultsWriter, "write_summary", _before(ResultsWriter.write_summary))
    elif where == "finalized":
        monkeypatch.setattr(ResultsWriter, "finalize", _after(ResultsWriter.finalize))
    elif where == "timeseries.csv":
        monkeypatch.setattr(outputs, "write_text_atomic", _before(outputs.write_text_atomic))
    elif where == "figures":
        monkeypatch.setattr(outputs, "_figures", _before(outputs._figures))
    elif where == "fabric figures":
        monkeypatch.setattr(figures, "fabric_figures", _before(figures.fabric_figures))
    elif where == "summary.json":
        monkeypatch.setattr(outputs, "write_json_atomic", _after(outputs.write_json_atomic))
    else:  # pragma: no cover
        raise AssertionError(where)


STOPS = [
    ("generation", None),
    ("checkpoint 1", None),
    ("checkpoint 2", "truncated"),
    ("checkpoint 3", "deleted"),
    ("shearing", None),
    ("shearing", "truncated"),
    ("checkpoint 4", None),
    ("summary", None),
    ("finalized", None),
    ("timeseries.csv", None),
    ("figures", None),
    ("fabric figures", None),
    ("summary.json", None),
]


@pytest.mark.parametrize(("where", "damage"), STOPS, ids=[f"{w}-{d or 'intact'}" for w, d in STOPS])
def test_a_run_stopped_anywhere_finishes_with_resume(tmp_path, monkeypatch, fast_figures, tiny_reference,
                                                     where, damage):
    config = tiny_config()
    out = tmp_path / "run"
    with monkeypatch.context() as patch:
        _stop_at(patch, where)
        with pytest.raises(Stop):
            biaxial.run_biaxial(config, out, progress=False)
    partial = out / "run.h5.partial"
    if where != "summary.json":
        assert not (out / "summary.json").exists()  # nothing that looks finished
    if where != "generation":
        assert (out / "checkpoint.h5").exists()
        with pytest.raises(ValueError, match="use --resume"):
            biaxial.run_biaxial(config, out, progress=False)  # a rerun would overwrite the stopped run
    # a SIGKILL does not let the writer close: the partial file may be cut short or gone
    if damage == "truncated":
        partial.write_bytes(partial.read_bytes()[: partial.stat().st_size // 2])
    elif damage == "deleted":
        partial.unlink()
    result = biaxial.run_biaxial(config, out, resume=True, progress=False)
    assert result.summary["records"] == 5
    assert_same_run(tiny_reference, out)
    again = biaxial.run_biaxial(config, out, resume=True, progress=False)  # a finished run stays finished
    assert again.summary == result.summary


def test_resume_names_the_keys_whose_values_differ(tmp_path, monkeypatch, fast_figures):
    out = tmp_path / "run"
    with monkeypatch.context() as patch:
        _stop_at(patch, "checkpoint 1")
        with pytest.raises(Stop):
            biaxial.run_biaxial(tiny_config(), out, progress=False)
    changed = tiny_config("shear.final_strain=0.003", "material.friction=0.5")
    with pytest.raises(ValueError) as info:
        biaxial.run_biaxial(changed, out, resume=True, progress=False)
    message = str(info.value)
    assert "material.friction = 0.9 in the run, 0.5 now" in message
    assert "shear.final_strain = 0.002 in the run, 0.003 now" in message
    assert "sample." not in message  # only the keys that differ


@pytest.mark.parametrize("where", ["shearing", "finalized"])
def test_a_run_resumes_on_another_thread_count_with_the_same_bits(tmp_path, monkeypatch, fast_figures,
                                                                   tiny_reference, where):
    """The thread count and the checkpoint interval change no bit: a run started on
    one thread finishes on two (as a campaign with fewer workers resumes it)."""
    out = tmp_path / "run"
    with monkeypatch.context() as patch:
        _stop_at(patch, where)
        with pytest.raises(Stop):
            biaxial.run_biaxial(tiny_config(), out, progress=False)
    other = tiny_config("run.threads=2", "run.checkpoint_interval=1e-9")
    result = biaxial.run_biaxial(other, out, resume=True, progress=False)
    assert result.summary["threads"] == (2 if where == "shearing" else 1)  # a finished engine is not rerun
    assert_same_run(tiny_reference, out, also_differing={"threads"})


def test_a_checkpoint_of_a_retired_layout_is_refused_and_the_folder_left_as_it_was(
    tmp_path, monkeypatch, fast_figures
):
    """A folder checkpointed by an earlier grainlab (checkpoint layout 1) is not
    resumed: one message names the layout, and nothing in the folder changes."""
    out = tmp_path / "run"
    with monkeypatch.context() as patch:
        _stop_at(patch, "shearing")
        with pytest.raises(Stop):
            biaxial.run_biaxial(tiny_config(), out, progress=False)
    with h5py.File(out / "checkpoint.h5", "r+") as f:
        f.attrs["format_version"] = np.int64(1)
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    with pytest.raises(CheckpointError, match=r"format_version 1: written by an earlier grainlab.*start the run "
                                              r"again in a new folder"):
        biaxial.run_biaxial(tiny_config(), out, resume=True, progress=False)
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before


def test_a_run_stopped_while_its_report_is_written_gets_it_with_resume(tmp_path, monkeypatch, fast_figures):
    import grainlab.commands.report as report

    (tmp_path / "tiny.toml").write_text(TINY_TOML)
    out = tmp_path / "run"
    args = ["biaxial", "--config", str(tmp_path / "tiny.toml"), "--out", str(out), "--no-progress"]
    with monkeypatch.context() as patch:
        patch.setattr(report, "write_report", _before(report.write_report))
        assert main(args) == 130
    assert (out / "summary.json").exists() and not (out / "report.html").exists()
    written = []

    def fake_report(folder, **kwargs):  # the real one draws the (stand-in) figures again
        written.append(folder)
        path = folder / "report.html"
        path.write_text("<html></html>")
        return path

    monkeypatch.setattr(report, "write_report", fake_report)
    assert main([*args, "--resume"]) == 0
    assert written == [out] and (out / "report.html").exists()
    assert main([*args, "--resume"]) == 0  # finished, report and all: nothing more to write
    assert written == [out]


#: The command line with stand-in figures that take a while to draw (the real ones take
#: ~10 s each run): a signal sent once run.h5 is final lands inside the output phase.
SLOW_STAND_INS = """\
import os, sys, time
sys.path.insert(0, {tests!r})
import reliability_factories as stand_ins
import grainlab.postprocess.figures as figures
import grainlab.protocols.biaxial.outputs as outputs
from grainlab.cli import main

def slow_curves(timeseries, out, constant_volume=False):
    time.sleep(float(os.environ.get("STAND_IN_SECONDS", "0")))
    return stand_ins.fake_curves(timeseries, out)

outputs._figures = slow_curves
figures.fabric_figures = stand_ins.fake_fabric_figures
sys.exit(main(sys.argv[1:]))
"""


def _command(tmp_path, real_figures: bool) -> list[str]:
    if real_figures:
        return [sys.executable, "-m", "grainlab.cli"]
    script = tmp_path / "stand_ins.py"
    script.write_text(SLOW_STAND_INS.format(tests=str(Path(__file__).parent)))
    return [sys.executable, str(script)]


def _signal_in_output_phase(tmp_path, stop, real_figures: bool) -> None:
    (tmp_path / "tiny.toml").write_text(TINY_TOML)
    # the reference from a process of its own: the engine this process loaded may
    # differ from the one a new process loads if the extension was rebuilt meanwhile
    reference = tmp_path / "straight"
    straight = subprocess.run([*_command(tmp_path, False), "biaxial", "--config", str(tmp_path / "tiny.toml"),
                               "--out", str(reference), "--no-progress", "--no-report"],
                              capture_output=True, text=True, timeout=300, check=False)
    assert straight.returncode == 0, straight.stderr
    out = tmp_path / "run"
    command = _command(tmp_path, real_figures)
    args = ["biaxial", "--config", str(tmp_path / "tiny.toml"), "--out", str(out), "--no-progress", "--no-report"]
    env = {**os.environ, "STAND_IN_SECONDS": "30"}
    process = subprocess.Popen([*command, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=env)
    deadline = time.monotonic() + 240
    # timeseries.csv is the first output written from the final run.h5: once it is there the
    # process is inside the output phase (the stand-in figures' sleep), past h5py's clean-up of
    # the results file, where an interrupt can land in a callback that ignores it
    while not (out / "timeseries.csv").exists() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert process.poll() is None, process.communicate()
    process.send_signal(stop)
    _, err = process.communicate(timeout=60)
    assert not (out / "summary.json").exists() and (out / "checkpoint.h5").exists()
    if stop == signal.SIGINT:
        assert process.returncode == 130
        assert "--resume" in err and "Traceback" not in err and err.count("\n") == 1, err
    else:
        assert process.returncode == -signal.SIGKILL

    def again(*extra: str) -> subprocess.CompletedProcess:
        return subprocess.run([*command, *args, *extra], capture_output=True, text=True, timeout=300,
                              check=False)

    assert main(args) == 2  # refused (the message, one line, says to use --resume: tested above)
    resumed = again("--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert (out / "summary.json").exists() and not (out / "checkpoint.h5").exists()
    a, b = read_results(reference), read_results(out)
    assert list(a.timeseries) == list(b.timeseries) and a.snapshot_names == b.snapshot_names
    for name in a.timeseries:
        assert a.timeseries[name].tolist() == b.timeseries[name].tolist(), name
    if real_figures:
        assert {"fig08_stress_ratio.svg", "fig12_stability_index.png"} <= set(os.listdir(out))


@pytest.mark.parametrize("stop", [signal.SIGKILL, signal.SIGINT], ids=["SIGKILL", "SIGINT"])
def test_a_signal_in_the_output_phase_leaves_a_run_that_resume_finishes(tmp_path, stop):
    _signal_in_output_phase(tmp_path, stop, real_figures=False)


@pytest.mark.slow
def test_a_kill_while_the_real_figures_are_drawn_leaves_a_run_that_resume_finishes(tmp_path):
    _signal_in_output_phase(tmp_path, signal.SIGKILL, real_figures=True)
