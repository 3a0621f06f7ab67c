"""The periodic simple-shear test's report page, declared: the effective friction
at its peak and in the steady state, the dilatancy, the fabric, the
Rothenburg-Bathurst residual over every record and the figures
(:class:`~grainlab.report.run_page.ReportPage`)."""

from __future__ import annotations

from typing import Any

from grainlab._html import fmt, paragraph
from grainlab.protocols.simple_shear.config import SIMPLE_SHEAR_SCHEMA
from grainlab.protocols.simple_shear.outputs import write_outputs
from grainlab.report.run_page import PageSection, ReportPage, RunPage

__all__ = ["FIGURES", "PAGE"]

#: The run's figures: file stem -> (title, caption).
FIGURES = {
    "fig01_friction_and_volume": ("Friction and volume", "mu = tau / sigma_n and the dilation against the shear "
                                  "strain; the steady state, over which the summary averages, is shaded."),
    "fig02_fabric": ("Fabric", "Coordination number Z, contact-normal anisotropy a and mean lambda against the "
                     "shear strain."),
    "fig03_stress_force_fabric": ("Stress-force-fabric relation", "Measured q/p against Rothenburg and Bathurst's "
                                  "(a + a_n + a_t)/2 projected on the stress direction, on every record, and the "
                                  "residual against the shear strain."),
    "fig04_stress_path": ("Stress path", "The shear stress against the normal stress, with the steady state's "
                          "tau = mu sigma_n, and the normal stress against the shear strain: at constant volume, "
                          "the undrained test's path."),
}


def _held(s: dict[str, Any]) -> str:
    if s["volume"] == "free":
        return "sigma_n held at " + fmt(s["normal_stress_set_pa"] / 1e3, 4, unit="kPa")
    return ("the cell's area held; sigma_n from " + fmt(s["normal_stress_set_pa"] / 1e3, 4, unit="kPa") + " to "
            + fmt(s["normal_stress_final_pa"] / 1e3, 4, unit="kPa"))


def _glance(r: RunPage) -> list[tuple[str, str]]:
    s = r.summary
    return [
        ("grains", fmt(s["n_particles"])),
        ("boundary", f"periodic cell {fmt(1e3 * s['cell_width_m'], 4, unit='mm')} wide; {_held(s)}"),
        ("shear rate", f"{fmt(s['shear_rate_per_s'], 4, unit='1/s')} (I = {fmt(s['inertial_number_set'], 3)} set, "
                       f"{fmt(s['inertial_number_steady'], 3)} in the steady state)"),
        ("porosity at the start / steady", f"{fmt(s['porosity_initial'], 4)} / {fmt(s['porosity_steady'], 4)}"),
        ("peak mu", f"{fmt(s['friction_coefficient_peak'], 3)} at gamma = "
                    f"{fmt(100 * s['shear_strain_at_peak'], 3, unit='%')}"),
        ("steady mu", f"{fmt(s['friction_coefficient_steady'], 3)} (sd {fmt(s['friction_coefficient_steady_sd'], 2)}; "
                      f"{s['steady_rule']}, {s['steady_records']} records)"),
        ("steady Z / mechanical Z", f"{fmt(s['coordination_number_steady'], 3)} / "
                                    f"{fmt(s['mechanical_coordination_number_steady'], 3)}"),
        ("steady mean lambda / anisotropy a", f"{fmt(s['mean_stability_index_steady'], 3)} / "
                                              f"{fmt(s['anisotropy_steady'], 3)}"),
        ("volumetric strain at the end", f"{fmt(100 * s['volumetric_strain_final'], 3, unit='%')} (compression "
                                         "positive)"),
        ("Rothenburg-Bathurst residual", f"mean |r| {fmt(s['rb_residual_mean_abs'], 3)}, largest "
                                         f"{fmt(s['rb_residual_max_abs'], 3)} over {s['records']} records"),
        ("wall time", fmt(s["wall_time_s"], 3, unit="s")),
    ]


def _shearing(r: RunPage) -> list[Any]:
    return [paragraph(
        "The cell's stress is the contacts' Love-Weber sum and the grains' kinetic part over the cell's area; "
        "the shear strain is the imposed rate integrated over time (docs/protocols.md, \"Periodic simple "
        "shear\").", "note")]


#: The periodic simple-shear test's page.
PAGE = ReportPage(
    SIMPLE_SHEAR_SCHEMA.name, test="periodic simple-shear test", name="simple-shear", figures=FIGURES, draw=write_outputs,
    glance=_glance, sections=(PageSection("shear", "Shearing", _shearing, with_figures=True),),
)
