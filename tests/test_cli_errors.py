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
