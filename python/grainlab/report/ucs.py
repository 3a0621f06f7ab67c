"""The unconfined compression test's report page, declared: the unconfined strength
q_u, Young's modulus and Poisson's ratio with their fit's rule, the bonds and the
cracks and the stress-strain figure (:class:`~grainlab.report.run_page.ReportPage`;
the crack map is every cemented run's)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from grainlab._html import fmt, paragraph
from grainlab.protocols.ucs.config import UCS_SCHEMA
from grainlab.report.run_page import PageSection, ReportPage, RunPage

__all__ = ["FIGURES", "PAGE"]

#: The run's figures: file stem -> (title, caption).
FIGURES = {
    "fig01_stress_strain": ("Stress and lateral strain", "Axial stress on the top platen over the sample's width, "
                            "and the lateral strain of the grains' width over the middle half of the height, "
                            "against the axial strain; the records of the E and nu fit are shaded, q_u marked."),
}


def _draw(folder: Path) -> None:
    from grainlab.protocols.ucs.outputs import write_outputs  # draws them from run.h5

    write_outputs(folder)


def _optional(value: Any, scale: float = 1.0, digits: int = 3, unit: str = "") -> str:
    return "n/a (fewer than two records in the fit's range)" if value is None else fmt(value / scale, digits,
                                                                                        unit=unit)


def _glance(r: RunPage) -> list[tuple[str, str]]:
    s = r.summary
    return [
        ("grains / cement bonds", f"{fmt(s['n_particles'])} / {fmt(s['cement_bonds'])}"),
        ("unconfined strength q_u", f"{fmt(s['unconfined_strength_pa'] / 1e3, 4, unit='kPa')} at "
                                    f"{fmt(s['axial_strain_at_peak'], percent=True)} axial strain"),
        ("Young's modulus E", _optional(s["youngs_modulus_pa"], 1e6, 4, "MPa")),
        ("Poisson's ratio nu", _optional(s["poisson_ratio"])),
        ("E and nu fitted", f"{s['elastic_fit_rule']} ({s['elastic_fit_records']} records)"),
        ("cracks at the peak / at the end", f"{fmt(s['cracks_at_peak'])} / {fmt(s['cracks_final'])}"),
        ("end of the loading", f"{fmt(s['axial_strain_final'], percent=True)} axial strain "
                               f"({s['ended_by'].replace('_', ' ')}), sigma_1 "
                               f"{fmt(s['axial_stress_final_pa'] / 1e3, 4, unit='kPa')}"),
        ("wall time", fmt(s["wall_time_s"], 3, unit="s")),
    ]


#: The unconfined compression test's page.
PAGE = ReportPage(
    UCS_SCHEMA.name, test="unconfined compression test", name="ucs", figures=FIGURES, draw=_draw, glance=_glance,
    sections=(PageSection("curve", "The stress-strain curve", lambda r: [paragraph(
        "The sample is cemented at the end of the consolidation, released (side walls removed, platens held "
        "still) and settled, then seated (the top platen servo-controlled to ucs.seating_stress); strains count "
        "from there. The loading ends at ucs.final_strain or once the axial "
        "stress after the peak falls below ucs.residual_fraction of q_u.", "note")], with_figures=True),),
)
