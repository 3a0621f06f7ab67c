"""The biaxial test's strain-rate rules: the ``auto`` rate (an inertial-number
bound), the inertial number itself, and the checks that refuse, before any
work, a rate too fast for meaningful records or warn about one whose density
scaling (paper Eq. 16) is too high."""

from __future__ import annotations

import math
import warnings

import grainlab
from grainlab.io.hdf5 import snapshot_name
from grainlab.paper import DENSITY_SCALING_LIMIT
from grainlab.protocols.biaxial.config import BiaxialConfig
from grainlab.protocols.specimen import contact_law
from grainlab.simulation import Simulation

__all__ = [
    "DENSITY_SCALING_LIMIT",
    "MAX_PLATEN_TRAVEL_PER_STEP",
    "MIN_STEPS_PER_RECORD",
    "DensityScalingWarning",
    "check_density_scaling",
    "check_strain_rate",
    "default_strain_rate",
    "inertial_number",
    "strain_rate_problem",
]


class DensityScalingWarning(UserWarning):
    """The strain rate makes the density-scaled sample too dynamic (paper Eq. 16)."""


def check_density_scaling(config: BiaxialConfig) -> float | None:
    """The Eq. 16 factor of an explicit ``shear.strain_rate`` (smallest grain,
    ``sample.d_min / 2``, and the limiting contact pressure ``p_y``,
    ``material.limiting_contact_pressure``), with a :class:`DensityScalingWarning`
    when it exceeds :data:`DENSITY_SCALING_LIMIT`; ``None`` for the ``auto``
    rate, which keeps the factor at or below ``shear.inertial_number``."""
    rate = config.shear.strain_rate
    if isinstance(rate, str):  # "auto"
        return None
    factor = grainlab.density_scaling_factor(
        rate, config.material.density, 0.5 * config.sample.d_min, config.material.limiting_contact_pressure
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
    for strain in config.values.get("shear.snapshot_strains", ()):  # a cyclic test names its own
        name = snapshot_name(strain)
        if name in names:
            raise ValueError(
                f"shear.snapshot_strains: {names[name]:g} and {strain:g} share the snapshot name {name!r}; "
                "keep snapshot strains at least 0.0001 apart"
            )
        names[name] = strain
    rate = config.shear.strain_rate
    if isinstance(rate, str):  # "auto"
        return  # bounded by the inertial number, far below these limits
    diameter = config.sample.d_min
    if config.boundary.kind == "membrane":
        diameter = min(diameter, config.boundary.membrane_diameter)
    radius = 0.5 * diameter
    # the critical time step of the smallest grain with the grains' law (its stiffest
    # contact: the law's tangent stiffnesses at the largest overlap allowed), as the
    # engine computes it
    smallest = Simulation([[0.0, 0.0]], [radius], config.material.density,
                          contact_model=contact_law(config, config.material.friction))
    time_step = 0.1 * config.run.time_step_safety * smallest.critical_time_step(1.0)
    problem = strain_rate_problem(rate, time_step, config.sample.height, radius, config.shear.record_interval)
    if problem is not None:
        raise ValueError(
            f"shear.strain_rate: {rate:g} 1/s is too fast even for a time step shorter than any this sample "
            f"reaches: {problem} (the run checks its own, longer time step again before shearing)"
        )


def default_strain_rate(config: BiaxialConfig, max_diameter: float, min_radius: float) -> float:
    """The fastest axial strain rate (the ``auto`` rate) whose inertial number
    ``I = rate * d_max * sqrt(rho / ((1 - alpha) sigma_3))`` (the heaviest grain, with
    local damping's effective mass) and paper's Eq. 16 factor ``rate * r_min * sqrt(rho /
    p_y)`` are both at most ``shear.inertial_number``; the run passes the grading's
    nominal ``sample.d_max`` and ``sample.d_min / 2`` (docs/biaxial.md, "The strain
    rate": why the bound is 1e-4, the paper's 2 %/min with Table 1).
    """
    rho, p = config.material.density, config.consolidation.pressure
    alpha = config.material.local_damping
    bound = config.shear.inertial_number
    inertial = max_diameter * math.sqrt(rho / ((1.0 - alpha) * p))
    eq16 = min_radius * math.sqrt(rho / config.material.limiting_contact_pressure)
    return float(bound) / max(inertial, eq16)


def inertial_number(config: BiaxialConfig, rate: float, diameter: float) -> float:
    """``rate * d * sqrt(rho / ((1 - alpha) sigma_3))``."""
    rho, p = config.material.density, config.consolidation.pressure
    return rate * diameter * math.sqrt(rho / ((1.0 - config.material.local_damping) * p))
