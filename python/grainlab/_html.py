"""HTML building blocks of the report: escaping, numbers, tables, embedded figures, the page.

Everything the page needs is inside it: the style sheet is inline, figures
are ``data:`` URIs, there are no scripts, fonts or links to other hosts, so
the file opens offline from ``file://`` and can be mailed as it is. Text is
escaped with :func:`html.escape`; a :class:`Markup` string is HTML already and
is inserted as it is.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grainlab._core import __version__
from grainlab.citation import how_to_cite

__all__ = [
    "CSS",
    "EmbeddedFigure",
    "Markup",
    "code_block",
    "definition_table",
    "escape",
    "figure",
    "figures",
    "fmt",
    "footer",
    "number",
    "page",
    "paragraph",
    "section",
    "table",
]


class Markup(str):
    """A string that is HTML already (not escaped again)."""

    __slots__ = ()


def escape(value: Any) -> Markup:
    """``value`` as HTML text: :class:`Markup` as it is, anything else escaped."""
    if isinstance(value, Markup):
        return value
    return Markup(html.escape(str(value), quote=True))


def number(value: Any) -> float:
    """``value`` as a float for arithmetic and :func:`fmt`: ints and floats as they
    are, anything else (None, a flag, text) NaN, which :func:`fmt` shows as ``n/a``.

    >>> number(3), number(0.5), number(None), number(True), number("x")
    (3.0, 0.5, nan, nan, nan)
    """
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else math.nan


def fmt(value: Any, digits: int = 3, *, percent: bool = False, unit: str = "", trailing_zeros: bool = True) -> str:
    """A number for a table: ``digits`` significant digits, ``percent`` multiplies
    by 100 and appends ``%``; None and NaN give ``n/a``; other types ``str()``.
    ``trailing_zeros=False`` writes a float as ``{:.{digits}g}`` (``4.6``,
    ``1.4e+03``), the reproduction's Markdown tables' style.

    >>> fmt(4.601713), fmt(4.0), fmt(0.0145, percent=True), fmt(None), fmt(float("nan")), fmt(3518)
    ('4.60', '4.00', '1.45 %', 'n/a', 'n/a', '3518')
    >>> fmt(3.3261e-3, unit="1/s"), fmt(1395.8), fmt(1.4e6), fmt(True)
    ('0.00333 1/s', '1396', '1400000', 'yes')
    >>> fmt(4.601713, trailing_zeros=False), fmt(4.0, trailing_zeros=False), fmt(1395.8, trailing_zeros=False)
    ('4.6', '4', '1.4e+03')
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        text = str(value)
    elif isinstance(value, float):
        if not math.isfinite(value):
            return "n/a"
        if percent:
            text = f"{100.0 * value:.2f} %"
        elif not trailing_zeros:
            text = f"{value:.{digits}g}"
        elif 10.0**digits <= abs(value) < 1e9:
            text = f"{value:.0f}"  # 1396, not 1.40e+03
        else:
            # significant digits, trailing zeros kept (4.60, 0.120), no bare trailing point
            text = f"{value:#.{digits}g}".replace(".e", "e")
            text = text[:-1] if text.endswith(".") else text
    else:
        return str(value)
    return f"{text} {unit}" if unit else text


@dataclass(frozen=True)
class EmbeddedFigure:
    """A figure of the report: PNG bytes and what it shows."""

    #: Stable id (the file stem for figures of the results folder).
    key: str
    #: Heading above the figure.
    title: str
    #: Caption below it (plain text or :class:`Markup`).
    caption: str
    #: The PNG image.
    png: bytes
    #: Where it comes from (a file of the folder, or drawn by the report).
    source: str


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

#: Figures are shown at this many times their printed size (matplotlib's inches at 96 px per inch).
DISPLAY_ZOOM = 1.3


def is_usable_png(path: Path) -> bool:
    """Whether ``path`` is a PNG file the report can embed (exists, signature and
    header present): an empty or truncated figure counts as missing and is redrawn."""
    try:
        data = path.read_bytes()
    except OSError:
        return False
    return len(data) > 33 and data[:8] == _PNG_SIGNATURE and data[12:16] == b"IHDR"


def png_info(png: bytes) -> tuple[int, int, float | None]:
    """Width and height (pixels) of a PNG, and its resolution in dots per inch (None if unrecorded)."""
    if png[:8] != _PNG_SIGNATURE or png[12:16] != b"IHDR":
        raise ValueError("not a PNG image (bad signature)")
    width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    dpi = None
    offset = 8
    while offset + 8 <= len(png):
        length = int.from_bytes(png[offset : offset + 4], "big")
        kind = png[offset + 4 : offset + 8]
        if kind == b"pHYs" and length == 9:
            per_unit = int.from_bytes(png[offset + 8 : offset + 12], "big")
            if png[offset + 16] == 1 and per_unit > 0:  # pixels per metre
                dpi = per_unit * 0.0254
            break
        if kind in (b"IDAT", b"IEND"):
            break
        offset += 12 + length
    return width, height, dpi


def figure(fig: EmbeddedFigure) -> Markup:
    """``<figure>`` with the PNG as a ``data:image/png;base64`` URI and its caption.

    The image is shown at :data:`DISPLAY_ZOOM` times its printed size (from the
    PNG's resolution), never wider than the page.
    """
    width, height, dpi = png_info(fig.png)
    scale = DISPLAY_ZOOM * 96.0 / dpi if dpi else 1.0
    shown_w, shown_h = max(1, round(width * scale)), max(1, round(height * scale))
    data = base64.b64encode(fig.png).decode("ascii")
    return Markup(
        f'<figure class="figure" id="figure-{escape(fig.key)}" style="width: {shown_w}px">'
        f"<h3>{escape(fig.title)}</h3>"
        f'<img src="data:image/png;base64,{data}" alt="{escape(fig.title)}" '
        f'width="{shown_w}" height="{shown_h}">'
        f"<figcaption>{escape(fig.caption)} <span class=\"source\">({escape(fig.source)})</span>"
        "</figcaption></figure>\n"
    )


def figures(figs: Iterable[EmbeddedFigure]) -> Markup:
    """Figures side by side where the page is wide enough."""
    return Markup('<div class="figures">' + "".join(figure(f) for f in figs) + "</div>\n")


def table(
    headers: Sequence[Any],
    rows: Iterable[Sequence[Any]],
    *,
    numeric: Iterable[int] = (),
    css_class: str = "",
    caption: str | None = None,
    row_classes: Sequence[str] | None = None,
    cell_classes: dict[int, str] | None = None,
) -> Markup:
    """A table; cells are escaped unless :class:`Markup`; ``numeric`` columns align
    right; ``row_classes`` gives each row a class, ``cell_classes`` a column."""
    right = set(numeric)
    extra = dict(cell_classes or {})
    head = "".join(f"<th>{escape(h)}</th>" for h in headers)
    body = []
    for i, row in enumerate(rows):
        cells = []
        for k, c in enumerate(row):
            cls = " ".join(x for x in ("num" if k in right else "", extra.get(k, "")) if x)
            attr = f' class="{escape(cls)}"' if cls else ""
            cells.append(f"<td{attr}>{escape(c)}</td>")
        row_cls = row_classes[i] if row_classes is not None and row_classes[i] else ""
        attr = f' class="{escape(row_cls)}"' if row_cls else ""
        body.append(f"<tr{attr}>{''.join(cells)}</tr>")
    cls = f' class="{escape(css_class)}"' if css_class else ""
    cap = f"<caption>{escape(caption)}</caption>" if caption else ""
    return Markup(
        f'<div class="table-wrap"><table{cls}>{cap}<thead><tr>{head}</tr></thead>'
        f"<tbody>{''.join(body)}</tbody></table></div>\n"
    )


def definition_table(items: Iterable[tuple[Any, Any]]) -> Markup:
    """A two-column table of label / value pairs."""
    rows = "".join(f"<tr><th>{escape(k)}</th><td>{escape(v)}</td></tr>" for k, v in items)
    return Markup(f'<div class="table-wrap"><table class="kv"><tbody>{rows}</tbody></table></div>\n')


def paragraph(text: Any, css_class: str = "") -> Markup:
    cls = f' class="{escape(css_class)}"' if css_class else ""
    return Markup(f"<p{cls}>{escape(text)}</p>\n")


def code_block(text: str) -> Markup:
    return Markup(f"<pre><code>{escape(text)}</code></pre>\n")


def section(anchor: str, title: str, *parts: Any) -> tuple[str, str, Markup]:
    """(anchor, title, HTML) of one section of the page; parts are joined (escaped unless Markup)."""
    body = "".join(escape(p) for p in parts)
    return anchor, title, Markup(f'<section id="{escape(anchor)}"><h2>{escape(title)}</h2>\n{body}</section>\n')


CSS = """
:root { color-scheme: light; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif;
       color: #1d2329; background: #f6f7f9; }
header.top { background: #22313f; color: #fff; padding: 1.2em 2em 1em; }
header.top h1 { margin: 0 0 .2em; font-size: 1.6em; }
header.top p { margin: .15em 0; color: #d5dde5; }
header.top code { color: #fff; }
nav.toc { background: #fff; border-bottom: 1px solid #dde2e7; padding: .5em 2em; font-size: .9em;
          display: flex; flex-wrap: wrap; gap: .2em 1.1em; }
nav.toc a { color: #2b5f8e; text-decoration: none; white-space: nowrap; }
nav.toc a:hover { text-decoration: underline; }
main { max-width: 1200px; margin: 0 auto; padding: 1em 2em 3em; }
section { background: #fff; border: 1px solid #dde2e7; border-radius: 6px; padding: .6em 1.4em 1.2em;
          margin: 1.2em 0; }
h2 { font-size: 1.3em; border-bottom: 2px solid #e4e8ec; padding-bottom: .25em; }
h3 { font-size: 1.05em; margin: .8em 0 .4em; }
.table-wrap { overflow-x: auto; margin: .6em 0; }
table { border-collapse: collapse; font-size: .9em; }
th, td { border: 1px solid #dde2e7; padding: .3em .6em; vertical-align: top; text-align: left; }
thead th { background: #eef2f5; }
table.kv th { background: #f4f6f8; font-weight: 600; white-space: nowrap; }
td.nowrap { white-space: nowrap; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.differs td { background: #fff8e1; }
tr.total td { font-weight: 600; border-top: 2px solid #9aa5b1; }
table.wide td { font-size: .85em; }
td.note { min-width: 22em; color: #4a5560; }
td.muted { color: #4a5560; }
pre { background: #f1f3f5; border: 1px solid #dde2e7; border-radius: 4px; padding: .7em 1em;
      overflow-x: auto; font-size: .85em; }
code { font-family: "DejaVu Sans Mono", Menlo, Consolas, monospace; }
.figures { display: flex; flex-wrap: wrap; gap: .5em 2em; align-items: flex-start; }
figure.figure { margin: 1.2em 0; max-width: 100%; }
figure.figure img { max-width: 100%; height: auto; display: block; border: 1px solid #e4e8ec;
                    background: #fff; }
figcaption { font-size: .9em; color: #4a5560; margin-top: .3em; }
figcaption .source { color: #7b8794; }
.glance { display: grid; grid-template-columns: repeat(auto-fill, minmax(13em, 1fr)); gap: .6em; }
.glance div { background: #f4f6f8; border-radius: 4px; padding: .5em .7em; }
.glance .v { font-size: 1.25em; font-weight: 600; display: block; }
.glance .k { font-size: .8em; color: #52606d; }
.note { color: #4a5560; }
.warn { background: #fff4e5; border-left: 4px solid #f0a020; padding: .5em .8em; }
.formula { font-family: "DejaVu Serif", Georgia, serif; background: #f8f9fb; padding: .4em .8em;
           border-left: 3px solid #b8c4ce; }
tr.verdict-reproduced td.verdict { background: #e3f4e6; }
tr.verdict-not-reproduced td.verdict { background: #fbe4e2; }
tr.verdict-inconclusive td.verdict { background: #f3f0e0; }
footer { color: #7b8794; font-size: .85em; text-align: center; padding: 1em; }
"""


def footer() -> str:
    """The line at the foot of every self-contained page: the version that wrote it, what
    the file holds, and how to cite grainlab and the article it reproduces."""
    return (
        f"grainlab {__version__}: this file is self-contained (figures embedded, no scripts, no network). "
        f"{how_to_cite()}"
    )


def page(title: str, header: Markup, sections: Sequence[tuple[str, str, Markup]], footer: str) -> str:
    """The whole document: head with the inline style sheet, header, table of contents, sections."""
    toc = "".join(f'<a href="#{escape(a)}">{escape(t)}</a>' for a, t, _ in sections)
    body = "".join(s for _, _, s in sections)
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        '<meta name="generator" content="grainlab report">\n'
        '<link rel="icon" href="data:,">\n'
        f"<title>{escape(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
        f'<header class="top">{header}</header>\n'
        f'<nav class="toc">{toc}</nav>\n<main>\n{body}</main>\n'
        f"<footer>{escape(footer)}</footer>\n</body>\n</html>\n"
    )
