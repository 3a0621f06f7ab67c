"""Periodic simple shear: a sample in a periodic cell sheared at constant
normal stress or constant volume to large strain, the cell remapped as it
leans (docs/protocols.md, "Periodic simple shear")."""

from grainlab.protocols.simple_shear.cell import CellStress, cell_stress, servo_rate
from grainlab.protocols.simple_shear.config import SIMPLE_SHEAR_FIELDS, SIMPLE_SHEAR_SCHEMA
from grainlab.protocols.simple_shear.outputs import STEADY_FROM, SimpleShearResult, steady_rows
from grainlab.protocols.simple_shear.protocol import (
           SimpleShearProtocol,
           run_simple_shear,
           snapshot_name_of,
)
from grainlab.protocols.simple_shear.state import SimpleShearRun

__all__ = ["SIMPLE_SHEAR_FIELDS", "SIMPLE_SHEAR_SCHEMA", "STEADY_FROM", "CellStress", "SimpleShearProtocol",
           "SimpleShearResult", "SimpleShearRun", "cell_stress", "run_simple_shear", "servo_rate",
           "snapshot_name_of", "steady_rows"]
