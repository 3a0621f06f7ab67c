"""examples/05_sweep.py runs, and a second run skips everything."""

import runpy
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "05_sweep.py"


def test_example_sweep(tmp_path, capsys):
    module = runpy.run_path(str(EXAMPLE), run_name="example")
    module["main"](tmp_path)
    out = capsys.readouterr().out
    assert "run_0000: irregular" in out and "run_0002: hexagonal" in out
    assert "3 run, 0 skipped" in out
    module["main"](tmp_path)
    assert "0 run, 3 skipped" in capsys.readouterr().out
