"""The paper's biaxial test, end to end (Sec. 6, Table 1).

Phases, each run by the engine in blocks of steps:

1. **generate**: random placement at half radii inside four rigid walls and
   radius expansion to the target nominal porosity (:mod:`grainlab.samples`).
2. **consolidate**: Table 1 friction; the four walls are servo-controlled to
   ``sigma_0`` until every wall stress is within the tolerance and the mean
   unbalanced force ratio is below its threshold.
3. **boundary**: the side walls are switched off and replaced by the bonded
   membrane chains under the confining pressure (follower load); the sample
   re-equilibrates with the platens holding ``sigma_0`` (servo-controlled once
   their stress leaves the tolerance), so shearing starts isotropic. (Variant B,
   the outermost grains as boundary, keeps its platens still.)
4. **shear**: the platens approach each other at a constant axial strain rate
   to the final strain while the confining pressure stays constant; a record
   every ``shear.record_interval`` of axial strain, full snapshots at the
   chosen strains.

Everything lands in one results folder: ``run.h5`` (config, time series,
snapshots, summary, phase times), ``timeseries.csv``, ``summary.json`` and the
figures. A ``checkpoint.h5`` is written after each phase and during shearing;
``run_biaxial(..., resume=True)`` continues a killed run and ends with the same
results as an uninterrupted one (same config, same thread count).

Sign conventions: stresses and strains compression positive; axial strain
``(H0 - H) / H0``, volumetric (area) strain ``(A0 - A) / A0`` from the
membrane polygon, both from the start of shearing.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import grainlab
from grainlab._interrupt import raise_if_interrupted
from grainlab._mapping import flatten_keys
from grainlab._progress import progress_bar
from grainlab.analysis import fabric_summary
from grainlab.analysis.stress import love_weber_stress
from grainlab.io.hdf5 import (
    PARTIAL_SUFFIX,
    ResultsWriter,
    read_checkpoint,
    snapshot_name,
    write_checkpoint,
)
from grainlab.io.results import (
    CHECKPOINT_FILE,
    RESULTS_FILE,
    ensure_output_folder,
    is_disk_full,
    refuse_overwrite,
    write_json_atomic,
    write_text_atomic,
)
from grainlab.io.walls import WallGeometry
from grainlab.protocols.boundary import (
    GrainBoundary,
    Membrane,
    install_grain_boundary,
    install_membrane,
    membrane_breach,
    sample_area,
    set_platen_velocity,
)
from grainlab.protocols.config import BiaxialConfig
from grainlab.protocols.consolidate import BOX_WALLS, BoxState, servo_box
from grainlab.samples import (
    PAPER_GRADING,
    GradingCurve,
    UniformByMass,
    UniformByNumber,
    expand_to_porosity,
    overlap_corrected_porosity,
)
from grainlab.simulation import ContactModel, Simulation
from grainlab.snapshot import ParticleKind

#: Steps per engine call while a phase waits for a condition.
CHUNK_STEPS = 2000

#: The paper's reported values, for the summary and the docs.
PAPER_VALUES = {
    "coordination_number_initial": 3.9,
    "coordination_number_at_peak": 3.0,
    "axial_strain_at_peak": 0.015,
}

TIMESERIES_UNITS = {
    "anisotropy": "1",
    "anisotropy_direction_rad": "rad",
    "anisotropy_binned": "1",
    "anisotropy_fourier": "1",
    "force_anisotropy": "1",
    "force_anisotropy_binned": "1",
    "mean_stability_index": "1",
    "mean_stability_index_all": "1",
    "mechanical_coordination_number": "1",
    "step": "1",
    "time_s": "s",
    "axial_strain": "1",
    "axial_stress_pa": "Pa",
    "confining_pressure_pa": "Pa",
    "confining_stress_felt_pa": "Pa",
    "stress_ratio": "1",
    "stress_ratio_mobilised": "1",
    "volumetric_strain": "1",
    "area_m2": "m^2",
    "height_m": "m",
    "love_weber_xx_pa": "Pa",
    "love_weber_yy_pa": "Pa",
    "love_weber_xy_pa": "Pa",
    "coordination_number": "1",
    "unbalanced_force_ratio": "1",
    "kinetic_energy_j": "J",
    "elastic_energy_j": "J",
    "friction_dissipated_j": "J",
    "damping_dissipated_j": "J",
    "boundary_work_j": "J",
    "wall_work_j": "J",
}


class DensityScalingWarning(UserWarning):
    """The strain rate makes the density-scaled sample too dynamic (paper Eq. 16)."""


#: DESIGN §3: above this density scaling factor (paper Eq. 16) a run is warned about.
DENSITY_SCALING_LIMIT = 1.0e-3


def check_density_scaling(config: BiaxialConfig) -> float | None:
    """The Eq. 16 factor of an explicit ``shear.strain_rate`` (smallest grain,
    ``sample.d_min / 2``, and the limiting contact pressure ``p_y``,
    ``material.limiting_contact_pressure``), with a :class:`DensityScalingWarning`
    when it exceeds :data:`DENSITY_SCALING_LIMIT`; ``None`` for the ``auto``
    rate, which keeps the factor at or below ``shear.inertial_number``."""
    rate = config["shear.strain_rate"]
    if rate == "auto":
        return None
    factor = grainlab.density_scaling_factor(
        rate, config["material.density"], 0.5 * config["sample.d_min"], config["material.limiting_contact_pressure"]
    )
    if factor > DENSITY_SCALING_LIMIT:
        warnings.warn(
            f"shear.strain_rate = {rate:g} 1/s gives a density scaling factor (paper Eq. 16) of "
            f"{factor:.1e}, above {DENSITY_SCALING_LIMIT:g}: inertia may change the result; "
            "lower the strain rate or the density, or use the auto rate",
            DensityScalingWarning,
            stacklevel=3,
        )
    return factor


#: A record interval must span at least this many time steps, so that every
#: record and snapshot lies within 1/20 of a record interval of its strain.
MIN_STEPS_PER_RECORD = 10
#: The farthest a platen may travel in one time step, as a fraction of the
#: smallest particle's radius (typical contact overlaps are below 1 % of it).
MAX_PLATEN_TRAVEL_PER_STEP = 0.01


def strain_rate_problem(
    rate: float, time_step_s: float, height_m: float, min_radius_m: float, record_interval: float
) -> str | None:
    """Why shearing at ``rate`` (1/s) with time step ``time_step_s`` cannot give
    meaningful records, or None when it can: a record interval spanning fewer
    than :data:`MIN_STEPS_PER_RECORD` steps, or a platen (each moves at
    ``rate * height / 2``) travelling more than :data:`MAX_PLATEN_TRAVEL_PER_STEP`
    of the smallest radius in one step. The message ends with the fastest rate
    that this time step allows.

    >>> strain_rate_problem(0.02 / 60, 1e-4, 0.15, 0.25e-3, 0.0005) is None
    True
    >>> print(strain_rate_problem(10.0, 1e-4, 0.15, 0.25e-3, 0.0005))
    one time step (0.0001 s) shears the sample by 0.001, so a record interval (0.0005) spans 0.5 steps, fewer than 10; this time step allows at most 0.333 1/s
    """
    strain_per_step = rate * time_step_s
    steps_per_record = record_interval / strain_per_step
    travel = 0.5 * rate * height_m * time_step_s
    fastest = min(
        record_interval / (MIN_STEPS_PER_RECORD * time_step_s),
        MAX_PLATEN_TRAVEL_PER_STEP * min_radius_m / (0.5 * height_m * time_step_s),
    )
    if steps_per_record < MIN_STEPS_PER_RECORD:
        why = (
            f"one time step ({time_step_s:.3g} s) shears the sample by {strain_per_step:.3g}, so a record "
            f"interval ({record_interval:g}) spans {steps_per_record:.3g} steps, fewer than {MIN_STEPS_PER_RECORD}"
        )
    elif travel > MAX_PLATEN_TRAVEL_PER_STEP * min_radius_m:
        why = (
            f"each platen moves {travel:.3g} m in one time step ({time_step_s:.3g} s), "
            f"{travel / min_radius_m:.1%} of the smallest radius ({MAX_PLATEN_TRAVEL_PER_STEP:.0%} allowed)"
        )
    else:
        return None
    return f"{why}; this time step allows at most {fastest:.3g} 1/s"


def check_strain_rate(config: BiaxialConfig) -> None:
    """Refuse, before any work, an explicit ``shear.strain_rate`` too fast for
    any time step the run can have (:func:`strain_rate_problem`), and snapshot
    strains that share a name. The time step is known only after the
    consolidation (:meth:`Simulation.critical_time_step`, from the contacts);
    this check takes a tenth of the one-contact critical step of the smallest
    particle (grain or membrane disk), below any the run reaches, and the run
    checks its own time step again before shearing."""
    names: dict[str, float] = {}
    for strain in config["shear.snapshot_strains"]:
        name = snapshot_name(strain)
        if name in names:
            raise ValueError(
                f"shear.snapshot_strains: {names[name]:g} and {strain:g} share the snapshot name {name!r}; "
                "keep snapshot strains at least 0.0001 apart"
            )
        names[name] = strain
    rate = config["shear.strain_rate"]
    if rate == "auto":
        return  # bounded by the inertial number, far below these limits
    diameter = config["sample.d_min"]
    if config["boundary.kind"] == "membrane":
        diameter = min(diameter, config["boundary.membrane_diameter"])
    radius = 0.5 * diameter
    mass = config["material.density"] * math.pi * radius**2
    stiffness = max(config["material.normal_stiffness"], 2.0 * config["material.shear_stiffness"])
    time_step = 0.1 * config["run.time_step_safety"] * math.sqrt(mass / stiffness)
    problem = strain_rate_problem(rate, time_step, config["sample.height"], radius, config["shear.record_interval"])
    if problem is not None:
        raise ValueError(
            f"shear.strain_rate: {rate:g} 1/s is too fast even for a time step shorter than any this sample "
            f"reaches: {problem} (the run checks its own, longer time step again before shearing)"
        )


class BiaxialError(RuntimeError):
    """The test could not proceed (e.g. consolidation did not converge)."""


@dataclass
class _Run:
    """What a run carries from phase to phase, saved in every checkpoint."""

    phase: str
    n_grains: int
    grain_density: float
    walls: dict[str, int]
    wall_time: dict[str, float]
    sample: dict[str, Any]
    consolidation: dict[str, Any]
    membrane: dict[str, Any] | None = None
    shear: dict[str, Any] | None = None
    rows: int = 0
    snapshots: list[str] | None = None
    peak: dict[str, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def _grading(config: BiaxialConfig):
    kind = config["sample.grading"]
    d_min, d_max = config["sample.d_min"], config["sample.d_max"]
    if kind == "uniform_by_number":
        return UniformByNumber(d_min, d_max)
    if kind == "uniform_by_mass":
        return UniformByMass(d_min, d_max)
    if kind == "curve":
        return GradingCurve(config["sample.sieve_sizes"], config["sample.percent_passing"])
    if (d_min, d_max) != (PAPER_GRADING.d_min, PAPER_GRADING.d_max):
        raise ValueError(
            "sample.grading: 'paper' is the 0.5-3 mm curve; with other sample.d_min/d_max "
            "choose 'uniform_by_number' or 'uniform_by_mass'"
        )
    return PAPER_GRADING


def _threads(config: BiaxialConfig) -> int:
    threads = config["run.threads"]
    return (os.cpu_count() or 1) if threads == "auto" else int(threads)


def _grain_model(config: BiaxialConfig) -> ContactModel:
    return ContactModel(
        config["material.normal_stiffness"], config["material.shear_stiffness"], config["material.friction"]
    )


def _platen_model(config: BiaxialConfig) -> ContactModel:
    return ContactModel(
        config["material.normal_stiffness"], config["material.shear_stiffness"], config["material.platen_friction"]
    )


def default_strain_rate(config: BiaxialConfig, max_diameter: float, min_radius: float) -> float:
    """The fastest axial strain rate whose inertial number and paper's Eq. 16
    factor are both at most ``shear.inertial_number`` (the ``auto`` rate; the run
    passes the grading's nominal ``sample.d_max`` and ``sample.d_min / 2``).

    The inertial number is taken for the heaviest grain and with local
    damping's effective mass ``m / (1 - alpha)``:
    ``I = rate * d_max * sqrt(rho / ((1 - alpha) sigma_3))``. The bound's default,
    1e-4, is this number at the fastest rate that the paper-scale rate study
    found converged (docs/reproduction.md): 2 %/min with Table 1, where 4 and
    8 %/min gave higher peaks and more dilation than 2 %/min beyond the seed
    scatter. For another material or sample, ``auto`` keeps that inertial
    number, which the study did not test. Eq. 16: ``rate * r_min * sqrt(rho /
    p_y)`` with the limiting contact pressure ``p_y`` (Table 1: 150 MPa), far
    from binding with Table 1.
    """
    rho, p = config["material.density"], config["consolidation.pressure"]
    alpha = config["material.local_damping"]
    bound = config["shear.inertial_number"]
    inertial = max_diameter * math.sqrt(rho / ((1.0 - alpha) * p))
    eq16 = min_radius * math.sqrt(rho / config["material.limiting_contact_pressure"])
    return bound / max(inertial, eq16)


def inertial_number(config: BiaxialConfig, rate: float, diameter: float) -> float:
    """``rate * d * sqrt(rho / ((1 - alpha) sigma_3))``."""
    rho, p = config["material.density"], config["consolidation.pressure"]
    return rate * diameter * math.sqrt(rho / ((1.0 - config["material.local_damping"]) * p))


# ---- measurements -----------------------------------------------------------


@dataclass(frozen=True)
class _Platens:
    """The platens' state: sample height and area, and the mean axial stress
    of the two platens over the sample's mean width (area over height)."""

    height_m: float
    area_m2: float
    width_m: float
    axial_stress_pa: float


def _platens(sim: Simulation, boundary: Membrane | GrainBoundary) -> _Platens:
    bottom, top = sim.wall(boundary.bottom_wall), sim.wall(boundary.top_wall)
    height = float(top.points[0, 1] - bottom.points[0, 1])
    area = _area(sim, boundary)
    width = area / height
    axial_force = 0.5 * (float(top.force[1]) - float(bottom.force[1]))
    return _Platens(height, area, width, axial_force / width)


def _measure(sim: Simulation, run: _Run, config: BiaxialConfig) -> dict[str, float]:
    """One record of the shearing phase."""
    boundary = _boundary(run)
    shear = run.shear
    platens = _platens(sim, boundary)
    height, area, sigma_1 = platens.height_m, platens.area_m2, platens.axial_stress_pa
    sigma_3 = config["consolidation.pressure"]

    c = sim.contacts()
    w = sim.wall_contacts()
    n = run.n_grains
    f_on_j = c.normal_force[:, None] * c.normal + c.shear_force[:, None] * np.column_stack(
        [-c.normal[:, 1], c.normal[:, 0]]
    )
    grain_i, grain_j = c.i < n, c.j < n
    if isinstance(boundary, Membrane):
        # confining stress the grains feel: force of the grains on the membrane, per side, over the height
        left = np.zeros(sim.n_particles, dtype=bool)
        left[boundary.left] = True
        right = np.zeros(sim.n_particles, dtype=bool)
        right[boundary.right] = True
        on_membrane = np.zeros((len(c), 2))
        on_membrane[grain_i & ~grain_j] = f_on_j[grain_i & ~grain_j]
        on_membrane[~grain_i & grain_j] = -f_on_j[~grain_i & grain_j]
        membrane_particle = np.where(grain_i, c.j, c.i)
        felt_left = -on_membrane[left[membrane_particle] & (grain_i ^ grain_j), 0].sum() / height
        felt_right = on_membrane[right[membrane_particle] & (grain_i ^ grain_j), 0].sum() / height
    else:
        # the follower loads act on the grains themselves: the pressure over the full height
        felt_left = felt_right = boundary.pressure
    wall_force = w.normal_force[:, None] * w.normal + w.shear_force[:, None] * np.column_stack(
        [-w.normal[:, 1], w.normal[:, 0]]
    )
    grains = np.zeros(sim.n_particles, dtype=bool)
    grains[:n] = True
    lw = love_weber_stress(
        sim.positions,
        c.i,
        c.j,
        c.point,
        f_on_j,
        area,
        grains,
        wall_particle=w.particle,
        wall_point=w.point,
        wall_force_on_particle=wall_force,
    )
    grain_contacts = int(np.count_nonzero(grain_i & grain_j & ~c.bonded))
    fabric = _fabric(sim, run)
    energy = sim.energy
    return {
        "step": float(sim.step_count),
        "time_s": sim.time,
        "axial_strain": (shear["height0"] - height) / shear["height0"],
        "axial_stress_pa": sigma_1,
        "confining_pressure_pa": sigma_3,
        "confining_stress_felt_pa": 0.5 * (felt_left + felt_right),
        "stress_ratio": sigma_1 / sigma_3,
        "stress_ratio_mobilised": (sigma_1 - sigma_3) / (sigma_1 + sigma_3),
        "volumetric_strain": (shear["area0"] - area) / shear["area0"],
        "area_m2": area,
        "height_m": height,
        "love_weber_xx_pa": float(lw[0, 0]),
        "love_weber_yy_pa": float(lw[1, 1]),
        "love_weber_xy_pa": float(lw[0, 1]),
        "coordination_number": 2.0 * grain_contacts / n,
        "unbalanced_force_ratio": sim.unbalanced_force_ratio,
        "kinetic_energy_j": energy["kinetic"],
        "elastic_energy_j": energy["elastic"],
        "friction_dissipated_j": energy["friction_dissipated"],
        "damping_dissipated_j": energy["damping_dissipated"],
        "boundary_work_j": energy["boundary_work"],
        "wall_work_j": energy["wall_work"],
        **fabric,
    }


def _fabric(sim: Simulation, run: _Run) -> dict[str, float]:
    """Fabric measures of the grains (membrane disks excluded as particles):
    anisotropy of contact normals and normal forces (the exact estimate, and
    Eq. 7-8 on the histogram as ``*_binned``), the mean stability index (Sec. 5)
    and the mechanical coordination number."""
    summary = fabric_summary(_snapshot(sim, run, 0.0))
    summary.pop("coordination_number")  # the record's own, grain-grain contacts
    return summary


def _boundary(run: _Run) -> Membrane | GrainBoundary:
    if run.membrane.get("kind") == GrainBoundary.kind:
        return GrainBoundary.from_dict(run.membrane)
    return Membrane.from_dict(run.membrane)


def _area(sim: Simulation, boundary: Membrane | GrainBoundary) -> float:
    return sample_area(sim, boundary) if isinstance(boundary, Membrane) else boundary.area(sim)


def _snapshot(sim: Simulation, run: _Run, strain: float):
    """The state as a snapshot: grains, membrane disks labelled by chain (left 0, right 1)."""
    kind = np.full(sim.n_particles, int(ParticleKind.SOIL), dtype=np.int8)
    kind[run.n_grains :] = int(ParticleKind.MEMBRANE)
    body = np.full(sim.n_particles, -1, dtype=np.int64)
    if run.membrane is not None and run.membrane.get("kind") == GrainBoundary.kind:
        kind[run.membrane["left"] + run.membrane["right"]] = int(ParticleKind.BOUNDARY)
    elif run.membrane is not None:
        body[run.membrane["left"]] = 0
        body[run.membrane["right"]] = 1
    snap = sim.snapshot(kind=kind, axial_strain=strain, step=sim.step_count)
    return snap.with_boundary_bodies(body)


# ---- phases -----------------------------------------------------------------


def _generate(config: BiaxialConfig, threads: int, progress: bool) -> tuple[Simulation, _Run]:
    start = time.perf_counter()
    box = (0.0, 0.0, config["sample.width"], config["sample.height"])
    sample = expand_to_porosity(
        box,
        config["sample.porosity"],
        _grading(config),
        seed=config["sample.seed"],
        friction=config["sample.generation_friction"],
        wall_friction=config["material.platen_friction"],
        normal_stiffness=config["material.normal_stiffness"],
        shear_stiffness=config["material.shear_stiffness"],
        density=config["material.density"],
        local_damping=config["material.local_damping"],
        max_stress_pa=config["sample.max_generation_stress"],
        threads=threads,
        progress=progress,
        keep_simulation=True,
    )
    sim = sample.simulation
    n = sim.n_particles
    sim.densities = np.full(n, config["material.density"])  # generation may scale densities
    info = {k: v for k, v in sample.to_dict().items() if isinstance(v, int | float | str | bool) or v is None}
    run = _Run(
        phase="consolidate",
        n_grains=n,
        grain_density=config["material.density"],
        walls={"bottom": 0, "right": 1, "top": 2, "left": 3},
        wall_time={"generate": time.perf_counter() - start},
        sample=info,
        consolidation={},
    )
    return sim, run


def _consolidate(sim: Simulation, run: _Run, config: BiaxialConfig, progress: bool) -> None:
    start = time.perf_counter()
    consolidation_model = ContactModel(
        config["material.normal_stiffness"], config["material.shear_stiffness"], config["consolidation.friction"]
    )
    sim.set_contact_model(0, 0, consolidation_model)
    sim.set_contact_model(0, 1, _platen_model(config))
    sim.local_damping = config["material.local_damping"]
    sim.time_step = config["run.time_step_safety"] * sim.critical_time_step(1.0)
    target = config["consolidation.pressure"]
    tolerance = config["consolidation.tolerance"]
    limit = config["consolidation.unbalanced_force_ratio"]
    max_steps = config["consolidation.max_steps"]
    speed = 0.05 * config["sample.d_min"] / (100 * sim.time_step)  # at most d_min/20 per 100 steps
    bar = progress_bar(max_steps, "consolidating", enabled=progress, unit="step")

    def show(state: BoxState, steps: int) -> None:
        bar.update(CHUNK_STEPS)
        bar.set_postfix_str(f"sxx {state.stress_xx_pa / 1e3:.1f} kPa, syy {state.stress_yy_pa / 1e3:.1f} kPa, "
                            f"unbalanced {sim.unbalanced_force_ratio:.1e}")

    walls = {name: sim.wall(run.walls[name]) for name in BOX_WALLS}
    state, steps, converged = servo_box(
        sim, walls, target, tolerance=tolerance, unbalanced_force_limit=limit, max_steps=max_steps,
        max_speed_m_per_s=speed, chunk_steps=CHUNK_STEPS, after_chunk=show,
    )
    if not converged:
        bar.close()
        raise BiaxialError(
            f"consolidation did not converge in {steps} steps: wall stresses {state.stress_xx_pa / 1e3:.1f} / "
            f"{state.stress_yy_pa / 1e3:.1f} kPa (target {target / 1e3:.1f} kPa +- {tolerance:.0%}), unbalanced "
            f"force ratio {sim.unbalanced_force_ratio:.2e} (limit {limit:.0e}); raise consolidation.max_steps"
        )
    sxx, syy, width, height = state.stress_xx_pa, state.stress_yy_pa, state.width_m, state.height_m
    bar.close()
    grains = np.arange(run.n_grains)
    radii = sim.radii[grains]
    area = width * height
    box = (float(sim.wall(run.walls["left"]).points[0, 0]), float(sim.wall(run.walls["bottom"]).points[0, 1]))
    run.consolidation = {
        "steps": steps,
        "stress_xx_pa": sxx,
        "stress_yy_pa": syy,
        "width_m": width,
        "height_m": height,
        "porosity": 1.0 - float(np.pi * np.sum(radii**2)) / area,
        "porosity_overlap_corrected": overlap_corrected_porosity(
            sim.positions[grains], radii, (box[0], box[1], box[0] + width, box[1] + height)
        ),
        "coordination_number": sim.coordination_number,
        "unbalanced_force_ratio": sim.unbalanced_force_ratio,
        "time_step_s": sim.time_step,
    }
    run.wall_time["consolidate"] = time.perf_counter() - start
    run.phase = "boundary"


def _install_boundary(sim: Simulation, run: _Run, config: BiaxialConfig, progress: bool) -> None:
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
    sim.set_contact_model(0, 0, _grain_model(config))  # Table 1 friction from here on
    sim.set_contact_model(0, 1, _platen_model(config))
    limit = config["consolidation.unbalanced_force_ratio"]
    steps = 0
    if config["boundary.kind"] == "membrane":
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
            grain_model=_grain_model(config),
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
    run.phase = "shear"


def _start_shear(sim: Simulation, run: _Run, config: BiaxialConfig) -> None:
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
    if isinstance(boundary, Membrane):
        set_platen_velocity(sim, boundary, speed)
    else:
        bottom.velocity = (0.0, speed)
        top.velocity = (0.0, -speed)
    dt = sim.time_step
    steps_per_strain = 1.0 / (rate * dt)
    final = config["shear.final_strain"]
    interval = config["shear.record_interval"]
    targets = {round(k * interval * steps_per_strain) for k in range(1, int(round(final / interval)) + 1)}
    snaps = [s for s in config["shear.snapshot_strains"] if s <= final + 1e-12]
    targets |= {round(s * steps_per_strain) for s in snaps if s > 0}
    root = math.sqrt(config["material.density"] / config["consolidation.pressure"])
    run.shear = {
        "strain_rate": rate,
        "platen_speed_m_per_s": speed,
        "height0": height0,
        "area0": area0,
        "start_step": sim.step_count,
        "record_steps": sorted(targets),
        "snapshot_steps": {str(round(s * steps_per_strain)): s for s in snaps},
        "next": 0,
        "inertial_number": inertial_number(config, rate, max_d),
        "inertial_number_mean_diameter": rate * float(2 * radii.mean()) * root,
        "density_scaling_factor": grainlab.density_scaling_factor(
            rate, config["material.density"], float(radii.min()), config["material.limiting_contact_pressure"]
        ),
        "porosity_initial": 1.0 - float(np.pi * np.sum(radii**2)) / area0,
    }


def _walls(sim: Simulation, run: _Run) -> WallGeometry:
    """The walls now (the platens active, the consolidation box's sides not), named
    as the run names them, for the snapshot."""
    return WallGeometry.from_simulation(sim, names={wall_id: name for name, wall_id in run.walls.items()})


def _shear(
    sim: Simulation,
    run: _Run,
    config: BiaxialConfig,
    writer: ResultsWriter,
    save: Callable[[], None],
    progress: bool,
) -> None:
    start = time.perf_counter() - run.wall_time.get("shear", 0.0)
    shear = run.shear
    steps = shear["record_steps"]
    snap_steps = shear["snapshot_steps"]
    final = config["shear.final_strain"]
    if shear["next"] == 0 and "0" in snap_steps and writer.n_rows == 0:
        record = _measure(sim, run, config)
        writer.append_timeseries(record, units=TIMESERIES_UNITS)
        writer.write_snapshot(snapshot_name(0.0), _snapshot(sim, run, 0.0), step=sim.step_count,
                              walls=_walls(sim, run))
    last_checkpoint = time.perf_counter()
    done_strain = 0.0
    bar = progress_bar(
        round(100 * final, 3),
        "shearing",
        enabled=progress,
        unit="% strain",
        bar_format="{l_bar}{bar}| {n:.2f}/{total:.1f} % [{elapsed}<{remaining}{postfix}]",
    )
    while shear["next"] < len(steps):
        target = shear["start_step"] + steps[shear["next"]]
        sim.run(target - sim.step_count)
        record = _measure(sim, run, config)
        writer.append_timeseries(record, units=TIMESERIES_UNITS)
        key = str(steps[shear["next"]])
        if key in snap_steps:
            strain = snap_steps[key]
            writer.write_snapshot(snapshot_name(strain), _snapshot(sim, run, record["axial_strain"]),
                                  step=sim.step_count, walls=_walls(sim, run))
        peak = run.peak or {"stress_ratio": -math.inf}
        if record["stress_ratio"] > peak["stress_ratio"]:
            run.peak = {
                "stress_ratio": record["stress_ratio"],
                "axial_strain": record["axial_strain"],
                "coordination_number": record["coordination_number"],
                "volumetric_strain": record["volumetric_strain"],
            }
        if run.membrane.get("kind") == GrainBoundary.kind:
            run.membrane = GrainBoundary.from_dict(run.membrane).identify(sim).to_dict()
        else:
            breach = membrane_breach(sim, Membrane.from_dict(run.membrane))
            if breach is not None:
                bar.close()
                raise BiaxialError(
                    f"shearing stopped at {100 * record['axial_strain']:.2f} % axial strain: {breach}"
                )
        shear["next"] += 1
        raise_if_interrupted()
        bar.update(100 * record["axial_strain"] - done_strain)
        done_strain = 100 * record["axial_strain"]
        bar.set_postfix_str(f"ratio {record['stress_ratio']:.2f}")
        if time.perf_counter() - last_checkpoint > config["run.checkpoint_interval"]:
            run.wall_time["shear"] = time.perf_counter() - start
            save()
            last_checkpoint = time.perf_counter()
    bar.close()
    run.wall_time["shear"] = time.perf_counter() - start
    run.phase = "done"


# ---- outputs ----------------------------------------------------------------


@dataclass(frozen=True)
class BiaxialResult:
    """What ``grainlab biaxial`` reports: the summary and where the files are."""

    out_dir: Path
    summary: dict[str, Any]

    def one_line(self) -> str:
        s = self.summary
        return (
            f"grainlab biaxial: {s['n_particles']} grains, porosity {s['porosity_initial']:.3f}, "
            f"Z0 {s['coordination_number_initial']:.2f}; peak sigma1/sigma3 {s['peak_stress_ratio']:.2f} "
            f"at {100 * s['axial_strain_at_peak']:.2f} % axial strain; strain rate {s['strain_rate']:.3g} 1/s; "
            f"{s['wall_time_s']:.1f} s -> {self.out_dir}"
        )


def _summary(run: _Run, config: BiaxialConfig, timeseries: dict[str, np.ndarray], total_s: float) -> dict[str, Any]:
    shear = run.shear
    first = {k: float(v[0]) for k, v in timeseries.items()}
    last = {k: float(v[-1]) for k, v in timeseries.items()}
    peak = run.peak or {}
    return {
        "n_particles": run.n_grains,
        "n_membrane_disks": run.consolidation.get("membrane_disks", 0),
        "porosity_initial": shear["porosity_initial"],
        "porosity_after_consolidation": run.consolidation["porosity"],
        "porosity_after_consolidation_overlap_corrected": run.consolidation["porosity_overlap_corrected"],
        "porosity_generated": run.sample.get("porosity"),
        "porosity_generated_overlap_corrected": run.sample.get("porosity_overlap_corrected"),
        "generation_stress_pa": run.sample.get("mean_wall_stress_pa"),
        "coordination_number_initial": first["coordination_number"],
        "coordination_number_at_peak": peak.get("coordination_number"),
        "coordination_number_final": last["coordination_number"],
        "peak_stress_ratio": peak.get("stress_ratio"),
        "axial_strain_at_peak": peak.get("axial_strain"),
        "volumetric_strain_at_peak": peak.get("volumetric_strain"),
        "final_stress_ratio": last["stress_ratio"],
        "final_volumetric_strain": last["volumetric_strain"],
        "max_contraction": float(np.max(timeseries["volumetric_strain"])),
        "strain_rate": shear["strain_rate"],
        "inertial_number": shear["inertial_number"],
        "inertial_number_mean_diameter": shear["inertial_number_mean_diameter"],
        "density_scaling_factor": shear["density_scaling_factor"],
        "time_step_s": run.consolidation["time_step_s"],
        "records": len(timeseries["axial_strain"]),
        "wall_time_s": total_s,
        "wall_time_by_phase_s": dict(run.wall_time),
        "paper": PAPER_VALUES,
        "grainlab_version": grainlab.__version__,
    }


def _csv(timeseries: dict[str, np.ndarray]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    names = list(timeseries)
    writer.writerow(names)
    for row in zip(*(timeseries[k] for k in names), strict=True):
        writer.writerow([repr(float(v)) for v in row])
    return buffer.getvalue()


def _figures(timeseries: dict[str, np.ndarray], out: Path) -> list[Path]:
    from grainlab.plot import biaxial_curves

    return biaxial_curves(timeseries, out)


# ---- the driver ---------------------------------------------------------------

#: Files that only a biaxial run writes: a new run refuses a folder holding any of
#: them (``--resume`` continues that run, or finishes its outputs).
RUN_FILES = (RESULTS_FILE, RESULTS_FILE + PARTIAL_SUFFIX, CHECKPOINT_FILE)
#: The run's other outputs (``report.html`` is ``grainlab biaxial``'s): a new run
#: refuses a folder that already holds one, which another run or the user wrote.
OUTPUT_FILES = ("timeseries.csv", "summary.json", "report.html", "fig[0-9][0-9]_*.png", "fig[0-9][0-9]_*.svg")
#: Name of the checkpoint array that holds the partial results file (:meth:`ResultsWriter.publish`).
_RESULTS_IMAGE = "results_partial"


def _saved_config(saved: Any) -> dict[str, Any] | None:
    """A checkpoint's configuration resolved as this grainlab would (keys added
    since it was written take their defaults), or None when it cannot be."""
    try:
        return BiaxialConfig.from_dict(saved).to_dict()
    except (ValueError, TypeError, AttributeError):
        return None


def _config_difference(saved: Any, config: BiaxialConfig) -> str | None:
    """The keys on which a run's saved configuration and ``config`` differ, with
    both values; None when they agree."""
    resolved = _saved_config(saved)
    if resolved is None:
        return "the run's saved configuration cannot be read by this grainlab"
    current = config.to_dict()
    if resolved == current:
        return None
    old, new = flatten_keys(resolved), flatten_keys(current)
    keys = [k for k in dict.fromkeys([*old, *new]) if old.get(k) != new.get(k)]
    return "; ".join(f"{k} = {old.get(k)!r} in the run, {new.get(k)!r} now" for k in keys)


def _refuse_differing(out: Path, saved: Any, config: BiaxialConfig) -> None:
    difference = _config_difference(saved, config)
    if difference is not None:
        raise ValueError(
            f"--resume: the configuration differs from the one {out} was started with: {difference} "
            "(resume with the run's own configuration, or start a new run in another folder)"
        )


def _write_outputs(out: Path) -> dict[str, Any]:
    """``timeseries.csv``, the figures and ``summary.json``, all from the finished
    ``run.h5``: a run stopped while they were written finishes them with ``--resume``."""
    from grainlab.io.hdf5 import read_results
    from grainlab.postprocess.figures import fabric_figures

    results = read_results(out / RESULTS_FILE)
    raise_if_interrupted()  # a Ctrl-C that h5py's clean-up swallowed stops the run here
    summary = dict(results.summary)
    write_text_atomic(out / "timeseries.csv", _csv(results.timeseries))
    _figures(results.timeseries, out)
    raise_if_interrupted()
    # the paper's fabric figures (6, 7, 9, 11-14) from the snapshots, and their numbers
    summary["fabric"] = fabric_figures(out).numbers.summary()
    raise_if_interrupted()
    write_json_atomic(out / "summary.json", summary)
    return summary


def _disk_full(out: Path, error: BaseException) -> BiaxialError:
    checkpoint = out / CHECKPOINT_FILE
    kept = (
        f"the last checkpoint, {checkpoint}, is intact: free some space and continue with --resume"
        if checkpoint.exists()
        else "no checkpoint was written yet: free some space and run again (with --resume it starts over)"
    )
    return BiaxialError(f"{out}: the disk is full (no space left on device while writing the results); {kept}")


def _stop_writer(writer: ResultsWriter | None, error: BaseException) -> None:
    """Leave the partial results file closed, marked ``failed`` with the error
    unless the run was interrupted (then it stays ``running``). Neither may hide
    ``error``: on a full disk they may fail too, and the checkpoint keeps the file."""
    if writer is None or writer.closed:
        return
    if isinstance(error, Exception):
        text = "no space left on device" if is_disk_full(error) else f"{type(error).__name__}: {error}"
        with contextlib.suppress(Exception):
            writer.set_status("failed", error=text)
    with contextlib.suppress(Exception):
        writer.close()


def _finished_run(out: Path, config: BiaxialConfig) -> BiaxialResult | None:
    """``--resume`` without a checkpoint: the result of the run that finished in
    ``out`` (its outputs finished first if a stop left them unfinished), or None
    for a run stopped before its first checkpoint, which starts over."""
    from grainlab.io.hdf5 import read_results

    if (out / RESULTS_FILE).exists():
        results = read_results(out / RESULTS_FILE)
        _refuse_differing(out, results.config, config)
        summary_path = out / "summary.json"
        if summary_path.exists():
            return BiaxialResult(out, json.loads(summary_path.read_text(encoding="utf-8")))
        try:
            return BiaxialResult(out, _write_outputs(out))
        except OSError as error:
            if is_disk_full(error):
                raise _disk_full(out, error) from error
            raise
    if (out / (RESULTS_FILE + PARTIAL_SUFFIX)).exists():
        return None
    raise ValueError(
        f"--resume: {out} holds no run: no {CHECKPOINT_FILE}, {RESULTS_FILE} or {RESULTS_FILE + PARTIAL_SUFFIX}; "
        "nothing to resume"
    )


def _reopen_results(out: Path, run: _Run, checkpoint: Any) -> ResultsWriter | None:
    """The results writer of a resumed run, as it was at the checkpoint; None
    when the run's ``run.h5`` is already final (only the outputs remain)."""
    final, partial = out / RESULTS_FILE, out / (RESULTS_FILE + PARTIAL_SUFFIX)
    if final.exists():
        if run.phase == "done":
            partial.unlink(missing_ok=True)  # a stop right after run.h5 was written
            return None
        raise ValueError(
            f"--resume: {final} exists, but {out / CHECKPOINT_FILE} is of a run still in its {run.phase!r} "
            "phase; the folder holds two different runs: move one away"
        )
    image = checkpoint.arrays.get(_RESULTS_IMAGE)
    if image is not None:  # the partial file as it was at the checkpoint, whatever became of it since
        return ResultsWriter.restore(out, np.asarray(image, dtype=np.uint8).tobytes(), buffered=True)
    if not partial.exists():
        raise ValueError(
            f"--resume: {partial} is missing and {out / CHECKPOINT_FILE} (written by an earlier grainlab) "
            "cannot rebuild it; start the run again in a new folder"
        )
    return ResultsWriter.resume(out, timeseries_rows=run.rows, snapshots=run.snapshots or [], buffered=True)


def _check_shear_plan(sim: Simulation, run: _Run, config: BiaxialConfig) -> None:
    """The shearing phase's records and snapshots fall on distinct time steps,
    checked with the run's own time step before the first record."""
    shear = run.shear
    problem = strain_rate_problem(
        shear["strain_rate"], sim.time_step, shear["height0"], float(sim.radii.min()), config["shear.record_interval"]
    )
    if problem is not None:
        raise BiaxialError(f"shear.strain_rate: {problem}; start again with a slower rate in another folder")
    wanted = [s for s in config["shear.snapshot_strains"] if s <= config["shear.final_strain"] + 1e-12]
    if len(shear["snapshot_steps"]) < len(wanted):
        raise BiaxialError(
            f"shear.snapshot_strains: two of {wanted} fall on the same time step "
            f"({sim.time_step:.3g} s at {shear['strain_rate']:.3g} 1/s); keep them further apart"
        )


def run_biaxial(
    config: BiaxialConfig,
    out_dir: str | os.PathLike[str],
    *,
    resume: bool = False,
    progress: bool = False,
) -> BiaxialResult:
    """Runs (or, with ``resume``, continues) the biaxial test into ``out_dir``.

    ``resume`` continues a run from wherever it stopped: from its last
    checkpoint (the partial results file is restored from it, so a kill or a
    full disk while it was written does not matter), or, for a run whose
    ``run.h5`` is final, by writing the outputs a stop left unwritten; a run
    that finished returns its result, and one stopped before its first
    checkpoint starts over. A new run refuses a folder that holds another
    run's files (:data:`RUN_FILES`, :data:`OUTPUT_FILES`). A full disk stops
    the run with a :class:`BiaxialError` that keeps the last checkpoint.
    ``progress`` shows each phase's progress on stderr (off by default; see
    :func:`grainlab._progress.progress_bar`).
    """
    out = Path(out_dir)
    checkpoint_path = out / CHECKPOINT_FILE
    started = time.perf_counter()
    check_strain_rate(config)  # a rate refused needs no warning about its inertia
    check_density_scaling(config)
    threads = _threads(config)
    if resume and not out.exists():
        raise ValueError(f"--resume: {out} does not exist: nothing to resume")
    ensure_output_folder(out, create=not resume)
    if resume and not checkpoint_path.exists():
        finished = _finished_run(out, config)
        if finished is not None:
            return finished
        resume = False  # stopped before its first checkpoint: starts over
    writer: ResultsWriter | None = None
    try:
        if resume:
            checkpoint = read_checkpoint(checkpoint_path)
            saved = dict(checkpoint.protocol_state)
            _refuse_differing(out, saved.get("config"), config)
            sim = Simulation.from_bytes(checkpoint.engine_state)
            run = _Run(**{k: v for k, v in saved.items() if k != "config" and k != "elapsed_s"})
            elapsed_before = float(saved.get("elapsed_s", 0.0))
            writer = _reopen_results(out, run, checkpoint)
        else:
            partial = out / (RESULTS_FILE + PARTIAL_SUFFIX)
            if partial.exists() and not checkpoint_path.exists() and not (out / RESULTS_FILE).exists():
                partial.unlink()  # a run stopped before its first checkpoint: nothing to keep or resume
            if any((out / name).exists() for name in RUN_FILES):
                raise ValueError(
                    f"--out: {out} already holds a run; use --resume to continue it or choose another folder"
                )
            refuse_overwrite(out, OUTPUT_FILES, why="a biaxial run writes its own")
            writer = ResultsWriter(out, kind="biaxial", buffered=True)  # HDF5 never writes the disk itself
            writer.write_config(config.to_dict())
            sim, run = _generate(config, threads, progress)
            elapsed_before = 0.0

        def save() -> None:
            state = run.to_dict()
            state["config"] = config.to_dict()
            state["elapsed_s"] = elapsed_before + time.perf_counter() - started
            state["rows"] = writer.n_rows
            state["snapshots"] = list(writer.snapshot_names)
            image = np.frombuffer(writer.publish(), dtype=np.uint8)
            write_checkpoint(checkpoint_path, sim.to_bytes(), state, arrays={_RESULTS_IMAGE: image})

        if writer is not None:
            if not resume:
                save()
            if run.phase == "consolidate":
                _consolidate(sim, run, config, progress)
                save()
            if run.phase == "boundary":
                _install_boundary(sim, run, config, progress)
                _start_shear(sim, run, config)
                _check_shear_plan(sim, run, config)
                save()
            if run.phase == "shear":
                _shear(sim, run, config, writer, save, progress)
                save()
            total = elapsed_before + time.perf_counter() - started
            summary = _summary(run, config, writer.read_timeseries(), total)
            summary["threads"] = sim.threads  # the count the run used (a resumed run keeps its own): reruns bitwise
            writer.write_summary(summary)
            writer.write_phases(run.wall_time)
            writer.finalize()
        summary = _write_outputs(out)
    except BaseException as error:
        _stop_writer(writer, error)
        if is_disk_full(error):
            raise _disk_full(out, error) from error
        raise
    checkpoint_path.unlink(missing_ok=True)
    return BiaxialResult(out, summary)
