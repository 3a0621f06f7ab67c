"""The examples in the docstrings of grainlab.samples run as tests."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "grainlab.samples.grading",
    "grainlab.samples.porosity",
    "grainlab.samples.placement",
    "grainlab.samples.expansion",
    "grainlab.samples.lattice",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0
    assert result.failed == 0
