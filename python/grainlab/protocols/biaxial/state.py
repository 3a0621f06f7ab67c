"""What a biaxial or cyclic run carries from stage to stage (saved in every
checkpoint), its lateral boundary, and the error a run stops with."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from grainlab.protocols.boundary import GrainBoundary, Membrane, WallBoundary
from grainlab.protocols.specimen import CHUNK_STEPS, SpecimenError, SpecimenRun

__all__ = ["CHUNK_STEPS", "BiaxialError", "BiaxialRun", "Boundary", "ShearPlan", "boundary_from_dict"]


class BiaxialError(SpecimenError):
    """The biaxial test could not proceed (e.g. the membrane was breached)."""


@dataclass
class ShearPlan:
    """The shearing's plan and progress, set when shearing starts: the rate and the
    platens' speed, the reference height and area of the strains, the engine steps
    (counted from ``start_step``) of the records and of the snapshots (``snapshot_steps``:
    step, as text, to the snapshot's strain), the next record to take, and the rate's
    inertial numbers and Eq. 16 factor, the turning points of a cyclic test. Checkpoints
    store it as a dict with these keys (``next_record`` as ``next``)."""

    strain_rate: float
    platen_speed_m_per_s: float
    height0: float
    area0: float
    start_step: int
    record_steps: list[int]
    snapshot_steps: dict[str, float]
    inertial_number: float
    inertial_number_mean_diameter: float
    density_scaling_factor: float
    porosity_initial: float
    next_record: int = 0
    #: Engine steps (counted from ``start_step``) at which the platens reverse (a cyclic test's
    #: turning points; none in a monotonic test), and the next of them to come.
    turn_steps: list[int] = field(default_factory=list)
    next_turn: int = 0
    #: Events a loading's rule has reported so far (a stress-controlled cyclic test's turning
    #: points and crossings of q = 0; none otherwise).
    events: int = 0

    def to_dict(self) -> dict[str, Any]:
        saved = asdict(self)
        saved["next"] = saved.pop("next_record")
        if not self.turn_steps:  # a monotonic test's checkpoints keep their earlier layout
            del saved["turn_steps"], saved["next_turn"]
        if not self.events:
            del saved["events"]
        return saved

    @classmethod
    def from_dict(cls, saved: dict[str, Any]) -> ShearPlan:
        values = dict(saved)
        values["next_record"] = values.pop("next", 0)
        return cls(**values)


#: A biaxial run's lateral boundary.
Boundary = Membrane | GrainBoundary | WallBoundary


def boundary_from_dict(saved: dict[str, Any]) -> Boundary:
    """The lateral boundary a checkpoint stored (its ``to_dict()``)."""
    kinds: dict[str, type[Boundary]] = {GrainBoundary.kind: GrainBoundary, WallBoundary.kind: WallBoundary}
    return kinds.get(saved.get("kind", ""), Membrane).from_dict(saved)


@dataclass
class BiaxialRun(SpecimenRun):
    """What a biaxial (or cyclic) run carries from stage to stage, saved in every
    checkpoint: :class:`SpecimenRun`'s fields, the lateral boundary (set by the boundary
    stage; checkpoints store it as ``membrane``, whichever it is) and the shearing's plan."""

    boundary: Boundary | None = None
    shear: ShearPlan | None = None

    def to_dict(self) -> dict[str, Any]:
        saved = dict(self.__dict__)
        boundary = saved.pop("boundary")
        saved["membrane"] = None if boundary is None else boundary.to_dict()
        saved["shear"] = None if self.shear is None else self.shear.to_dict()
        return saved

    @classmethod
    def from_dict(cls, saved: dict[str, Any]) -> BiaxialRun:
        values = dict(saved)
        boundary = values.pop("membrane", None)
        values["boundary"] = None if boundary is None else boundary_from_dict(boundary)
        if values.get("shear") is not None:
            values["shear"] = ShearPlan.from_dict(values["shear"])
        return cls(**values)

    def lateral_boundary(self) -> Boundary:
        """The lateral boundary (the membrane, variant B's grain chains or variant C's
        walls), set by the boundary stage."""
        if self.boundary is None:
            raise BiaxialError(f"the run has no lateral boundary yet (phase {self.phase!r})")
        return self.boundary

    def shear_plan(self) -> ShearPlan:
        """The shearing's plan and progress (:attr:`shear`), set when shearing starts."""
        if self.shear is None:
            raise BiaxialError(f"the run has no shearing plan yet (phase {self.phase!r})")
        return self.shear
