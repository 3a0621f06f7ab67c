"""The biaxial test as a protocol of the runner (:mod:`grainlab.protocols.runner`):
its stages in order, its configuration, its summary and its outputs; and
:func:`run_biaxial`, which runs it into a results folder."""

from __future__ import annotations

import os
from typing import Any, ClassVar

from grainlab.columns import BIAXIAL
from grainlab.io.hdf5 import snapshot_name
from grainlab.protocols.biaxial import records as biaxial_records
from grainlab.protocols.biaxial.config import BiaxialConfig
from grainlab.protocols.biaxial.outputs import BiaxialResult, summarise, write_outputs
from grainlab.protocols.biaxial.phases import check_shear_plan, install_boundary, start_shear
from grainlab.protocols.biaxial.rates import check_density_scaling, check_strain_rate
from grainlab.protocols.biaxial.shearing import shear, shear_records, shear_snapshots
from grainlab.protocols.biaxial.state import BiaxialRun
from grainlab.protocols.cracks import record_units
from grainlab.protocols.runner import RUN_FILES, Stage, StageContext, run_protocol
from grainlab.protocols.specimen import CONSOLIDATE, OUTPUT_FILES, SpecimenProtocol

__all__ = ["OUTPUT_FILES", "RUN_FILES", "BiaxialProtocol", "run_biaxial"]


Context = StageContext[BiaxialConfig, BiaxialRun]



def _boundary(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    install_boundary(sim, run, config, context.progress)
    start_shear(sim, run, config)
    check_shear_plan(sim, run, config)


def _shear(context: Context) -> None:
    sim, run, config = context.sim, context.state, context.config
    records = shear_records(context, lambda: biaxial_records.measure(sim, run, config), record_units(BIAXIAL, config))
    shear(context, records, shear_snapshots(context, records, snapshot_name), final=config.shear.final_strain)


class BiaxialProtocol(SpecimenProtocol[BiaxialConfig, BiaxialRun, BiaxialResult]):
    """The paper's biaxial test (Sec. 6, Table 1); the sample is generated when the run starts."""

    name = "biaxial"
    stages: ClassVar[tuple[Stage[Any, Any], ...]] = (
        CONSOLIDATE,
        Stage("boundary", _boundary, "the side walls replaced by the membrane (or the outer grains) under "
                                     "sigma_0, the sample re-equilibrated, the shearing planned"),
        Stage("shear", _shear, "the platens at a constant axial strain rate to the final strain; records "
                               "and snapshots on their triggers, checkpoints on the wall clock"),
    )
    state_type = BiaxialRun
    summarise = summarise
    outputs = write_outputs
    result_type = BiaxialResult

    def check(self) -> None:
        check_strain_rate(self.config)  # a rate refused needs no warning about its inertia
        check_density_scaling(self.config)


def run_biaxial(
    config: BiaxialConfig,
    out_dir: str | os.PathLike[str],
    *,
    resume: bool = False,
    progress: bool = False,
) -> BiaxialResult:
    """Runs (or, with ``resume``, continues) the biaxial test into ``out_dir``
    (:func:`grainlab.protocols.runner.run_protocol`: resume from any stop point, a
    folder holding another run refused, a full disk stopped with the last checkpoint
    kept). ``progress`` shows each stage's progress on stderr (off by default; see
    :func:`grainlab._progress.progress_bar`)."""
    return run_protocol(BiaxialProtocol(config), out_dir, resume=resume, progress=progress)

