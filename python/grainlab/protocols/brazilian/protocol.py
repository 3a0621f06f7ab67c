"""The Brazilian (indirect tensile) test of a cemented disc as a protocol of the
runner: the sample made and consolidated as every test's and cemented at the end
of the consolidation (:mod:`grainlab.protocols.specimen`), a disc carved from it
(:mod:`grainlab.protocols.brazilian.disc`) between two platens touching it at its
top and bottom, settled, then loaded by the top platen at a constant speed, the
bottom one fixed, until ``brazilian.final_strain`` or until the platen force falls
below ``brazilian.residual_fraction`` of its peak. The indirect tensile strength is
``sigma_t = 2 F_max / (pi D t)``, ``t = 1 m``; :func:`run_brazilian` runs it into a
folder (docs/cemented.md, "The Brazilian test")."""

from __future__ import annotations

import math
import os
import time
from typing import Any, ClassVar

import numpy as np

from grainlab.columns import BRAZILIAN, PLATEN_FORCE_N_PER_M, TENSILE_STRESS_PA
from grainlab.protocols.brazilian.config import BrazilianConfig
from grainlab.protocols.brazilian.disc import (
    carved_simulation,
    disc_circle,
    held_by_cement,
    in_disc,
)
from grainlab.protocols.brazilian.outputs import BrazilianResult, summarise, write_outputs
from grainlab.protocols.brazilian.state import BrazilianRun
from grainlab.protocols.consolidate import add_platens
from grainlab.protocols.cracks import broken_since
from grainlab.protocols.platens import Press, platen_snapshot, press, release
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.specimen import CONSOLIDATE, SpecimenProtocol, engine_columns
from grainlab.simulation import Simulation

__all__ = ["THICKNESS_M", "BrazilianProtocol", "BrazilianRun", "indirect_tensile_stress", "measure",
           "platen_force", "run_brazilian"]

Context = StageContext[BrazilianConfig, BrazilianRun]

#: The thickness t of every grainlab quantity (forces are per metre of it).
THICKNESS_M = 1.0


def indirect_tensile_stress(force_n_per_m: float, diameter_m: float) -> float:
    """The tensile stress at the centre of a disc of diameter D under two opposite line
    loads F (per metre of thickness t), ``2 F / (pi D t)`` (Hertz's elastic solution)."""
    return 2.0 * force_n_per_m / (math.pi * diameter_m * THICKNESS_M)


def platen_force(sim: Simulation, run: BrazilianRun) -> float:
    """F: the mean of the two platens' normal forces (N per m of thickness, compression positive)."""
    forces = []
    for name in ("bottom", "top"):
        state = sim.wall(run.walls[name]).state
        forces.append(-float(np.dot(state.force, state.inward_normal)))
    return 0.5 * (forces[0] + forces[1])


def _gap(sim: Simulation, run: BrazilianRun) -> float:
    return float(sim.wall(run.walls["top"]).points[0, 1] - sim.wall(run.walls["bottom"]).points[0, 1])


def measure(sim: Simulation, run: BrazilianRun) -> dict[str, float]:
    """One record of the loading, in :data:`grainlab.columns.BRAZILIAN`'s order."""
    displacement, force = run.diameter_m - _gap(sim, run), platen_force(sim, run)
    values = {
        "step": float(sim.step_count), "time_s": sim.time, "axial_strain": displacement / run.diameter_m,
        "platen_displacement_m": displacement, "platen_force_n_per_m": force,
        "tensile_stress_pa": indirect_tensile_stress(force, run.diameter_m), **engine_columns(sim),
        "cement_bonds_broken": broken_since(sim, run.consolidation),
    }
    return {name: values[name] for name in BRAZILIAN}


def _carve(context: Context) -> None:
    """The disc carved into a new simulation (the context's from here on), two platens
    twice its circle's diameter long touching it at its top and bottom in place of the
    box; Table 1 friction on and the disc settled, the platens held still; D is the
    distance between them."""
    sim, run, config = context.sim, context.state, context.config
    start = time.perf_counter()
    centre, diameter = disc_circle(sim, run, config.brazilian.diameter_fraction)
    inside = in_disc(sim.grain_centroids, centre, diameter)
    bonds = sim.cement_bonds()
    keep = held_by_cement(inside, np.asarray(bonds.i, dtype=np.int64), np.asarray(bonds.j, dtype=np.int64),
                          sim.body_of_particles)
    disc = carved_simulation(sim, keep, config)
    run.sample_particles, run.sample_cement_bonds = run.n_grains, run.consolidation["cement_bonds"]
    run.loose_particles = int(np.count_nonzero(inside & ~keep))
    run.centre_m, run.carve_diameter_m = list(centre), diameter
    run.n_grains, run.consolidation["cement_bonds"] = disc.n_particles, disc.n_cement_bonds
    y, r = disc.positions[:, 1], disc.radii
    run.walls = {}
    add_platens(disc, run.walls, (centre[0] - diameter, centre[0] + diameter), float(np.min(y - r)),
                float(np.max(y + r)))
    context.sim = disc
    run.release_steps = release(disc, config, "carve", config.brazilian.platen_friction)
    run.diameter_m = _gap(disc, run)
    run.consolidation["release_steps"] = run.release_steps
    run.wall_time["carve"] = time.perf_counter() - start


def _load(context: Context) -> None:
    """The top platen down at ``brazilian.strain_rate`` x D (:func:`~grainlab.protocols.platens.press`)."""
    sim, run, config = context.sim, context.state, context.config
    press(context, config.brazilian, config.brazilian.strain_rate * run.diameter_m, Press(
        lambda: measure(sim, run), BRAZILIAN, TENSILE_STRESS_PA,
        lambda: platen_snapshot(sim, measure(sim, run), (PLATEN_FORCE_N_PER_M, TENSILE_STRESS_PA)), "loading",
        lambda values: f"sigma_t {values[TENSILE_STRESS_PA] / 1e3:.0f} kPa"))


class BrazilianProtocol(SpecimenProtocol[BrazilianConfig, BrazilianRun, BrazilianResult]):
    """The Brazilian test of a cemented disc: two platens, the top one at a constant speed."""

    name = "brazilian"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        CONSOLIDATE,
        Stage("carve", _carve, "the disc of brazilian.diameter_fraction carved from the sample into a new simulation "
                               "with its bonds; two platens touching it at its top and bottom; Table 1 friction on; "
                               "settled until the unbalanced force ratio is below "
                               "consolidation.unbalanced_force_ratio"),
        Stage("load", _load, "the top platen down at brazilian.strain_rate x D, the bottom one fixed; a record every "
                             "brazilian.final_strain / brazilian.records of displacement over D, to "
                             "brazilian.final_strain or the residual drop; a checkpoint on a record step once "
                             "run.checkpoint_interval has passed"),
    )
    state_type = BrazilianRun
    summarise = summarise
    outputs = write_outputs
    result_type = BrazilianResult


def run_brazilian(config: BrazilianConfig, out_dir: str | os.PathLike[str], *, resume: bool = False,
                  progress: bool = False) -> BrazilianResult:
    """Runs (or, with ``resume``, continues) the Brazilian test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`)."""
    return run_protocol(BrazilianProtocol(config), out_dir, resume=resume, progress=progress)
