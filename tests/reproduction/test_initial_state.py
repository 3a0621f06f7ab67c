"""grainlab.reproduction.initial_state: the noise floor against sampling, the measures of
constructed snapshots with known values, a run folder, and the resumable exploration."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from grainlab.analysis import ContactAnisotropy, StabilityIndex, anisotropy_fourier
from grainlab.io.hdf5 import ResultsWriter, snapshot_name
from grainlab.reproduction.initial_state import (
    explore,
    gap_for_coordination_number,
    initial_state,
    isotropic_noise_floor,
    mean_interval,
    snapshot_initial_state,
)
from grainlab.snapshot import ParticleKind, Snapshot


# --------------------------------------------------------------------------- noise floor
def test_noise_floor_against_sampled_isotropic_normals() -> None:
    """E[a], the median and P(a <= x) of the library's exact estimate, from 2,000 samples of
    500 uniform angles. The tolerances are 4 standard errors: for the mean
    sqrt((4 - pi) / (n M)) (the Rayleigh variance (4 - pi) / n), 3.7e-3 against E[a] =
    0.079, so that counting each contact's two ends as independent (a factor sqrt(2))
    or dropping the 2 in a = 2 |m| fails; for a probability p, 4 sqrt(p (1 - p) / M)."""
    n, m = 500, 2000
    rng = np.random.default_rng(12)
    a = np.array([anisotropy_fourier(rng.uniform(0.0, 2 * np.pi, n))[0] for _ in range(m)])
    floor = isotropic_noise_floor(n)
    assert floor.mean == pytest.approx(math.sqrt(math.pi / n), rel=1e-12)
    assert abs(a.mean() - floor.mean) < 4 * math.sqrt((4 - math.pi) / (n * m))
    for x in (floor.median, 0.05, 0.12):
        p = floor.probability_at_most(x)
        assert abs(np.mean(a <= x) - p) < 4 * math.sqrt(p * (1 - p) / m)
    assert floor.probability_at_most(floor.median) == pytest.approx(0.5, rel=1e-12)


def _star(angles: np.ndarray) -> Snapshot:
    """A disk at the origin touching one disk per angle: contact normals at ``angles``."""
    k = angles.size
    pos = np.vstack([[0.0, 0.0], 2.0 * np.c_[np.cos(angles), np.sin(angles)]])
    return Snapshot(pos, np.ones(k + 1), contact_i=np.zeros(k, int), contact_j=np.arange(1, k + 1))


def test_noise_floor_of_contact_anisotropy_and_eq7() -> None:
    """The same through ContactAnisotropy on snapshots, its exact a and Eq. 7 on 18 bins
    (scale sin(20 deg) / 20 deg); 4 standard errors of 400 samples of 300 contacts."""
    n, m = 300, 400
    rng = np.random.default_rng(5)
    exact, binned = [], []
    for _ in range(m):
        fabric = ContactAnisotropy().compute(_star(rng.uniform(0.0, 2 * np.pi, n)))
        exact.append(fabric.anisotropy)
        binned.append(fabric.anisotropy_binned)
    se = 4 * math.sqrt((4 - math.pi) / (n * m))
    floor, floor7 = isotropic_noise_floor(n), isotropic_noise_floor(n, bins=18)
    assert floor7.scale == pytest.approx(math.sin(math.pi / 9) / (math.pi / 9))
    assert abs(np.mean(exact) - floor.mean) < se
    assert abs(np.mean(binned) - floor7.mean) < floor7.scale * se


def test_noise_floor_formulas_and_validation() -> None:
    floor = isotropic_noise_floor(6250)
    assert floor.median == pytest.approx(2 * math.sqrt(math.log(2) / 6250))
    assert floor.quantile(0.5) == pytest.approx(floor.median)
    assert floor.probability_at_most(floor.quantile(0.9)) == pytest.approx(0.9)
    assert floor.probability_at_most(0.0034) == pytest.approx(1 - math.exp(-6250 * 0.0034**2 / 4))
    assert floor.probability_at_most(-1.0) == 0.0
    for bad in (0, math.nan, -3):
        with pytest.raises(ValueError, match="n_contacts"):
            isotropic_noise_floor(bad)
    with pytest.raises(ValueError, match="bins"):
        isotropic_noise_floor(100, bins=2)
    with pytest.raises(ValueError, match="q"):
        floor.quantile(1.0)


# --------------------------------------------------------------------------- snapshots
def _lattice_with_tail() -> Snapshot:
    """A 10 x 10 square lattice of touching disks (radius 0.5, spacing 1), a tail of two
    disks to the left of its first disk (A touching it, B touching A), and an isolated disk.

    Contacts: 180 in the lattice (90 horizontal, 90 vertical) and 2 horizontal in the
    tail; horizontal contacts carry 2 N, vertical ones 1 N. B has one contact, A two, the
    isolated disk none: iterative removal takes all three (B, then A).
    """
    x, y = np.meshgrid(np.arange(10.0), np.arange(10.0))
    lattice = np.c_[x.ravel(), y.ravel()]
    pos = np.vstack([lattice, [[-1.0, 0.0], [-2.0, 0.0], [4.5, -5.0]]])
    geometry = Snapshot.from_geometry(pos, np.full(len(pos), 0.5), tolerance=1e-9)
    normals = geometry.contact_normals()
    force = np.where(np.abs(normals[:, 0]) > 0.5, 2.0, 1.0)
    return geometry.with_contacts(geometry.contact_i, geometry.contact_j, normal_force=force)


def test_snapshot_initial_state_counts_and_fabric() -> None:
    snap = _lattice_with_tail()
    assert snap.n_contacts == 182
    state = snapshot_initial_state(snap)
    assert state.n_grains == 103 and state.n_contacts == 182
    assert state.coordination_number == pytest.approx(2 * 182 / 103)
    assert state.mechanical_coordination_number == pytest.approx(3.6)  # the lattice's 360 / 100
    assert state.rattler_share == pytest.approx(3 / 103)
    assert state.share_no_contact == pytest.approx(1 / 103)
    assert state.share_one_contact == pytest.approx(1 / 103)
    assert state.coordination_number_contacting == pytest.approx(2 * 182 / 102)
    assert state.coordination_number_with_boundary == pytest.approx(state.coordination_number)  # no walls
    assert state.anisotropy == pytest.approx(2 * (92 - 90) / 182)
    assert state.force_anisotropy == pytest.approx(2 * (184 - 90) / 274)
    assert state.force_effective_contacts == pytest.approx(274**2 / (92 * 4 + 90))
    assert state.noise_mean == pytest.approx(math.sqrt(math.pi / 182))
    assert state.noise_p_paper == pytest.approx(1 - math.exp(-182 * 0.0034**2 / 4))
    assert state.noise_p_measured == pytest.approx(1 - math.exp(-182 * state.anisotropy**2 / 4))
    assert math.isnan(state.porosity)  # no area given
    lam = StabilityIndex().compute(snap).stability_index
    assert state.mean_lambda_active == pytest.approx(np.mean(lam[:100]))  # A, B, isolated out
    assert state.mean_lambda == pytest.approx(np.mean(lam[:101]))  # A has 2 contacts: in
    assert state.mean_lambda != pytest.approx(state.mean_lambda_active)
    assert state.share_lambda_grains == pytest.approx(101 / 103)
    assert state.share_active_grains == pytest.approx(100 / 103)
    # interior: midpoints two largest diameters (2) inside the box x -2.5..9.5, y -5.5..9.5;
    # 7 x 8 horizontal and 8 x 7 vertical lattice contacts, the tail's at x = -0.5 not
    assert state.n_contacts_interior == 112
    assert state.anisotropy_interior == pytest.approx(0.0, abs=1e-12)
    assert state.noise_mean_interior == pytest.approx(math.sqrt(math.pi / 112))
    # Z = 3.9 needs 201 pairs; the next after the 182 contacts, the lattice's diagonals
    # (gap sqrt(2) - 1), lie beyond the default reach of 1e-4
    assert math.isnan(state.gap_for_paper_z_m)


def test_snapshot_initial_state_leaves_out_membrane_contacts() -> None:
    """A membrane disk touching the lattice adds no grain and no contact to Z and a."""
    base = _lattice_with_tail()
    pos = np.vstack([base.positions, [[4.0, 10.0]]])  # on top of lattice disk (4, 9)
    kind = np.r_[np.zeros(103, np.int8), [int(ParticleKind.MEMBRANE)]]
    snap = Snapshot.from_geometry(pos, np.full(104, 0.5), kind=kind, tolerance=1e-9)
    state = snapshot_initial_state(snap)
    assert snap.n_contacts == 183
    assert state.n_grains == 103 and state.n_contacts == 182
    assert state.coordination_number == pytest.approx(2 * 182 / 103)
    assert state.coordination_number_with_boundary == pytest.approx(2 * 182 / 103 + 1 / 103)
    assert state.anisotropy == pytest.approx(2 * (92 - 90) / 182)


def test_snapshot_initial_state_circles_on_a_lattice() -> None:
    """40 x 80 touching disks of radius 0.5: circles of radius 0.4 x 40 = 16 at heights 20,
    40 and 60, inside the lattice, whose grains all have 4 contacts; porosity 1 - pi/4 in
    each circle within the bound 2 sqrt(2) pi r / R (tests/samples/test_measurement_circle.py)
    and exactly over the whole box."""
    x, y = np.meshgrid(np.arange(40.0) + 0.5, np.arange(80.0) + 0.5)
    snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(3200, 0.5), tolerance=1e-9)
    state = snapshot_initial_state(snap, area=40.0 * 80.0)
    assert (state.sample_width_m, state.sample_height_m, state.circle_radius_m) == pytest.approx((40, 80, 16))
    assert state.porosity == pytest.approx(1 - math.pi / 4)
    assert state.circle_coordination_number == pytest.approx((4.0, 4.0, 4.0))
    assert state.coordination_number < 4.0  # the edge grains have 3 or 2
    bound = 2 * math.sqrt(2) * math.pi * 0.5 / 16
    for n, nc in zip(state.circle_porosity, state.circle_porosity_overlap_corrected, strict=True):
        assert abs(n - (1 - math.pi / 4)) < bound
        assert nc == pytest.approx(n, abs=1e-12)  # touching disks: no lens
    row = state.to_dict()
    assert row["circle_porosity_mean"] == pytest.approx(np.mean(state.circle_porosity))
    json.dumps(row)


def test_gap_for_coordination_number() -> None:
    """A 10 x 10 square lattice of disks of radius 0.5 at spacing 1.01: 180 pairs at gap
    0.01, the diagonal ones at sqrt(2) 1.01 - 1 = 0.428; Z = 3.6 needs gap 0.01."""
    x, y = np.meshgrid(np.arange(10.0), np.arange(10.0))
    pos, rad = 1.01 * np.c_[x.ravel(), y.ravel()], np.full(100, 0.5)
    assert gap_for_coordination_number(pos, rad, 3.6, reach=0.1) == pytest.approx(0.01)
    assert gap_for_coordination_number(pos, rad, 3.0, reach=0.1) == pytest.approx(0.01)
    assert math.isnan(gap_for_coordination_number(pos, rad, 3.61, reach=0.1))  # diagonals beyond reach
    assert gap_for_coordination_number(pos, rad, 3.61, reach=0.5) == pytest.approx(math.sqrt(2) * 1.01 - 1)
    assert math.isnan(gap_for_coordination_number(pos, rad, 3.6, reach=1e-3))
    assert gap_for_coordination_number(pos / 1.01, rad, 3.6, reach=0.1) == 0.0  # touching already
    assert gap_for_coordination_number(pos, rad, 0.0) == 0.0


def test_circles_stay_inside_a_squat_sample() -> None:
    """A square 40 x 40 lattice: radius 0.4 x half the height (8), so that the circles at
    heights 10 and 30 stay inside; the porosity in each within the lattice bound."""
    x, y = np.meshgrid(np.arange(40.0) + 0.5, np.arange(40.0) + 0.5)
    snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(1600, 0.5), tolerance=1e-9)
    state = snapshot_initial_state(snap)
    assert state.circle_radius_m == pytest.approx(8.0)
    for n in state.circle_porosity:
        assert abs(n - (1 - math.pi / 4)) < 2 * math.sqrt(2) * math.pi * 0.5 / 8.0


# --------------------------------------------------------------------------- a run folder
def test_initial_state_of_a_run_folder_reads_the_first_snapshot(tmp_path) -> None:
    """The 0 % snapshot (not the later one, which has lost its tail contacts) and the
    first record's area for the whole-sample porosity."""
    first = _lattice_with_tail()
    later = first.select_contacts(np.arange(first.n_contacts) < 180)
    area = 120.0
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as writer:
        writer.append_rows({"axial_strain": [0.0, 0.01], "area_m2": [area, 119.0]})
        writer.write_snapshot(snapshot_name(0.01), Snapshot(**_fields(later), axial_strain=0.01))
        writer.write_snapshot(snapshot_name(0.0), Snapshot(**_fields(first), axial_strain=0.0))
    state = initial_state(tmp_path)
    assert state.n_contacts == 182
    assert state.porosity == pytest.approx(1 - 103 * math.pi * 0.25 / area)
    assert state.anisotropy == pytest.approx(snapshot_initial_state(first).anisotropy)


def _fields(s: Snapshot) -> dict:
    return {"positions": s.positions, "radii": s.radii, "contact_i": s.contact_i, "contact_j": s.contact_j,
            "normal_force": s.normal_force}


# --------------------------------------------------------------------------- exploration
def test_explore_appends_and_resumes(tmp_path) -> None:
    calls: list[tuple[str, int]] = []
    state = snapshot_initial_state(_lattice_with_tail())

    def prepare(overrides, seed, *, threads):
        assert threads == 1
        calls.append((json.dumps(overrides, sort_keys=True), seed))
        if overrides.get("bad"):
            raise RuntimeError("did not converge")
        return state, {"seconds": 1.0}

    settings = [("a", {}, "why a"), ("b", {"bad": True}, "why b")]
    path = tmp_path / "x.json"
    data = explore(path, settings, seeds=(1, 2), prepare=prepare, log=lambda s: None)
    assert len(calls) == 4 and len(data["results"]) == 4
    stored = json.loads(path.read_text())
    assert [(r["setting"], r["seed"]) for r in stored["results"]] == [("a", 1), ("a", 2), ("b", 1), ("b", 2)]
    assert stored["results"][0]["coordination_number"] == pytest.approx(state.coordination_number, rel=1e-5)
    assert "did not converge" in stored["results"][2]["error"]
    explore(path, [*settings, ("c", {"c": 1}, "why c")], seeds=(1, 2), prepare=prepare, log=lambda s: None)
    assert len(calls) == 6  # only the new setting ran
    assert len(json.loads(path.read_text())["results"]) == 6


def test_mean_interval() -> None:
    mean, half = mean_interval([1.0, 2.0, 3.0])
    assert mean == 2.0
    assert half == pytest.approx(4.302652729911275 / math.sqrt(3))
    assert math.isnan(mean_interval([1.0])[1])


def test_the_numbers_docs_quote_come_from_the_stored_runs():
    """docs/reproduction.md's initial-state section quotes paper_scale/initial_state_runs.json."""
    import json
    from pathlib import Path

    import numpy as np
    from scipy import stats

    root = Path(__file__).resolve().parents[2]
    runs = json.loads((root / "python/grainlab/reproduction/paper_scale/initial_state_runs.json").read_text())["runs"]
    page = (root / "docs" / "reproduction.md").read_text(encoding="utf-8")
    assert len(runs) == 20

    def mean_ci(key, digits):
        v = np.array([r[key] for r in runs], dtype=float)
        half = stats.t.ppf(0.975, v.size - 1) * v.std(ddof=1) / np.sqrt(v.size)
        return f"{v.mean():.{digits}f} ± {half:.{digits}f}"

    assert f"Z = {mean_ci('coordination_number', 3)}" in page
    assert f"Z_m = {mean_ci('mechanical_coordination_number', 3)}" in page
    assert f"a = {mean_ci('anisotropy', 4)}" in page
    assert f"a = {mean_ci('anisotropy_interior', 4)}" in page
    assert f"E[a] = {np.mean([r['noise_mean'] for r in runs]):.4f}" in page
    assert f"P = {np.mean([r['noise_p_paper'] for r in runs]):.3f}" in page
    assert f"**{np.mean([r['circle_porosity_mean'] for r in runs]):.4f}** nominal" in page
    assert f"against {np.mean([r['porosity'] for r in runs]):.4f} for the whole sample" in page
