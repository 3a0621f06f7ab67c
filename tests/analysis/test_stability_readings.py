"""The readings of the paper's Eq. 9-11 as options of the stability index
(docs/fabric.md, "Readings of Eqs. 9-11"): hand-worked values, properties, the
default reading bit for bit, and the options through ``grainlab analyze``."""

from __future__ import annotations

import csv
import importlib.util
import itertools
import json

import numpy as np
import pytest
from factories_analysis import hex_lattice, jittered_packing, ring

from grainlab import _core, _kernels, cli
from grainlab.analysis import (
    StabilityIndex,
    analyze_snapshot,
    stability_index,
    stability_index_of_angles,
)
from grainlab.analysis._util import contact_ends
from grainlab.analysis.stability import (
    DEFAULT_READING,
    LAMBDA_ANCHORS,
    LAMBDA_DEVIATIONS,
    LAMBDA_SLOTS,
    _group_reading,
)
from grainlab.io import read_snapshot, write_particles_csv
from grainlab.snapshot import Snapshot

READINGS = list(itertools.product(LAMBDA_SLOTS, LAMBDA_ANCHORS, LAMBDA_DEVIATIONS))
TWO_PI = 2 * np.pi


def lam_of(angles_deg, slots="angular", anchor="min", deviation="sum") -> float:
    return stability_index_of_angles(
        angles_deg, degrees=True, slots=slots, anchor=anchor, deviation=deviation
    )


def min_angle(x: float, y: float) -> float:
    d = abs(x - y) % TWO_PI
    return min(d, TWO_PI - d)


def loop_reading(angles_rad, slots, anchor, deviation) -> float:
    """Eq. 9-11 under one reading, one particle, explicit loops (reference only);
    ``angles_rad`` in the order the contacts are given."""
    a = [float(x) % TWO_PI for x in angles_rad]
    n = len(a)
    if n < 2:
        return 1.0
    if slots == "angular":
        a = sorted(a)
    totals = []
    for k in range(n):
        total = 0.0
        for m in range(n):
            if slots == "nearest":  # contact m, whichever slot is nearest
                total += min(min_angle(a[m], a[k] + TWO_PI * s / n) for s in range(n))
            else:  # the contact m places after k, with slot m
                total += min_angle(a[(k + m) % n], a[k] + TWO_PI * m / n)
        totals.append(total)
    d = min(totals) if anchor == "min" else sum(totals) / n
    if deviation == "per_contact":
        d /= n - 1
    return d / TWO_PI


# --------------------------------------------------------------- hand-worked values
# 0, 60, 120 deg. angular: ref 0 -> 60 vs slot 120, 120 vs 240: 60 + 120 = 180;
# ref 60 -> 120 vs 180, 360 vs 300: 120; ref 120 -> 360 vs 240, 420 vs 360: 180.
# nearest: ref 0 (slots 0, 120, 240) -> 60 + 0 = 60; ref 60 (60, 180, 300) -> 60 + 60 = 120;
# ref 120 (120, 240, 0) -> 0 + 60 = 60. list = angular (given in angular order).
# min / mean of {180, 120, 180} = 120 / 160 deg, of {60, 120, 60} = 60 / 80 deg;
# per_contact divides by n - 1 = 2.
THREE = [
    (("angular", "min", "sum"), 120 / 360),  # 1/3, today's value
    (("angular", "min", "per_contact"), 60 / 360),  # 1/6
    (("angular", "mean", "sum"), 160 / 360),  # 4/9
    (("angular", "mean", "per_contact"), 80 / 360),  # 2/9
    (("nearest", "min", "sum"), 60 / 360),  # 1/6
    (("nearest", "mean", "sum"), 80 / 360),  # 2/9
    (("nearest", "min", "per_contact"), 30 / 360),  # 1/12
    (("nearest", "mean", "per_contact"), 40 / 360),  # 1/9
    (("list", "min", "sum"), 120 / 360),
    (("list", "mean", "sum"), 160 / 360),
]


@pytest.mark.parametrize(("reading", "expected"), THREE)
def test_three_contacts_at_0_60_120(reading, expected):
    assert lam_of([0, 60, 120], *reading) == pytest.approx(expected, abs=1e-12)


def test_the_default_reading_is_todays():
    assert lam_of([0, 60, 120]) == stability_index_of_angles([0, 60, 120], degrees=True)
    assert lam_of([0, 60, 120]) == pytest.approx(1 / 3, abs=1e-12)


# Given as 0, 120, 60 deg. list: ref 0 -> 120 vs slot 120, 60 vs 240: 0 + 180 = 180;
# ref 120 -> 60 vs 240, 0 vs 360: 180 + 0 = 180; ref 60 -> 0 vs 180, 120 vs 300: 180 + 180 = 360.
# min 180 -> 1/2, mean 240 -> 2/3; per contact 1/4, 1/3. angular and nearest do not read the order.
LISTED = [
    (("list", "min", "sum"), 180 / 360),
    (("list", "mean", "sum"), 240 / 360),
    (("list", "min", "per_contact"), 90 / 360),
    (("list", "mean", "per_contact"), 120 / 360),
    (("angular", "min", "sum"), 120 / 360),
    (("nearest", "min", "sum"), 60 / 360),
]


@pytest.mark.parametrize(("reading", "expected"), LISTED)
def test_list_order_differing_from_angular_order(reading, expected):
    assert lam_of([0, 120, 60], *reading) == pytest.approx(expected, abs=1e-12)


def test_equal_spacing_listed_out_of_order_is_not_stable_under_list():
    # 0, 180, 90, 270 listed: ref 0 -> 180 vs 90, 90 vs 180, 270 vs 270: 180;
    # ref 180 -> 90 vs 270, 270 vs 360, 0 vs 450: 360; ref 90 -> 270 vs 180, 0 vs 270,
    # 180 vs 360: 360; ref 270 -> 0 vs 360, 180 vs 450, 90 vs 540: 180
    assert lam_of([0, 180, 90, 270], "list") == pytest.approx(180 / 360, abs=1e-12)
    assert lam_of([0, 180, 90, 270], "list", "mean") == pytest.approx(270 / 360, abs=1e-12)
    assert lam_of([0, 180, 90, 270], "angular") == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("reading", READINGS)
def test_two_contacts_at_0_and_90_give_one_quarter(reading):
    # ref 0: 90 vs slot 180 (angular, list) or the nearer of 0 and 180 (nearest): 90, and
    # the same from ref 90; one deviation summed, so per_contact is the sum
    assert lam_of([0, 90], *reading) == pytest.approx(1 / 4, abs=1e-12)


@pytest.mark.parametrize("reading", READINGS)
def test_hexagonal_star_and_few_contacts(reading):
    assert lam_of([0, 60, 120, 180, 240, 300], *reading) == pytest.approx(0.0, abs=1e-12)
    assert lam_of([], *reading) == 1.0
    assert lam_of([37.0], *reading) == 1.0


# --------------------------------------------------------------------------- properties
@pytest.mark.parametrize("reading", READINGS)
@pytest.mark.parametrize("n", [2, 3, 4, 5, 7])
def test_equal_spacing_is_zero_and_rotation_changes_nothing(reading, n, rng):
    start = rng.uniform(0, 360)
    assert lam_of(start + 360 * np.arange(n) / n, *reading) == pytest.approx(0.0, abs=1e-12)
    sets = 200
    owner = np.repeat(np.arange(sets), n)
    angles = rng.uniform(0, TWO_PI, owner.size)
    kw = dict(zip(("slots", "anchor", "deviation"), reading, strict=True))
    lam, _ = stability_index(owner, angles, sets, **kw)
    for turn in (0.3, 2.0, -5.0):
        turned, _ = stability_index(owner, angles + turn, sets, **kw)
        np.testing.assert_allclose(turned, lam, atol=1e-12)


@pytest.mark.parametrize("anchor", LAMBDA_ANCHORS)
@pytest.mark.parametrize("deviation", LAMBDA_DEVIATIONS)
def test_nearest_never_exceeds_angular_and_mean_never_below_min(anchor, deviation):
    rng = np.random.default_rng(7)
    counts = rng.integers(2, 10, 2000)
    owner = np.repeat(np.arange(counts.size), counts)
    angles = rng.uniform(-10, 10, owner.size)
    sets = counts.size

    def lam(**kw):
        return stability_index(owner, angles, sets, **kw)[0]

    nearest = lam(slots="nearest", anchor=anchor, deviation=deviation)
    angular = lam(slots="angular", anchor=anchor, deviation=deviation)
    assert np.all(nearest <= angular + 1e-12)
    assert np.any(nearest < angular - 1e-3)  # not the same reading
    for slots in LAMBDA_SLOTS:
        low = lam(slots=slots, anchor="min", deviation=deviation)
        high = lam(slots=slots, anchor="mean", deviation=deviation)
        assert np.all(high >= low - 1e-12)
        assert np.any(high > low + 1e-3)


# ------------------------------------------------------------- implementation checks
def test_default_reading_is_todays_compiled_output_bit_for_bit():
    snap = jittered_packing(24, 20, seed=11)
    assert _kernels.compiled() and snap.n_contacts > 500
    today, counts = _core.stability_index_of_contacts(
        np.ascontiguousarray(snap.contact_i),
        np.ascontiguousarray(snap.contact_j),
        np.ascontiguousarray(snap.contact_angles()),
        snap.n_particles,
        _kernels.threads(),
    )
    for measure in (
        StabilityIndex(),
        StabilityIndex(slots="angular", anchor="min", deviation="sum"),
    ):
        measure.compute(snap)
        np.testing.assert_array_equal(measure.stability_index, today)
        np.testing.assert_array_equal(measure.n_contacts, counts)
    owner, ends, _ = contact_ends(snap, include_boundary=True)
    lam, _ = stability_index(owner, ends, snap.n_particles, slots="angular", anchor="min")
    np.testing.assert_array_equal(lam, today)
    # the NumPy kernel of the other readings, run on the default one, agrees to rounding
    for p in np.flatnonzero(counts >= 2):
        row = ends[owner == p][None, :]
        got = _group_reading(row, row.shape[1], "angular", "min", "sum")
        assert got[0] == pytest.approx(today[p], abs=1e-12)
    assert StabilityIndex(slots="angular", anchor="min", deviation="per_contact").compute(
        snap
    ).stability_index == pytest.approx(
        np.where(counts >= 2, today / np.maximum(counts - 1, 1), 1.0), abs=1e-12
    )


@pytest.mark.parametrize("reading", READINGS)
def test_numpy_readings_match_a_per_particle_loop(reading, rng):
    counts = rng.integers(0, 9, 300)
    owner = rng.permutation(np.repeat(np.arange(counts.size), counts))  # particles interleaved
    angles = rng.uniform(-720, 720, owner.size)
    kw = dict(zip(("slots", "anchor", "deviation"), reading, strict=True))
    lam, got_counts = stability_index(owner, np.radians(angles), counts.size, **kw)
    np.testing.assert_array_equal(got_counts, counts)
    expected = [loop_reading(np.radians(angles[owner == p]), *reading) for p in range(counts.size)]
    np.testing.assert_allclose(lam, expected, atol=1e-12)


def test_list_reads_the_snapshots_contact_list_order_whichever_side():
    # grain 2 at the origin; neighbours 0 at 0 deg, 3 at 120 deg, 1 at 60 deg. Listed as
    # (0, 2), (2, 3), (1, 2): grain 2's ends in list order are 0, 120, 60 (lambda 1/2);
    # i-ends first (120, then 0, 60) would be the angular cycle (1/3)
    a = np.radians([0.0, 60.0, 0.0, 120.0])
    pos = 1e-3 * np.c_[np.cos(a), np.sin(a)]
    pos[2] = 0.0
    snap = Snapshot(pos, np.full(4, 0.5e-3), contact_i=[0, 2, 1], contact_j=[2, 3, 2])
    lam = StabilityIndex(slots="list").compute(snap).stability_index
    assert lam[2] == pytest.approx(1 / 2, abs=1e-12)
    assert StabilityIndex().compute(snap).stability_index[2] == pytest.approx(1 / 3, abs=1e-12)
    # a ring listed 0, 120, 60 (the grain is i in every contact)
    ring_lam = StabilityIndex(slots="list").compute(ring([0, 120, 60])).stability_index
    assert ring_lam[0] == pytest.approx(1 / 2, abs=1e-12)
    assert np.all(ring_lam[1:] == 1.0)


def test_a_merged_boundary_end_sits_at_the_first_contact_with_its_body():
    # grain 0; grains 1 at 0 deg and 2 at 60 deg; membrane disks 3, 4 at 110 and 130 deg
    # (one body, merged at 120 deg). Listed (0, 1), (3, 0), (0, 2), (0, 4): the membrane's
    # end comes second (0, 120, 60: lambda 1/2), not last (0, 60, 120: 1/3)
    a = np.radians([0.0, 0.0, 60.0, 110.0, 130.0])
    dist = np.r_[0.0, 1e-3, 1e-3, 0.75e-3, 0.75e-3]
    pos = dist[:, None] * np.c_[np.cos(a), np.sin(a)]
    snap = Snapshot(
        pos,
        np.r_[0.5e-3, 0.5e-3, 0.5e-3, 0.25e-3, 0.25e-3],
        kind=[0, 0, 0, 1, 1],
        contact_i=[0, 3, 0, 0],
        contact_j=[1, 0, 2, 4],
        particle_fields={"body": np.r_[-1, -1, -1, 0, 0]},
    )
    measure = StabilityIndex(slots="list").compute(snap)
    assert measure.n_contacts[0] == 3
    assert measure.stability_index[0] == pytest.approx(1 / 2, abs=1e-12)
    assert StabilityIndex().compute(snap).stability_index[0] == pytest.approx(1 / 3, abs=1e-12)
    assert np.isnan(measure.stability_index[3:]).all()


def test_repr_and_reading():
    m = StabilityIndex(slots="nearest", anchor="mean", deviation="per_contact")
    assert m.reading == "nearest/mean/per_contact"
    assert StabilityIndex().reading == DEFAULT_READING == "angular/min/sum"
    assert "slots='nearest', anchor='mean', deviation='per_contact'" in repr(m)


@pytest.mark.parametrize("option", ["slots", "anchor", "deviation"])
def test_bad_options_name_the_option(option):
    for call in (
        lambda: StabilityIndex(**{option: "bogus"}),
        lambda: stability_index([0, 0], [0.0, 1.0], 1, **{option: "bogus"}),
        lambda: stability_index_of_angles([0, 1], **{option: "bogus"}),
        lambda: analyze_snapshot(hex_lattice(4, 4), **{f"lambda_{option}": "bogus"}),
    ):
        with pytest.raises(ValueError, match=rf"^{option}: must be one of .*'bogus'"):
            call()
    with pytest.raises(ValueError, match="^slots:"):  # before any work: bad owners not reached
        stability_index([5], [0.0], 1, slots="Angular")


# --------------------------------------------------------------------------- the CLI
@pytest.fixture
def run_cli(monkeypatch):
    present = tuple(m for m in cli.COMMAND_MODULES if importlib.util.find_spec(m) is not None)
    monkeypatch.setattr(cli, "COMMAND_MODULES", present)
    return cli.main


def _lambda_column(path):
    with open(path, newline="") as fh:
        return np.array([float(r["stability_index"]) for r in csv.DictReader(fh)])


def test_cli_options_reach_the_computation(tmp_path, run_cli, capsys):
    write_particles_csv(tmp_path / "p.csv", jittered_packing(8, 8, seed=5))
    snap = read_snapshot(tmp_path / "p.csv", tolerance=0.0)
    common = [str(tmp_path / "p.csv"), "--no-figures"]
    assert run_cli(["analyze", *common, "--out", str(tmp_path / "default")]) == 0
    assert "(angular" not in capsys.readouterr().out
    options = ["--lambda-slots", "nearest", "--lambda-anchor", "mean"]
    options += ["--lambda-deviation", "per_contact"]
    assert run_cli(["analyze", *common, *options, "--out", str(tmp_path / "other")]) == 0
    assert "(nearest/mean/per_contact)" in capsys.readouterr().out
    default = StabilityIndex().compute(snap)
    other = StabilityIndex(slots="nearest", anchor="mean", deviation="per_contact").compute(snap)
    assert not np.allclose(default.stability_index, other.stability_index)
    np.testing.assert_allclose(
        _lambda_column(tmp_path / "default" / "particles.csv"), default.stability_index, rtol=1e-9
    )
    np.testing.assert_allclose(
        _lambda_column(tmp_path / "other" / "particles.csv"), other.stability_index, rtol=1e-9
    )
    summary = json.loads((tmp_path / "other" / "fabric.json").read_text())
    assert summary["lambda_reading"] == "nearest/mean/per_contact"
    assert summary["mean_lambda"] == pytest.approx(other.mean, rel=1e-12)
    summary = json.loads((tmp_path / "default" / "fabric.json").read_text())
    assert "lambda_reading" not in summary  # the default files are unchanged
    assert summary["mean_lambda"] == pytest.approx(default.mean, rel=1e-12)
    result = analyze_snapshot(snap, lambda_slots="list")
    assert result.stability.reading == "list/min/sum"
    np.testing.assert_array_equal(
        result.stability.stability_index,
        StabilityIndex(slots="list").compute(snap).stability_index,
    )


@pytest.mark.parametrize("option", ["--lambda-slots", "--lambda-anchor", "--lambda-deviation"])
def test_cli_rejects_bad_values(tmp_path, run_cli, capsys, option):
    write_particles_csv(tmp_path / "p.csv", hex_lattice(4, 4))
    with pytest.raises(SystemExit) as exit_info:
        run_cli(["analyze", str(tmp_path / "p.csv"), option, "bogus", "--out", str(tmp_path)])
    assert exit_info.value.code == 2
    assert option in capsys.readouterr().err
