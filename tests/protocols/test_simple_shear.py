"""Periodic simple shear (docs/protocols.md, "Periodic simple shear"): the
stress-controlled cell holds sigma_n, the constant-volume cell its area, the
leaning cell is remapped past half its width, the imposed shear's work is the
energy the grains dissipate and store (a check of the cell's stress and of
tau's sign), the Rothenburg-Bathurst relation holds on every record, and a
stopped run resumes to the same bits."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

import grainlab.protocols.runner as runner
from grainlab.cli import main
from grainlab.columns import SIMPLE_SHEAR
from grainlab.io.hdf5 import read_results
from grainlab.protocols.registry import resolve_config
from grainlab.protocols.simple_shear import SimpleShearProtocol, SimpleShearResult, snapshot_name_of
from grainlab.report import detect_kind

# the quick cell (about 280 grains) to 60 % strain at I = 0.01: past one remap, a few seconds
SMALL = ["simple_shear.final_strain=0.6", "simple_shear.record_interval=0.02", "simple_shear.inertial_number=0.01",
         "simple_shear.snapshot_strains=[0, 0.3, 0.6]", "run.threads=1"]


#: At constant volume a looser sample (as docs/protocols.md's run): the dense default, held at its
#: area, climbs to megapascals, where Table 1's soft contacts reach the engine's overlap limit.
LOOSE_CONSTANT = ("simple_shear.volume=constant", "sample.porosity=0.24", "sample.generation_friction=0.9",
                  "consolidation.friction=0.9")


def _config(*extra: str):  # type: ignore[no-untyped-def]
    return resolve_config("simple_shear", overrides=[*SMALL, *extra], quick=True)


@pytest.fixture(scope="module")
def free(tmp_path_factory):
    out = tmp_path_factory.mktemp("simple_shear") / "free"
    runner.run_protocol(SimpleShearProtocol(_config()), out)
    return out


@pytest.fixture(scope="module")
def constant(tmp_path_factory):
    out = tmp_path_factory.mktemp("simple_shear") / "constant"
    runner.run_protocol(SimpleShearProtocol(_config(*LOOSE_CONSTANT)), out)
    return out


def _series(out: Path) -> dict[str, np.ndarray]:
    return {k: np.asarray(v, dtype=np.float64) for k, v in read_results(out / "run.h5").timeseries.items()}


def test_the_records_have_the_columns_and_the_strain_is_the_rate_times_the_time(free):
    ts = _series(free)
    assert list(ts) == [str(c) for c in SIMPLE_SHEAR]
    summary = json.loads((free / "summary.json").read_text())
    elapsed = ts["time_s"] - ts["time_s"][0]
    np.testing.assert_allclose(ts["shear_strain"], summary["shear_rate_per_s"] * elapsed, rtol=1e-9, atol=1e-12)
    assert ts["shear_strain"][-1] == pytest.approx(0.6, rel=1e-3)
    names = read_results(free / "run.h5").snapshot_names
    assert names == [snapshot_name_of(g) for g in (0.0, 0.3, 0.6)]


def test_the_cell_leans_no_further_than_half_its_width_and_is_remapped(free):
    tilt = _series(free)["cell_tilt"]
    assert np.all(np.abs(tilt) <= 0.5)
    assert np.count_nonzero(np.diff(tilt) < -0.5) == 1  # 60 % of strain: one remap


def test_the_free_cell_holds_the_normal_stress(free):
    ts = _series(free)
    sigma_n = ts["normal_stress_pa"][1:]
    assert np.median(np.abs(sigma_n / 1e5 - 1.0)) < 0.05
    assert np.mean(sigma_n) == pytest.approx(1e5, rel=0.03)
    assert ts["inertial_number"][1:].mean() == pytest.approx(0.01, rel=0.05)


def test_the_constant_volume_cell_holds_its_area(constant):
    ts = _series(constant)
    np.testing.assert_allclose(ts["area_m2"], ts["area_m2"][0], rtol=1e-12)
    assert np.all(ts["volumetric_strain"] == pytest.approx(0.0, abs=1e-12))
    # held at its area, the sample's wish to contract or dilate moves its normal stress instead
    assert np.abs(ts["normal_stress_pa"][1:] / ts["normal_stress_pa"][0] - 1.0).max() > 0.2


def test_the_shear_work_is_what_the_grains_dissipate_and_store(constant):
    """At constant volume the cell does work only through the shear, A tau dgamma; the
    ledger (which leaves that work out) must account for it as friction and damping
    losses and stored elastic and kinetic energy. A wrong sign or scale of tau, or a
    stress that misses the branch vectors across the remapped side, breaks this."""
    ts = _series(constant)
    work = np.sum(0.5 * (ts["area_m2"][1:] * ts["shear_stress_pa"][1:] + ts["area_m2"][:-1] * ts["shear_stress_pa"][:-1])
                  * np.diff(ts["shear_strain"]))
    ledger = sum(ts[name][-1] - ts[name][0] for name in ("friction_dissipated_j", "damping_dissipated_j",
                                                          "elastic_energy_j", "kinetic_energy_j"))
    assert work > 0
    assert ledger == pytest.approx(work, rel=0.05)


def test_the_stress_force_fabric_relation_holds_on_every_record(free, constant):
    for out in (free, constant):
        ts = _series(out)
        assert np.all(np.isfinite(ts["rb_residual"]))
        # the relation is of second order in the anisotropies and leaves out the branch
        # lengths' (a_l): it explains q/p to within a few hundredths, not exactly; a wrong
        # stress, sign or anisotropy misses by a share of q/p itself
        assert np.mean(np.abs(ts["rb_residual"][1:])) < 0.25 * np.mean(ts["rb_stress_ratio"][1:])
        np.testing.assert_allclose(ts["rb_stress_ratio"] - ts["rb_predicted_stress_ratio"], ts["rb_residual"],
                                   atol=1e-12)


@pytest.mark.parametrize("checkpoints", [2, 12])
def test_a_stopped_run_resumes_to_the_same_bits(free, tmp_path, monkeypatch, checkpoints):
    """Stopped after consolidation, and mid-shear (past the remap)."""
    config = _config("run.checkpoint_interval=1e-6")
    stop_and_resume(SimpleShearProtocol(config), tmp_path / "run", checkpoints, monkeypatch)
    assert_same_run(free, tmp_path / "run")


def test_the_command_line_writes_the_report(tmp_path, capsys):
    out = tmp_path / "ss"
    assert main(["run", "simple_shear", "--quick", "--out", str(out), "--no-progress", *sum(
        (["--set", s] for s in SMALL), [])]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("grainlab simple_shear (free volume): ")
    assert detect_kind(out) == (out, "simple_shear")
    page = (out / "report.html").read_text()
    assert "Stress-force-fabric relation" in page and "data:image/png;base64," in page
    assert "grainlab run simple_shear --out" in page


@pytest.mark.parametrize(("override", "message"), [
    ("simple_shear.record_interval=2", "simple_shear.record_interval: 2 exceeds simple_shear.final_strain"),
    ("simple_shear.volume=constant", "a constant-volume run holds the cell's area"),
    ("simple_shear.snapshot_strains=[0.5, 2]", "simple_shear.snapshot_strains: 2 lies outside"),
    ("simple_shear.inertial_number=0", "simple_shear.inertial_number: 0 is out of range"),
])
def test_bad_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    extra = ["--set", "simple_shear.normal_stress=100 kPa"] if "volume" in override else []
    assert main(["run", "simple_shear", "--quick", "--out", str(out), *extra, "--set", override]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_a_saved_constant_volume_configuration_reads_back():
    """A checkpoint stores every key (simple_shear.normal_stress too): reading it back must not refuse it."""
    protocol = SimpleShearProtocol(_config("simple_shear.volume=constant"))
    assert protocol.resolve_saved(protocol.config_dict()) == protocol.config_dict()


def test_the_inertial_number_sets_the_rate(free):
    s = json.loads((free / "summary.json").read_text())
    density = resolve_config("simple_shear")["material.density"]
    assert s["shear_rate_per_s"] == pytest.approx(0.01 * math.sqrt(1e5 / density) / s["mean_diameter_m"], rel=1e-12)


@pytest.mark.slow
def test_the_example_prints_both_cells(tmp_path):
    example = Path(__file__).resolve().parents[2] / "examples" / "11_simple_shear.py"
    printed = subprocess.run([sys.executable, str(example), str(tmp_path / "run")], check=True,
                             capture_output=True, text=True).stdout
    lines = printed.splitlines()
    assert [line.split(":")[0] for line in lines] == ["free volume", "constant volume"]
    assert "dilation" in lines[0] and re.search(r"sigma_n \d+\.\d -> \d+\.\d kPa", lines[1])


def test_contact_dashpots_shorten_the_time_step_and_act_while_shearing(tmp_path):
    """With dashpots at half of critical, the sliding-and-rolling mode is damped at sqrt(3) / 2 of its
    critical value and its central-difference limit is sqrt(1 + 0.75) - sqrt(0.75) = 0.457 of the
    undamped one: the run's time step is shortened by that factor, and it settles and shears."""
    config = _config("material.contact_damping=0.5", "simple_shear.local_damping=0",
                     "simple_shear.inertial_number=0.1", "simple_shear.final_strain=0.2",
                     "simple_shear.snapshot_strains=[0]")
    result = runner.run_protocol(SimpleShearProtocol(config), tmp_path / "run")
    undamped = runner.run_protocol(SimpleShearProtocol(_config("simple_shear.final_strain=0.04",
                                                               "simple_shear.snapshot_strains=[0]")),
                                   tmp_path / "undamped")
    ratio = result.summary["time_step_s"] / undamped.summary["time_step_s"]
    assert ratio == pytest.approx(math.sqrt(1.75) - math.sqrt(0.75), rel=1e-9)
    assert result.summary["friction_coefficient_steady"] > 0.2


def test_the_viewer_draws_mu_against_the_shear_strain_and_no_band(free):
    from grainlab.viewer.data import viewer_data

    data = viewer_data(free)
    assert (data["curve"]["x"], data["curve"]["y"]) == ("shear_strain", "friction_coefficient")
    assert data["strain_label"] == "shear strain"
    last = data["snapshots"][-1]
    assert last["axial_strain"] == pytest.approx(0.6, rel=1e-3)
    assert last["band"] == {"first": None, "second": None}


DOCS = Path(__file__).resolve().parents[2] / "docs" / "protocols.md"
DEFAULT = Path(__file__).resolve().parents[2] / "tests" / "data" / "simple_shear" / "default_summary.json"


def _assert_quoted_line(text: str, summary: dict, start: str) -> None:
    """The docs' line starting with ``start`` is what the run printed for ``summary``, but
    for its wall time and folder (``SimpleShearResult.one_line``)."""
    line = next(x for x in text.splitlines() if x.startswith(start))
    printed = SimpleShearResult(Path("run"), summary).one_line()
    assert line.split("; ")[:-1] == printed.split("; ")[:-1]


def test_the_docs_quote_the_default_runs_summary():
    """docs/protocols.md's default simple-shear run is tests/data/simple_shear's summary."""
    s = json.loads(DEFAULT.read_text())
    text = DOCS.read_text()
    _assert_quoted_line(text, s, "grainlab simple_shear (free volume): 1759")
    assert f"{s['shear_steps']:,} steps" in text
    assert f"mu = {s['friction_coefficient_steady']:.3f} (sd\n{s['friction_coefficient_steady_sd']:.3f})" in text
    assert f"within {s['rb_residual_mean_abs']:.3f} on average, and {s['rb_residual_max_abs']:.3f}" in text


def test_the_docs_quote_the_constant_volume_run():
    s = json.loads((DEFAULT.parent / "constant_volume_summary.json").read_text())
    text = DOCS.read_text()
    _assert_quoted_line(text, s, "grainlab simple_shear (constant volume): 1519")
    assert f"ends at {s['normal_stress_final_pa'] / 1e3:.1f} kPa (" in text
    assert f"{s['normal_stress_pa_steady'] / 1e3:.0f}\nkPa on average" in text
    assert f"residual is at most {s['rb_residual_max_abs']:.3f}" in text


def test_the_run_keeps_its_sample_for_the_lammps_export(free, tmp_path, capsys):
    """The folder holds the state at the start of shearing; grainlab export takes it with the
    run's own shear rate and strain (the deck runs in LAMMPS in tests/io/test_lammps_export.py)."""
    from grainlab.io.lammps_input import simulation_to_export

    s = json.loads((free / "summary.json").read_text())
    sim = simulation_to_export(free)
    assert sim.n_particles == s["n_particles"] and sim.cell is not None
    assert sim.time_step == pytest.approx(s["time_step_s"], rel=1e-12)
    out = tmp_path / "lammps"
    assert main(["export", str(free), "--lammps", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    steps = round(s["final_strain"] / (s["shear_rate_per_s"] * s["time_step_s"]))
    assert f"{s['n_particles']} disks, {steps} steps" in printed
    export = json.loads((out / "export.json").read_text())
    assert json.dumps(export).count(repr(s["shear_rate_per_s"])) >= 1


def test_the_docs_quote_the_mu_of_i_sweep():
    """docs/protocols.md's mu(I) table and lines are tests/data/simple_shear/mu_of_i.json's, and
    the sweep shows the rheology's form: mu rising and nu falling with I."""
    d = json.loads((DEFAULT.parent / "mu_of_i.json").read_text())
    text = DOCS.read_text()
    for m in d["means"]:
        row = (f"| {m['inertial_number_set']:g} | {m['inertial_number']:.4f} | {m['friction_coefficient']:.3f} | "
               f"{m['solid_fraction']:.3f} | {m['coordination_number']:.2f} | {m['anisotropy']:.3f} | "
               f"{m['mean_stability_index']:.4f} |")
        assert row in text, row
    f = d["fit"]
    assert f"mu = {f['mu_min']:.3f} +\n{f['b']:.2f} I and nu = {f['nu_max']:.3f} - {f['a']:.2f} I" in text
    assert len(d["runs"]) == 12 and f["b"] > 0 and f["a"] > 0
    mu = [m["friction_coefficient"] for m in d["means"]]
    assert mu[-1] > mu[0] + 0.2


def test_the_controls_side_stress_is_the_cells_stress(free):
    """What the control reads every 100 steps (one side, cheaply) is the cell's stress and its
    affine stiffness, to rounding."""
    from grainlab.io.lammps_input import simulation_to_export
    from grainlab.protocols.simple_shear.cell import cell_stress, side_stresses

    sim = simulation_to_export(free)
    sim.set_velocity_gradient([[0.0, 0.05], [0.0, 0.0]])
    sim.run(300)
    full = cell_stress(sim)
    for k, (stress, stiffness) in zip((0, 1), side_stresses(sim, (0, 1)), strict=True):
        assert stress == pytest.approx(float(full.total[k, k]), rel=1e-12)
        assert stiffness == pytest.approx(full.stiffness_pa[k], rel=1e-12)
    assert full.total[1, 1] > 0 and full.stiffness_pa[1] > 0


def test_a_clump_chains_cell_stress_takes_branches_between_centroids():
    """Oracle: three dimers end to end along x fill a periodic cell of length L, each
    contact at overlap delta, so each carries kn delta along a branch of L / 3 from
    centroid to centroid: sigma_xx = L kn delta / A exactly (the pebbles' own branch,
    2 r - delta, would give less); nothing along y, and no kinetic part at rest."""
    from grainlab import ContactModel, Simulation
    from grainlab.protocols.simple_shear.cell import cell_stress, side_stresses

    r, arm, delta, kn = 1e-3, 0.5e-3, 2e-6, 1e7
    pitch = 2 * arm + 2 * r - delta  # centroid to centroid
    length, height = 3 * pitch, 10 * r
    centres = [(k * pitch + side * arm, 5 * r) for k in range(3) for side in (-1, 1)]
    sim = Simulation(np.array(centres) + [pitch / 2, 0.0], [r] * 6, 2650.0,
                     contact_model=ContactModel(kn, kn, 0.5))
    sim.add_bodies([[0, 1], [2, 3], [4, 5]])
    sim.set_periodic_cell((0.0, 0.0), (length, height))
    stress = cell_stress(sim)
    area = length * height
    assert stress.contact[0, 0] == pytest.approx(length * kn * delta / area, rel=1e-9)
    assert abs(stress.contact[1, 1]) < 1e-12 * stress.contact[0, 0]
    assert not stress.kinetic.any()
    (sigma_xx, stiffness_xx), = side_stresses(sim, (0,))
    assert sigma_xx == pytest.approx(stress.total[0, 0], rel=1e-12)
    # the affine stiffness estimate with the same branches: sum kn (L/3)^2 / A
    assert stiffness_xx == pytest.approx(3 * kn * pitch**2 / area, rel=1e-9)
