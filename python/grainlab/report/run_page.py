"""A test's report page, declared (:class:`ReportPage`) and assembled here once
(docs/report.md, "Pages from the registry").
"""

from __future__ import annotations

import datetime
import shlex
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from grainlab._html import (
    EmbeddedFigure,
    Markup,
    code_block,
    definition_table,
    figures,
    footer,
    page,
    paragraph,
    section,
    table,
)
from grainlab._mapping import flatten_keys
from grainlab.io.hdf5 import Results, read_results
from grainlab.protocols.config import SCHEMAS

__all__ = ["CRACKS", "PageSection", "ReportPage", "RunPage", "crack_map", "footer", "gather_run_page", "rerun_sections"]


@dataclass
class RunPage:
    """What a protocol's report page shows: the run, its summary, its figures."""

    folder: Path
    results: Results
    summary: dict[str, Any]
    figures: list[EmbeddedFigure]
    generated: str


@dataclass(frozen=True)
class PageSection:
    """One section of a declared page: its anchor, its title and its parts (notes,
    tables) from the gathered run; ``with_figures`` ends it with the figures grid."""

    anchor: str
    title: str
    parts: Callable[[RunPage], Sequence[Any]]
    with_figures: bool = False


@dataclass(frozen=True)
class ReportPage:
    """A test's report page, declared: what ``report.html`` shows for a run of ``protocol``.

    ``test`` names the test in the page's head line ("oedometer test") and
    ``name`` in its title ("grainlab oedometer report"); ``figures`` maps each
    figure's file stem to (title, caption), drawn by ``draw(folder)`` (the
    protocol's outputs) when one is missing; ``glance`` gives the summary
    numbers as (label, value) pairs; ``sections`` follow them, then a cemented
    sample's "Cracks" (:func:`crack_map`), before "How to rerun" and "Resolved
    configuration". A page laid out by a module of its own
    sets ``render(folder, redraw)`` instead, and the rest is not used.
    """

    protocol: str
    test: str = ""
    name: str = ""
    figures: Mapping[str, tuple[str, str]] = field(default_factory=dict)
    draw: Callable[[Path], Any] | None = None
    glance: Callable[[RunPage], Sequence[tuple[str, str]]] | None = None
    sections: Sequence[PageSection] = ()
    render: Callable[[Path, bool], str] | None = None

    def __post_init__(self) -> None:
        if self.render is None and (self.draw is None or self.glance is None):
            raise ValueError(f"{self.protocol}: a report page declares draw and glance, or its own render")

    def html(self, folder: Path, *, redraw: bool = False) -> str:
        """The page of the run in ``folder`` (figures missing from it, all of them with
        ``redraw``, are drawn into it first)."""
        if self.render is not None:
            return self.render(folder, redraw)
        if self.draw is None or self.glance is None:  # refused by __post_init__; this narrows the types
            raise ValueError(f"{self.protocol}: a report page declares draw and glance, or its own render")
        r = gather_run_page(folder, self.figures, self.draw, redraw=redraw)
        parts = [section("glance", "At a glance", definition_table(list(self.glance(r))))]
        parts += [section(s.anchor, s.title, *s.parts(r), *([figures(r.figures)] if s.with_figures else []))
                  for s in self.sections]
        if "cement_bonds" in r.summary:  # a cemented sample's
            parts.append(section("cracks", "Cracks", *crack_map(r)))
        parts += rerun_sections(self.protocol, r.folder, r.results)
        title = r.folder.resolve().name
        header = paragraph(f"grainlab {self.test}: {title}; run by grainlab {r.results.grainlab_version}, "
                           f"report generated {r.generated}.")
        return page(f"grainlab {self.name} report: {title}", header, parts, footer())


#: The crack map (drawn by the outputs when the run has cracks): stem, title, caption.
CRACKS = ("fig20_cracks", "Cracks", "The cement bonds broken during the test on the last snapshot's grains (a "
          "segment along each crack, blue in tension, red in shear) and the rose of their orientations "
          "(docs/cemented.md).")


def crack_map(r: RunPage) -> list[Any]:
    """A cemented run's crack map, or a note that no bond broke."""
    from grainlab.report.figures import embedded_png  # matplotlib: only when a page is made

    stem, title, caption = CRACKS
    path = r.folder / f"{stem}.png"
    if not path.exists():
        return [paragraph("No cement bond broke: no crack map.", "note")]
    return [figures([EmbeddedFigure(stem, title, caption, embedded_png(path.read_bytes()), path.name)])]


def gather_run_page(folder: str | Path, figures: Mapping[str, tuple[str, str]],
                    write_outputs: Callable[[Path], Any], *, redraw: bool = False) -> RunPage:
    """The page of the run in ``folder``: ``figures`` (file stem -> (title, caption)),
    drawn first by the protocol's ``write_outputs`` when one is missing (all of them
    with ``redraw``)."""
    from grainlab.report.figures import embedded_png  # matplotlib: only when a page is made

    folder = Path(folder)
    results = read_results(folder / "run.h5")
    if redraw or any(not (folder / f"{stem}.png").exists() for stem in figures):
        write_outputs(folder)
    shown = [EmbeddedFigure(stem, title, caption, embedded_png((folder / f"{stem}.png").read_bytes()), f"{stem}.png")
             for stem, (title, caption) in figures.items()]
    generated = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    return RunPage(folder, results, dict(results.summary), shown, generated)


def _toml(value: Any) -> str:
    """A configuration value as ``--set`` reads it back (TOML, or a bare word)."""
    if isinstance(value, list):
        return "[" + ", ".join(repr(float(v)) for v in value) + "]"
    return repr(value) if isinstance(value, float) else str(value)


def rerun_sections(kind: str, folder: Path, results: Results) -> list[tuple[str, str, Markup]]:
    """The "How to rerun" section (the command with every key of protocol ``kind``
    that differs from its default, but the run's own ``run.*`` keys) and the
    "Resolved configuration" section."""
    fields = SCHEMAS[kind].fields
    overrides = [f"--set {shlex.quote(f'{key}={_toml(value)}')}"
                 for key, value in flatten_keys(results.config).items()
                 if key in fields and not key.startswith("run.") and value != fields[key].default]
    command = " ".join([f"grainlab run {kind} --out", shlex.quote(str(folder)), *overrides])
    config_rows = [(f"{section_}.{key}", str(value)) for section_, values in results.config.items()
                   for key, value in values.items()]
    return [
        section("rerun", "How to rerun", code_block(command),
                paragraph(f"Rebuild this report: grainlab report {shlex.quote(str(folder.resolve()))}", "note")),
        section("config", "Resolved configuration", table(["key", "value (SI)"], config_rows)),
    ]
