"""``report.html``: one self-contained page describing a results folder (docs/report.md).

:func:`write_report` tells a biaxial run (``run.h5``) from a packing study
(``study.csv``), gathers what the page shows (:mod:`.biaxial`, :mod:`.study`),
renders it (:mod:`.render`, :mod:`.html`) and writes ``DIR/report.html``
atomically. The page embeds its figures as PNG ``data:`` URIs and has no
scripts, fonts or links to other hosts: it opens offline from ``file://``.

Example
-------
>>> from grainlab.report import write_report          # doctest: +SKIP
>>> write_report("results")                            # doctest: +SKIP
PosixPath('results/report.html')
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from grainlab.io.results import write_text_atomic
from grainlab.report.angles import (
    ClassicalAngles,
    DilationFit,
    arthur_angle,
    dilation_angle_from_slope,
    fit_dilation,
    mobilised_friction_angle,
    mohr_coulomb_angle,
    roscoe_angle,
)

__all__ = [
    "REPORT_FILE",
    "ClassicalAngles",
    "DilationFit",
    "ReportError",
    "arthur_angle",
    "detect_kind",
    "dilation_angle_from_slope",
    "fit_dilation",
    "mobilised_friction_angle",
    "mohr_coulomb_angle",
    "roscoe_angle",
    "write_report",
]

#: Name of the report in a results folder.
REPORT_FILE = "report.html"

#: What a results folder holds: a run of a protocol (its results file's ``kind``) or a study.
Kind = Literal["biaxial", "oedometer", "cyclic", "simple_shear", "study"]


class ReportError(ValueError):
    """The folder cannot be reported on (the message says why and what would work)."""


def detect_kind(folder: str | os.PathLike[str]) -> tuple[Path, Kind]:
    """``(folder, kind)`` of a results folder, or :class:`ReportError`.

    A run's folder holds a finished ``run.h5``, whose ``kind`` attribute names
    its test (``"biaxial"``, ``"oedometer"``, ``"cyclic"``, ``"simple_shear"``); a study folder holds
    ``study.csv``. A path to either file stands for its folder. Nothing is
    read beyond the folder listing and that attribute, so this fails before any work.
    """
    path = Path(folder)
    if path.is_file() and path.name in ("run.h5", "study.csv"):
        path = path.parent
    if not path.exists():
        raise ReportError(f"{path}: no such folder")
    if not path.is_dir():
        raise ReportError(f"{path}: not a folder (give a biaxial results folder or a study folder)")
    if (path / "run.h5").exists():
        from grainlab.io.hdf5 import results_kind

        kind = results_kind(path / "run.h5") or "biaxial"
        if kind == "biaxial":
            return path, "biaxial"
        if kind == "oedometer":
            return path, "oedometer"
        if kind == "cyclic":
            return path, "cyclic"
        if kind == "simple_shear":
            return path, "simple_shear"
        raise ReportError(f"{path}: a run of kind {kind!r}, which grainlab report does not cover "
                          "(it covers biaxial, oedometer, cyclic and simple-shear runs and the packing study)")
    if (path / "run.h5.partial").exists():
        raise ReportError(
            f"{path}: the run has not finished (only run.h5.partial); continue it with "
            f"grainlab run KIND --out {path} --resume (grainlab biaxial for a biaxial run), then make the report"
        )
    if (path / "study.csv").exists():
        return path, "study"
    if (path / "sweep.csv").exists():
        biaxial = sorted(path.glob("runs/*/biaxial/run.h5"))
        hint = (f"report a run of the sweep, e.g. grainlab report {biaxial[0].parent}" if biaxial else
                f"its runs are packing runs, which have no report: their numbers are in {path / 'sweep.csv'} "
                f"and {path / 'runs' / 'NAME' / 'result.json'}")
        raise ReportError(
            f"{path}: a sweep folder (sweep.csv); grainlab report covers one biaxial run or the packing study: {hint}"
        )
    raise ReportError(
        f"{path}: neither a biaxial results folder (no run.h5) nor a study folder (no study.csv)"
    )


def write_report(
    folder: str | os.PathLike[str],
    *,
    redraw: bool = False,
    out: str | os.PathLike[str] | None = None,
) -> Path:
    """Writes ``report.html`` for the run (biaxial, oedometer, cyclic, simple shear) or study in ``folder``;
    returns its path.

    Figures missing from the folder are drawn into it first (all of them
    with ``redraw``); ``out`` writes the page elsewhere than
    ``folder/report.html``. Raises :class:`ReportError` (or the reader's
    ``ValueError``) before any work when the folder is neither kind.
    """
    path, kind = detect_kind(folder)
    target = Path(out) if out is not None else path / REPORT_FILE
    if kind == "biaxial":
        from grainlab.report.biaxial import gather_biaxial
        from grainlab.report.render import render_biaxial

        text = render_biaxial(gather_biaxial(path, redraw=redraw))
    elif kind == "oedometer":
        from grainlab.report.oedometer import gather_oedometer, render_oedometer

        text = render_oedometer(gather_oedometer(path, redraw=redraw))
    elif kind == "cyclic":
        from grainlab.report.cyclic import gather_cyclic, render_cyclic

        text = render_cyclic(gather_cyclic(path, redraw=redraw))
    elif kind == "simple_shear":
        from grainlab.report.simple_shear import gather_simple_shear, render_simple_shear

        text = render_simple_shear(gather_simple_shear(path, redraw=redraw))
    else:
        from grainlab.report.render import render_study
        from grainlab.report.study import gather_study

        text = render_study(gather_study(path, redraw=redraw))
    return write_text_atomic(target, text)
