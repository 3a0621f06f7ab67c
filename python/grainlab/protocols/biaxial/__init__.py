"""The paper's biaxial test, end to end (Sec. 6, Table 1): the sample generated,
consolidated, its side walls replaced by the flexible boundary and sheared at a
constant axial strain rate, into one results folder that ``--resume`` continues
to the same bits (docs/biaxial.md: the phases, the records, the sign
conventions)."""

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
