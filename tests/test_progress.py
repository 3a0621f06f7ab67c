"""The progress display: bars only on a terminal, plain lines elsewhere, nothing by default."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from grainlab import _progress
from grainlab._progress import progress_bar
from grainlab.samples import UniformByNumber, expand_to_porosity


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_plain_lines_off_a_terminal_have_milestones_and_no_carriage_return():
    stream = io.StringIO()
    bar = progress_bar(2.0, "shearing", enabled=True, stream=stream)
    for _ in range(400):  # many small updates, as a shear phase makes
        bar.update(0.005)
    bar.close()
    text = stream.getvalue()
    assert "\r" not in text
    assert text.count("\n") == 1
    assert text.startswith("shearing: 25 % ... 50 % ... 75 % ... 100 % ... done in ")


def test_verbose_lines_have_ten_milestones_with_their_postfix():
    stream = io.StringIO()
    _progress.set_verbose(True)
    try:
        bar = progress_bar(10, "campaign", enabled=True, stream=stream)
        for k in range(10):
            bar.set_postfix_str(f"failed {k}")
            bar.update(1)
        bar.close()
    finally:
        _progress.set_verbose(False)
    text = stream.getvalue()
    assert text.count(" % (failed ") == 10
    assert "10 % (failed 0)" in text and "100 % (failed 9)" in text


def test_overshoot_on_a_terminal_is_clamped_without_warning():
    # a strain step past the final strain used to give tqdm's clamping warning and a negative ETA;
    # pytest's filterwarnings=error turns any TqdmWarning into a failure here
    stream = _Terminal()
    bar = progress_bar(2.0, "shearing", enabled=True, stream=stream)
    bar.update(1.5)
    bar.update(0.7)
    bar.update(-5.0)  # a count never goes below zero either
    assert bar.n == 0.0
    bar.moveto(3.0)
    assert bar.n == 2.0
    bar.close()
    assert "\r" in stream.getvalue()  # a real bar, redrawn in place


def test_disabled_is_the_default_and_prints_nothing(capsys):
    bar = progress_bar(5, "anything")
    bar.update(10)
    bar.close()
    assert capsys.readouterr() == ("", "")


def test_library_call_prints_nothing_by_default(capfd):
    sample = expand_to_porosity((0.0, 0.0, 0.012, 0.012), 0.16, UniformByNumber(0.5e-3, 1.0e-3), seed=1)
    assert abs(sample.porosity - 0.16) < 1e-12
    assert capfd.readouterr() == ("", "")


def _cli(tmp_path, *argv):
    err = tmp_path / "stderr.txt"
    with open(err, "w") as stderr:
        done = subprocess.run([sys.executable, "-m", "grainlab.cli", *argv], stdout=subprocess.PIPE,
                              stderr=stderr, text=True, cwd=tmp_path, timeout=600, check=True)
    return done.stdout, err.read_text()


def test_cli_progress_to_a_file_is_a_few_plain_lines(tmp_path):
    out, err = _cli(tmp_path, "demo", "--n-side", "6", "--out", "d")
    assert "\r" not in err
    assert err.startswith("compressing: ") and err.count("\n") == 1
    assert out.startswith("grainlab demo: 36 disks") and out.count("\n") == 1


def test_cli_quiet_prints_only_the_summary_line(tmp_path):
    out, err = _cli(tmp_path, "demo", "--n-side", "6", "--out", "d", "--quiet")
    assert err == ""
    assert out.startswith("grainlab demo: 36 disks") and out.count("\n") == 1


@pytest.mark.slow
def test_biaxial_to_a_file_has_no_carriage_returns_and_quiet_only_the_summary(tmp_path):
    tiny = ["biaxial", "--quick", "--set", "shear.strain_rate=20%/min", "--set", "shear.final_strain=0.02"]
    out, err = _cli(tmp_path, *tiny, "--out", "r")
    assert "\r" not in err
    assert len(err.splitlines()) <= 24
    assert [line.split(":")[0] for line in err.splitlines()] == ["radius expansion", "consolidating", "shearing"]
    assert out.splitlines()[0].startswith("grainlab biaxial: ") and "report" in out.splitlines()[-1]
    out, err = _cli(tmp_path, *tiny, "--out", "q", "--quiet")
    assert err == ""
    assert len(out.splitlines()) == 1 and out.startswith("grainlab biaxial: ")
