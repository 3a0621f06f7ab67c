"""The examples in the docstrings run as tests."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "grainlab.snapshot",
    "grainlab.analysis.fabric",
    "grainlab.analysis.stability",
    "grainlab.analysis.strain",
    "grainlab.analysis.shear_band",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0
    assert result.failed == 0
