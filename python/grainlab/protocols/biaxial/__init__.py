"""The paper's biaxial test, end to end (Sec. 6, Table 1).

The stages of :class:`BiaxialProtocol`, run in order by the protocol runner
(:mod:`grainlab.protocols.runner`), each by the engine in blocks of steps
(generation makes the sample when the run starts):

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
results as an uninterrupted one (same configuration, on any thread count).

Sign conventions: stresses and strains compression positive; axial strain
``(H0 - H) / H0``, volumetric (area) strain ``(A0 - A) / A0`` from the
membrane polygon, both from the start of shearing.
"""

from grainlab.protocols.biaxial.outputs import PAPER_VALUES, BiaxialResult
from grainlab.protocols.biaxial.protocol import (
    OUTPUT_FILES,
    RUN_FILES,
    BiaxialProtocol,
    run_biaxial,
)
from grainlab.protocols.biaxial.rates import (
    DENSITY_SCALING_LIMIT,
    MAX_PLATEN_TRAVEL_PER_STEP,
    MIN_STEPS_PER_RECORD,
    DensityScalingWarning,
    check_density_scaling,
    check_strain_rate,
    default_strain_rate,
    inertial_number,
    strain_rate_problem,
)
from grainlab.protocols.biaxial.records import TIMESERIES_UNITS
from grainlab.protocols.biaxial.state import CHUNK_STEPS, BiaxialError

__all__ = [
    "CHUNK_STEPS",
    "DENSITY_SCALING_LIMIT",
    "MAX_PLATEN_TRAVEL_PER_STEP",
    "MIN_STEPS_PER_RECORD",
    "OUTPUT_FILES",
    "PAPER_VALUES",
    "RUN_FILES",
    "TIMESERIES_UNITS",
    "BiaxialError",
    "BiaxialProtocol",
    "BiaxialResult",
    "DensityScalingWarning",
    "check_density_scaling",
    "check_strain_rate",
    "default_strain_rate",
    "inertial_number",
    "run_biaxial",
    "strain_rate_problem",
]
