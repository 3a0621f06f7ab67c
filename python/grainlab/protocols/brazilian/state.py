"""What a Brazilian run carries from stage to stage (saved in every checkpoint)."""

from __future__ import annotations

from dataclasses import dataclass, field

from grainlab.protocols.platens import PlatenRun

__all__ = ["BrazilianRun"]


@dataclass
class BrazilianRun(PlatenRun):
    """What a Brazilian run carries from stage to stage (saved in every checkpoint):
    :class:`PlatenRun`'s fields (the loading's start, records, peak and end), the
    consolidated sample's particles and cement bonds, the disc's centre and the diameter of
    the circle its grains' centres lie in, the particles in that circle left out (the
    cement did not hold them to the disc), and D, the disc's diameter between the
    platens (the distance between them when the loading starts)."""

    sample_particles: int = 0
    sample_cement_bonds: int = 0
    loose_particles: int = 0
    centre_m: list[float] = field(default_factory=list)
    carve_diameter_m: float = 0.0
    diameter_m: float = 0.0
