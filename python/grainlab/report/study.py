"""Everything the report of the packing study shows, gathered from its folder.

:func:`gather_study` reads ``study.csv`` (one row per packing),
``summary.json`` (campaign wall time, seed, parameters, Fig. 17 fit, trends)
and the figures ``fig15``-``fig17``, drawing the missing ones with
:func:`grainlab.study.study_figures`. No HTML here (:mod:`grainlab.report.render`).
"""

from __future__ import annotations

import csv
import json
import math
import shlex
from collections import Counter
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from grainlab._html import EmbeddedFigure, fmt, is_usable_png
from grainlab.paper import STUDY_CLAIMS
from grainlab.report.figures import embedded_png
from grainlab.study.packing import PackingParams
from grainlab.study.paper import (
    HEXAGONAL_POROSITIES,
    IRREGULAR_POROSITIES,
    linear_fit,
    number_or_nan,
    packing_series,
    study_figures,
)

__all__ = ["STUDY_FIGURES", "StudyReport", "gather_study", "read_study_table"]

#: The study's figures, with their titles and captions.
STUDY_FIGURES: dict[str, tuple[str, str]] = {
    "fig15_lambda_vs_coordination": (
        "Fig. 15: mean λ against coordination number",
        "Mean geometrical stability index against Z, irregular (dots) and hexagonal (open squares) packings.",
    ),
    "fig16_lambda_vs_porosity": (
        "Fig. 16: mean λ against porosity",
        "Mean geometrical stability index against the nominal porosity.",
    ),
    "fig17_lambda_vs_anisotropy": (
        "Fig. 17: mean λ against fabric anisotropy",
        "Mean geometrical stability index against the anisotropy a of Eq. 7, with the least-squares line "
        "over all packings.",
    ),
}

#: Units of the packing parameters (SI).
_UNITS = {
    "width": "m", "height": "m", "d_min": "m", "d_max": "m", "diameter": "m",
    "normal_stiffness": "N/m", "shear_stiffness": "N/m", "density": "kg/m^3", "max_stress": "Pa",
}

#: Parameters that vary per packing (not part of the common configuration).
_PER_RUN = ("kind", "porosity", "seed", "threads")


@dataclass
class StudyReport:
    """The content of a study report."""

    folder: Path
    generated: str
    summary: dict[str, Any]
    #: study.csv: its columns in order, and its rows (strings, as written).
    columns: list[str]
    rows: list[dict[str, str]]
    #: Packing parameters common to all runs, and where they come from.
    params: dict[str, Any]
    params_source: str
    irregular: list[float]
    hexagonal: list[float]
    rerun_command: str
    rerun_notes: list[str]
    figures: dict[str, EmbeddedFigure]
    #: (quantity, paper, run, where) rows.
    claims: list[tuple[str, str, str, str]]
    statuses: dict[str, int]
    regenerated: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def version(self) -> str:
        return str(self.summary.get("grainlab_version", "unknown"))


def read_study_table(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    """Columns and rows of ``study.csv`` (ValueError when it is not one)."""
    with open(path, newline="") as handle:
        reader = csv.DictReader(handle)
        columns = list(reader.fieldnames or [])
        rows = list(reader)
    needed = {"kind", "porosity_target", "mean_stability_index", "status"}
    if not needed <= set(columns):
        raise ValueError(
            f"{path}: not a study table (columns {sorted(needed - set(columns))} are missing)"
        )
    return columns, rows


def _fit_text(rows: list[dict[str, str]], kind: str | None, x: str) -> str:
    xs, ys = packing_series(rows, kind, x, "mean_stability_index")
    fit = linear_fit(xs, ys)
    label = kind or "all packings"
    if not math.isfinite(fit["slope"]):
        return f"{label}: {len(xs)} point(s), no fit"
    return f"{label}: slope {fmt(fit['slope'], 3)}, R² {fmt(fit['r2'], 3)} ({fit['n']} packings)"


def _claims(rows: list[dict[str, str]], summary: dict[str, Any]) -> list[tuple[str, str, str, str]]:
    run: dict[str, str] = {}
    run["lambda_vs_z"] = "; ".join(
        _fit_text(rows, k, "coordination_number") for k in ("irregular", "hexagonal", None)
    )
    zi, li = packing_series(rows, "irregular", "coordination_number", "mean_stability_index")
    zh, lh = packing_series(rows, "hexagonal", "coordination_number", "mean_stability_index")
    if li.size and lh.size:
        overlap = int(np.sum((zh >= zi.min()) & (zh <= zi.max())))
        run["hexagonal_lower"] = (
            f"hexagonal λ {fmt(float(lh.min()), 3)}-{fmt(float(lh.max()), 3)} (Z {fmt(float(zh.min()), 3)}-"
            f"{fmt(float(zh.max()), 3)}), irregular {fmt(float(li.min()), 3)}-{fmt(float(li.max()), 3)} "
            f"(Z {fmt(float(zi.min()), 3)}-{fmt(float(zi.max()), 3)}); "
            + ("every hexagonal packing below every irregular one" if lh.max() < li.min() else "the ranges overlap")
            + f"; {overlap} hexagonal packing(s) inside the irregular Z range"
        )
    else:
        run["hexagonal_lower"] = "n/a (one series is empty)"
    run["lambda_vs_porosity"] = "; ".join(_fit_text(rows, k, "porosity") for k in ("irregular", "hexagonal"))
    fit = summary.get("fig17_fit") or {}
    if not fit:
        xs, ys = packing_series(rows, None, "anisotropy", "mean_stability_index")
        fit = linear_fit(xs, ys)
    text = (
        f"all packings: λ = {fmt(number_or_nan(fit.get('slope')), 3)} a + "
        f"{fmt(number_or_nan(fit.get('intercept')), 3)}, "
        f"R² {fmt(number_or_nan(fit.get('r2')), 3)} (Eq. 7's a)"
    )
    text += "; " + _fit_text(rows, None, "anisotropy_fourier").replace("all packings", "on the unbinned a")
    run["lambda_vs_a"] = text
    return [(c.quantity, c.text, run.get(c.key, "n/a"), c.where) for c in STUDY_CLAIMS]


def _targets(rows: list[dict[str, str]], kind: str) -> list[float]:
    return [number_or_nan(r.get("porosity_target")) for r in rows if r.get("kind") == kind]


def _same(a: list[float], b: tuple[float, ...]) -> bool:
    return len(a) == len(b) and bool(np.allclose(sorted(a), sorted(b)))


def _rerun(folder: Path, summary: dict[str, Any], irregular: list[float], hexagonal: list[float]) -> tuple[str, list[str]]:
    out = f"{folder.resolve()}-rerun"
    seed = int(summary.get("seed", 0) or 0)
    workers = summary.get("workers")
    overrides = summary.get("overrides") or {}
    notes = [
        "Each packing's seed derives from the campaign seed and its parameters, so the numbers do not "
        "depend on the number of workers; the engine threads per run (cores // workers) are the same "
        "on the same machine."
    ]
    default_targets = _same(irregular, IRREGULAR_POROSITIES) and _same(hexagonal, HEXAGONAL_POROSITIES)
    if not overrides and default_targets:
        args = ["grainlab", "study", "--out", out, "--seed", str(seed)]
        if isinstance(workers, int):
            args += ["--workers", str(workers)]
        return shlex.join(args), notes
    notes.insert(0, "This study used parameters or targets the command line does not take; rerun it from Python.")
    call = (
        "from grainlab.study import run_study\n"
        f"run_study({out!r}, seed={seed}, workers={workers!r},\n"
        f"          overrides={json.dumps(overrides)},\n"
        f"          irregular={tuple(irregular)!r}, hexagonal={tuple(hexagonal)!r})"
    )
    return call, notes


def gather_study(folder: str | Path, *, redraw: bool = False) -> StudyReport:
    """Collects the report of the study in ``folder`` (drawing Figs. 15-17 when missing)."""
    folder = Path(folder)
    columns, rows = read_study_table(folder / "study.csv")
    summary: dict[str, Any] = {}
    notes: list[str] = []
    path = folder / "summary.json"
    if path.exists():
        try:
            loaded = json.loads(path.read_text())
            summary = loaded if isinstance(loaded, dict) else {}
        except ValueError as error:
            notes.append(f"summary.json could not be read ({error}): no campaign times, seed or fit")
    else:
        notes.append("no summary.json: no campaign wall time, seed or Fig. 17 fit from the run")

    recorded = summary.get("packing_params")
    if isinstance(recorded, dict):
        params, source = dict(recorded), "summary.json (recorded by the study)"
    else:
        params = {**asdict(PackingParams()), **(summary.get("overrides") or {})}
        source = (
            "reconstructed: this grainlab's PackingParams defaults with summary.json's overrides "
            "(the study did not record its parameters)"
        )
    for key in _PER_RUN:
        params.pop(key, None)

    irregular, hexagonal = _targets(rows, "irregular"), _targets(rows, "hexagonal")
    regenerated: list[str] = []
    missing = [n for n in STUDY_FIGURES if not is_usable_png(folder / f"{n}.png")]
    if redraw or missing:
        study_figures(rows, folder)
        regenerated = list(STUDY_FIGURES)
        notes.append("drawn by this report (missing from the folder or --redraw): " + ", ".join(regenerated))
    figures = {}
    for key, (title, caption) in STUDY_FIGURES.items():
        png = folder / f"{key}.png"
        if is_usable_png(png):
            figures[key] = EmbeddedFigure(key, title, caption, embedded_png(png.read_bytes()), f"{png.name} in the study folder")
    statuses = dict(Counter(r.get("status", "?") for r in rows))
    command, rerun_notes = _rerun(folder, summary, irregular, hexagonal)
    return StudyReport(
        folder=folder,
        generated=datetime.now(UTC).isoformat(timespec="seconds"),
        summary=summary,
        columns=columns,
        rows=rows,
        params=params,
        params_source=source,
        irregular=irregular,
        hexagonal=hexagonal,
        rerun_command=command,
        rerun_notes=rerun_notes,
        figures=figures,
        claims=_claims(rows, summary),
        statuses=statuses,
        regenerated=regenerated,
        notes=notes,
    )


def param_unit(name: str) -> str:
    """SI unit of a packing parameter ("-" when dimensionless)."""
    return _UNITS.get(name, "-")
