"""The crushing test of single agglomerates as a protocol of the runner: agglomerate k
(``crushing.agglomerates`` of them, each from its own random stream of
``sample.seed``) is made of bonded disks (:mod:`grainlab.samples.agglomerate`),
set between two platens that touch it, and crushed diametrically by the top platen
at ``crushing.strain_rate`` x d, the bottom one fixed, until it fails (the first
record with a bond broken whose force is below ``crushing.residual_fraction`` of the
peak once it has split in two major fragments) or the platen has travelled ``crushing.final_strain`` x d. Each agglomerate
runs in a simulation of its own, the context's while it runs, so that a checkpoint
between two agglomerates holds the last one's and a resumed run crushes the next ones
to the same bits (docs/cemented.md, "Crushable grains")."""

from __future__ import annotations

import dataclasses
import os
import time
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from grainlab._progress import progress_bar
from grainlab.analysis.fragments import fragment_labels, fragment_sizes
from grainlab.columns import CRUSHING, MAJOR_FRAGMENTS, PLATEN_FORCE_N
from grainlab.io.walls import WallGeometry
from grainlab.protocols.agglomerates import bond_agglomerates, bond_strengths
from grainlab.protocols.cracks import CrackRecords
from grainlab.protocols.crushing.config import CrushingConfig
from grainlab.protocols.crushing.outputs import CrushingResult, summarise, write_outputs
from grainlab.protocols.crushing.state import CrushingRun
from grainlab.protocols.operations import Loading, Operation, Records, Stop
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.specimen import (
    ConfiguredProtocol,
    damped_time_step_factor,
    engine_columns,
    grain_model,
    platen_model,
)
from grainlab.protocols.triggers import Flag, OnSteps, WallClock, schedule_steps
from grainlab.samples import UniformByNumber
from grainlab.samples.agglomerate import Agglomerates, agglomerate_stream, build_agglomerate
from grainlab.simulation import Simulation

__all__ = ["MAJOR_FRAGMENT", "THICKNESS_M", "CrushingProtocol", "Failure", "agglomerate_test", "measure", "outcome",
           "run_crushing"]

Context = StageContext[CrushingConfig, CrushingRun]

#: The thickness t of every 2D quantity (m): sigma = F / (d t).
THICKNESS_M = 1.0
#: A fragment holding at least this share of an agglomerate's solid area is a major one:
#: an agglomerate with two of them has split (docs/cemented.md, "Crushable grains").
MAJOR_FRAGMENT = 0.1
#: The platens' engine ids in an agglomerate's simulation.
BOTTOM, TOP = 0, 1


def agglomerate_test(config: CrushingConfig, k: int, threads: int) -> tuple[Simulation, Agglomerates]:
    """Agglomerate ``k`` (its diameter and then its disks drawn from its own stream),
    bonded, between two platens three diameters long that touch it, the contact laws,
    local damping and time step of ``config`` (as the consolidation sets them)."""
    c, a = config.crushing, config.agglomerate
    rng = agglomerate_stream(config.sample.seed, k)
    d = float(UniformByNumber(c.d_min, c.d_max).sample(1, rng)[0])
    grain = build_agglomerate(d, a.disk_diameter, rng, vacancies=a.vacancies, size_scatter=a.size_scatter,
                              strengths=bond_strengths(config))
    sim = Simulation(grain.positions, grain.radii, density=config.material.density, threads=threads)
    bond_agglomerates(sim, grain, config)
    y = grain.positions[:, 1]
    low, high = float(np.min(y - grain.radii)), float(np.max(y + grain.radii))
    sim.add_segment_wall((-3 * d, low), (3 * d, low))  # BOTTOM: the grain above
    sim.add_segment_wall((3 * d, high), (-3 * d, high))  # TOP: the grain below
    sim.set_contact_model(0, 0, grain_model(config))
    sim.set_contact_model(0, 1, platen_model(config))
    sim.local_damping = config.material.local_damping
    sim.time_step = config.run.time_step_safety * sim.critical_time_step(1.0) * damped_time_step_factor(config)
    return sim, grain


def _fragment_shares(sim: Simulation) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The fragments' shares of the solid area, largest first, and each disk's fragment."""
    bonds = sim.cement_bonds()
    labels = fragment_labels(sim.n_particles, bonds.i, bonds.j)
    area, _ = fragment_sizes(sim.radii, labels)
    return np.sort(area / area.sum())[::-1], labels


def measure(sim: Simulation, k: int, diameter: float, bonds: int) -> dict[str, float]:
    """One record of agglomerate ``k`` (of ``diameter`` and ``bonds`` bonds at its start),
    in :data:`grainlab.columns.CRUSHING`'s order."""
    top = sim.wall(TOP).state
    force = float(-np.dot(top.force, top.inward_normal))
    displacement = float(-top.displacement[1])
    shares, _ = _fragment_shares(sim)
    values = {
        "agglomerate": float(k), "step": float(sim.step_count), "time_s": sim.time, "diameter_m": diameter,
        "axial_strain": displacement / diameter, "platen_displacement_m": displacement, "platen_force_n": force,
        "characteristic_stress_pa": force / (diameter * THICKNESS_M),
        "cement_bonds_broken": float(bonds - sim.n_cement_bonds), "fragments": float(len(shares)),
        "major_fragments": float(np.count_nonzero(shares >= MAJOR_FRAGMENT)),
        "largest_fragment_fraction": float(shares[0]), **engine_columns(sim),
    }
    return {name: values[name] for name in CRUSHING}


class Failure(Operation):
    """After each record: the peak force so far, and :attr:`ended` raised at the first
    record where the agglomerate has split (two major fragments, each at least
    :data:`MAJOR_FRAGMENT` of its solid area) and the force is below
    ``residual_fraction`` of the peak (``ended_by`` "failure"; a chip that lets the
    force drop leaves one major fragment and the loading goes on), or at the last
    record step ("final_strain")."""

    def __init__(self, trigger: OnSteps, records: Records, residual_fraction: float, last_step: int) -> None:
        super().__init__(trigger)
        self.records, self.fraction, self.last_step = records, residual_fraction, last_step
        self.peak, self.ended_by, self.ended = -np.inf, "", Flag()

    def act(self, loading: Loading) -> None:
        values, step = self.records.values, loading.sim.step_count
        force = values[PLATEN_FORCE_N]
        self.peak = max(self.peak, force)
        failed = values[MAJOR_FRAGMENTS] >= 2 and force < self.fraction * self.peak
        if failed or step >= self.last_step:
            self.ended_by = "failure" if failed else "final_strain"
            self.ended.raise_at(step)


def outcome(sim: Simulation, grain: Agglomerates, ended_by: str) -> dict[str, Any]:
    """Agglomerate's end: how its loading ended, its fragments, its major ones (at least
    :data:`MAJOR_FRAGMENT` of its solid area), the two largest's shares of its area and
    its mode: "split" (failed in two major fragments), "fragmented" (failed in three or
    more) or "unfailed" (no failure by ``crushing.final_strain``)."""
    shares, _ = _fragment_shares(sim)
    major = int(np.count_nonzero(shares >= MAJOR_FRAGMENT))
    mode = "unfailed" if ended_by != "failure" else "split" if major == 2 else "fragmented"
    return {"diameter_m": float(grain.diameters[0]), "disks": grain.n_disks, "bonds": grain.n_bonds,
            "ended_by": ended_by, "mode": mode, "fragments": len(shares), "major_fragments": major,
            "largest_fragment_fraction": float(shares[0]),
            "second_fragment_fraction": float(shares[1]) if len(shares) > 1 else 0.0}


def _snapshot(context: Context, name: str) -> None:
    """The agglomerate's state as snapshot ``name``, each disk's fragment in ``particle_fields``."""
    sim = context.sim
    _, labels = _fragment_shares(sim)
    snapshot = sim.snapshot(step=sim.step_count)
    snapshot = dataclasses.replace(snapshot, particle_fields={**snapshot.particle_fields, "fragment": labels})
    walls = WallGeometry.from_simulation(sim, names={BOTTOM: "bottom", TOP: "top"})
    context.writer.write_snapshot(name, snapshot, step=sim.step_count, walls=walls)


def crush(context: Context, k: int) -> dict[str, Any]:
    """Agglomerate ``k`` crushed in a simulation of its own (the context's from now on):
    its records, crack records and snapshots at its start and end; returns its outcome."""
    config = context.config
    context.sim, grain = agglomerate_test(config, k, context.sim.threads)
    sim, c = context.sim, config.crushing
    diameter, bonds = float(grain.diameters[0]), grain.n_bonds
    steps = schedule_steps(c.final_strain / c.records, final=c.final_strain,
                           steps_per_unit=1.0 / (c.strain_rate * sim.time_step))
    scheduled = OnSteps(steps)
    records = Records(scheduled, context.writer, lambda: measure(sim, k, diameter, bonds), CRUSHING.units(),
                      buffered=True)  # written at the end: no checkpoint inside an agglomerate
    failure = Failure(scheduled, records, c.residual_fraction, steps[-1])
    records.write(0)
    _snapshot(context, f"agglomerate_{k:03d}_start")
    sim.wall(TOP).velocity = (0.0, -c.strain_rate * diameter)
    Loading(sim, [
        records,
        CrackRecords(scheduled, context.writer, strain_of=lambda t: c.strain_rate * t, labels={"agglomerate": k}),
        failure,
        Stop(failure.ended),
    ]).run()
    records.flush()
    _snapshot(context, f"agglomerate_{k:03d}_end")
    return outcome(sim, grain, failure.ended_by)


def _crush_all(context: Context) -> None:
    run, config = context.state, context.config
    total = config.crushing.agglomerates
    bar = progress_bar(total, "crushing", enabled=context.progress, unit="agglomerate", initial=run.next_agglomerate)
    clock = WallClock(config.run.checkpoint_interval)
    booked = run.wall_time.get("crush", 0.0)
    started = time.perf_counter()
    try:
        while run.next_agglomerate < total:
            result = crush(context, run.next_agglomerate)
            run.agglomerates.append(result)
            run.next_agglomerate += 1
            bar.update(1)
            bar.set_postfix_str(f"{result['mode']}, {len(run.agglomerates)} crushed")
            run.wall_time["crush"] = booked + time.perf_counter() - started
            if run.next_agglomerate < total and clock(0):
                context.save()
    finally:
        bar.close()


class CrushingProtocol(ConfiguredProtocol[CrushingConfig, CrushingRun, CrushingResult]):
    """Single agglomerates crushed between two platens, one after the other."""

    name = "crushing"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        Stage("crush", _crush_all, "each agglomerate in a simulation of its own, between two platens, the top one "
                                   "down at crushing.strain_rate x d until the force drops below "
                                   "crushing.residual_fraction of its peak or crushing.final_strain; a checkpoint "
                                   "between two agglomerates once run.checkpoint_interval has passed"),
    )
    state_type = CrushingRun
    summarise = summarise
    outputs = write_outputs
    result_type = CrushingResult

    def start(self, threads: int, progress: bool) -> tuple[Simulation, CrushingRun]:
        sim, _ = agglomerate_test(self.config, 0, threads)
        return sim, CrushingRun(phase=self.stages[0].name)


def run_crushing(config: CrushingConfig, out_dir: str | os.PathLike[str], *, resume: bool = False,
                 progress: bool = False) -> CrushingResult:
    """Runs (or, with ``resume``, continues) the crushing test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`)."""
    return run_protocol(CrushingProtocol(config), out_dir, resume=resume, progress=progress)
