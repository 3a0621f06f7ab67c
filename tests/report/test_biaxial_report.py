"""The biaxial report: its numbers are the run's, it needs nothing outside itself, it reruns the run."""

from __future__ import annotations

import html
import json
import math
import re
import shlex
import shutil

import numpy as np
import pytest
from report_factories import BAND_DEG, DILATION_SLOPE, PEAK_RATIO, PEAK_STRAIN, PHASES, THREADS
from report_helpers import check_self_contained, parse

from grainlab._html import fmt
from grainlab.cli import build_parser, main
from grainlab.io.hdf5 import read_results
from grainlab.postprocess import FIGURES
from grainlab.protocols.biaxial.config import resolve
from grainlab.report import write_report
from grainlab.report.biaxial import CURVE_FIGURES, gather_biaxial

#: Figures of a biaxial report: the folder's ten and the report's grading and macro curves.
N_FIGURES = len(FIGURES) + len(CURVE_FIGURES) + 2


def _text(path) -> str:
    """The page's visible text, tags removed, entities decoded, blanks collapsed."""
    raw = path.read_text(encoding="utf-8")
    raw = re.sub(r"<style>.*?</style>", " ", raw, flags=re.S)
    raw = re.sub(r'src="data:[^"]*"', "", raw)
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", raw)))


def _deg(x: float) -> str:
    return f"{math.degrees(x):.1f} deg"


# ----------------------------------------------------------------------------- synthetic run (fast)
@pytest.fixture(scope="module")
def synthetic(synthetic_run):
    return gather_biaxial(synthetic_run)


def test_angles_are_the_formulas_on_the_runs_own_curves(synthetic, synthetic_run):
    r = synthetic
    phi = math.asin((PEAK_RATIO - 1) / (PEAK_RATIO + 1))  # 3/5
    psi = math.asin(-DILATION_SLOPE / (2 - DILATION_SLOPE))  # 1/5
    assert r.peak_ratio == pytest.approx(PEAK_RATIO) and r.peak_strain == pytest.approx(PEAK_STRAIN)
    assert r.phi == pytest.approx(phi)
    assert r.dilation.slope == pytest.approx(DILATION_SLOPE) and r.dilation.angle == pytest.approx(psi)
    assert r.dilation.n_records == 21  # records every 0.05 %, 1 % window
    a = r.angles.degrees()
    assert a["mohr_coulomb"] == pytest.approx(45 + math.degrees(phi) / 2)
    assert a["roscoe"] == pytest.approx(45 + math.degrees(psi) / 2)
    assert a["arthur"] == pytest.approx(45 + (math.degrees(phi) + math.degrees(psi)) / 4)
    text = _text(synthetic_run / "report.html")
    for value in (phi, psi, r.angles.mohr_coulomb, r.angles.roscoe, r.angles.arthur):
        assert _deg(value) in text
    assert "sin ψ = −s/(2 − s)" in text and "45° + (φ + ψ)/4" in text


def test_the_band_is_measured_at_the_end_and_compared(synthetic, synthetic_run):
    end = synthetic.band_end
    assert end is not None and end.snapshot == "strain_0.0300" and end.reference == "strain_0.0000"
    assert synthetic.band_peak is not None and synthetic.band_peak.snapshot == "strain_0.0100"
    text = _text(synthetic_run / "report.html")
    if end.found:
        assert end.inclination_deg == pytest.approx(BAND_DEG, abs=5.0)
        assert end.thickness_diameters > 1.0
        assert fmt(end.inclination_deg, 3) in text
        assert "closest to the" in text
    else:  # the detector may refuse it; the report then says why and compares nothing
        assert end.reason and end.reason in text
        assert "No band was accepted" in text


def test_sample_and_wall_time_are_the_runs(synthetic, synthetic_run):
    res = read_results(synthetic_run)
    first = res.snapshot(0)
    assert synthetic.n_grains == res.summary["n_particles"] == int(first.is_sample.sum())
    np.testing.assert_allclose(synthetic.diameters, 2 * first.radii[first.is_sample])
    assert [(n, t) for n, _, t in synthetic.wall_times] == list(PHASES.items())
    assert synthetic.wall_total == pytest.approx(res.summary["wall_time_s"])
    assert synthetic.threads == THREADS
    text = _text(synthetic_run / "report.html")
    assert f"{synthetic.n_grains} grains" in text
    for seconds in PHASES.values():
        assert fmt(seconds, 4) in text
    assert "Engine threads: 2" in text


def test_the_rerun_command_and_toml_resolve_to_the_same_configuration(synthetic, synthetic_run, tmp_path):
    config = read_results(synthetic_run).config
    command = synthetic.rerun.command
    argv = shlex.split(command)
    assert argv[:2] == ["grainlab", "biaxial"] and "--quick" in argv
    assert f"run.threads={THREADS}" in argv
    args = build_parser().parse_args(argv[1:])
    again = resolve(args.config, args.overrides, quick=args.quick).to_dict()
    assert again.pop("run") == {**config["run"], "threads": THREADS}
    assert again == {k: v for k, v in config.items() if k != "run"}
    (tmp_path / "config.toml").write_text(synthetic.rerun.toml)
    assert resolve(tmp_path / "config.toml").to_dict() == config
    text = _text(synthetic_run / "report.html")
    assert command in text
    differs = {row.key for row in synthetic.config_rows if row.differs}
    assert differs == {"sample.width", "sample.height", "sample.seed", "shear.final_strain",
                       "shear.snapshot_strains"}


def test_missing_figures_were_drawn_and_every_figure_is_embedded(synthetic_run):
    for name in FIGURES + CURVE_FIGURES:
        assert (synthetic_run / f"{name}.png").exists() and (synthetic_run / f"{name}.svg").exists()
    kinds = check_self_contained(synthetic_run / "report.html")
    assert kinds == ["png"] * N_FIGURES
    text = _text(synthetic_run / "report.html")
    assert "drawn by this report (missing from the folder or --redraw)" in text


def test_paper_table_and_sections(synthetic, synthetic_run):
    rows = {q: run for q, _, run, _ in synthetic.paper_rows}
    assert rows["peak stress ratio σ₁/σ₃"] == fmt(PEAK_RATIO, 3)
    assert rows["axial strain at the peak stress ratio"] == fmt(PEAK_STRAIN, percent=True)
    eps, a = synthetic.timeseries["axial_strain"], synthetic.timeseries["anisotropy"]
    assert rows["anisotropy a at 0.5 % axial strain"] == fmt(float(np.interp(0.005, eps, a)), 3)
    page = parse((synthetic_run / "report.html").read_text())
    ids = [attrs.get("id") for tag, attrs in page.tags if tag == "section"]
    assert ids == ["glance", "rerun", "config", "sample", "macro", "fabric", "band", "paper", "time", "notes"]


def test_cli_prints_the_path_and_writes_elsewhere_with_out(synthetic_run, tmp_path, capsys):
    target = tmp_path / "elsewhere.html"
    assert main(["report", str(synthetic_run), "--out", str(target)]) == 0
    assert str(target) in capsys.readouterr().out
    assert target.exists() and target.read_text().startswith("<!DOCTYPE html>")


# ----------------------------------------------------------------------------- the quick run (slow)
@pytest.mark.slow
def test_quick_run_writes_its_report_and_its_numbers_are_the_runs(quick_biaxial_run):
    report = quick_biaxial_run / "report.html"
    assert report.exists(), "grainlab biaxial writes report.html at the end"
    res = read_results(quick_biaxial_run)
    summary = json.loads((quick_biaxial_run / "summary.json").read_text())
    r = gather_biaxial(quick_biaxial_run)
    q = res.timeseries["stress_ratio"]
    assert r.peak_ratio == q.max() == pytest.approx(summary["peak_stress_ratio"])
    assert r.peak_strain == pytest.approx(summary["axial_strain_at_peak"])
    assert r.n_grains == summary["n_particles"] == int(res.snapshot(0).is_sample.sum())
    assert math.sin(r.phi) == pytest.approx((r.peak_ratio - 1) / (r.peak_ratio + 1))
    assert math.sin(r.phi) == pytest.approx(res.timeseries["stress_ratio_mobilised"][r.peak_row])
    assert dict((n, t) for n, _, t in r.wall_times) == pytest.approx(res.phases)
    assert r.threads == summary["threads"] >= 1
    text = _text(report)
    for shown in (fmt(r.peak_ratio, 3), fmt(r.peak_strain, percent=True), _deg(r.phi),
                  fmt(summary["coordination_number_initial"], 3), f"grainlab {res.grainlab_version}"):
        assert shown in text, shown
    assert check_self_contained(report) == ["png"] * N_FIGURES


@pytest.mark.slow
def test_quick_run_figures_deleted_are_drawn_again(quick_biaxial_run, tmp_path):
    folder = tmp_path / "copy"
    shutil.copytree(quick_biaxial_run, folder)
    for name in ("fig08_stress_ratio", "fig12_stability_index"):
        for suffix in (".png", ".svg"):
            (folder / f"{name}{suffix}").unlink()
    (folder / "fig09_anisotropy.png").write_bytes(b"")  # an empty (interrupted) figure counts as missing
    (folder / "report.html").unlink()
    assert write_report(folder) == folder / "report.html"
    assert (folder / "fig08_stress_ratio.png").exists() and (folder / "fig12_stability_index.png").exists()
    assert (folder / "fig09_anisotropy.png").read_bytes()[:4] == b"\x89PNG"
    assert check_self_contained(folder / "report.html") == ["png"] * N_FIGURES


def test_grainlab_biaxial_writes_the_report_unless_told_not_to(synthetic_run, tmp_path, monkeypatch, capsys):
    import grainlab.commands.biaxial as biaxial_command
    import grainlab.commands.report as report_command
    from grainlab.protocols.biaxial import BiaxialResult

    folder = tmp_path / "run"
    shutil.copytree(synthetic_run, folder)
    (folder / "report.html").unlink()
    # the simulation is not what is tested here: the "run" is the finished synthetic folder
    monkeypatch.setattr(
        biaxial_command, "run_biaxial", lambda config, out, **kw: BiaxialResult(out, read_results(out).summary)
    )
    argv = ["biaxial", "--quick", "--out", str(folder), "--no-progress"]
    assert main([*argv, "--no-report"]) == 0
    assert not (folder / "report.html").exists()
    assert main(argv) == 0
    assert (folder / "report.html").exists()
    assert f"grainlab biaxial: report {folder / 'report.html'}" in capsys.readouterr().out

    def broken(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(report_command, "write_report", broken)
    assert main(argv) == 1  # the run's results stay; the message says how to retry
    err = capsys.readouterr().err
    assert "report could not be written (RuntimeError: disk full)" in err
    assert f"retry with: grainlab report {folder}" in err


def test_a_sieve_curve_configuration_reruns_and_draws_its_grading(tmp_path):
    from grainlab.report.biaxial import config_rows, requested_grading, rerun_command

    overrides = ["sample.grading=curve", "sample.sieve_sizes=[0.0005, 0.001, 0.003]",
                 "sample.percent_passing=[0, 30, 100]", "shear.strain_rate=2%/min"]
    config = resolve(overrides=overrides, quick=True).to_dict()
    rerun = rerun_command(config, str(tmp_path / "again"))
    args = build_parser().parse_args(shlex.split(rerun.command)[1:])
    assert resolve(args.config, args.overrides, quick=args.quick).to_dict() == config
    (tmp_path / "config.toml").write_text(rerun.toml)
    assert resolve(tmp_path / "config.toml").to_dict() == config
    grading, name = requested_grading(config)
    assert grading is not None and grading.passing(0.001) == pytest.approx(30.0) and "curve" in name
    rows = {row.key: row for row in config_rows(config, {}, None)}
    assert rows["sample.sieve_sizes"].unit == "m" and rows["sample.sieve_sizes"].differs
    assert rows["shear.strain_rate"].shown == f"{0.02 / 60:g} (2 %/min)"
    assert any("did not record the count" in note for note in rerun.notes)
