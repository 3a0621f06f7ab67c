"""The crushing test's report page, declared: the Weibull fit of the agglomerates'
strengths (m and sigma_0 with their intervals, R^2), the modes, every agglomerate's
peak in a table, and the force curves and Weibull plot
(:class:`~grainlab.report.run_page.ReportPage`)."""

from __future__ import annotations

from typing import Any

from grainlab._html import Markup, fmt, paragraph, table
from grainlab.protocols.crushing.config import CRUSHING_SCHEMA
from grainlab.protocols.crushing.outputs import MODES, write_outputs
from grainlab.report.run_page import PageSection, ReportPage, RunPage

__all__ = ["FIGURES", "PAGE"]

#: The run's figures: file stem -> (title, caption).
FIGURES = {
    "fig01_force_displacement": ("Force curves", "Each agglomerate's force on the top platen (N per m of thickness) "
                                 "against the platen's displacement over its diameter; its peak marked in the colour "
                                 "of its mode."),
    "fig02_weibull": ("Weibull plot", "ln(-ln P_s) of the median ranks against ln sigma_f of the agglomerates that "
                      "failed, and the least-squares line: its slope is the Weibull modulus m."),
}


def _interval(values: list[float], scale: float = 1.0, digits: int = 3) -> str:
    return f"{fmt(values[0] / scale, digits)} to {fmt(values[1] / scale, digits)}"


def _glance(r: RunPage) -> list[tuple[str, str]]:
    s, w = r.summary, r.summary["weibull"]
    fit: list[tuple[str, str]] = [("Weibull fit", "none: fewer than 3 agglomerates failed")] if w is None else [
        ("Weibull modulus m", f"{fmt(w['modulus'], 3)} (95 % bootstrap {_interval(w['modulus_interval'])})"),
        ("sigma_0 (37 % survive)", f"{fmt(w['scale'] / 1e3, 4, unit='kPa')} (95 % bootstrap "
                                   f"{_interval(w['scale_interval'], 1e3, 4)} kPa)"),
        ("R^2 of the Weibull line", fmt(w["r_squared"], 3)),
        ("the fit", w["estimator"]),
    ]
    return [
        ("agglomerates / failed", f"{fmt(s['n_agglomerates'])} / {fmt(s['n_failed'])}"),
        ("disks / bonds per agglomerate (mean)", f"{fmt(s['mean_disks'], 3)} / {fmt(s['mean_bonds'], 3)}"),
        *fit,
        ("mean / median sigma_f", "n/a" if s["mean_strength_pa"] is None else
         f"{fmt(s['mean_strength_pa'] / 1e3, 4)} / {fmt(s['median_strength_pa'] / 1e3, 4, unit='kPa')}"),
        ("modes", ", ".join(f"{s['modes'][m]} {m}" for m in MODES)),
        ("wall time", fmt(s["wall_time_s"], 3, unit="s")),
    ]


def _agglomerates(r: RunPage) -> list[Any]:
    rows = [(a["agglomerate"], fmt(a["diameter_m"] * 1e3, 3), a["disks"], a["bonds"], fmt(a["peak_force_n"], 4),
             fmt(a["strength_pa"] / 1e3, 4), fmt(a["axial_strain_at_peak"], percent=True), a["mode"],
             a["fragments"], a["major_fragments"]) for a in r.summary["agglomerates"]]
    headers = ["#", "d (mm)", "disks", "bonds", "F_max (N/m)", "sigma_f (kPa)", "at u/d", "mode", "fragments",
               "major"]
    note: Markup = paragraph(f"sigma_f = F_max / (d t), t = 1 m. Modes: {r.summary['mode_rule']}.", "note")
    return [note, table(headers, rows, numeric=(0, 1, 2, 3, 4, 5, 6, 8, 9))]


#: The crushing test's page.
PAGE = ReportPage(
    CRUSHING_SCHEMA.name, test="crushing test", name="crushing", figures=FIGURES, draw=write_outputs,
    glance=_glance,
    sections=(PageSection("curves", "Force curves and Weibull plot", lambda r: [paragraph(
        "Each agglomerate is crushed in a simulation of its own between two platens, the top one moving down at "
        "crushing.strain_rate x d, until it has split and its force has dropped below crushing.residual_fraction "
        "of its peak, or at crushing.final_strain.", "note")], with_figures=True),
              PageSection("agglomerates", "The agglomerates", _agglomerates)),
)
