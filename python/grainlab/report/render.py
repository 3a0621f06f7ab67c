"""The two report pages, HTML from the gathered content (:mod:`grainlab.report.biaxial`,
:mod:`grainlab.report.study`). Layout only: every number is computed elsewhere."""

from __future__ import annotations

import math
import shlex
from typing import Any

import grainlab
from grainlab._html import (
    EmbeddedFigure,
    Markup,
    code_block,
    definition_table,
    escape,
    figure,
    figures,
    fmt,
    number,
    page,
    paragraph,
    section,
    table,
)
from grainlab.columns import AXIAL_STRAIN
from grainlab.report.band import ACCEPTANCE
from grainlab.report.biaxial import BiaxialReport
from grainlab.report.run_page import footer
from grainlab.report.study import StudyReport, param_unit

__all__ = ["render_biaxial", "render_study"]


def _deg(rad: float) -> str:
    """An angle in radians as degrees to 0.1 deg, for the page."""
    return f"{math.degrees(rad):.1f} deg" if math.isfinite(rad) else "n/a"


def _glance(items: list[tuple[str, str]]) -> Markup:
    cells = "".join(f'<div><span class="v">{escape(v)}</span><span class="k">{escape(k)}</span></div>' for k, v in items)
    return Markup(f'<div class="glance">{cells}</div>\n')


def _notes(notes: list[str]) -> Markup:
    if not notes:
        return Markup("<p>None.</p>")
    return Markup("<ul>" + "".join(f"<li>{escape(n)}</li>" for n in notes) + "</ul>\n")


def _header(title: str, lines: list[Any]) -> Markup:
    body = "".join(f"<p>{escape(line)}</p>" for line in lines)
    return Markup(f"<h1>{escape(title)}</h1>{body}")


# ----------------------------------------------------------------------------- biaxial
def _claims_part(r: BiaxialReport) -> list[Markup]:
    """The reproduction's claims on this one run, and where the ensemble's verdicts come from."""
    if not r.claim_rows:
        return []
    from grainlab.reproduction.stored import paper_scale_verdicts

    ensemble = paper_scale_verdicts()

    def verdict(claim_id: str) -> str:
        v = ensemble.get(claim_id)
        if v is None:
            return ""
        ci = v["ci95"] or [None, None]
        interval = "" if ci[0] is None else f" [{fmt(float(ci[0]), 3)}, {fmt(float(ci[1]), 3)}]"
        mean = "" if v["mean"] is None else f": {fmt(float(v['mean']), 3)}{interval}"
        return f"{v['verdict']}{mean}"

    rows = [
        (Markup(f"<code>{escape(c['id'])}</code>"), c["statement"], c["source"],
         "" if c["paper_value"] is None else fmt(float(c["paper_value"]), 3), c["measure"],
         fmt(float(c["value"]), 4), c["this_run"], verdict(c["id"]))
        for c in r.claim_rows
    ]
    same = sum(c["this_run"] == "as the paper" for c in r.claim_rows)
    seeds = next(iter(ensemble.values()))["seeds"] if ensemble else 0
    where = (f"The last column is the verdict of grainlab's paper-scale ensemble ({seeds} seeds, the mean and its "
             "95 % interval), shipped with grainlab." if ensemble else "")
    return [
        Markup("<h3>Every claim of the paper on this run</h3>"),
        paragraph(
            f"The claims that grainlab reproduce checks, measured on this one run from its snapshots: {same} of "
            f"{len(rows)} lie where the claim's rule wants them (inside the tolerance band, on the paper's side). "
            "One run is one sample, not a verdict: grainlab reproduce --out DIR runs the test over an ensemble "
            f"of seeds and gives each claim a verdict with its 95 % interval (docs/reproduction.md). {where}",
            "note",
        ),
        table(["claim", "the paper", "where", "paper's value", "measured", "this run", "one run",
               "paper-scale verdict"], rows, numeric=(5,), css_class="wide"),
    ]


def _band_table(r: BiaxialReport) -> Markup:
    rows = []
    for label, b in (("nearest the peak", r.band_peak), ("end of shearing", r.band_end)):
        if b is None:
            rows.append((label, "-", "not available (a single snapshot, or no fabric numbers)", "", "", "", "", "", "", ""))
            continue
        rows.append(
            (
                label,
                f"{b.snapshot} vs {b.reference}",
                "found" if b.found else "not found (candidate)",
                fmt(b.angle_deg, 4),
                fmt(b.inclination_deg, 3),
                fmt(b.thickness_diameters, 3),
                fmt(1e3 * b.thickness_m, 3),
                fmt(b.contrast, 3),
                f"{fmt(b.mean_lambda_inside, 3)} / {fmt(b.mean_lambda_outside, 3)}",
                b.reason,
            )
        )
    return table(
        ["band", "snapshots", "result", "direction from +x (deg)", "inclination to σ₃ (deg)",
         "thickness (mean diameters)", "thickness (mm)", "contrast", "mean λ in / out", "why not accepted"],
        rows,
        numeric=(3, 4, 5, 6, 7, 8),
        cell_classes={9: "note"},
    )


def _classical_table(r: BiaxialReport) -> Markup:
    a = r.angles
    b = r.band_end
    incl = math.radians(b.inclination_deg) if b is not None and b.found else math.nan

    def diff(theta: float) -> str:
        if not (math.isfinite(theta) and math.isfinite(incl)):
            return "n/a"
        return fmt(math.degrees(incl - theta), 3, unit="deg")

    rows = [
        ("Mohr-Coulomb", "45° + φ/2", _deg(a.mohr_coulomb), diff(a.mohr_coulomb)),
        ("Roscoe", "45° + ψ/2", _deg(a.roscoe), diff(a.roscoe)),
        ("Arthur", "45° + (φ + ψ)/4", _deg(a.arthur), diff(a.arthur)),
    ]
    if b is not None and b.found:
        rows.append(("the run's band", f"ShearBand at {b.snapshot}", _deg(incl), ""))
    return table(["angle", "formula", "inclination to σ₃", "band minus it"], rows, numeric=(2, 3))


def _fabric_states(r: BiaxialReport) -> Markup:
    states = (r.fabric or {}).get("states") or {}
    rows = []
    for role in ("initial", "peak", "final"):
        s = states.get(role)
        if not isinstance(s, dict):
            continue
        rows.append(
            (
                role,
                s.get("snapshot", ""),
                fmt(number(s.get(AXIAL_STRAIN)), percent=True),
                fmt(number(s.get("a")), 3),
                fmt(number(s.get("theta_a_deg")), 3),
                fmt(number(s.get("a_n")), 3),
                fmt(number(s.get("theta_n_deg")), 3),
                fmt(number(s.get("mean_lambda")), 3),
                fmt(number(s.get("coordination_number")), 3),
            )
        )
    if not rows:
        return paragraph("No fabric numbers (see the notes).")
    return table(
        ["state", "snapshot", "axial strain", "a (Eq. 7)", "theta_a (deg)", "a_n", "theta_n (deg)",
         "mean λ", "Z"],
        rows,
        numeric=range(2, 9),
    )


def _biaxial_header(r: BiaxialReport) -> Markup:
    """The head of the page: the run, when it ran, this report, the folder."""
    res = r.results
    finished = res.attrs.get("finished", "unknown")
    return _header(
        f"grainlab biaxial test: {r.folder.resolve().name}",
        [
            f"Run by grainlab {res.grainlab_version}: started {res.created}, finished {finished}, status "
            f"{res.status}.",
            f"Report generated {r.generated} by grainlab {grainlab.__version__}.",
            Markup(f"Folder: <code>{escape(str(r.folder.resolve()))}</code>"),
        ],
    )


def _glance_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "At a glance" section: the run's headline numbers."""
    s = r.summary
    band = r.band_end
    band_glance = (
        f"{fmt(band.inclination_deg, 3)} deg, {fmt(band.thickness_diameters, 3)} diameters"
        if band is not None and band.found
        else "not found"
    )
    return section("glance", "At a glance", _glance(
        [
            ("grains", fmt(r.n_grains)),
            ("porosity at the start of shearing", fmt(number(s.get("porosity_initial")), 3)),
            ("initial coordination number Z", fmt(number(s.get("coordination_number_initial")), 3)),
            ("peak stress ratio σ₁/σ₃", fmt(r.peak_ratio, 3)),
            ("axial strain at the peak", fmt(r.peak_strain, percent=True)),
            ("friction angle φ (peak)", _deg(r.phi)),
            ("dilation angle ψ (after the peak)", _deg(r.dilation.angle)),
            ("shear band (inclination, thickness)", band_glance),
            ("wall time", fmt(r.wall_total, 3, unit="s")),
        ]
    ))


def _rerun_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "How to rerun" section: the command, the configuration file, the report again."""
    rerun_parts: list[Any] = [
        paragraph("The same test again (keys equal to the defaults left out):"),
        code_block(r.rerun.command),
    ]
    rerun_parts += [paragraph(n, "note") for n in r.rerun.notes]
    rerun_parts += [
        paragraph("Or with the whole resolved configuration in a file:"),
        code_block(r.rerun.command_with_file),
        Markup(f"<details><summary>config.toml (the resolved configuration)</summary>{code_block(r.rerun.toml)}"
               "</details>\n"),
        paragraph(f"Rebuild this report: grainlab report {shlex.quote(str(r.folder.resolve()))}", "note"),
    ]
    return section("rerun", "How to rerun", *rerun_parts)


def _config_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "Resolved configuration" section: every key, those that differ from the defaults highlighted."""
    rows = [(c.key, c.shown, c.unit, c.default, c.paper, c.help) for c in r.config_rows]
    return (
        section(
            "config",
            "Resolved configuration",
            paragraph(
                "As stored in run.h5 (/config/json), SI units; highlighted rows differ from grainlab's "
                "defaults (the paper's Table 1 where it gives a value).",
                "note",
            ),
            table(
                ["key", "value", "SI unit", "default", "paper", "meaning"],
                rows,
                row_classes=["differs" if c.differs else "" for c in r.config_rows],
                cell_classes={1: "nowrap", 3: "nowrap", 5: "muted"},
            ),
        )
    )


def _sample_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "Sample" section: the grains, the porosities and Z, the rates, the grading curve."""
    s, res = r.summary, r.results
    d = r.diameters
    sample_items = [
        ("grains", fmt(r.n_grains)),
        ("membrane disks (not part of the sample)", fmt(r.n_membrane)),
        ("grain diameters (first snapshot)",
         f"{fmt(1e3 * float(d.min()), 3)} to {fmt(1e3 * float(d.max()), 3)} mm, mean {fmt(1e3 * float(d.mean()), 3)} mm"),
        ("requested grading", r.grading_name),
        ("porosity after generation, nominal / overlap-corrected",
         f"{fmt(number(s.get('porosity_generated')), 4)} / {fmt(number(s.get('porosity_generated_overlap_corrected')), 4)}"),
        ("stress locked in by the generation", fmt(number(s.get("generation_stress_pa")) / 1e3, 4, unit="kPa")),
        ("porosity after consolidation (rigid box), nominal / overlap-corrected",
         f"{fmt(number(s.get('porosity_after_consolidation')), 4)} / "
         f"{fmt(number(s.get('porosity_after_consolidation_overlap_corrected')), 4)}"),
        ("porosity at the start of shearing (membrane), nominal", fmt(number(s.get("porosity_initial")), 4)),
        ("coordination number Z at the start of shearing", fmt(number(s.get("coordination_number_initial")), 4)),
    ]
    ts = r.timeseries
    if "mechanical_coordination_number" in ts:
        sample_items.append(
            ("mechanical coordination number (rattlers removed), start of shearing",
             fmt(float(ts["mechanical_coordination_number"][0]), 4))
        )
    sample_items += [
        ("strain rate", fmt(number(s.get("strain_rate")), 4, unit="1/s")),
        ("inertial number (heaviest grain, damped) / mean diameter",
         f"{fmt(number(s.get('inertial_number')), 3)} / {fmt(number(s.get('inertial_number_mean_diameter')), 3)}"),
        ("density scaling factor I (Eq. 16 with p_y)", fmt(number(s.get("density_scaling_factor")), 3)),
        ("time step", fmt(number(s.get("time_step_s")), 4, unit="s")),
        ("records", fmt(len(ts[AXIAL_STRAIN]))),
        ("snapshots", ", ".join(res.snapshot_names)),
    ]
    grading_fig = EmbeddedFigure(
        "grading",
        "Grading curve",
        "Percent finer by mass (2D: mass ~ d^2) and by number of the grains of the first snapshot, against the "
        f"requested grading ({r.grading_name}).",
        r.grading_png,
        "drawn by the report",
    )
    return (
        section(
            "sample",
            "Sample",
            paragraph(
                "Porosity in 2D: nominal = 1 - (sum of disk areas) / (sample area); overlap-corrected counts "
                "the overlapping area of contacting disks once. Z = 2 Nc / N over grain-grain contacts.",
                "note",
            ),
            definition_table(sample_items),
            figure(grading_fig),
        )
    )


def _macro_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "Macro curves" section: the stress ratio and the volumetric strain."""
    figs = r.figures
    macro_fig = EmbeddedFigure(
        "macro",
        "Stress ratio and volumetric strain, with the peak and the dilation fit",
        "The peak record gives the friction angle φ, the straight line after it the dilation angle ψ "
        "(section Shear band).",
        r.macro_png,
        "drawn by the report",
    )
    macro_figs = [macro_fig] + [figs[k] for k in ("fig08_stress_ratio", "fig10_volumetric_strain", "fig19_stress_path")
                                if k in figs]
    return section("macro", "Macro curves", figures(macro_figs))


def _fabric_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "Fabric figures" section: the fabric at the snapshots and Figs. 6-14."""
    figs = r.figures
    fabric_parts: list[Any] = [
        paragraph(f"Fabric numbers from {r.fabric_source}.", "note"),
        _fabric_states(r),
    ]
    order = ("fig06_contact_normals", "fig07_normal_forces", "fig09_anisotropy", "fig18_coordination_number",
             "fig11_displacement", "fig12_stability_index", "fig13_contact_count", "fig14_mean_stability_index")
    fabric_parts.append(figures(figs[k] for k in order if k in figs))
    return section("fabric", "Fabric figures (Figs. 6-14)", *fabric_parts)


def _angle_formulas(r: BiaxialReport) -> Markup:
    """How phi and psi are computed from this run's records, and the classical inclinations."""
    dl = r.dilation

    def pct(x: float) -> Markup:
        return escape(fmt(x, percent=True))

    return Markup(
        '<p class="formula">Friction angle at the peak record (row '
        f"{r.peak_row}, ε<sub>1</sub> = {pct(r.peak_strain)}, R = σ<sub>1</sub>/σ<sub>3</sub> = "
        f"{escape(fmt(r.peak_ratio, 4))}): sin φ = (σ<sub>1</sub> − σ<sub>3</sub>)/(σ<sub>1</sub> + "
        f"σ<sub>3</sub>) = (R − 1)/(R + 1), φ = {escape(_deg(r.phi))}</p>"
        '<p class="formula">Dilation angle after the peak: sin ψ = −dε<sub>v</sub>/dγ with '
        "γ = ε<sub>1</sub> − ε<sub>3</sub> and the area strain ε<sub>v</sub> = ε<sub>1</sub> + ε<sub>3</sub>, "
        "compression positive, so dγ = 2 dε<sub>1</sub> − dε<sub>v</sub> and sin ψ = −s/(2 − s), with "
        "s = dε<sub>v</sub>/dε<sub>1</sub> the least-squares slope over ε<sub>1</sub> from "
        f"{pct(dl.start_strain)} to {pct(dl.end_strain)} ({dl.n_records} records, a window of "
        f"{pct(dl.window)} after the peak): s = {escape(fmt(dl.slope, 4))}, ψ = {escape(_deg(dl.angle))}</p>"
        '<p class="formula">Inclination to the σ<sub>3</sub> (horizontal) direction: Mohr–Coulomb '
        "45° + φ/2, Roscoe 45° + ψ/2, Arthur 45° + (φ + ψ)/4.</p>"
    )


def _band_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "Shear band and classical angles" section: the band, the formulas, the angles beside it."""
    band = r.band_end
    band_parts: list[Any] = [
        paragraph(
            "The band is located by grainlab.analysis.ShearBand in the excess local shear strain of the grains "
            "away from the boundary since the first snapshot (grainlab.analysis.LocalStrain), at the snapshot "
            "nearest the peak and at "
            f"the end of shearing; found means accepted by {ACCEPTANCE}. Its inclination is "
            "the acute angle to the horizontal, the σ₃ direction; a band not accepted is shown as a "
            "candidate and not compared.",
            "note",
        ),
        _band_table(r),
        paragraph(
            f"These are the bands outlined on Figs. 11-13 (numbers from {r.fabric_source}); "
            "'grainlab report --redraw' recomputes them with the installed grainlab.",
            "note",
        ),
        _angle_formulas(r),
        _classical_table(r),
    ]
    if not (band is not None and band.found):
        band_parts.append(
            paragraph(
                "No band was accepted at the end of shearing, so there is no measured inclination to set "
                "beside the classical angles; the table above says why.",
                "warn",
            )
        )
    else:
        closest = r.angles.closest(math.radians(band.inclination_deg))
        if closest:
            band_parts.append(paragraph(f"The band's inclination is closest to the {closest} angle."))
    return section("band", "Shear band and classical angles", *band_parts)


def _paper_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "The paper beside this run" section: its stated values and the claims on this run."""
    return (
        section(
            "paper",
            "The paper beside this run",
            paragraph(
                "The paper's values as it states them in its text and tables (nothing read off its plots).",
                "note",
            ),
            table(["quantity", "paper", "this run", "where in the paper"], r.paper_rows, cell_classes={2: "note"}),
            *_claims_part(r),
        )
    )


def _time_section(r: BiaxialReport) -> tuple[str, str, Markup]:
    """The "Wall time" section: each phase's share of the run."""
    total = r.wall_total
    time_rows = [
        (name, what, fmt(t, 4), fmt(t / total, percent=True) if total > 0 else "n/a") for name, what, t in r.wall_times
    ]
    other = total - sum(t for _, _, t in r.wall_times)
    if other > 1e-3:
        time_rows.append(("other", "records, files", fmt(other, 3), fmt(other / total, percent=True)))
    time_rows.append(("total", "generation to the end of shearing, as recorded", fmt(total, 4), "100.00 %"))
    return (
        section(
            "time",
            "Wall time",
            table(
                ["phase", "what", "wall time (s)", "share"],
                time_rows,
                numeric=(2, 3),
                row_classes=["" for _ in time_rows[:-1]] + ["total"],
            ),
            paragraph(
                f"Engine threads: {r.threads if r.threads is not None else 'not recorded'}. Figures and this "
                "report are drawn after the total.",
                "note",
            ),
        )
    )


def render_biaxial(r: BiaxialReport) -> str:
    """The biaxial report page: its sections in the page's order."""
    sections = [_glance_section(r), _rerun_section(r), _config_section(r), _sample_section(r), _macro_section(r),
                _fabric_section(r), _band_section(r), _paper_section(r), _time_section(r),
                section("notes", "Notes", _notes(r.notes))]
    return page(f"grainlab biaxial report: {r.folder.resolve().name}", _biaxial_header(r), sections, footer())


# ----------------------------------------------------------------------------- study
def _cell(column: str, text: str) -> str:
    if column in ("kind", "status", "note", "name", "error"):
        return text
    try:
        value = float(text)
    except ValueError:
        return text
    if column in ("seed", "n_particles"):
        return str(int(value)) if math.isfinite(value) else "n/a"
    return fmt(value, 4)


def _trend(value: Any) -> str:
    if isinstance(value, list):
        return ", ".join(fmt(v, 3) for v in value) or "none"
    return fmt(value, 4)


def _study_table_section(r: StudyReport) -> tuple[str, str, Markup]:
    """The "study.csv" section: one row per packing, free text below the table."""
    # the free-text columns go below the table, one line per packing that has any,
    # so that the table keeps one line per row
    texts = [c for c in r.columns if c in ("note", "error")]
    columns = [c for c in r.columns if c not in texts]
    rows = [[_cell(c, row.get(c, "")) for c in columns] for row in r.rows]
    numeric = [k for k, c in enumerate(columns) if c not in ("kind", "status", "name")]
    remarks = [
        (str(row.get("name", "")), c, str(row.get(c, "")))
        for row in r.rows
        for c in texts
        if str(row.get(c, "")).strip()
    ]
    table_parts: list[Any] = [
        paragraph("One row per packing, as written (numbers to 4 significant digits).", "note"),
        table(columns, rows, numeric=numeric, css_class="wide"),
    ]
    if remarks:
        table_parts.append(table(["packing", "column", "text"], remarks, cell_classes={2: "note"}))
    return section("table", "study.csv", *table_parts)


def _study_figures_section(r: StudyReport) -> tuple[str, str, Markup]:
    """The "Figures 15-17 and fits" section."""
    s = r.summary
    fit = s.get("fig17_fit") or {}
    fig_parts: list[Any] = [figures(r.figures.values())]
    trends = s.get("trends") or {}
    if fit or trends:
        fit_rows = [("Fig. 17: λ = slope a + intercept (all packings)",
                     f"slope {fmt(number(fit.get('slope')), 4)}, intercept {fmt(number(fit.get('intercept')), 4)}, "
                     f"R² {fmt(number(fit.get('r2')), 4)}, n = {fit.get('n', 'n/a')}")]
        fit_rows += [(k.replace("_", " "), _trend(v)) for k, v in trends.items()]
        fig_parts.append(Markup("<h3>Fits</h3>"))
        fig_parts.append(definition_table(fit_rows))
    return section("figures", "Figures 15-17 and fits", *fig_parts)


def _study_time_section(r: StudyReport) -> tuple[str, str, Markup]:
    """The "Wall time" section: the campaign's and each run's."""
    s = r.summary
    time_rows = [
        ("campaign (all runs, figures, table)", fmt(number(s.get("campaign_wall_time_s")), 4)),
        ("sum of the runs' own wall times", fmt(number(s.get("runs_wall_time_s_sum")), 4)),
    ]
    per_run = [
        (row.get("name") or f"{row.get('kind')}_{row.get('porosity_target')}", row.get("status", ""),
         _cell("wall_time_s", row.get("wall_time_s", "")))
        for row in r.rows
    ]
    return (
        section(
            "time",
            "Wall time",
            definition_table(time_rows),
            table(["run", "status", "wall time (s)"], per_run, numeric=(2,)),
        )
    )


def render_study(r: StudyReport) -> str:
    """The study report page."""
    s = r.summary
    header = _header(
        f"grainlab packing study: {r.folder.resolve().name}",
        [
            f"Study by grainlab {r.version}; report generated {r.generated} by grainlab {grainlab.__version__}.",
            Markup(f"Folder: <code>{escape(str(r.folder.resolve()))}</code>"),
        ],
    )
    fit = s.get("fig17_fit") or {}
    glance = _glance(
        [
            ("packings", fmt(len(r.rows))),
            ("statuses", ", ".join(f"{k} {v}" for k, v in r.statuses.items())),
            ("Fig. 17 fit R² (all packings)", fmt(number(fit.get("r2")), 3)),
            ("campaign wall time", fmt(number(s.get("campaign_wall_time_s")), 3, unit="s")),
        ]
    )
    sections = [section("glance", "At a glance", glance)]
    parts: list[Any] = [code_block(r.rerun_command)]
    parts += [paragraph(n, "note") for n in r.rerun_notes]
    parts.append(paragraph(f"Rebuild this report: grainlab report {shlex.quote(str(r.folder.resolve()))}", "note"))
    sections.append(section("rerun", "How to rerun", *parts))

    params = [(k, fmt(v, 6) if isinstance(v, float) else str(v), param_unit(k)) for k, v in r.params.items()]
    campaign = [
        ("campaign seed", str(s.get("seed", "n/a"))),
        ("workers", str(s.get("workers", "n/a"))),
        ("scheduler", str(s.get("scheduler") or "local processes")),
        ("irregular targets (Table 2)", ", ".join(fmt(t, 4) for t in r.irregular) or "none"),
        ("hexagonal targets (Table 3)", ", ".join(fmt(t, 4) for t in r.hexagonal) or "none"),
    ]
    sections.append(
        section(
            "config",
            "Configuration",
            definition_table(campaign),
            paragraph(f"Packing parameters common to every run, SI units; source: {r.params_source}.", "note"),
            table(["parameter", "value", "SI unit"], params, numeric=(1,)),
        )
    )
    sections.append(_study_table_section(r))
    sections.append(_study_figures_section(r))
    sections.append(
        section(
            "paper",
            "The paper beside this study",
            table(["claim", "paper", "this study", "where in the paper"], r.claims, cell_classes={2: "note"}),
        )
    )
    sections.append(_study_time_section(r))
    sections.append(section("notes", "Notes", _notes(r.notes)))
    return page(
        f"grainlab study report: {r.folder.resolve().name}",
        header,
        sections,
        footer(),
    )
