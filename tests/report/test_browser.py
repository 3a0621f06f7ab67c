"""The reports in a real headless browser (Debian's chromium driven by Playwright):
they load from file:// with no console errors, request nothing and show every figure.

Skipped when chromium or Playwright is missing, unless GRAINLAB_REQUIRE_BROWSER=1 (CI)."""

from __future__ import annotations

import shutil

import pytest
from report_helpers import chromium_or_skip, open_in_browser

from grainlab.report import write_report

BIAXIAL_FIGURES = 12  # Figs. 6-14, 18 of the folder, the grading curve and the macro curves
STUDY_FIGURES = 3


def _check(seen: dict, figures: int) -> None:
    assert seen["problems"] == [], seen["problems"]
    assert all(url.startswith(("file:", "data:")) for url in seen["requests"]), seen["requests"]
    assert seen["figures"] == figures
    assert len(seen["images"]) == figures
    for image in seen["images"]:
        assert image["ok"] and image["w"] > 0 and image["h"] > 0, image
    assert seen["height"] > 2000  # laid out, not an empty page


def test_biaxial_report_in_chromium(synthetic_run):
    seen = open_in_browser(chromium_or_skip(), synthetic_run / "report.html")
    _check(seen, BIAXIAL_FIGURES)
    assert seen["title"].startswith("grainlab biaxial report")
    assert seen["sections"][:2] == ["glance", "rerun"] and "band" in seen["sections"]


def test_study_report_in_chromium(small_study, tmp_path):
    folder = tmp_path / "study"
    shutil.copytree(small_study, folder)
    report = write_report(folder)
    seen = open_in_browser(chromium_or_skip(), report)
    _check(seen, STUDY_FIGURES)
    assert seen["title"].startswith("grainlab study report")


@pytest.mark.slow
def test_quick_run_report_in_chromium(quick_biaxial_run):
    seen = open_in_browser(chromium_or_skip(), quick_biaxial_run / "report.html")
    _check(seen, BIAXIAL_FIGURES)


def test_without_chromium_the_test_skips_unless_ci_requires_it(monkeypatch):
    import external_tools

    monkeypatch.setattr(external_tools.shutil, "which", lambda name: None)
    monkeypatch.delenv("GRAINLAB_REQUIRE_BROWSER", raising=False)
    with pytest.raises(pytest.skip.Exception, match="chromium"):
        chromium_or_skip()
    monkeypatch.setenv("GRAINLAB_REQUIRE_BROWSER", "1")
    with pytest.raises(pytest.fail.Exception, match="GRAINLAB_REQUIRE_BROWSER"):
        chromium_or_skip()
