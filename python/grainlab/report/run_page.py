"""What the report pages of the protocols' runs share: the gathered page
(:class:`RunPage`: the run, its summary and its figures, drawn first when
missing), how to rerun the run (``grainlab run KIND`` with the keys that differ
from the defaults) and its resolved configuration, as page sections."""

from __future__ import annotations

import datetime
import shlex
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grainlab._html import EmbeddedFigure, Markup, code_block, paragraph, section, table
from grainlab._mapping import flatten_keys
from grainlab.io.hdf5 import Results, read_results
from grainlab.protocols.config import SCHEMAS
from grainlab.report.figures import embedded_png

__all__ = ["RunPage", "gather_run_page", "rerun_sections"]


@dataclass
class RunPage:
    """What a protocol's report page shows: the run, its summary, its figures."""

    folder: Path
    results: Results
    summary: dict[str, Any]
    figures: list[EmbeddedFigure]
    generated: str


def gather_run_page(folder: str | Path, figures: Mapping[str, tuple[str, str]],
                    write_outputs: Callable[[Path], Any], *, redraw: bool = False) -> RunPage:
    """The page of the run in ``folder``: ``figures`` (file stem -> (title, caption)),
    drawn first by the protocol's ``write_outputs`` when one is missing (all of them
    with ``redraw``)."""
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
