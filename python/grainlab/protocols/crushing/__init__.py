"""The crushing test of single agglomerates: crushable grains of bonded disks crushed
diametrically between two platens one after the other, their strengths and the
Weibull fit (docs/cemented.md, "Crushable grains")."""

from grainlab.protocols.crushing.config import CRUSHING_FIELDS, CRUSHING_SCHEMA, CrushingConfig
from grainlab.protocols.crushing.outputs import CrushingResult, agglomerate_peaks
from grainlab.protocols.crushing.protocol import CrushingProtocol, agglomerate_test, run_crushing
from grainlab.protocols.crushing.state import CrushingRun

__all__ = ["CRUSHING_FIELDS", "CRUSHING_SCHEMA", "CrushingConfig", "CrushingProtocol", "CrushingResult", "CrushingRun",
           "agglomerate_peaks", "agglomerate_test", "run_crushing"]
