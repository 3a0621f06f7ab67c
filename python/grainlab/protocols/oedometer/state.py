"""What an oedometer run carries from stage to stage (saved in every checkpoint)."""

from __future__ import annotations

from dataclasses import dataclass

from grainlab.protocols.specimen import SpecimenRun

__all__ = ["OedometerRun"]


@dataclass
class OedometerRun(SpecimenRun):
    """What an oedometer run carries from stage to stage (saved in every checkpoint):
    :class:`SpecimenRun`'s fields, the box at sigma_0 with friction on (the strains' reference), the next load
    step and the largest vertical stress reached so far."""

    height0: float = 0.0
    area0: float = 0.0
    next_load: int = 0
    max_vertical_stress_pa: float = 0.0
