"""The bonded membrane: which of its disks touch one another, and the breach check."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.protocols.boundary import (
    MAX_NEIGHBOUR_DISTANCE_DIAMETERS,
    MEMBRANE_GROUP,
    SLACK_TIE,
    install_membrane,
    membrane_breach,
)
from grainlab.simulation import ContactModel, Simulation

KN = 8.45e7
BOND = 8.45e5
D_M = 0.5e-3


def _membrane_sim():
    """A column of a few grains between two platens, the side walls gone, the membrane on."""
    grains = np.array([[0.0025, 0.0015 + 0.003 * k] for k in range(4)])
    sim = Simulation(grains, np.full(4, 0.0015), 2650.0, contact_model=ContactModel(KN, KN, 0.5), time_step=1e-8)
    bottom = sim.add_segment_wall((-0.01, 0.0), (0.015, 0.0))
    top = sim.add_segment_wall((0.015, 0.012), (-0.01, 0.012))
    membrane = install_membrane(
        sim, left_x=0.001, right_x=0.004, bottom=bottom, top=top, diameter=D_M, overlap=0.5,
        bond_stiffness=BOND, friction=0.0, grain_model=ContactModel(KN, KN, 0.5), density=2650.0, pressure=0.0,
    )
    return sim, membrane


def _force_on(sim, i, j):
    """Contact force between particles i and j from the engine's contact list (0 if none)."""
    c = sim.contacts()
    both = ((c.i == i) & (c.j == j)) | ((c.i == j) & (c.j == i))
    return float(np.abs(c.normal_force[both]).sum())


def test_membrane_disks_touch_from_third_neighbours_on():
    sim, membrane = _membrane_sim()
    assert np.all(sim.groups[membrane.particles] == MEMBRANE_GROUP)
    chain = membrane.left
    a = chain[10]
    x = sim.positions.copy()
    # a fold: the third neighbour laid on top of disk a, overlapping by a tenth of the diameter
    x[chain[13]] = x[a] + np.array([-0.9 * D_M, 0.0])
    sim.positions = x
    sim.run(1)
    overlap = 0.1 * D_M
    # at the grains' stiffness, not the bond's: a fold must not close under the pressure
    assert _force_on(sim, a, chain[13]) == pytest.approx(KN * overlap, rel=1e-3)
    # second neighbours at rest touch exactly (spacing = d_m / 2); squeezed together they
    # still exchange only the slack tie's force, far below a contact's
    x = sim.positions.copy()
    x[chain[12]] = x[a] + np.array([0.0, 0.8 * D_M])
    sim.positions = x
    sim.run(1)
    squeeze = 0.2 * D_M
    assert _force_on(sim, a, chain[12]) == pytest.approx(SLACK_TIE * BOND * squeeze, rel=1e-3)


def test_a_membrane_chain_that_opens_is_reported():
    sim, membrane = _membrane_sim()
    assert membrane_breach(sim, membrane) is None
    x = sim.positions.copy()
    k = len(membrane.right) // 2
    gap = 1.05 * MAX_NEIGHBOUR_DISTANCE_DIAMETERS * D_M
    x[membrane.right[k:]] += np.array([0.0, -gap])  # pull the lower half of the right chain away
    sim.positions = x
    message = membrane_breach(sim, membrane)
    assert message is not None
    assert "right membrane chain" in message
    assert f"disks {membrane.right[k - 1]} and {membrane.right[k]}" in message
