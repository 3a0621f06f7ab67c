"""grainlab: a 2D discrete element laboratory for granular soils."""

from grainlab._core import __version__

__all__ = ["__version__"]
