"""Every example in grainlab's docstrings runs as a test: the modules are found
by their ``>>>`` lines (other than ``+SKIP`` ones, which need a results folder),
so a new example cannot go untested."""

from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "grainlab"
MODULES = sorted(
    "grainlab." + ".".join(path.relative_to(PACKAGE).with_suffix("").parts).removesuffix(".__init__")
    for path in PACKAGE.rglob("*.py")
    if any(">>>" in line and "+SKIP" not in line for line in path.read_text(encoding="utf-8").splitlines())
)


def test_modules_with_examples_are_found():
    assert {"grainlab.analysis.stability", "grainlab.samples.grading", "grainlab.report.angles"} <= set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0
    assert result.failed == 0
