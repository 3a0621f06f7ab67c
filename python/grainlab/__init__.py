"""grainlab: a 2D discrete element laboratory for granular soils.

The engine is Rust (:mod:`grainlab._core`); :class:`Simulation` drives it from NumPy.
"""

from grainlab._core import SimulationUnstableError, __version__, density_scaling_factor
from grainlab.bodies import ClumpMassProperties, clump_mass_properties
from grainlab.simulation import (
    FIX_ROTATION,
    FIX_X,
    FIX_Y,
    ContactModel,
    Contacts,
    Energy,
    PeriodicCell,
    PressureChainState,
    Simulation,
    Wall,
    WallContacts,
    WallState,
)

__all__ = [
    "FIX_ROTATION",
    "FIX_X",
    "FIX_Y",
    "ClumpMassProperties",
    "ContactModel",
    "Contacts",
    "Energy",
    "PeriodicCell",
    "PressureChainState",
    "Simulation",
    "SimulationUnstableError",
    "Wall",
    "WallContacts",
    "WallState",
    "__version__",
    "clump_mass_properties",
    "density_scaling_factor",
]
