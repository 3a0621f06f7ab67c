"""The Brazilian (indirect tensile) test of a cemented disc: a disc carved from the
consolidated sample between two platens, the top one down at a constant speed to
the peak force and past it, sigma_t = 2 F_max / (pi D t) (docs/cemented.md, "The
Brazilian test")."""

from grainlab.protocols.brazilian.config import BRAZILIAN_FIELDS, BRAZILIAN_SCHEMA, BrazilianConfig
from grainlab.protocols.brazilian.outputs import BrazilianResult
from grainlab.protocols.brazilian.protocol import (
           BrazilianProtocol,
           indirect_tensile_stress,
           run_brazilian,
)
from grainlab.protocols.brazilian.state import BrazilianRun

__all__ = ["BRAZILIAN_FIELDS", "BRAZILIAN_SCHEMA", "BrazilianConfig", "BrazilianProtocol", "BrazilianResult",
           "BrazilianRun", "indirect_tensile_stress", "run_brazilian"]
