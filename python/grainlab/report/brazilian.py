"""The Brazilian test's report page, declared: the indirect tensile strength
sigma_t = 2 F_max / (pi D t), the disc, its bonds and its cracks, the
force-displacement figure (:class:`~grainlab.report.run_page.ReportPage`; the crack
map is every cemented run's)."""

from __future__ import annotations

from pathlib import Path

from grainlab._html import fmt, paragraph
from grainlab.protocols.brazilian.config import BRAZILIAN_SCHEMA
from grainlab.report.run_page import PageSection, ReportPage, RunPage

__all__ = ["FIGURES", "PAGE"]

#: The run's figures: file stem -> (title, caption).
FIGURES = {
    "fig01_force_displacement": ("Force and displacement", "The mean of the two platens' normal forces F (per m of "
                                 "thickness) against the top platen's travel, the indirect tensile stress "
                                 "2F/(pi D t) on the right axis and its peak sigma_t marked; below, the cement "
                                 "bonds broken so far."),
}


def _draw(folder: Path) -> None:
    from grainlab.protocols.brazilian.outputs import write_outputs  # draws them from run.h5

    write_outputs(folder)


def _glance(r: RunPage) -> list[tuple[str, str]]:
    s = r.summary
    return [
        ("disc", f"D {fmt(1e3 * s['diameter_m'], 4, unit='mm')} between the platens; its grains' centres in a "
                 f"circle {fmt(1e3 * s['carve_diameter_m'], 4, unit='mm')} across"),
        ("grains / cement bonds", f"{fmt(s['n_particles'])} / {fmt(s['cement_bonds'])} (of the sample's "
                                  f"{fmt(s['sample_particles'])} / {fmt(s['sample_cement_bonds'])}; "
                                  f"{fmt(s['loose_particles'])} in the circle not held by the cement)"),
        ("indirect tensile strength sigma_t", f"{fmt(s['tensile_strength_pa'] / 1e3, 4, unit='kPa')}: F_max "
                                              f"{fmt(s['peak_force_n_per_m'] / 1e3, 4, unit='kN/m')} at "
                                              f"{fmt(1e6 * s['displacement_at_peak_m'], 4, unit='um')} "
                                              f"({fmt(s['axial_strain_at_peak'], percent=True)} of D)"),
        ("cracks at the peak / at the end", f"{fmt(s['cracks_at_peak'])} / {fmt(s['cracks_final'])}"),
        ("end of the loading", f"{fmt(1e6 * s['displacement_final_m'], 4, unit='um')} "
                               f"({fmt(s['axial_strain_final'], percent=True)} of D, "
                               f"{s['ended_by'].replace('_', ' ')}), 2F/(pi D t) "
                               f"{fmt(s['tensile_stress_final_pa'] / 1e3, 4, unit='kPa')}"),
        ("wall time", fmt(s["wall_time_s"], 3, unit="s")),
    ]


#: The Brazilian test's page.
PAGE = ReportPage(
    BRAZILIAN_SCHEMA.name, test="Brazilian test", name="brazilian", figures=FIGURES, draw=_draw, glance=_glance,
    sections=(PageSection("curve", "The force-displacement curve", lambda r: [paragraph(
        "The sample is cemented at the end of the consolidation; the disc is carved from it (the grains in its "
        "circle that the cement holds, each by two bonds or more), put between two platens touching it and settled; the "
        "displacement counts from there. The loading ends at brazilian.final_strain (of D) or once the platen "
        "force after the peak falls below brazilian.residual_fraction of F_max. Forces are per metre of "
        "thickness (t = 1 m).", "note")], with_figures=True),),
)
