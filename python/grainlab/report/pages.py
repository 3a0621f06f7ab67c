"""The registry of report pages: each test's declared :class:`ReportPage`, by its
protocol's name (the results file's ``kind``), and the packing study's page.

Adding a test's page is adding its declaration here; :func:`grainlab.report.write_report`
looks the page up by the run's ``kind`` and nothing else names the tests.
"""

from __future__ import annotations

from pathlib import Path

from grainlab.report import brazilian, crushing, cyclic, oedometer, simple_shear, ucs
from grainlab.report.run_page import ReportPage

__all__ = ["PAGES", "STUDY", "STUDY_PAGE"]

#: What a packing study's folder is reported as (its folder holds ``study.csv``, not ``run.h5``).
STUDY = "study"


def _biaxial(folder: Path, redraw: bool) -> str:
    # the paper's page: its own gathering (report.biaxial) and layout (report.render)
    from grainlab.report.biaxial import gather_biaxial
    from grainlab.report.render import render_biaxial

    return render_biaxial(gather_biaxial(folder, redraw=redraw))


def _study(folder: Path, redraw: bool) -> str:
    from grainlab.report.render import render_study
    from grainlab.report.study import gather_study

    return render_study(gather_study(folder, redraw=redraw))


#: Protocol name -> its report page.
PAGES: dict[str, ReportPage] = {page.protocol: page for page in (
    ReportPage("biaxial", test="biaxial test", name="biaxial", render=_biaxial),
    oedometer.PAGE,
    cyclic.PAGE,
    simple_shear.PAGE,
    ucs.PAGE,
    brazilian.PAGE,
    crushing.PAGE,
)}

#: The packing study's page.
STUDY_PAGE = ReportPage(STUDY, test="packing study", name="study", render=_study)
