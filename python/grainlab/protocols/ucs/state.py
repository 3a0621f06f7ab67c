"""What an unconfined compression run carries from stage to stage (saved in every checkpoint)."""

from __future__ import annotations

from dataclasses import dataclass

from grainlab.protocols.specimen import SpecimenRun

__all__ = ["UcsRun"]


@dataclass
class UcsRun(SpecimenRun):
    """What an unconfined compression run carries from stage to stage (saved in every
    checkpoint): :class:`SpecimenRun`'s fields, the sample's height and width after the
    seating (the strains' references), the step the compression started at (-1 before),
    the records taken, the peak so far (its stress, strain and record) and how the loading ended
    ("" while it runs, "final_strain" or "residual")."""

    height0: float = 0.0
    width0: float = 0.0
    release_steps: int = 0
    seating_steps: int = 0
    start_step: int = -1
    peak_stress_pa: float = 0.0
    peak_strain: float = 0.0
    peak_record: int = -1
    next_record: int = 0
    ended: str = ""
