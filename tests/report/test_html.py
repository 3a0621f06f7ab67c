"""HTML building blocks: escaping, numbers, embedded figures."""

from __future__ import annotations

import base64
import re

from matplotlib.figure import Figure

from grainlab._html import (
    DISPLAY_ZOOM,
    EmbeddedFigure,
    Markup,
    figure,
    page,
    png_info,
    section,
    table,
)
from grainlab.report.figures import png_bytes


def test_text_from_the_data_is_escaped_and_markup_is_not():
    hostile = '<script>alert("x")</script> & <img src=http://example.org/x.png>'
    out = table(["a", "b"], [(hostile, Markup("<b>bold</b>"))])
    assert "<script>" not in out and "<img" not in out
    assert "&lt;script&gt;" in out and "&amp;" in out and "<b>bold</b>" in out
    anchor, title, body = section("s", "A <title>", hostile)
    assert "<script>" not in body and "A &lt;title&gt;" in body
    doc = page("t <x>", Markup("<h1>h</h1>"), [(anchor, title, body)], "f & g")
    assert doc.startswith("<!DOCTYPE html>") and "<title>t &lt;x&gt;</title>" in doc
    assert 'href="#s"' in doc and "f &amp; g" in doc


def test_figures_are_png_data_uris_shown_at_their_printed_size():
    fig = Figure(figsize=(4.0, 3.0))
    fig.add_subplot().plot([0, 1], [0, 1])
    png = png_bytes(fig)
    width, height, dpi = png_info(png)
    assert dpi is not None and abs(dpi - 150.0) < 0.5
    out = figure(EmbeddedFigure("k", "Title", "caption <1>", png, "drawn"))
    src = re.search(r'src="data:image/png;base64,([^"]+)"', out).group(1)
    assert base64.b64decode(src) == png
    shown = int(re.search(r'width="(\d+)"', out).group(1))
    assert shown == round(width * DISPLAY_ZOOM * 96.0 / dpi)
    assert 'id="figure-k"' in out and "caption &lt;1&gt;" in out
