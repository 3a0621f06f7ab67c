"""A hexagonal array of equal frictionless disks under biaxial load fails at
sigma_1 / sigma_3 = tan(60 deg) tan(60 deg + atan(mu)) = 3 for mu = 0.

With rows horizontal, each disk has contacts at 0, +-60 and 180 deg. In the
frictionless lattice the vertical stress goes through the four inclined
contacts, ``sigma_1 ~ 4 F_d sin^2 60``, and the horizontal stress through them
and the two horizontal ones, ``sigma_3 ~ 4 F_d cos^2 60 + 2 F_h``; the rows slide
when the horizontal contacts open (``F_h = 0``): ``sigma_1 / sigma_3 = tan^2 60 = 3``.
"""

from __future__ import annotations

import numpy as np
import pytest

from grainlab import ContactModel, Simulation


def hexagonal_box(n_cols: int, n_rows: int, r: float):
    rows = np.arange(n_rows)
    cols = np.arange(n_cols)
    x = (2 * cols[None, :] + 1 + (rows[:, None] % 2)) * r
    y = np.broadcast_to((r + rows * r * np.sqrt(3))[:, None], x.shape)
    width = (2 * n_cols + 1) * r
    height = 2 * r + (n_rows - 1) * r * np.sqrt(3)
    return np.column_stack([x.ravel(), y.ravel()]), width, height


@pytest.mark.slow
def test_frictionless_hexagonal_array_fails_at_stress_ratio_three():
    r = 1e-3
    positions, width, height = hexagonal_box(10, 12, r)
    sim = Simulation(
        positions,
        np.full(len(positions), r), density=2.0e8,
        contact_model=ContactModel(8.45e7, 8.45e7, 0.0),
        local_damping=0.7,
        threads=1,
    )
    # counter-clockwise around the box: the particles are on each wall's left
    bottom = sim.add_segment_wall((0.0, 0.0), (width, 0.0))
    right = sim.add_segment_wall((width, 0.0), (width, height))
    top = sim.add_segment_wall((width, height), (0.0, height))
    left = sim.add_segment_wall((0.0, height), (0.0, 0.0))
    sigma_3 = 1e5
    for wall, length in ((left, height), (right, height), (bottom, width), (top, width)):
        wall.servo(sigma_3, length, relaxation=0.3, max_speed_m_per_s=1e-3)
    sim.run(20_000)  # isotropic state
    assert top.normal_stress(width) == pytest.approx(sigma_3, rel=0.01)
    # shear: the top platen moves down slowly, the bottom stays, the sides keep sigma_3
    top.velocity = (0.0, -2e-5)
    bottom.velocity = (0.0, 0.0)
    ratios = []
    for _ in range(150):
        sim.run(1_000)
        h = top.points[0, 1] - bottom.points[0, 1]
        w = right.points[0, 0] - left.points[0, 0]
        s1 = 0.5 * (top.normal_stress(w) + bottom.normal_stress(w))
        s3 = 0.5 * (left.normal_stress(h) + right.normal_stress(h))
        ratios.append(s1 / s3)
    peak = max(ratios)
    assert peak == pytest.approx(np.tan(np.pi / 3) ** 2, rel=0.03)
    # and it did fail: the ratio dropped after the peak
    assert ratios[-1] < 0.9 * peak
