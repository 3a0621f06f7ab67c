"""grainlab's command line turns failures into one-line messages and exit codes
(docs/cli.md, "Exit codes") instead of tracebacks."""

from __future__ import annotations

import argparse

import pytest

from grainlab import SimulationUnstableError, cli
from grainlab.protocols.biaxial import BiaxialError


def _parser_raising(error: BaseException):
    def build_parser() -> argparse.ArgumentParser:
        parser = argparse.ArgumentParser(prog="grainlab")
        sub = parser.add_subparsers(dest="command")
        cmd = sub.add_parser("boom")

        def fail(_args):
            raise error

        cmd.set_defaults(func=fail)
        return parser

    return build_parser


@pytest.mark.parametrize(
    ("error", "code", "text"),
    [
        (ValueError("sample.porosity: 2 is out of range"), 2, "grainlab boom: error: sample.porosity"),
        (SimulationUnstableError("particles 3 and 7 overlap"), 1, "grainlab boom: run stopped: particles 3 and 7"),
        (BiaxialError("consolidation did not converge"), 1, "run stopped: consolidation did not converge"),
        (KeyboardInterrupt(), 130, "interrupted; what was written so far is kept"),
    ],
)
def test_failures_become_one_line_and_an_exit_code(monkeypatch, capsys, error, code, text):
    monkeypatch.setattr(cli, "build_parser", _parser_raising(error))
    assert cli.main(["boom"]) == code
    err = capsys.readouterr().err
    assert text in err and "Traceback" not in err and err.count("\n") == 1


def test_a_bug_still_shows_its_traceback(monkeypatch):
    monkeypatch.setattr(cli, "build_parser", _parser_raising(ZeroDivisionError("a bug")))
    with pytest.raises(ZeroDivisionError):
        cli.main(["boom"])


def _one_line(capsys, *needles: str) -> None:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, err


def test_a_folder_given_as_the_configuration_file_is_one_line(tmp_path, capsys):
    assert cli.main(["biaxial", "--config", str(tmp_path), "--out", str(tmp_path / "run")]) == 2
    _one_line(capsys, f"{tmp_path}: is a folder, not a configuration file")
    assert not (tmp_path / "run").exists()


def test_every_value_of_a_configuration_file_is_checked_even_one_an_override_replaces(tmp_path, capsys):
    (tmp_path / "run.toml").write_text("[run]\nthreads = 0\n")
    args = ["biaxial", "--config", str(tmp_path / "run.toml"), "--set", "run.threads=2", "--out", str(tmp_path / "r")]
    assert cli.main(args) == 2
    _one_line(capsys, f"{tmp_path / 'run.toml'}: run.threads: 0 is out of range")


def test_resume_of_a_folder_without_a_run_is_one_line(tmp_path, capsys):
    assert cli.main(["biaxial", "--quick", "--out", str(tmp_path), "--resume"]) == 2
    _one_line(capsys, "--resume:", "holds no run", "nothing to resume")
    assert cli.main(["biaxial", "--quick", "--out", str(tmp_path / "missing"), "--resume"]) == 2
    _one_line(capsys, "does not exist: nothing to resume")


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.filterwarnings("ignore::ResourceWarning")
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_unreachable_scheduler_is_one_line_after_a_short_wait(tmp_path, capsys, monkeypatch):
    import time

    pytest.importorskip("dask.distributed")
    from grainlab.study import campaign

    monkeypatch.setattr(campaign, "SCHEDULER_TIMEOUT_S", 1.0)
    plan = tmp_path / "plan.toml"
    plan.write_text('base = "packing"\nmode = "zip"\n[fixed]\nwidth = 0.02\nheight = 0.04\n'
                    '[vary]\nporosity = [0.12]\n')
    started = time.monotonic()
    # port 9 (discard) on this machine: nothing listens there
    code = cli.main(["sweep", str(plan), "--out", str(tmp_path / "sweep"), "--scheduler", "tcp://127.0.0.1:9",
                     "--no-progress"])
    assert code == 2 and time.monotonic() - started < 20
    _one_line(capsys, "--scheduler: cannot reach a Dask scheduler at tcp://127.0.0.1:9 within 1 s")


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        ("material.rolling_friction=-0.1", "material.rolling_friction: -0.1 is out of range"),
        ("material.rolling_stiffness=0", "material.rolling_stiffness: 0"),
        ("material.rolling_damping=-1", "material.rolling_damping: -1"),
    ],
)
def test_a_bad_rolling_resistance_is_one_line_before_any_folder(tmp_path, capsys, setting, message):
    out = tmp_path / "run"
    assert cli.main(["biaxial", "--quick", "--set", setting, "--out", str(out)]) == 2
    _one_line(capsys, message)
    assert not out.exists()


def test_an_export_of_a_missing_source_says_so_before_asking_for_the_shear(tmp_path, capsys):
    missing = tmp_path / "nonexistent"
    assert cli.main(["export", str(missing), "--lammps"]) == 2
    _one_line(capsys, f"{missing}: no such file or folder")
    # a folder with no state to export is named as such, not as a missing --shear-rate
    assert cli.main(["export", str(tmp_path), "--lammps"]) == 2
    _one_line(capsys, f"{tmp_path}: no checkpoint.h5 or shear_start.state")
    assert not (tmp_path / "lammps").exists()


def test_an_export_of_clumps_to_a_shear_is_one_line_before_any_folder(tmp_path, capsys):
    import numpy as np

    from grainlab import Simulation

    sim = Simulation(np.empty((0, 2)), np.empty(0), 2650.0, time_step=1e-7)
    sim.add_clumps([[-0.3e-3, 0.0], [0.3e-3, 0.0]], [0.7e-3] * 2, positions=[[2e-3, 2e-3]], angles=[0.0], density=2650.0)
    sim.set_periodic_cell((0.0, 0.0), (6e-3, 6e-3))
    state = tmp_path / "clumps.state"
    sim.save(state)
    out = tmp_path / "deck"
    assert cli.main(["export", str(state), "--lammps", "--shear-rate", "1", "--shear-strain", "0.1", "--out", str(out)]) == 2
    _one_line(capsys, "sim: 1 clump(s) cannot be sheared in LAMMPS")
    assert not out.exists()
    assert cli.main(["export", str(state), "--lammps", "--steps", "10", "--shear-rate", "1", "--out", str(out)]) == 2
    _one_line(capsys, "--steps: holds the cell fixed; give it without --shear-rate and --shear-strain")
    assert not out.exists()
    assert cli.main(["export", str(state), "--lammps", "--steps", "1000", "--out", str(out)]) == 0
    assert "fix             rigid clumps rigid/small molecule infile bodies.grainlab" in (out / "in.grainlab").read_text()
    assert (out / "bodies.grainlab").is_file()
