"""What an unconfined compression run carries from stage to stage (saved in every checkpoint)."""

from __future__ import annotations

from dataclasses import dataclass

from grainlab.protocols.platens import PlatenRun

__all__ = ["UcsRun"]


@dataclass
class UcsRun(PlatenRun):
    """What an unconfined compression run carries from stage to stage (saved in every
    checkpoint): :class:`PlatenRun`'s fields (the loading's start, records, peak and end),
    the steps of the seating and the sample's height and width after it (the strains'
    references)."""

    height0: float = 0.0
    width0: float = 0.0
    seating_steps: int = 0
