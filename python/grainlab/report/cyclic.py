"""The cyclic biaxial test's report page, declared: each cycle's stress ratios at
its turning points and its end state (volumetric strain, Z, mean lambda,
anisotropy), the loops and the fabric over the cycles
(:class:`~grainlab.report.run_page.ReportPage`)."""

from __future__ import annotations

from typing import Any

from grainlab._html import fmt, paragraph, table
from grainlab.columns import COORDINATION_NUMBER, VOLUMETRIC_STRAIN
from grainlab.protocols.cyclic.config import CYCLIC_SCHEMA
from grainlab.protocols.cyclic.outputs import write_outputs
from grainlab.report.run_page import PageSection, ReportPage, RunPage

__all__ = ["FIGURES", "PAGE"]

#: The run's figures: file stem -> (title, caption).
FIGURES = {
    "fig01_cycles": ("The loops", "sigma1/sigma3 (axial over confining stress) and the volumetric strain against "
                     "the axial strain, compression positive; the first cycle lightest, the last darkest."),
    "fig02_fabric_over_cycles": ("Fabric over the cycles", "Coordination number Z, mean geometrical stability "
                                 "index lambda and contact-normal anisotropy a at every record; markers at the "
                                 "start and at the end of each cycle (axial strain back to 0)."),
}


def _amplitude(s: dict[str, Any]) -> str:
    amplitude = (f"+/- {fmt(100 * s['strain_amplitude'], 3)} % axial strain" if s.get("control", "strain") == "strain"
                 else f"deviator q +/- {fmt(s['stress_amplitude_pa'] / 1e3, 3)} kPa")
    limit = (f" of {s['cycles_asked']} (the axial strain reached +/- {fmt(100 * s['strain_limit'], 3)} %)"
             if s.get("stopped_at_strain_limit") else "")
    return f"{amplitude}, {len(s['cycles'])}{limit}"


def _glance(r: RunPage) -> list[tuple[str, str]]:
    s = r.summary
    last = s["cycles"][-1]
    return [
        ("grains", fmt(s["n_particles"])),
        ("porosity at the start of cycling", fmt(s["porosity_initial"], 4)),
        ("amplitude, cycles", _amplitude(s)),
        ("strain rate", f"{fmt(s['strain_rate'], 3, unit='1/s')} (inertial number {fmt(s['inertial_number'], 3)})"),
        ("Z: start -> end", f"{fmt(s['coordination_number_initial'], 4)} -> {fmt(last[COORDINATION_NUMBER], 4)}"),
        ("mean lambda: start -> end",
         f"{fmt(s['mean_stability_index_initial'], 4)} -> {fmt(last['mean_stability_index'], 4)}"),
        ("volumetric strain after the last cycle", fmt(100 * last[VOLUMETRIC_STRAIN], 3, unit="%")),
        ("wall time", fmt(s["wall_time_s"], 3, unit="s")),
    ]


def _cycles(r: RunPage) -> list[Any]:
    cycles = r.summary["cycles"]
    headers = ["cycle", "sigma1/sigma3 at +A", "sigma1/sigma3 at -A", "volumetric strain at end (%)", "Z at end",
               "mean lambda at end", "a at end"]
    rows = [[fmt(c["cycle"]), fmt(c["stress_ratio_compression"], 4), fmt(c["stress_ratio_extension"], 4),
             fmt(100 * c[VOLUMETRIC_STRAIN], 4), fmt(c[COORDINATION_NUMBER], 4), fmt(c["mean_stability_index"], 4),
             fmt(c["anisotropy"], 4)] for c in cycles]
    undrained = r.summary.get("shear_volume") == "constant"
    if undrained:  # the mean effective stress and the pore-pressure analogue at each cycle's end
        headers += ["p' at end (kPa)", "u at end (kPa)"]
        for row, c in zip(rows, cycles, strict=True):
            row += [fmt(c["mean_effective_stress_pa"] / 1e3, 4), fmt(c["pore_pressure_pa"] / 1e3, 4)]
    drainage = ("The sample's area is held by the rigid side walls (shear.volume = constant): sigma_3 is the "
                "effective lateral stress the walls feel, and u = sigma_0 - sigma_3' is the pore pressure water "
                "held in the sample would carry." if undrained else
                "The confining pressure is held constant, so the volumetric strain is the drained response.")
    return [paragraph(
        "One row per cycle: the stress ratio at its compression (+A) and extension (-A) turning points, and "
        "the state at its end, where the axial strain is back to 0 (grainlab.protocols.cyclic.outputs). "
        + drainage, "note"), table(headers, rows, numeric=range(len(headers)))]


#: The cyclic biaxial test's page.
PAGE = ReportPage(
    CYCLIC_SCHEMA.name, test="cyclic biaxial test", name="cyclic", figures=FIGURES, draw=write_outputs, glance=_glance,
    sections=(PageSection("cycles", "The cycles", _cycles, with_figures=True),),
)
