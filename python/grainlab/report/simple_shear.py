"""The periodic simple-shear test's report page: the effective friction at its
peak and in the steady state, the dilatancy, the fabric, the
Rothenburg-Bathurst residual over every record, the figures, the
configuration and how to rerun."""

from __future__ import annotations

from pathlib import Path

import grainlab
from grainlab._html import definition_table, figures, fmt, page, paragraph, section
from grainlab.protocols.simple_shear.config import SIMPLE_SHEAR_SCHEMA
from grainlab.report.run_page import RunPage, gather_run_page, rerun_sections

__all__ = ["FIGURES", "SimpleShearReport", "gather_simple_shear", "render_simple_shear"]

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

#: What the simple-shear page shows.
SimpleShearReport = RunPage


def gather_simple_shear(folder: str | Path, *, redraw: bool = False) -> RunPage:
    """Collects the report of the simple-shear run in ``folder``; figures missing from it
    (all of them with ``redraw``) are drawn into it first."""
    from grainlab.protocols.simple_shear.outputs import write_outputs  # draws them from run.h5

    return gather_run_page(folder, FIGURES, write_outputs, redraw=redraw)


def render_simple_shear(r: RunPage) -> str:
    """The simple-shear report page."""
    s = r.summary
    held = ("sigma_n held at " + fmt(s["normal_stress_set_pa"] / 1e3, 4, unit="kPa") if s["volume"] == "free"
            else "the cell's area held; sigma_n from " + fmt(s["normal_stress_set_pa"] / 1e3, 4, unit="kPa") + " to "
            + fmt(s["normal_stress_final_pa"] / 1e3, 4, unit="kPa"))
    glance = definition_table([
        ("grains", fmt(s["n_particles"])),
        ("boundary", f"periodic cell {fmt(1e3 * s['cell_width_m'], 4, unit='mm')} wide; {held}"),
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
    ])
    sections = [
        section("glance", "At a glance", glance),
        section("shear", "Shearing", paragraph(
            "The cell's stress is the contacts' Love-Weber sum and the grains' kinetic part over the cell's area; "
            "the shear strain is the imposed rate integrated over time (docs/protocols.md, \"Periodic simple "
            "shear\").", "note"), figures(r.figures)),
        *rerun_sections(SIMPLE_SHEAR_SCHEMA.name, r.folder, r.results),
    ]
    header = paragraph(f"grainlab periodic simple-shear test: {r.folder.resolve().name}; run by grainlab "
                       f"{r.results.grainlab_version}, report generated {r.generated}.")
    return page(f"grainlab simple-shear report: {r.folder.resolve().name}", header, sections,
                f"grainlab {grainlab.__version__}: this file is self-contained (figures embedded, no scripts, "
                "no network).")
