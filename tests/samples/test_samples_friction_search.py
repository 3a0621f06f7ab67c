"""The generation friction search: a loose target made stress-bearing, the monotone bracket, errors."""

from __future__ import annotations

import json
import math

import pytest

import grainlab.samples.friction_search as friction_search
from grainlab.samples import (
    ExpansionError,
    FrictionSearchError,
    expand_to_porosity,
    expand_with_friction_search,
)
from grainlab.samples.friction_search import TRIAL_OUTCOMES

SMALL = (0.0, 0.0, 0.02, 0.04)  # about 210 disks of the paper's grading at porosity 0.2
LOOSE = 0.2  # looser than the frictionless expansion jams in this box (between 0.18 and 0.19)
BAND = (1.0e5, 3.0e5)


@pytest.fixture(scope="module")
def loose_search():
    return expand_with_friction_search(SMALL, LOOSE, seed=1, stress_band_pa=BAND, progress=False,
                                       keep_simulation=True)


def test_frictionless_expansion_leaves_the_loose_target_stress_free():
    s = expand_to_porosity(SMALL, LOOSE, seed=1, friction=0.0, progress=False)
    assert s.porosity == pytest.approx(LOOSE, abs=1e-12)
    assert not s.jammed and s.mean_wall_stress_pa < 1e3


def test_the_search_makes_the_loose_target_stress_bearing(loose_search):
    found = loose_search
    s = found.sample
    assert s.porosity == pytest.approx(LOOSE, abs=1e-12)  # the target, exactly (one radius factor)
    assert s.jammed and s.equilibrium_reached and s.unbalanced_force_ratio < 1e-4
    assert BAND[0] <= s.mean_wall_stress_pa <= BAND[1] and found.in_band
    assert s.mechanical_coordination_number >= 3.0
    # the stress is what the walls carry: the live simulation agrees with the record
    sim = s.simulation
    lengths = (0.02, 0.04, 0.02, 0.04)
    walls = [w.normal_stress(length) for w, length in zip(sim.walls, lengths, strict=True)]
    assert sum(walls) / 4 == pytest.approx(s.mean_wall_stress_pa, rel=1e-12)
    assert 0.0 < found.friction <= 0.9 and s.friction == found.friction
    # the first trial is the frictionless expansion, stress-free here; the accepted one is the last
    assert found.trials[0].friction == 0.0 and found.trials[0].outcome == "stress_free"
    assert found.accepted is found.trials[-1] and found.accepted.outcome == "in_band"
    assert found.steps == sum(t.steps for t in found.trials) and found.wall_time_s > 0
    # at most two ends plus ceil(log2(0.9 / 0.005)) = 8 midpoints
    assert 2 <= len(found.trials) <= 10


def test_the_bracket_is_monotone(loose_search):
    found = loose_search
    assert found.monotone
    ordered = sorted(found.trials, key=lambda t: t.friction)
    loose = [t.friction for t in ordered if t.rank == 0]
    bearing = [t.friction for t in ordered if t.rank > 0]
    assert loose and bearing and max(loose) < min(bearing)
    # bisection: every midpoint lies strictly inside the bracket of the trials before it
    for k, t in enumerate(found.trials[2:], start=2):
        lower = max(u.friction for u in found.trials[:k] if u.rank == 0)
        upper = min(u.friction for u in found.trials[:k] if u.rank > 0)
        assert t.friction == pytest.approx(0.5 * (lower + upper), abs=1e-15)


def test_stress_at_a_fixed_porosity_rises_with_generation_friction():
    """The relation the search relies on, measured without it: the jamming porosity rises with
    friction, so at one loose target the locked-in stress rises with the friction. (In a sample
    this small the realisations scatter near the threshold, within about 0.05 of it: the
    relation is monotone on this coarse grid.)"""
    stresses = [expand_to_porosity(SMALL, LOOSE, seed=1, friction=mu, progress=False).mean_wall_stress_pa
                for mu in (0.0, 0.2, 0.5, 0.9)]
    assert stresses[0] < 1e3 < stresses[1]
    assert all(a < b for a, b in zip(stresses, stresses[1:], strict=False))


def test_a_target_the_least_friction_jams_keeps_it():
    found = expand_with_friction_search(SMALL, 0.12, seed=3, stress_band_pa=BAND, progress=False)
    assert found.friction == 0.0 and len(found.trials) == 1
    # friction only adds stress: the frictionless packing is taken above the band too
    assert found.sample.mean_wall_stress_pa > BAND[1] and not found.in_band
    assert found.trials[0].outcome == "above_band"
    same = expand_to_porosity(SMALL, 0.12, seed=3, progress=False)
    assert found.sample.mean_wall_stress_pa == same.mean_wall_stress_pa  # the same expansion


def test_summary_and_json(loose_search):
    line = loose_search.summary()
    assert f"generation friction {loose_search.friction:.4g}" in line and "in the band 100-300 kPa" in line
    trials = json.loads(loose_search.trials_json())
    assert [t["friction"] for t in trials] == [t.friction for t in loose_search.trials]
    assert all(t["outcome"] in TRIAL_OUTCOMES for t in trials)
    d = json.loads(json.dumps(loose_search.to_dict(), allow_nan=True))
    assert d["friction"] == loose_search.friction and d["in_band"] and d["monotone"]


def test_a_target_looser_than_any_friction_jams_is_refused_clearly():
    with pytest.raises(FrictionSearchError) as info:
        expand_with_friction_search(SMALL, 0.3, seed=1, stress_band_pa=BAND, progress=False)
    error = info.value
    assert isinstance(error, ValueError) and error.target == 0.3
    assert [t.friction for t in error.trials] == [0.0, 0.9]  # the two ends, no bisection
    assert all(t.rank == 0 for t in error.trials)
    assert "looser than radius expansion jams even with the largest generation friction" in str(error)
    assert "friction 0.9" in str(error)


def test_a_target_too_dense_for_the_stress_bound_raises_the_expansion_error():
    with pytest.raises(ExpansionError, match="max_stress_pa"):
        expand_with_friction_search(SMALL, 0.08, seed=3, stress_band_pa=BAND, max_stress_pa=1.0e6,
                                    progress=False)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"friction_range": (0.5, 0.2)}, "friction_range"),
        ({"friction_range": (-0.1, 0.5)}, "friction_range"),
        ({"friction_range": (0.0, math.inf)}, "friction_range"),
        ({"friction_range": 0.9}, "friction_range"),
        ({"stress_band_pa": (3e5, 1e5)}, "stress_band_pa"),
        ({"stress_band_pa": (0.0, 1e5)}, "stress_band_pa"),
        ({"stress_band_pa": (1e5, 6e6)}, "stress_band_pa"),  # above the default 5 MPa bound
        ({"stress_band_pa": (1e5, 3e5), "max_stress_pa": 2e5}, "stress_band_pa"),
        ({"friction_tolerance": 0.0}, "friction_tolerance"),
        ({"min_mechanical_coordination": -1.0}, "min_mechanical_coordination"),
        ({"friction": 0.3}, "friction"),
        ({"porosity": 1.2}, "porosity"),
    ],
)
def test_bad_input_is_refused_before_any_work(monkeypatch, kwargs, field):
    def no_work(*args, **kwargs):
        raise AssertionError("an expansion ran before the input was checked")

    monkeypatch.setattr(friction_search, "expand_to_porosity", no_work)
    with pytest.raises(ValueError, match=field):
        expand_with_friction_search(**{"box": SMALL, "porosity": LOOSE, "progress": False, **kwargs})
