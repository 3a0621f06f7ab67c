"""Analysis of snapshots: fabric, stability index, strain fields, shear band, stresses,
force networks and chains, power cells, contact loops; per body for clumps
(:func:`body_view`).

Every measure is a small class in the freud style (parameters in the
constructor, ``compute(...)`` returns ``self``, results as properties that
raise until computed, ``plot(ax=None)``) backed by plain NumPy functions.
:func:`analyze_snapshot` runs them all, as ``grainlab analyze`` does.
"""

from grainlab.analysis.analyze import AnalysisResult, analyze_snapshot, fabric_summary
from grainlab.analysis.band_contacts import BandContacts
from grainlab.analysis.band_readings import DisplacementBand
from grainlab.analysis.body_analysis import BodyAnalysis, analyze_bodies
from grainlab.analysis.fabric import (
    EDGE_TOLERANCE_RAD,
    ContactAnisotropy,
    CoordinationNumber,
    angular_histogram,
    anisotropy_eq7,
    anisotropy_fourier,
    fabric_tensor,
    rattlers,
)
from grainlab.analysis.force_chains import ForceChains
from grainlab.analysis.loops import ContactLoops
from grainlab.analysis.networks import ForceNetworks
from grainlab.analysis.per_body import (
    BodyCoordination,
    BodyOrientation,
    BodyStabilityIndex,
    BodyView,
    body_view,
)
from grainlab.analysis.shear_band import ShearBand, Slab
from grainlab.analysis.stability import StabilityIndex, stability_index, stability_index_of_angles
from grainlab.analysis.strain import LocalStrain, match_ids, neighbour_pairs
from grainlab.analysis.stress import GrainStress, LoveWeberStress
from grainlab.analysis.stress_fabric import FabricTensor, StressForceFabric
from grainlab.analysis.tessellation import LocalPorosity, power_cells

__all__ = [
    "EDGE_TOLERANCE_RAD",
    "AnalysisResult",
    "BandContacts",
    "BodyAnalysis",
    "BodyCoordination",
    "BodyOrientation",
    "BodyStabilityIndex",
    "BodyView",
    "ContactAnisotropy",
    "ContactLoops",
    "CoordinationNumber",
    "DisplacementBand",
    "FabricTensor",
    "ForceChains",
    "ForceNetworks",
    "GrainStress",
    "LocalPorosity",
    "LocalStrain",
    "LoveWeberStress",
    "ShearBand",
    "Slab",
    "StabilityIndex",
    "StressForceFabric",
    "analyze_bodies",
    "analyze_snapshot",
    "angular_histogram",
    "anisotropy_eq7",
    "anisotropy_fourier",
    "body_view",
    "fabric_summary",
    "fabric_tensor",
    "match_ids",
    "neighbour_pairs",
    "power_cells",
    "rattlers",
    "stability_index",
    "stability_index_of_angles",
]
