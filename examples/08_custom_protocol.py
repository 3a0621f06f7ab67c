"""A protocol of your own on grainlab's runner: isotropic compression by steps.

A sample made by radius expansion is servo-compressed in four rigid walls to
each pressure of a list in turn; at each equilibrium a record (pressure,
porosity, coordination number) and a snapshot go into ``run.h5``. The runner
(:func:`grainlab.protocols.runner.run_protocol`) gives it what the biaxial test
has: checkpoints, ``resume``, the folder lock, the full disk handled
(docs/protocols.md walks through it).
Run it: ``python examples/08_custom_protocol.py [out_dir]``.
"""

import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from grainlab.io.hdf5 import read_results
from grainlab.protocols.consolidate import BOX_WALLS, servo_box
from grainlab.protocols.runner import Protocol, RunResult, Stage, StageContext, run_protocol
from grainlab.samples import UniformByNumber, expand_to_porosity


@dataclass(frozen=True)
class CompressionConfig:
    pressures_pa: tuple[float, ...] = (50e3, 100e3, 200e3, 400e3)
    width_m: float = 0.02
    height_m: float = 0.02
    seed: int = 1
    friction: float = 0.5


@dataclass
class CompressionState:
    phase: str = "compress"
    wall_time: dict[str, float] = field(default_factory=dict)
    done: int = 0  # pressures reached so far

    def to_dict(self):
        return asdict(self)


def compress(context: StageContext) -> None:
    """Each pressure in turn: servo the box to it, then record and store a snapshot."""
    sim, state, config = context.sim, context.state, context.config
    started = time.perf_counter()
    walls = {name: sim.wall(k) for k, name in enumerate(BOX_WALLS)}
    while state.done < len(config.pressures_pa):
        pressure = config.pressures_pa[state.done]
        box, _, converged = servo_box(sim, walls, pressure, tolerance=0.01, unbalanced_force_limit=1e-3,
                                      max_steps=400_000, max_speed_m_per_s=0.05)
        if not converged:
            raise RuntimeError(f"no equilibrium at {pressure:.3g} Pa")
        porosity = 1.0 - float(np.pi * np.sum(sim.radii**2)) / (box.width_m * box.height_m)
        context.writer.append_timeseries(
            {"pressure_pa": pressure, "porosity": porosity, "coordination_number": sim.coordination_number},
            units={"pressure_pa": "Pa", "porosity": "", "coordination_number": ""})
        context.writer.write_snapshot(f"p_{pressure:.0f}", sim.snapshot())
        state.done += 1
        context.save()  # a checkpoint at every equilibrium: a stop loses at most one step
    state.wall_time["compress"] = time.perf_counter() - started


class IsotropicCompression(Protocol):
    name = "isotropic_compression"
    stages = (Stage("compress", compress, "servo to each pressure in turn, a record at each"),)

    def threads(self):
        return 1

    def config_dict(self):
        return asdict(self.config)

    def resolve_saved(self, saved):
        return saved if isinstance(saved, dict) else None

    def start(self, threads, progress):
        c = self.config
        sample = expand_to_porosity((0.0, 0.0, c.width_m, c.height_m), 0.2, UniformByNumber(0.8e-3, 1.2e-3),
                                    seed=c.seed, friction=c.friction, keep_simulation=True, threads=threads)
        return sample.simulation, CompressionState()

    def state_from_dict(self, saved):
        return CompressionState(saved["phase"], dict(saved["wall_time"]), int(saved["done"]))

    def summary(self, context, wall_time_s):
        series = context.writer.read_timeseries()
        return {"final_porosity": float(series["porosity"][-1]), "wall_time_s": wall_time_s}

    def write_outputs(self, out):
        return dict(read_results(out / "run.h5").summary)

    def result(self, out, summary):
        return RunResult(out, summary)


if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("compression")
    result = run_protocol(IsotropicCompression(CompressionConfig()), out, resume=(out / "checkpoint.h5").exists())
    series = read_results(out / "run.h5").timeseries
    for p, n, z in zip(series["pressure_pa"], series["porosity"], series["coordination_number"], strict=True):
        print(f"{p / 1e3:6.0f} kPa: porosity {n:.4f}, Z {z:.2f}")
    print(f"-> {out / 'run.h5'} ({result.summary['wall_time_s']:.1f} s)")
