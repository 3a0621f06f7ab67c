"""Fixtures of the reliability tests (factories in reliability_factories.py)."""

from __future__ import annotations

from pathlib import Path

import pytest
from reliability_factories import fake_curves, fake_fabric_figures, tiny_config


@pytest.fixture
def fast_figures(monkeypatch):
    """The biaxial driver with stand-in figures (the output phase's logic is unchanged)."""
    import grainlab.postprocess.figures as figures
    import grainlab.protocols.biaxial.outputs as outputs

    monkeypatch.setattr(outputs, "_figures", fake_curves)
    monkeypatch.setattr(figures, "fabric_figures", fake_fabric_figures)


@pytest.fixture(scope="session")
def tiny_reference(tmp_path_factory) -> Path:
    """One uninterrupted tiny run (stand-in figures) for the stopped runs to match."""
    import grainlab.postprocess.figures as figures
    import grainlab.protocols.biaxial as biaxial
    import grainlab.protocols.biaxial.outputs as outputs

    out = tmp_path_factory.mktemp("tiny") / "straight"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(outputs, "_figures", fake_curves)
        patch.setattr(figures, "fabric_figures", fake_fabric_figures)
        biaxial.run_biaxial(tiny_config(), out, progress=False)
    return out
