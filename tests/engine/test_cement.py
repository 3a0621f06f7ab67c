"""Cement bonds from Python: the break of a pulled pair at sigma_c A, the break
records, seeded strengths, refusals in one line, and a checkpoint taken while
bonds break (the engine's own oracles are in crates/grainlab-core/tests/cement.rs)."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab import FIX_ROTATION, FIX_X, FIX_Y, Simulation
from grainlab.cement import draw_strengths

R = 1e-3
KN_BAR = 4e10  # Pa/m: kn_bar A = 8e7 N/m for lambda_b = 1, R = 1 mm


def _pulled_pair(sigma_c: float) -> Simulation:
    sim = Simulation(positions=[[0.0, 0.0], [2 * R, 0.0]], radii=[R, R], density=2e8)
    sim.add_cement_bonds([0], [1], normal_stiffness=KN_BAR, shear_stiffness=KN_BAR,
                         tensile_strength=sigma_c, cohesion=1e12)
    sim.fixity = np.array([7, 7], dtype=np.uint8)
    sim.velocities = [[0.0, 0.0], [1e-4, 0.0]]
    return sim


def test_a_pulled_pair_breaks_at_sigma_c_times_the_area() -> None:
    sigma_c = 1e6
    sim = _pulled_pair(sigma_c)
    bonds = sim.cement_bonds()
    area = float(bonds.area[0])
    assert area == pytest.approx(2 * R) and str(bonds.kind[0]) == "parallel"
    step_stretch = KN_BAR * area * 1e-4 * sim.time_step
    for _ in range(100_000):
        sim.run(1)
        if sim.n_cement_bonds == 0:
            break
    breaks = sim.take_bond_breaks()
    assert len(breaks) == 1 and str(breaks.mode[0]) == "tension"
    tension = -float(breaks.normal_force[0])
    assert sigma_c * area <= tension < sigma_c * area + step_stretch
    assert (int(breaks.i[0]), int(breaks.j[0])) == (0, 1)
    assert breaks.position.shape == (1, 2) and breaks.normal[0].tolist() == [1.0, 0.0]
    assert float(breaks.energy[0]) == pytest.approx(tension**2 / (2 * KN_BAR * area))
    assert sim.energy.bond_released == pytest.approx(float(breaks.energy[0]), rel=0.05)
    assert len(sim.take_bond_breaks()) == 0, "the log was drained"


def test_the_break_log_survives_a_checkpoint_and_the_run_resumes_to_the_same_bits() -> None:
    sim = _pulled_pair(1e6)
    sim.run(200)
    other = Simulation.from_bytes(sim.to_bytes())
    for s in (sim, other):
        s.run(2000)
    assert sim.n_cement_bonds == other.n_cement_bonds == 0
    a, b = sim.take_bond_breaks(), other.take_bond_breaks()
    assert a.step.tolist() == b.step.tolist() and a.energy.tobytes() == b.energy.tobytes()
    assert sim.positions.tobytes() == other.positions.tobytes()


def test_strengths_are_seeded_and_follow_their_law() -> None:
    a = draw_strengths(np.random.default_rng(5), 2e6, 5e5, 50_000, "weibull")
    b = draw_strengths(np.random.default_rng(5), 2e6, 5e5, 50_000, "weibull")
    assert a.tobytes() == b.tobytes()
    assert a.mean() == pytest.approx(2e6, rel=0.01) and a.std() == pytest.approx(5e5, rel=0.02)
    n = draw_strengths(np.random.default_rng(5), 1e6, 5e5, 50_000)
    assert n.min() >= 0 and np.median(n) == pytest.approx(1e6, rel=0.02)
    assert np.all(draw_strengths(np.random.default_rng(0), 3.0, 0.0, 4) == 3.0)
    with pytest.raises(ValueError, match="^distribution: "):
        draw_strengths(np.random.default_rng(0), 1.0, 0.1, 3, "lognormal")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("i", "j", "change", "message"),
    [
        ([0], [0], {}, r"^cement\[0\]: cannot cement particle 0 to itself"),
        ([0, 1], [1, 0], {}, r"^cement\[1\]: particles 1 and 0 are already cemented"),
        ([0], [5], {}, r"^j\[0\]: particle index 5 out of range"),
        ([-1], [1], {}, r"^i\[0\]: particle index -1 out of range"),
        ([0], [1], {"tensile_strength": -1.0}, r"^cement\.tensile_strength\[0\]: must be finite and >= 0"),
        ([0], [1], {"radius_multiplier": 0.0}, r"^cement\.radius_multiplier\[0\]: must be finite and > 0"),
        ([0], [1], {"cohesion": np.nan}, r"^cement\.cohesion\[0\]: must be finite"),
        ([0, 1], [1, 2], {"cohesion": [1.0, 2.0, 3.0]}, r"^cohesion: expected one number or one per pair"),
        ([0], [1], {"kind": "glue"}, r"^kind: expected 'parallel' or 'contact'"),
    ],
)
def test_bad_cement_is_refused_in_one_line_before_any_bond(
    i: list[int], j: list[int], change: dict[str, object], message: str
) -> None:
    sim = Simulation(positions=[[0.0, 0.0], [2 * R, 0.0], [4 * R, 0.0]], radii=[R] * 3, density=2e8)
    kwargs: dict[str, object] = {"normal_stiffness": KN_BAR, "shear_stiffness": KN_BAR,
                                 "tensile_strength": 1e6, "cohesion": 1e6, **change}
    with pytest.raises(ValueError, match=message) as err:
        sim.add_cement_bonds(i, j, **kwargs)  # type: ignore[arg-type]
    assert "\n" not in str(err.value)
    assert sim.n_cement_bonds == 0


def test_a_contact_bond_has_no_moment_and_breaks_at_its_force() -> None:
    sim = Simulation(positions=[[0.0, 0.0], [2 * R, 0.0]], radii=[R, R], density=2e8)
    sim.add_cement_bonds([0], [1], kind="contact", normal_stiffness=8e7, shear_stiffness=8e7,
                         tensile_strength=500.0, cohesion=1e9)
    sim.fixity = np.array([FIX_X | FIX_Y | FIX_ROTATION] * 2, dtype=np.uint8)
    sim.angular_velocities = [-1.0, 1.0]
    sim.run(100)
    assert float(sim.cement_bonds().moment[0]) == 0.0
    sim.velocities = [[0.0, 0.0], [1e-4, 0.0]]
    sim.run(20_000)
    breaks = sim.take_bond_breaks()
    step_stretch = 8e7 * 1e-4 * sim.time_step
    assert str(breaks.mode[0]) == "tension" and 500.0 <= -float(breaks.normal_force[0]) < 500.0 + step_stretch
