"""``report.html``: one self-contained page describing a results folder (docs/report.md).

Example
-------
>>> from grainlab.report import write_report          # doctest: +SKIP
>>> write_report("results")                            # doctest: +SKIP
PosixPath('results/report.html')
"""

from __future__ import annotations

import os
from pathlib import Path

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


class ReportError(ValueError):
    """The folder cannot be reported on (the message says why and what would work)."""


def detect_kind(folder: str | os.PathLike[str]) -> tuple[Path, str]:
    """``(folder, kind)`` of a results folder, or :class:`ReportError`.

    A run's folder holds a finished ``run.h5``, whose ``kind`` attribute names
    its test, one with a page in :data:`grainlab.report.pages.PAGES`
    (``"biaxial"``, ``"oedometer"``, ``"cyclic"``, ``"simple_shear"``, ``"ucs"``, ``"brazilian"``, ``"crushing"``); a
    study folder holds ``study.csv`` (kind ``"study"``). A path to either file
    stands for its folder. Nothing is read beyond the folder listing and that
    attribute, so this fails before any work.
    """
    from grainlab.report.pages import PAGES, STUDY

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
        if kind in PAGES:
            return path, kind
        covered = ", ".join(p.name for p in PAGES.values())
        raise ReportError(f"{path}: a run of kind {kind!r}, which grainlab report does not cover "
                          f"(it covers the runs of {covered} and the packing study)")
    if (path / "run.h5.partial").exists():
        raise ReportError(
            f"{path}: the run has not finished (only run.h5.partial); continue it with "
            f"grainlab run KIND --out {path} --resume (grainlab biaxial for a biaxial run), then make the report"
        )
    if (path / "study.csv").exists():
        return path, STUDY
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
    from grainlab.report.pages import PAGES, STUDY_PAGE

    path, kind = detect_kind(folder)
    target = Path(out) if out is not None else path / REPORT_FILE
    page = PAGES.get(kind, STUDY_PAGE)  # detect_kind gives a registered test's kind or the study's
    return write_text_atomic(target, page.html(path, redraw=redraw))
