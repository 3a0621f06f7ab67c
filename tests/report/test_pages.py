"""The registry of report pages and the page a declaration assembles (grainlab.report.run_page)."""

from __future__ import annotations

import base64
import re
import shutil

import pytest

from grainlab._html import fmt, paragraph
from grainlab.protocols.registry import PROTOCOLS
from grainlab.report.figures import embedded_png
from grainlab.report.pages import PAGES, STUDY_PAGE
from grainlab.report.run_page import PageSection, ReportPage, RunPage


def test_every_protocol_has_a_page_under_its_name():
    assert set(PAGES) == set(PROTOCOLS)
    assert all(page.protocol == name for name, page in PAGES.items())
    assert STUDY_PAGE.protocol not in PROTOCOLS


def test_a_page_declares_how_it_is_drawn_or_its_own_layout():
    with pytest.raises(ValueError, match="^biaxial: a report page declares draw and glance, or its own render$"):
        ReportPage("biaxial", test="biaxial test", name="biaxial", glance=lambda r: [])


def _embedded(path) -> str:
    """The figure file as the page embeds it (its data: URI's text)."""
    return base64.b64encode(embedded_png(path.read_bytes())).decode("ascii")


def _png(folder, stem: str, colour: str) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(1, 1))
    fig.patch.set_facecolor(colour)
    fig.savefig(folder / f"{stem}.png", dpi=20)


def test_a_declared_page_is_assembled_in_its_order_with_its_numbers_and_figures(synthetic_results, tmp_path):
    folder = tmp_path / "run"
    shutil.copytree(synthetic_results, folder)
    drawn: list[str] = []

    def draw(where):  # the protocol's outputs: one figure, red the first time, blue after
        drawn.append(str(where))
        _png(where, "fig01_test", "red" if len(drawn) == 1 else "blue")

    def numbers(r: RunPage) -> list[tuple[str, str]]:
        return [("grains", fmt(r.summary["n_particles"])), ("porosity", fmt(r.summary["porosity_initial"], 4))]

    page = ReportPage("biaxial", test="test of the page", name="page", figures={"fig01_test": ("One", "The figure.")},
                      draw=draw, glance=numbers,
                      sections=(PageSection("first", "First", lambda r: [paragraph("a note", "note")]),
                                PageSection("second", "Second", lambda r: [], with_figures=True)))
    html = page.html(folder)
    assert drawn == [str(folder)]  # the missing figure was drawn, once
    anchors = re.findall(r'<section id="([a-z]+)">', html)
    assert anchors == ["glance", "first", "second", "rerun", "config"]
    glance = html[html.index('<section id="glance">'):html.index('<section id="first">')]
    assert "0.1450" in glance and ">grains<" in glance
    assert "grainlab test of the page: run;" in html and "<title>grainlab page report: run" in html
    second = html[html.index('<section id="second">'):html.index('<section id="rerun">')]
    red = _embedded(folder / "fig01_test.png")
    assert red in second and red not in html[:html.index('<section id="second">')]
    assert "grainlab run biaxial --out" in html
    page.html(folder)
    assert len(drawn) == 1  # present: not drawn again
    html = page.html(folder, redraw=True)
    assert len(drawn) == 2 and red not in html and _embedded(folder / "fig01_test.png") in html
