"""What a crushing run carries from agglomerate to agglomerate (saved in every checkpoint)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Self

__all__ = ["CrushingRun"]


@dataclass
class CrushingRun:
    """What a crushing run carries (saved in every checkpoint): the phase, the wall time
    of each stage, the next agglomerate to crush and, for each one crushed, its outcome
    (:func:`grainlab.protocols.crushing.protocol.outcome`)."""

    phase: str
    wall_time: dict[str, float] = field(default_factory=dict)
    next_agglomerate: int = 0
    agglomerates: list[dict[str, Any]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, saved: dict[str, Any]) -> Self:
        """The state :meth:`to_dict` gave."""
        return cls(**saved)
