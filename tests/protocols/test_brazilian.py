"""The Brazilian test of a cemented disc: the carve (the grains in the circle that
the cement holds, remade in a new simulation that runs as the old one would), the
records against their formulas (2F / (pi D t), delta / D, the platen at its speed),
the peak and the stop, the cracks, the resume to the same bits before the carve and
in the loading, the command line and report as docs/cemented.md quotes them, and the
refusals of bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

import grainlab.protocols.runner as runner
from grainlab import ContactModel, Simulation
from grainlab.cement import pairs_within_gap
from grainlab.cli import main
from grainlab.columns import BRAZILIAN
from grainlab.io.hdf5 import read_results
from grainlab.protocols.brazilian import BrazilianProtocol, indirect_tensile_stress
from grainlab.protocols.brazilian.disc import carved_simulation, held_by_cement, in_disc
from grainlab.protocols.config import ConfigError
from grainlab.protocols.registry import PROTOCOLS, resolve_config
from grainlab.protocols.specimen import SpecimenError, add_cement
from grainlab.report import detect_kind

CEMENT = ["cement.bonds=parallel", "cement.tensile_strength=500 kPa", "cement.cohesion=500 kPa"]
# four times the default rate, a record every 0.04 % of D: about 5 s on the quick sample
FAST = [*CEMENT, "brazilian.strain_rate=4 %/min", "brazilian.records=50", "run.threads=1"]
DOCS = Path(__file__).resolve().parents[2] / "docs" / "cemented.md"


# ---- the carve ---------------------------------------------------------------------------
def test_the_disc_is_the_grains_in_its_circle_held_by_two_bonds_or_more_in_the_largest_group():
    inside = np.array([True] * 11 + [False])
    pairs = [(0, 1), (1, 2), (2, 0),  # a triangle: three grains
             (3, 4), (4, 5), (5, 6), (6, 3),  # a ring of four: the largest group
             (7, 3),  # a grain hanging by one bond
             (9, 10), (10, 4),  # a chain: 9 hangs on 10, which then hangs on 4
             (11, 0), (11, 1)]  # outside the circle: its bonds do not hold 0 and 1
    i, j = (np.array(ends, dtype=np.int64) for ends in zip(*pairs, strict=True))
    kept = held_by_cement(inside, i, j, np.arange(12))
    assert np.flatnonzero(kept).tolist() == [3, 4, 5, 6]
    # a clump (pebbles 0 and 1) counts its bonds together: held by 2 and 3 through a pebble each
    i, j, inside = np.array([0, 1, 2]), np.array([2, 3, 3]), np.ones(4, dtype=bool)
    assert np.flatnonzero(held_by_cement(inside, i, j, np.array([0, 0, 1, 2]))).tolist() == [0, 1, 2, 3]
    assert np.flatnonzero(held_by_cement(inside, i, j, np.arange(4))).tolist() == []  # as four disks: a chain
    assert in_disc(np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 4.1]]), (0.0, 0.0), 10.0).tolist() == [True, True, False]


def _bonded_sample(config):
    """Twelve disks on a jittered grid and a clump of two, touching pairs cemented, moving."""
    g = np.random.default_rng(7)
    a, b = np.meshgrid(np.arange(4), np.arange(3), indexing="ij")
    positions = np.column_stack([a.ravel(), b.ravel()]) * 1.95e-3 + g.uniform(-2e-5, 2e-5, (12, 2))
    sim = Simulation(positions, g.uniform(0.97e-3, 1.0e-3, 12), density=2650.0,
                     contact_model=ContactModel(1e7, 1e7, 0.5), threads=1)
    sim.add_clumps([[-0.5e-3, 0.0], [0.5e-3, 0.0]], [0.6e-3, 0.6e-3], positions=[[2.9e-3, 5.4e-3]], angles=[0.2],
                   density=2650.0)
    sim.time_step = 0.5 * sim.critical_time_step()
    sim.velocities = g.normal(0.0, 1e-3, (sim.n_particles, 2))
    sim.angular_velocities = g.normal(0.0, 1.0, sim.n_particles)
    i, j = pairs_within_gap(sim.positions, sim.radii, 1e-5, body=sim.body_of_particles)
    add_cement(sim, config, i, j, g.uniform(1e5, 2e5, len(i)), g.uniform(1e5, 2e5, len(i)))
    return sim


def test_a_disc_carved_whole_runs_as_the_sample_would_and_a_part_keeps_its_grains_and_bonds():
    config = resolve_config("brazilian", overrides=CEMENT, quick=True)
    sim = _bonded_sample(config)
    whole = carved_simulation(sim, np.ones(sim.n_particles, dtype=bool), config)
    sim.run(300)
    whole.run(300)
    for name in ("positions", "velocities", "rotations", "angular_velocities"):
        np.testing.assert_array_equal(getattr(whole, name), getattr(sim, name), err_msg=name)
    assert whole.n_cement_bonds == sim.n_cement_bonds and len(whole.clumps) == 1

    fresh = _bonded_sample(config)
    keep = np.ones(fresh.n_particles, dtype=bool)
    keep[[0, 5]] = False
    part = carved_simulation(fresh, keep, config)
    np.testing.assert_array_equal(part.positions, fresh.positions[keep])
    bonds, kept = fresh.cement_bonds(), part.cement_bonds()
    both = keep[bonds.i] & keep[bonds.j]
    assert len(kept) == np.count_nonzero(both) < len(bonds)
    np.testing.assert_array_equal(kept.tensile_strength, bonds.tensile_strength[both])
    np.testing.assert_array_equal(np.flatnonzero(keep)[kept.i], bonds.i[both])
    # a bond under load cannot be remade as it is: the carve refuses it
    with pytest.raises(SpecimenError, match="carries a force"):
        carved_simulation(sim, keep, config)


def test_the_indirect_tensile_stress_is_two_f_over_pi_d_t():
    assert indirect_tensile_stress(6000.0, 0.04) == pytest.approx(2 * 6000.0 / (math.pi * 0.04 * 1.0), rel=1e-15)


# ---- a run -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def straight(tmp_path_factory):
    out = tmp_path_factory.mktemp("brazilian") / "run"
    runner.run_protocol(BrazilianProtocol(resolve_config("brazilian", overrides=FAST, quick=True)), out)
    return out


@pytest.mark.slow
def test_the_records_follow_their_formulas(straight):
    results = read_results(straight / "run.h5")
    s, ts = results.summary, results.timeseries
    assert list(ts) == [str(c) for c in BRAZILIAN] and dict(results.timeseries_units) == BRAZILIAN.units()
    assert results.snapshot_names == ["start", "end"]
    d = s["diameter_m"]
    np.testing.assert_allclose(ts["tensile_stress_pa"], 2 * ts["platen_force_n_per_m"] / (np.pi * d), rtol=1e-12)
    np.testing.assert_allclose(ts["axial_strain"], ts["platen_displacement_m"] / d, rtol=1e-12)
    # the top platen at brazilian.strain_rate x D from the start, a record every 2 % / 50 of D
    np.testing.assert_allclose(ts["platen_displacement_m"], 4e-2 / 60 * d * (ts["time_s"] - ts["time_s"][0]),
                               rtol=1e-3, atol=1e-12)
    np.testing.assert_allclose(np.diff(ts["axial_strain"]), 0.02 / 50, rtol=1e-3)


@pytest.mark.slow
def test_the_disc_is_cut_from_the_sample_and_touches_both_platens(straight):
    results = read_results(straight / "run.h5")
    s, start = results.summary, results.snapshot("start")
    offset = start.positions - np.asarray(s["disc_centre_m"])
    # the grains moved by the settling only: all within the circle (and a grain's radius) of its centre
    assert np.hypot(offset[:, 0], offset[:, 1]).max() <= 0.5 * s["carve_diameter_m"] + 1e-4
    assert s["n_particles"] + s["loose_particles"] < s["sample_particles"]
    assert 0 < s["cement_bonds"] < s["sample_cement_bonds"]
    # D, the distance between the platens, is the disc's height: both platens bear on it
    top = start.positions[:, 1] + start.radii
    bottom = start.positions[:, 1] - start.radii
    assert top.max() - bottom.min() == pytest.approx(s["diameter_m"], rel=1e-3)
    assert s["platen_force_start_n_per_m"] > 0


@pytest.mark.slow
def test_the_peak_is_the_largest_force_and_the_run_stops_after_the_split(straight):
    results = read_results(straight / "run.h5")
    s, ts, cracks = results.summary, results.timeseries, results.cracks
    force, broken = ts["platen_force_n_per_m"], ts["cement_bonds_broken"]
    peak = int(np.argmax(force))
    assert s["peak_force_n_per_m"] == force.max() and 0 < peak < len(force) - 1
    assert s["tensile_strength_pa"] == pytest.approx(2 * force.max() / (np.pi * s["diameter_m"]), rel=1e-12)
    assert s["displacement_at_peak_m"] == ts["platen_displacement_m"][peak]
    assert s["ended_by"] == "residual" and force[-1] < 0.2 * force.max() <= force[-2]
    assert len(cracks["step"]) == broken[-1] == s["cracks_final"] > s["cracks_at_peak"] == broken[peak]
    assert (straight / "fig01_force_displacement.png").exists() and (straight / "fig20_cracks.png").exists()


@pytest.mark.slow
@pytest.mark.parametrize("at", ["before the carve", "in the loading"])
def test_a_stopped_run_resumes_to_the_same_bits(straight, tmp_path, monkeypatch, at):
    config = resolve_config("brazilian", overrides=[*FAST, "run.checkpoint_interval=1e-6"], quick=True)
    # checkpoints: the start, after the consolidation, after the carve, then at each record but the first (the
    # 30th: past the first bonds broken under a platen, before the split)
    stop_and_resume(BrazilianProtocol(config), tmp_path / "run", 2 if at == "before the carve" else 30, monkeypatch)
    assert_same_run(straight, tmp_path / "run")
    a, b = read_results(straight / "run.h5"), read_results(tmp_path / "run" / "run.h5")
    for name in a.cracks:
        np.testing.assert_array_equal(a.cracks[name], b.cracks[name], err_msg=name)


@pytest.mark.slow
def test_the_command_line_runs_it_with_its_report_as_cemented_md_prints(tmp_path, capsys):
    out = tmp_path / "brazilian"
    assert main(["run", "brazilian", "--quick", "--out", str(out), "--no-progress",
                 *(arg for key in CEMENT for arg in ("--set", key))]) == 0
    printed = capsys.readouterr().out.splitlines()[0]
    quoted = " ".join(DOCS.read_text().split())
    assert "; ".join(printed.split("; ")[:-1]) in quoted, printed  # all but the wall time and folder
    summary = json.loads((out / "summary.json").read_text())
    assert f"sigma_t {summary['tensile_strength_pa'] / 1e3:.0f} kPa" in printed
    assert detect_kind(out) == (out, "brazilian")
    page = (out / "report.html").read_text()
    assert "indirect tensile strength sigma_t" in page and "data:image/png;base64," in page
    assert "figure-fig20_cracks" in page and "figure-fig01_force_displacement" in page
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert [name.split(" ")[0] for name in header] == [str(c) for c in BRAZILIAN]


# ---- bad input ---------------------------------------------------------------------------
@pytest.mark.parametrize(("override", "message"), [
    ([], "brazilian: an uncemented sample has no tensile strength; give cement.bonds=parallel and its strengths"),
    ([*CEMENT, "brazilian.diameter_fraction=0"], "brazilian.diameter_fraction: 0 is out of range"),
    ([*CEMENT, "brazilian.diameter_fraction=1.2"], "brazilian.diameter_fraction: 1.2 is out of range"),
    ([*CEMENT, "brazilian.diameter_fraction=0.5"], "brazilian.diameter_fraction: a disc 0.02 m across holds fewer"),
    ([*CEMENT, "brazilian.strain_rate=0"], "brazilian.strain_rate: 0 is out of range"),
    ([*CEMENT, "brazilian.strain_rate=-1 %/min"], "brazilian.strain_rate"),
    ([*CEMENT, "brazilian.residual_fraction=1"], "brazilian.residual_fraction: 1 is out of range"),
    ([*CEMENT, "brazilian.platen_friction=-0.1"], "brazilian.platen_friction"),
    ([*CEMENT, "brazilian.records=0"], "brazilian.records"),
])
def test_bad_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    assert main(["run", "brazilian", "--quick", "--out", str(out),
                 *(arg for key in override for arg in ("--set", key))]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_registry_knows_it_and_refuses_an_uncemented_sample_before_any_work():
    assert "brazilian" in PROTOCOLS
    with pytest.raises(ConfigError, match="^brazilian: an uncemented sample"):
        resolve_config("brazilian", quick=True)
