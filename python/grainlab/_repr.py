"""Short text and HTML representations for notebooks (Jupyter shows ``_repr_html_``).

Small tables only: a results file, a snapshot or a computed measure shows its
counts, its scalar results and the shapes of its arrays, never the arrays
themselves.
"""

from __future__ import annotations

import dataclasses
import html
import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

__all__ = ["html_table", "measure_html", "results_html", "results_repr", "snapshot_html"]

_STYLE = "border-collapse:collapse;font-size:0.9em"
_CELL = "text-align:left;padding:1px 10px 1px 0"


def _show(value: Any) -> str:
    if value is None:
        return "–"
    if isinstance(value, bool | np.bool_):
        return str(bool(value))
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        v = float(value)
        return "nan" if math.isnan(v) else f"{v:.6g}"
    if isinstance(value, np.ndarray):
        text = f"array {value.shape} {value.dtype}"
        if value.dtype.kind in "biuf" and value.size:
            finite = value[np.isfinite(value)] if value.dtype.kind == "f" else value
            if finite.size:
                text += f", mean {float(np.mean(finite)):.4g}"
        return text
    if isinstance(value, str):
        return value if len(value) <= 80 else value[:77] + "..."
    if isinstance(value, list | tuple):
        return f"{type(value).__name__} of {len(value)}"
    if isinstance(value, Mapping):
        return f"{len(value)} entries"
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def html_table(title: str, rows: Iterable[tuple[str, Any]]) -> str:
    """An HTML table: a bold title, then one ``name | value`` row each (values escaped)."""
    body = "".join(
        f"<tr><th style='{_CELL};font-weight:normal;color:#555'>{html.escape(str(k))}</th>"
        f"<td style='{_CELL}'>{html.escape(_show(v))}</td></tr>"
        for k, v in rows
    )
    return f"<div><b>{html.escape(title)}</b><table style='{_STYLE}'>{body}</table></div>"


def results_repr(res: Any) -> str:
    """``Results('run.h5', kind='biaxial', status='complete', 120 rows x 29 columns, 6 snapshots)``."""
    n_rows = len(next(iter(res.timeseries.values()))) if res.timeseries else 0
    return (
        f"Results({str(res.path)!r}, kind={res.kind!r}, status={res.status!r}, "
        f"{n_rows} rows x {len(res.timeseries)} columns, {len(res.snapshots)} snapshots)"
    )


def results_html(res: Any, max_summary: int = 12) -> str:
    """The file, its status, time series size, snapshots (strain, N, Nc) and the first summary values."""
    n_rows = len(next(iter(res.timeseries.values()))) if res.timeseries else 0
    rows: list[tuple[str, Any]] = [
        ("file", str(res.path)),
        ("kind, status", f"{res.kind}, {res.status}"),
        ("grainlab", res.grainlab_version),
        ("created", res.created),
        ("time series", f"{n_rows} rows x {len(res.timeseries)} columns"),
    ]
    for info in res.snapshots:
        strain = "" if info.axial_strain is None else f"axial strain {100 * info.axial_strain:.2f} %, "
        rows.append((f"snapshot {info.name}", f"{strain}N = {info.n_particles}, Nc = {info.n_contacts}"))
    scalars = [(k, v) for k, v in res.summary.items() if isinstance(v, int | float | str | bool)]
    rows += [(f"summary: {k}", v) for k, v in scalars[:max_summary]]
    if len(scalars) > max_summary:
        rows.append(("summary", f"... {len(scalars) - max_summary} more in .summary"))
    return html_table("grainlab results", rows)


def snapshot_html(snap: Any) -> str:
    """Counts by kind, radii, extent and the stored fields of a snapshot."""
    kinds, counts = np.unique(np.asarray(snap.kind), return_counts=True)
    names = {0: "soil", 1: "membrane", 2: "boundary grains"}
    radii = np.asarray(snap.radii)
    rows: list[tuple[str, Any]] = [
        ("particles", ", ".join(f"{int(c)} {names.get(int(k), k)}" for k, c in zip(kinds, counts, strict=True))),
        ("contacts", snap.n_contacts),
        ("radius (m)", f"{radii.min():.4g} to {radii.max():.4g}, mean {radii.mean():.4g}" if radii.size else "–"),
    ]
    if radii.size:
        lo, hi = snap.positions.min(axis=0), snap.positions.max(axis=0)
        rows.append(("extent of the centres (m)", f"x {lo[0]:.4g} to {hi[0]:.4g}, y {lo[1]:.4g} to {hi[1]:.4g}"))
    rows += [("time (s)", snap.time), ("axial strain", snap.axial_strain), ("periodic", str(tuple(snap.periodic)))]
    for owner in ("particle_fields", "contact_fields"):
        fields = getattr(snap, owner)
        if fields:
            rows.append((owner, ", ".join(fields)))
    return html_table(repr(snap), rows)


def measure_html(measure: Any) -> str:
    """A measure's repr, then its results: scalars as values, arrays as shape, dtype and mean."""
    results = getattr(measure, "_results", None)
    if results is None:
        return html_table(repr(measure), [("results", "not computed: call compute(...) first")])
    rows = [
        (f.name, getattr(results, f.name))
        for f in dataclasses.fields(results)
        if not f.name.startswith("_")
    ]
    return html_table(repr(measure), rows)
