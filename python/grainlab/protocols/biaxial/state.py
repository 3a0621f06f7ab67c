"""What a biaxial run carries from phase to phase (saved in every checkpoint),
its boundary, and the error a run stops with."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grainlab.protocols.boundary import GrainBoundary, Membrane
from grainlab.protocols.runner import ProtocolError

#: Steps per engine call while a phase waits for a condition.
CHUNK_STEPS = 2000


class BiaxialError(ProtocolError):
    """The test could not proceed (e.g. consolidation did not converge)."""


@dataclass
class _Run:
    """What a run carries from phase to phase, saved in every checkpoint."""

    phase: str
    n_grains: int
    grain_density: float
    walls: dict[str, int]
    wall_time: dict[str, float]
    sample: dict[str, Any]
    consolidation: dict[str, Any]
    membrane: dict[str, Any] | None = None
    shear: dict[str, Any] | None = None
    rows: int = 0
    snapshots: list[str] | None = None

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)

    def boundary_state(self) -> dict[str, Any]:
        """The lateral boundary's record (:attr:`membrane`), set by the boundary phase."""
        if self.membrane is None:
            raise BiaxialError(f"the run has no lateral boundary yet (phase {self.phase!r})")
        return self.membrane

    def shear_plan(self) -> dict[str, Any]:
        """The shearing phase's plan and progress (:attr:`shear`), set when shearing starts."""
        if self.shear is None:
            raise BiaxialError(f"the run has no shearing plan yet (phase {self.phase!r})")
        return self.shear


def _boundary(run: _Run) -> Membrane | GrainBoundary:
    """The run's lateral boundary (the membrane, or variant B's grain chains)."""
    boundary = run.boundary_state()
    if boundary.get("kind") == GrainBoundary.kind:
        return GrainBoundary.from_dict(boundary)
    return Membrane.from_dict(boundary)
