"""The biaxial test's own stage before shearing: the flexible boundary
installed and the shearing planned (the sample's generation and consolidation
are every test's, :mod:`grainlab.protocols.specimen`; the shearing is
:mod:`grainlab.protocols.biaxial.shearing`). The cyclic test installs its
boundary and plans its loading with the same functions."""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Sequence

import numpy as np

import grainlab
from grainlab.protocols.biaxial.config import BiaxialConfig
from grainlab.protocols.biaxial.rates import (
    default_strain_rate,
    inertial_number,
    strain_rate_problem,
)
from grainlab.protocols.biaxial.records import enclosed_area, platen_state
from grainlab.protocols.biaxial.state import (
    CHUNK_STEPS,
    BiaxialError,
    BiaxialRun,
    Boundary,
    ShearPlan,
)
from grainlab.protocols.boundary import (
    Membrane,
    WallBoundary,
    install_grain_boundary,
    install_membrane,
    set_platen_velocity,
)
from grainlab.protocols.consolidate import long_platens, servo_box
from grainlab.protocols.grains import grain_porosity
from grainlab.protocols.specimen import grain_model, platen_model
from grainlab.protocols.triggers import schedule_steps
from grainlab.simulation import Simulation, Wall

__all__ = ["check_shear_plan", "drive_platens", "install_boundary", "start_platens", "start_shear"]


def install_boundary(sim: Simulation, run: BiaxialRun, config: BiaxialConfig, progress: bool) -> None:
    """The box's walls replaced by platens three sample widths long and the lateral
    boundary of ``boundary.kind`` (the membrane, the outer grains or rigid side walls),
    Table 1 friction on, the sample re-equilibrated under sigma_0."""
    start = time.perf_counter()
    bottom, top, left_x, right_x = long_platens(sim, run.walls)
    sim.set_contact_model(0, 0, grain_model(config))  # Table 1 friction from here on
    sim.set_contact_model(0, 1, platen_model(config))
    if config.boundary.kind == "walls":
        steps = _install_walls(sim, run, config, left_x, right_x, bottom, top)
    elif config.boundary.kind == "membrane":
        steps = _install_membrane(sim, run, config, left_x, right_x, bottom, top)
    else:
        steps = _install_outer_grains(sim, run, config, bottom, top)
    run.consolidation["boundary_steps"] = steps
    run.wall_time["boundary"] = time.perf_counter() - start


def _unsettled(where: str) -> None:
    """Warns that the boundary stage ends out of equilibrium, with ``where`` the boundary stood."""
    warnings.warn(f"boundary phase: consolidation.max_steps reached with {where}: shearing starts from there",
                  RuntimeWarning, stacklevel=4)


def _install_membrane(sim: Simulation, run: BiaxialRun, config: BiaxialConfig, left_x: float, right_x: float,
                      bottom: Wall, top: Wall) -> int:
    """Variant A: the membrane chains; the sample re-equilibrated. The platens hold
    sigma_0 while the membrane takes over and friction switches on, so that shearing
    starts from an isotropic state: they stand still while their stress stays within
    the tolerance of sigma_0, and are servo-controlled to it (the engine's servo, as in
    the consolidation) from the first chunk that ends outside it until the sample is in
    equilibrium. The membrane's end disks keep their place: the platens move by
    micrometres. Returns the steps it took."""
    membrane = install_membrane(
        sim, left_x=left_x, right_x=right_x, bottom=bottom, top=top, diameter=config.boundary.membrane_diameter,
        overlap=config.boundary.membrane_overlap, bond_stiffness=config.boundary.membrane_stiffness,
        friction=config.boundary.membrane_friction, grain_model=grain_model(config),
        density=config.material.density, pressure=config.consolidation.pressure,
    )
    run.consolidation["membrane_disks"] = len(membrane.left) + len(membrane.right)
    run.boundary = membrane
    sim.time_step = config.run.time_step_safety * sim.critical_time_step(1.0)
    target, tolerance = config.consolidation.pressure, config.consolidation.tolerance
    limit = config.consolidation.unbalanced_force_ratio
    max_speed = 0.05 * config.sample.d_min / (100 * sim.time_step)
    servo, steps = False, 0
    while True:
        sim.run(CHUNK_STEPS)
        steps += CHUNK_STEPS
        platens = platen_state(sim, membrane)
        sigma_1 = platens.axial_stress_pa
        settled = abs(sigma_1 / target - 1.0) < tolerance
        if not settled or servo:
            servo = True
            for platen in (bottom, top):
                platen.servo(target, platens.width_m, relaxation=0.5, max_speed_m_per_s=max_speed)
        if settled and sim.unbalanced_force_ratio < limit:
            break
        if steps >= config.consolidation.max_steps:
            break
    if servo:
        bottom.velocity = (0.0, 0.0)
        top.velocity = (0.0, 0.0)
    if not settled:
        _unsettled(f"the platens at {sigma_1 / 1e3:.1f} kPa (sigma_0 {target / 1e3:.1f} kPa +- {tolerance:.0%})")
    run.consolidation["platen_stress_pa"] = sigma_1
    return steps


def _install_outer_grains(sim: Simulation, run: BiaxialRun, config: BiaxialConfig, bottom: Wall, top: Wall) -> int:
    """Variant B: the follower loads on the outermost grains, re-identified every chunk
    until equilibrium; returns the steps it took."""
    radii = sim.radii[: run.n_grains]
    grains = install_grain_boundary(sim, n_grains=run.n_grains, bottom=bottom, top=top,
                                    pressure=config.consolidation.pressure, bin_height=float(2 * radii.mean()))
    steps = 0
    while True:
        sim.run(CHUNK_STEPS)
        steps += CHUNK_STEPS
        grains = grains.identify(sim)
        if sim.unbalanced_force_ratio < config.consolidation.unbalanced_force_ratio or \
                steps >= config.consolidation.max_steps:
            break
    run.boundary = grains
    return steps


def _install_walls(sim: Simulation, run: BiaxialRun, config: BiaxialConfig, left_x: float, right_x: float, bottom: Wall,
                   top: Wall) -> int:
    """Variant C: rigid side walls three sample heights long where the box's were, the
    four walls servo-controlled to sigma_0 with friction on until equilibrium, then
    stopped; returns the steps it took."""
    walls = run.walls
    y0, y1 = float(bottom.points[0, 1]), float(top.points[0, 1])
    reach = y0 - (y1 - y0), y1 + (y1 - y0)
    left = sim.add_segment_wall((left_x, reach[1]), (left_x, reach[0]))  # the sample on its left, as the box's
    right = sim.add_segment_wall((right_x, reach[0]), (right_x, reach[1]))
    walls["left"], walls["right"] = left.id, right.id
    box = {"bottom": bottom, "right": right, "top": top, "left": left}
    target = config.consolidation.pressure
    state, steps, settled = servo_box(
        sim, box, target, tolerance=config.consolidation.tolerance,
        unbalanced_force_limit=config.consolidation.unbalanced_force_ratio,
        max_steps=config.consolidation.max_steps,
        max_speed_m_per_s=0.05 * config.sample.d_min / (100 * sim.time_step), chunk_steps=CHUNK_STEPS)
    for wall in box.values():
        wall.velocity = (0.0, 0.0)
    if not settled:
        _unsettled(f"the walls at {state.stress_xx_pa / 1e3:.1f} and {state.stress_yy_pa / 1e3:.1f} kPa "
                   f"(sigma_0 {target / 1e3:.1f} kPa)")
    run.consolidation["platen_stress_pa"] = state.stress_yy_pa
    run.boundary = WallBoundary(left.id, right.id, bottom.id, top.id, target, config.shear.volume == "constant")
    return steps


def start_shear(sim: Simulation, run: BiaxialRun, config: BiaxialConfig) -> None:
    """The platens set moving at the axial strain rate, the shearing planned to
    ``shear.final_strain`` (snapshots at ``shear.snapshot_strains``)."""
    final = config.shear.final_strain
    start_platens(sim, run, config, final=final,
                  snapshots=[s for s in config.shear.snapshot_strains if s <= final + 1e-12])


def drive_platens(sim: Simulation, boundary: Boundary, speed: float) -> None:
    """Each platen moves towards the other at ``speed`` (m/s; negative: apart)."""
    if isinstance(boundary, Membrane):
        set_platen_velocity(sim, boundary, speed)
    else:
        sim.wall(boundary.bottom_wall).velocity = (0.0, speed)
        sim.wall(boundary.top_wall).velocity = (0.0, -speed)


def start_platens(sim: Simulation, run: BiaxialRun, config: BiaxialConfig, *, final: float,
                  snapshots: Sequence[float], turns: Sequence[float] = ()) -> None:
    """The platens set approaching each other at ``shear.strain_rate`` and the loading
    planned over ``final`` of *strain path* (the axial strain travelled, whatever its
    direction): records every ``shear.record_interval`` and at each snapshot and turn,
    snapshots at the path strains ``snapshots``, the platens' direction reversed at the
    path strains ``turns`` (:class:`ShearPlan`; a monotonic test has none)."""
    boundary = run.lateral_boundary()
    grains = np.arange(run.n_grains)
    radii = sim.radii[grains]
    rate = config.shear.strain_rate
    max_d = float(2 * radii.max())
    if isinstance(rate, str):  # "auto"
        rate = default_strain_rate(config, config.sample.d_max, 0.5 * config.sample.d_min)
    bottom, top = sim.wall(boundary.bottom_wall), sim.wall(boundary.top_wall)
    height0 = float(top.points[0, 1] - bottom.points[0, 1])
    area0 = enclosed_area(sim, boundary)
    speed = 0.5 * rate * height0
    drive_platens(sim, boundary, speed)
    dt = sim.time_step
    steps_per_strain = 1.0 / (rate * dt)
    record_steps = schedule_steps(config.shear.record_interval, [*turns, *snapshots], final=final,
                                  steps_per_unit=steps_per_strain)
    root = math.sqrt(config.material.density / config.consolidation.pressure)
    run.shear = ShearPlan(
        strain_rate=rate,
        platen_speed_m_per_s=speed,
        height0=height0,
        area0=area0,
        start_step=sim.step_count,
        record_steps=record_steps,
        snapshot_steps={str(round(s * steps_per_strain)): s for s in snapshots},
        inertial_number=inertial_number(config, rate, max_d),
        inertial_number_mean_diameter=rate * float(2 * radii.mean()) * root,
        density_scaling_factor=grainlab.density_scaling_factor(
            rate, config.material.density, float(radii.min()), config.material.limiting_contact_pressure
        ),
        porosity_initial=grain_porosity(sim, run.n_grains, area0),
        turn_steps=[round(t * steps_per_strain) for t in turns],
    )


def check_shear_plan(sim: Simulation, run: BiaxialRun, config: BiaxialConfig, snapshots: Sequence[float] | None = None,
                     key: str = "shear.snapshot_strains") -> None:
    """The shearing phase's records and snapshots (path strains ``snapshots``, default
    ``shear.snapshot_strains`` up to ``shear.final_strain``; ``key`` names them in the
    error) fall on distinct time steps, checked with the run's own time step before the
    first record."""
    shear = run.shear_plan()
    problem = strain_rate_problem(
        shear.strain_rate, sim.time_step, shear.height0, float(sim.radii.min()), config.shear.record_interval
    )
    if problem is not None:
        raise BiaxialError(f"shear.strain_rate: {problem}; start again with a slower rate in another folder")
    wanted = ([s for s in config.shear.snapshot_strains if s <= config.shear.final_strain + 1e-12]
              if snapshots is None else list(snapshots))
    if len(shear.snapshot_steps) < len(wanted):
        raise BiaxialError(
            f"{key}: two of {wanted} fall on the same time step "
            f"({sim.time_step:.3g} s at {shear.strain_rate:.3g} 1/s); keep them further apart"
        )
