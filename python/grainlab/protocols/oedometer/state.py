"""What an oedometer run carries from stage to stage (saved in every checkpoint)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from grainlab.protocols.specimen import SpecimenRun

__all__ = ["OedometerRun"]


@dataclass
class OedometerRun(SpecimenRun):
    """What an oedometer run carries from stage to stage (saved in every checkpoint):
    :class:`SpecimenRun`'s fields, the box at sigma_0 with friction on (the strains' reference), the next load
    step, the largest vertical stress reached so far and the step the loading started at."""

    height0: float = 0.0
    area0: float = 0.0
    next_load: int = 0
    max_vertical_stress_pa: float = 0.0
    #: The engine step at which the loading started (after the confinement).
    load_start_step: int = 0
    #: A sample of agglomerates: the fragments' grading at each load step's equilibrium.
    fragment_grading: list[dict[str, Any]] = field(default_factory=list)
