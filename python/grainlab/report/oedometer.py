"""The oedometer's report page, declared: K0 on first loading beside Jaky's
1 - sin phi', K against the overconsolidation ratio on unloading beside Mayne
and Kulhawy's K0 OCR^sin phi' (when the run names phi'), the load path's
records and the figures (:class:`~grainlab.report.run_page.ReportPage`)."""

from __future__ import annotations

from typing import Any

from grainlab._html import EmbeddedFigure, Markup, figures, fmt, paragraph, table
from grainlab.columns import (
    COORDINATION_NUMBER,
    HORIZONTAL_STRESS_PA,
    LATERAL_STRESS_RATIO,
    OVERCONSOLIDATION_RATIO,
    TARGET_VERTICAL_STRESS_PA,
    VERTICAL_STRESS_PA,
    VOID_RATIO,
)
from grainlab.protocols.oedometer.config import OEDOMETER_SCHEMA
from grainlab.protocols.oedometer.outputs import write_outputs
from grainlab.report.run_page import PageSection, ReportPage, RunPage

__all__ = ["FIGURES", "PAGE"]

#: The run's figures: file stem -> (title, caption).
FIGURES = {
    "fig01_lateral_stress_ratio": ("K along the load path", "K = sigma_h / sigma_v at each load step's equilibrium; "
                                   "the dotted line is Jaky's 1 - sin phi' when the run names phi'."),
    "fig02_compression": ("Compression curve", "Void ratio against the vertical stress, loading and unloading."),
}

#: The load path table's columns, those the run recorded shown.
_PATH_COLUMNS = (TARGET_VERTICAL_STRESS_PA, VERTICAL_STRESS_PA, HORIZONTAL_STRESS_PA, LATERAL_STRESS_RATIO,
                 OVERCONSOLIDATION_RATIO, VOID_RATIO, COORDINATION_NUMBER, "mean_stability_index", "anisotropy")


def _glance(r: RunPage) -> list[tuple[str, str]]:
    s = r.summary
    jaky = s.get("k0_jaky")
    return [
        ("grains", fmt(s["n_particles"])),
        ("porosity / void ratio at the start of loading",
         f"{fmt(s['porosity_initial'], 4)} / {fmt(s['void_ratio_initial'], 4)}"),
        ("K0 on first loading", f"{fmt(s['k0_loading'], 3)} ({s['k0_rule']})"),
        ("Jaky's K0 = 1 - sin phi'", "no phi' given (oedometer.friction_angle)" if jaky is None
         else f"{fmt(jaky, 3)} for phi' = {fmt(s.get('friction_angle_deg'), 3)} deg"),
        ("largest vertical stress", fmt(s["max_vertical_stress_pa"] / 1e3, 4, unit="kPa")),
        ("K at the end", f"{fmt(s['lateral_stress_ratio_final'], 3)} at OCR {fmt(s['overconsolidation_ratio_final'], 3)}"),
        ("wall time", fmt(s["wall_time_s"], 3, unit="s")),
    ]


def _load_path(r: RunPage) -> list[Markup]:
    ts = r.results.timeseries
    present = [c for c in _PATH_COLUMNS if c in ts]
    rows = [[fmt(float(ts[c][k]) / (1e3 if c.endswith("_pa") else 1.0), 4) for c in present]
            for k in range(len(ts[VERTICAL_STRESS_PA]))]
    headers = [f"{c[:-3]} (kPa)" if c.endswith("_pa") else str(c) for c in present]
    return [paragraph(
        "One record per load step, at its equilibrium (the step ends with sigma_v within oedometer.tolerance "
        "of its target and the unbalanced force ratio below consolidation.unbalanced_force_ratio); the first "
        "is the consolidated sample with Table 1 friction on, from which strains count.", "note"),
        table(headers, rows, numeric=range(len(headers)))]


def _unloading(r: RunPage) -> list[Any]:
    rows = [(fmt(u["overconsolidation_ratio"], 3), fmt(u["lateral_stress_ratio"], 3),
             "n/a" if u["mayne_kulhawy"] is None else fmt(u["mayne_kulhawy"], 3)) for u in r.summary["unloading"]]
    return [paragraph("Mayne and Kulhawy (1982): K0 = (1 - sin phi') OCR^(sin phi'), a comparison for sands, not "
                      "an oracle for disks.", "note"),
            table(["OCR", "K (this run)", "Mayne-Kulhawy"], rows, numeric=(0, 1, 2))]


def _fragments(r: RunPage) -> list[Any]:
    from grainlab.report.figures import embedded_png  # matplotlib: only when a page is made

    s = r.summary
    if "agglomerates" not in s:
        return [paragraph("The grains are disks (sample.grains = disk): nothing to crush.", "note")]
    y = s["yield_stress_pa"]
    rows = [(g["load_step"], fmt(g["vertical_stress_pa"] / 1e3, 4), g["fragments"], fmt(1e3 * g["d50_m"], 3))
            for g in s["fragment_grading"]]
    path = r.folder / "fig03_fragment_grading.png"
    shown = [figures([EmbeddedFigure("fig03_fragment_grading", "Fragment grading", "Percent of the solid area "
                                     "passing each size at each load step; a fragment's size is its "
                                     "equivalent-area diameter.", embedded_png(path.read_bytes()), path.name)])] \
        if path.exists() else []
    return [paragraph(f"{s['agglomerates']} agglomerates of bonded disks; the fragments are the connected components "
                      f"of the intact bonds (fragments.csv). Yield stress: "
                      f"{'n/a' if y is None else fmt(y / 1e3, 4, unit='kPa')} ({s['yield_rule']}).", "note"),
            table(["load step", "sigma_v (kPa)", "fragments", "d50 (mm)"], rows, numeric=(0, 1, 2, 3)), *shown]


#: The oedometer test's page.
PAGE = ReportPage(
    OEDOMETER_SCHEMA.name, test="oedometer test", name="oedometer", figures=FIGURES, draw=write_outputs, glance=_glance,
    sections=(PageSection("path", "The load path", _load_path, with_figures=True),
              PageSection("unloading", "Unloading: K against OCR", _unloading),
              PageSection("fragments", "Crushable grains", _fragments)),
)
