"""Servo control of a rectangular box of four walls to an isotropic stress: the
consolidation of the biaxial test and of ``grainlab demo``.

Each chunk of steps, every wall is servo-controlled (PFC-style, the engine's
:meth:`~grainlab.simulation.Wall.servo`) to the target over its current loaded
length, the chunk runs, and the box's stresses are measured; it stops when both
are within ``tolerance`` of the target and the mean unbalanced force ratio is
below ``unbalanced_force_limit``, or after ``max_steps``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from grainlab.simulation import Simulation, Wall

__all__ = ["BOX_WALLS", "BoxState", "add_platens", "box_state", "long_platens", "servo_box"]

#: The walls of a box, in the order the box is built (counter-clockwise from the bottom).
BOX_WALLS = ("bottom", "right", "top", "left")


@dataclass(frozen=True)
class BoxState:
    """The box's mean normal stresses (Pa, compression positive) and size (m)."""

    stress_xx_pa: float
    stress_yy_pa: float
    width_m: float
    height_m: float


def box_state(walls: Mapping[str, Wall]) -> BoxState:
    """Stresses from the mean of the opposite walls' forces over the box's current size."""
    bottom, right, top, left = (walls[k] for k in BOX_WALLS)
    width = float(right.points[0, 0] - left.points[0, 0])
    height = float(top.points[0, 1] - bottom.points[0, 1])
    sxx = 0.5 * (left.normal_stress(height) + right.normal_stress(height))
    syy = 0.5 * (bottom.normal_stress(width) + top.normal_stress(width))
    return BoxState(sxx, syy, width, height)


def servo_box(
    sim: Simulation,
    walls: Mapping[str, Wall],
    pressure_pa: float,
    *,
    tolerance: float,
    unbalanced_force_limit: float,
    max_steps: int,
    max_speed_m_per_s: float,
    chunk_steps: int = 2000,
    relaxation: float = 0.5,
    after_chunk: Callable[[BoxState, int], None] | None = None,
) -> tuple[BoxState, int, bool]:
    """Servo-controls the box to ``pressure_pa``: ``(final state, steps run,
    converged)``. ``after_chunk(state, steps)`` is called after every chunk (records,
    progress)."""
    steps = 0
    while True:
        state = box_state(walls)
        for name, length in zip(BOX_WALLS, (state.width_m, state.height_m) * 2, strict=True):
            walls[name].servo(pressure_pa, length, relaxation=relaxation, max_speed_m_per_s=max_speed_m_per_s)
        sim.run(chunk_steps)
        steps += chunk_steps
        state = box_state(walls)
        if after_chunk is not None:
            after_chunk(state, steps)
        if (
            abs(state.stress_xx_pa / pressure_pa - 1) < tolerance
            and abs(state.stress_yy_pa / pressure_pa - 1) < tolerance
            and sim.unbalanced_force_ratio < unbalanced_force_limit
        ):
            return state, steps, True
        if steps >= max_steps:
            return state, steps, False


def long_platens(sim: Simulation, walls: dict[str, int]) -> tuple[Wall, Wall, float, float]:
    """The box's four walls switched off and its top and bottom replaced by platens three
    sample widths long (so that the sample can widen and still bear on them), their ids
    put in ``walls``; returns the platens (bottom, top) and the box's side positions."""
    left_x = float(sim.wall(walls["left"]).points[0, 0])
    right_x = float(sim.wall(walls["right"]).points[0, 0])
    y_bottom = float(sim.wall(walls["bottom"]).points[0, 1])
    y_top = float(sim.wall(walls["top"]).points[0, 1])
    for name in BOX_WALLS:
        sim.wall(walls[name]).active = False
    bottom, top = add_platens(sim, walls, (left_x - (right_x - left_x), right_x + (right_x - left_x)), y_bottom, y_top)
    return bottom, top, left_x, right_x


def add_platens(sim: Simulation, walls: dict[str, int], reach: tuple[float, float], y_bottom: float,
                y_top: float) -> tuple[Wall, Wall]:
    """Two horizontal platens from ``reach[0]`` to ``reach[1]`` in x, at ``y_bottom`` (the
    sample above) and ``y_top`` (the sample below), their ids put in ``walls``."""
    bottom = sim.add_segment_wall((reach[0], y_bottom), (reach[1], y_bottom))
    top = sim.add_segment_wall((reach[1], y_top), (reach[0], y_top))
    walls["bottom"], walls["top"] = bottom.id, top.id
    return bottom, top
