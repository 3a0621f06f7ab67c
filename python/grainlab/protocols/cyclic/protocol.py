"""The cyclic biaxial test as a protocol of the runner: the biaxial test's sample,
consolidation and flexible boundary under sigma_0, then the platens driven at
``shear.strain_rate`` from 0 to +A, to -A and back to 0 (A =
``cyclic.strain_amplitude``, compression positive), ``cyclic.cycles`` times, the
confining pressure held. Records every ``shear.record_interval`` of strain path and
at every turning point; snapshots at the start, at the first and last cycles'
turning points and at the end of every cycle. :func:`run_cyclic` runs it into a folder."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, ClassVar

from grainlab.columns import CYCLE, CYCLIC, STRAIN_PATH
from grainlab.protocols.biaxial.phases import (
    check_shear_plan,
    install_boundary,
    shear,
    start_platens,
)
from grainlab.protocols.biaxial.rates import check_density_scaling, check_strain_rate
from grainlab.protocols.biaxial.state import _Run
from grainlab.protocols.config import Config
from grainlab.protocols.cyclic.config import CYCLIC_SCHEMA  # noqa: F401 - registers the schema
from grainlab.protocols.cyclic.outputs import CyclicResult, summarise, write_outputs
from grainlab.protocols.runner import Stage, StageContext, run_protocol
from grainlab.protocols.specimen import SpecimenProtocol, consolidate
from grainlab.protocols.triggers import At, Every

__all__ = ["CyclicProtocol", "cycle_plan", "run_cyclic", "snapshot_name_of"]

Context = StageContext[Config, _Run]


def cycle_plan(amplitude: float, cycles: int) -> tuple[float, list[float], list[float]]:
    """The loading in strain path (axial strain travelled): its length ``4 A N``, the
    turning points ``A, 3A, 5A, ..., (4N - 1) A`` and the snapshots (the start, the
    first and last cycles' turning points, every cycle's end).

    >>> cycle_plan(0.01, 2)
    (0.08, [0.01, 0.03, 0.05, 0.07], [0.0, 0.01, 0.03, 0.04, 0.05, 0.07, 0.08])
    """
    a = amplitude
    turns = [round((2 * k + 1) * a, 12) for k in range(2 * cycles)]
    ends = [round(4 * a * k, 12) for k in range(1, cycles + 1)]
    peaks = turns[:2] + turns[-2:]
    return round(4 * a * cycles, 12), turns, sorted({0.0, *peaks, *ends})


def snapshot_name_of(amplitude: float) -> Any:
    """The snapshot name of a path strain: ``start``, ``cycle_003_compression`` (its
    compression turning point), ``cycle_003_extension``, ``cycle_003_end``."""

    def name(path: float) -> str:
        quarter = round(path / amplitude)
        if quarter == 0:
            return "start"
        cycle, where = divmod(quarter, 4)
        if where == 0:
            return f"cycle_{cycle:03d}_end"
        return f"cycle_{cycle + 1:03d}_{'compression' if where == 1 else 'extension'}"

    return name


def _consolidate(context: Context) -> None:
    consolidate(context.sim, context.state, context.config, context.progress)


def _boundary(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    install_boundary(sim, run, config, context.progress)
    final, turns, snapshots = cycle_plan(config["cyclic.strain_amplitude"], config["cyclic.cycles"])
    start_platens(sim, run, config, final=final,
                  records=[Every(config["shear.record_interval"]), At([*turns, *snapshots])],
                  snapshots=snapshots, turns=turns)
    check_shear_plan(sim, run, config, snapshots, key="cyclic.strain_amplitude")


def _cycle(context: Context) -> None:
    config = context.config
    amplitude = config["cyclic.strain_amplitude"]
    plan = context.state.shear_plan()
    strain_per_step = plan.strain_rate * context.sim.time_step

    def path(steps: int) -> dict[str, float]:
        travelled = steps * strain_per_step
        return {STRAIN_PATH: travelled, CYCLE: travelled / (4.0 * amplitude)}

    final, _, _ = cycle_plan(amplitude, config["cyclic.cycles"])
    shear(context.sim, context.state, config, context.writer, context.save, context.progress, final=final,
          snapshot_name_of=snapshot_name_of(amplitude), extra=path, units=CYCLIC.units())


class CyclicProtocol(SpecimenProtocol[_Run, CyclicResult]):
    """The cyclic biaxial test (strain amplitude, N cycles, constant confining pressure)."""

    name = "cyclic"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        Stage("consolidate", _consolidate, "the four walls servo-controlled to sigma_0 until equilibrium"),
        Stage("boundary", _boundary, "the side walls replaced by the membrane (or the outer grains) under "
                                     "sigma_0, the sample re-equilibrated, the cycles planned"),
        Stage("shear", _cycle, "the platens between +/- the amplitude, N cycles; records and snapshots on "
                               "their triggers, checkpoints on the wall clock"),
    )
    state_type = _Run

    def check(self) -> None:
        check_strain_rate(self.config)
        check_density_scaling(self.config)

    def state_from_dict(self, saved: Any) -> _Run:
        return _Run.from_dict({k: v for k, v in saved.items() if k not in ("config", "elapsed_s")})

    def summary(self, context: Context, wall_time_s: float) -> dict[str, Any]:
        return summarise(context.state, self.config, context.writer.read_timeseries(), wall_time_s)

    def write_outputs(self, out: Path) -> dict[str, Any]:
        return write_outputs(out)

    def result(self, out: Path, summary: dict[str, Any]) -> CyclicResult:
        return CyclicResult(out, summary)


def run_cyclic(config: Config, out_dir: str | os.PathLike[str], *, resume: bool = False,
               progress: bool = False) -> CyclicResult:
    """Runs (or, with ``resume``, continues) the cyclic biaxial test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`)."""
    return run_protocol(CyclicProtocol(config), out_dir, resume=resume, progress=progress)
