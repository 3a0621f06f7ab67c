"""The biaxial test's own phases: install the boundary, start and run the
shearing (the sample's generation and consolidation are every test's,
:mod:`grainlab.protocols.specimen`). Each takes the simulation, the run state
and the configuration; :mod:`grainlab.protocols.biaxial.protocol` lists them as
the protocol's stages, and the runner moves the run from one to the next."""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

import grainlab
from grainlab._interrupt import raise_if_interrupted
from grainlab._progress import progress_bar
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO
from grainlab.io.hdf5 import ResultsWriter, snapshot_name
from grainlab.protocols.biaxial.rates import (
    default_strain_rate,
    inertial_number,
    strain_rate_problem,
)
from grainlab.protocols.biaxial.records import (
    TIMESERIES_UNITS,
    _area,
    _measure,
    _platens,
    _snapshot,
    _walls,
)
from grainlab.protocols.biaxial.state import (
    CHUNK_STEPS,
    BiaxialError,
    Boundary,
    ShearPlan,
    _boundary,
    _Run,
)
from grainlab.protocols.boundary import (
    GrainBoundary,
    Membrane,
    WallBoundary,
    install_grain_boundary,
    install_membrane,
    membrane_breach,
    set_platen_velocity,
)
from grainlab.protocols.config import BiaxialConfig
from grainlab.protocols.consolidate import servo_box
from grainlab.protocols.specimen import grain_model, platen_model
from grainlab.protocols.triggers import At, Every, WallClock, schedule_steps
from grainlab.simulation import Simulation, Wall

#: Steps between two settings of rigid side walls' motion while shearing (variant C).
WALL_CONTROL_STEPS = 100


def install_boundary(sim: Simulation, run: _Run, config: BiaxialConfig, progress: bool) -> None:
    start = time.perf_counter()
    walls = run.walls
    left_x = float(sim.wall(walls["left"]).points[0, 0])
    right_x = float(sim.wall(walls["right"]).points[0, 0])
    y_bottom = float(sim.wall(walls["bottom"]).points[0, 1])
    y_top = float(sim.wall(walls["top"]).points[0, 1])
    # the rigid box goes; platens three sample widths long take the place of its
    # top and bottom, so that the sample can bulge and still bear on them
    for name in ("left", "right", "bottom", "top"):
        sim.wall(walls[name]).active = False
    reach = left_x - (right_x - left_x), right_x + (right_x - left_x)
    bottom = sim.add_segment_wall((reach[0], y_bottom), (reach[1], y_bottom))  # sample on the left
    top = sim.add_segment_wall((reach[1], y_top), (reach[0], y_top))
    walls["bottom"], walls["top"] = bottom.id, top.id
    sim.set_contact_model(0, 0, grain_model(config))  # Table 1 friction from here on
    sim.set_contact_model(0, 1, platen_model(config))
    limit = config["consolidation.unbalanced_force_ratio"]
    steps = 0
    if config["boundary.kind"] == "walls":
        steps = _install_walls(sim, run, config, left_x, right_x, bottom, top)
    elif config["boundary.kind"] == "membrane":
        membrane = install_membrane(
            sim,
            left_x=left_x,
            right_x=right_x,
            bottom=bottom,
            top=top,
            diameter=config["boundary.membrane_diameter"],
            overlap=config["boundary.membrane_overlap"],
            bond_stiffness=config["boundary.membrane_stiffness"],
            friction=config["boundary.membrane_friction"],
            grain_model=grain_model(config),
            density=config["material.density"],
            pressure=config["consolidation.pressure"],
        )
        run.consolidation["membrane_disks"] = len(membrane.left) + len(membrane.right)
        run.membrane = membrane.to_dict()
        sim.time_step = config["run.time_step_safety"] * sim.critical_time_step(1.0)
        # The platens hold sigma_0 while the membrane takes over and friction
        # switches on, so that shearing starts from an isotropic state: they
        # stand still while their stress stays within the tolerance of sigma_0,
        # and are servo-controlled to it (the engine's servo, as in the
        # consolidation) from the first chunk that ends outside it until the
        # sample is in equilibrium. The membrane's end disks keep their place: the
        # platens move by micrometres.
        target = config["consolidation.pressure"]
        tolerance = config["consolidation.tolerance"]
        max_speed = 0.05 * config["sample.d_min"] / (100 * sim.time_step)
        servo = False
        while True:
            sim.run(CHUNK_STEPS)
            steps += CHUNK_STEPS
            platens = _platens(sim, membrane)
            sigma_1 = platens.axial_stress_pa
            settled = abs(sigma_1 / target - 1.0) < tolerance
            if not settled or servo:
                servo = True
                for platen in (bottom, top):
                    platen.servo(target, platens.width_m, relaxation=0.5, max_speed_m_per_s=max_speed)
            if settled and sim.unbalanced_force_ratio < limit:
                break
            if steps >= config["consolidation.max_steps"]:
                break
        if servo:
            bottom.velocity = (0.0, 0.0)
            top.velocity = (0.0, 0.0)
        if not settled:
            warnings.warn(
                f"boundary phase: consolidation.max_steps reached with the platens at {sigma_1 / 1e3:.1f} kPa "
                f"(sigma_0 {target / 1e3:.1f} kPa +- {tolerance:.0%}): shearing starts from there",
                RuntimeWarning,
                stacklevel=2,
            )
        run.consolidation["platen_stress_pa"] = sigma_1
    else:
        radii = sim.radii[: run.n_grains]
        grains = install_grain_boundary(
            sim,
            n_grains=run.n_grains,
            bottom=bottom,
            top=top,
            pressure=config["consolidation.pressure"],
            bin_height=float(2 * radii.mean()),
        )
        while True:
            sim.run(CHUNK_STEPS)
            steps += CHUNK_STEPS
            grains = grains.identify(sim)
            if sim.unbalanced_force_ratio < limit or steps >= config["consolidation.max_steps"]:
                break
        run.membrane = grains.to_dict()
    run.consolidation["boundary_steps"] = steps
    run.wall_time["boundary"] = time.perf_counter() - start


def _install_walls(sim: Simulation, run: _Run, config: Any, left_x: float, right_x: float, bottom: Wall,
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
    target = config["consolidation.pressure"]
    state, steps, settled = servo_box(
        sim, box, target, tolerance=config["consolidation.tolerance"],
        unbalanced_force_limit=config["consolidation.unbalanced_force_ratio"],
        max_steps=config["consolidation.max_steps"],
        max_speed_m_per_s=0.05 * config["sample.d_min"] / (100 * sim.time_step), chunk_steps=CHUNK_STEPS)
    for wall in box.values():
        wall.velocity = (0.0, 0.0)
    if not settled:
        warnings.warn(
            f"boundary phase: consolidation.max_steps reached with the walls at {state.stress_xx_pa / 1e3:.1f} and "
            f"{state.stress_yy_pa / 1e3:.1f} kPa (sigma_0 {target / 1e3:.1f} kPa): shearing starts from there",
            RuntimeWarning,
            stacklevel=3,
        )
    run.consolidation["platen_stress_pa"] = state.stress_yy_pa
    run.membrane = WallBoundary(left.id, right.id, bottom.id, top.id, target,
                                config["shear.volume"] == "constant").to_dict()
    return steps


def start_shear(sim: Simulation, run: _Run, config: BiaxialConfig) -> None:
    """The platens set moving at the axial strain rate, the shearing planned to
    ``shear.final_strain`` (records ``Every(shear.record_interval)``, snapshots
    ``At(shear.snapshot_strains)``)."""
    final = config["shear.final_strain"]
    snaps = [s for s in config["shear.snapshot_strains"] if s <= final + 1e-12]
    start_platens(sim, run, config, final=final, records=[Every(config["shear.record_interval"]), At(snaps)],
                  snapshots=snaps)


def drive_platens(sim: Simulation, boundary: Boundary, speed: float) -> None:
    """Each platen moves towards the other at ``speed`` (m/s; negative: apart)."""
    if isinstance(boundary, Membrane):
        set_platen_velocity(sim, boundary, speed)
    else:
        sim.wall(boundary.bottom_wall).velocity = (0.0, speed)
        sim.wall(boundary.top_wall).velocity = (0.0, -speed)


def start_platens(sim: Simulation, run: _Run, config: Any, *, final: float, records: Sequence[Any],
                  snapshots: Sequence[float], turns: Sequence[float] = ()) -> None:
    """The platens set approaching each other at ``shear.strain_rate`` and the loading
    planned over ``final`` of *strain path* (the axial strain travelled, whatever its
    direction): records on the ``records`` triggers, snapshots at the path strains
    ``snapshots``, the platens' direction reversed at the path strains ``turns``
    (:class:`ShearPlan`; a monotonic test has none)."""
    boundary = _boundary(run)
    grains = np.arange(run.n_grains)
    radii = sim.radii[grains]
    rate = config["shear.strain_rate"]
    max_d = float(2 * radii.max())
    if rate == "auto":
        rate = default_strain_rate(config, config["sample.d_max"], 0.5 * config["sample.d_min"])
    bottom, top = sim.wall(boundary.bottom_wall), sim.wall(boundary.top_wall)
    height0 = float(top.points[0, 1] - bottom.points[0, 1])
    area0 = _area(sim, boundary)
    speed = 0.5 * rate * height0
    drive_platens(sim, boundary, speed)
    dt = sim.time_step
    steps_per_strain = 1.0 / (rate * dt)
    record_steps = schedule_steps(list(records), final=final, steps_per_unit=steps_per_strain)
    root = math.sqrt(config["material.density"] / config["consolidation.pressure"])
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
            rate, config["material.density"], float(radii.min()), config["material.limiting_contact_pressure"]
        ),
        porosity_initial=1.0 - float(np.pi * np.sum(radii**2)) / area0,
        turn_steps=[round(t * steps_per_strain) for t in turns],
    )


def shear(
    sim: Simulation,
    run: _Run,
    config: Any,
    writer: ResultsWriter,
    save: Callable[[], None],
    progress: bool,
    *,
    final: float | None = None,
    snapshot_name_of: Callable[[float], str] = snapshot_name,
    extra: Callable[[int], dict[str, float]] | None = None,
    units: Mapping[str, str] = TIMESERIES_UNITS,
    rule: Callable[[Simulation, _Run], str] | None = None,
    event_snapshot: Callable[[int], str | None] | None = None,
) -> None:
    """Runs the planned loading (:func:`start_platens`) to its end: the platens reversed
    at the plan's turns, a record (with ``extra(steps since the start)``'s columns, in
    ``units``) on each record step, a snapshot named ``snapshot_name_of(path strain)``
    on each snapshot step, a checkpoint on the wall clock; ``final`` (default
    ``shear.final_strain``) is the path strain the progress counts to.

    A ``rule(sim, run)`` (a stress-controlled cyclic test's) is asked every
    WALL_CONTROL_STEPS steps between records; it answers ``""``, ``"turn"`` (the
    platens reverse there), ``"mark"`` or ``"end"`` (the loading stops there). Each
    answer but ``""`` is an event: counted in the plan, recorded, and stored as a
    snapshot when ``event_snapshot(events so far)`` names one."""
    start = time.perf_counter() - run.wall_time.get("shear", 0.0)
    plan = run.shear_plan()
    steps = plan.record_steps
    snap_steps = plan.snapshot_steps
    final = config["shear.final_strain"] if final is None else final

    def record() -> dict[str, float]:
        values = _measure(sim, run, config)
        if extra is not None:
            values.update(extra(sim.step_count - plan.start_step))
        return values

    boundary = _boundary(run)
    walls = boundary if isinstance(boundary, WallBoundary) else None
    wall_speed = 0.05 * float(sim.radii[: run.n_grains].min()) / (50 * sim.time_step)

    last_event: dict[str, Any] = {"step": -1, "values": {}}

    def on_event(answer: str) -> None:
        """An event of the rule: counted, recorded and (when named) stored; the
        platens reversed at a turn; the loading ended at the end."""
        plan.events += 1
        if answer == "turn":
            plan.turn_steps.append(sim.step_count - plan.start_step)
            _reverse(sim, run, plan)
        values = record()
        writer.append_timeseries(values, units=units)
        last_event.update(step=sim.step_count, values=values)
        name = None if event_snapshot is None else event_snapshot(plan.events)
        if name is not None:
            writer.write_snapshot(name, _snapshot(sim, run, values[AXIAL_STRAIN]), step=sim.step_count,
                                  walls=_walls(sim, run))
        if answer == "end":
            plan.next_record = len(steps)

    def advance(to_step: int) -> bool:
        """Runs to ``to_step``; rigid side walls are controlled, and the rule asked,
        every WALL_CONTROL_STEPS. False when the rule ended the loading on the way."""
        if walls is None and rule is None:
            sim.run(to_step - sim.step_count)
            return True
        while sim.step_count < to_step:
            n = min(WALL_CONTROL_STEPS, to_step - sim.step_count)
            if walls is not None:
                walls.control(sim, n, plan.area0, wall_speed)
            sim.run(n)
            answer = "" if rule is None else rule(sim, run)
            if answer:
                on_event(answer)
                if answer == "end":
                    return False
        return True

    if plan.next_record == 0 and "0" in snap_steps and writer.n_rows == 0:
        first = record()
        writer.append_timeseries(first, units=units)
        writer.write_snapshot(snapshot_name_of(0.0), _snapshot(sim, run, 0.0), step=sim.step_count,
                              walls=_walls(sim, run))
    checkpoint_due = WallClock(config["run.checkpoint_interval"])
    done = 100 * final * steps[plan.next_record - 1] / steps[-1] if plan.next_record and steps[-1] else 0.0
    bar = progress_bar(
        round(100 * final, 3),
        "shearing",
        enabled=progress,
        unit="% strain",
        initial=done,
        bar_format="{l_bar}{bar}| {n:.2f}/{total:.1f} % [{elapsed}<{remaining}{postfix}]",
    )
    while plan.next_record < len(steps):
        target = plan.start_step + steps[plan.next_record]
        turn = plan.start_step + plan.turn_steps[plan.next_turn] if plan.next_turn < len(plan.turn_steps) else None
        if turn is not None and turn < target:
            advance(turn)
            _reverse(sim, run, plan)
            continue
        if not advance(target):
            break
        if last_event["step"] == sim.step_count:  # an event's record is this step's
            values = last_event["values"]
        else:
            values = record()
            writer.append_timeseries(values, units=units)
        key = str(steps[plan.next_record])
        if key in snap_steps:
            writer.write_snapshot(snapshot_name_of(snap_steps[key]), _snapshot(sim, run, values[AXIAL_STRAIN]),
                                  step=sim.step_count, walls=_walls(sim, run))
        boundary = _boundary(run)
        if isinstance(boundary, GrainBoundary):
            run.membrane = boundary.identify(sim).to_dict()
        elif isinstance(boundary, Membrane):
            breach = membrane_breach(sim, boundary)
            if breach is not None:
                bar.close()
                raise BiaxialError(
                    f"shearing stopped at {100 * values[AXIAL_STRAIN]:.2f} % axial strain: {breach}"
                )
        plan.next_record += 1
        if turn == target:  # a turning point recorded: reversed after its record
            _reverse(sim, run, plan)
        raise_if_interrupted()
        path = 100 * final * steps[plan.next_record - 1] / steps[-1]
        bar.update(path - done)
        done = path
        bar.set_postfix_str(f"ratio {values[STRESS_RATIO]:.2f}")
        if checkpoint_due():
            run.wall_time["shear"] = time.perf_counter() - start
            save()
    bar.close()
    run.wall_time["shear"] = time.perf_counter() - start


def _reverse(sim: Simulation, run: _Run, plan: ShearPlan) -> None:
    """The platens reversed at the plan's next turn: compression after an even number of
    turns, extension after an odd one."""
    plan.next_turn += 1
    drive_platens(sim, _boundary(run), plan.platen_speed_m_per_s * (-1.0) ** plan.next_turn)


def check_shear_plan(sim: Simulation, run: _Run, config: Any, snapshots: Sequence[float] | None = None,
                     key: str = "shear.snapshot_strains") -> None:
    """The shearing phase's records and snapshots (path strains ``snapshots``, default
    ``shear.snapshot_strains`` up to ``shear.final_strain``; ``key`` names them in the
    error) fall on distinct time steps, checked with the run's own time step before the
    first record."""
    shear = run.shear_plan()
    problem = strain_rate_problem(
        shear.strain_rate, sim.time_step, shear.height0, float(sim.radii.min()), config["shear.record_interval"]
    )
    if problem is not None:
        raise BiaxialError(f"shear.strain_rate: {problem}; start again with a slower rate in another folder")
    wanted = ([s for s in config["shear.snapshot_strains"] if s <= config["shear.final_strain"] + 1e-12]
              if snapshots is None else list(snapshots))
    if len(shear.snapshot_steps) < len(wanted):
        raise BiaxialError(
            f"{key}: two of {wanted} fall on the same time step "
            f"({sim.time_step:.3g} s at {shear.strain_rate:.3g} 1/s); keep them further apart"
        )
