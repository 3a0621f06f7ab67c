"""Fixtures of the report tests: the folders of report_factories.py, made once per session.

``quick_biaxial_run`` (the session's ``grainlab biaxial --quick``) is in tests/conftest.py.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from report_factories import STUDY_OVERRIDES, STUDY_TARGETS, write_synthetic_run


@pytest.fixture(scope="session")
def synthetic_run(tmp_path_factory) -> Path:
    """The synthetic folder with its report written (figures drawn by the report)."""
    from grainlab.report import write_report

    folder = write_synthetic_run(tmp_path_factory.mktemp("report") / "synthetic")
    write_report(folder)
    return folder


@pytest.fixture(scope="session")
def synthetic_results(tmp_path_factory) -> Path:
    """The synthetic folder without a report (run.h5 only, no figures drawn): for what reads run.h5 alone."""
    return write_synthetic_run(tmp_path_factory.mktemp("report") / "synthetic_results")


@pytest.fixture(scope="session")
def small_study(tmp_path_factory) -> Path:
    """A finished small study (no report yet)."""
    from grainlab.study import run_study

    folder = tmp_path_factory.mktemp("report") / "study"
    run_study(folder, workers=2, progress=False, overrides=STUDY_OVERRIDES, **STUDY_TARGETS)
    return folder
