"""What a simple-shear run carries from stage to stage (saved in every checkpoint)."""

from __future__ import annotations

from dataclasses import dataclass, field

from grainlab.protocols.specimen import SpecimenRun

__all__ = ["SimpleShearRun"]


@dataclass
class SimpleShearRun(SpecimenRun):
    """:class:`SpecimenRun`'s fields and the shearing's plan: the shear rate
    (1/s), the normal stress held (Pa; the starting sigma_yy at constant
    volume), the mean grain diameter (m), the step shearing started at, the
    cell's area then, the next record, and the integral part of
    the cell's control for each side (1/s)."""

    shear_rate_per_s: float = 0.0
    normal_stress_pa: float = 0.0
    mean_diameter_m: float = 0.0
    start_step: int = 0
    area0: float = 0.0
    next_record: int = 0
    cell_rate_integral: list[float] = field(default_factory=lambda: [0.0, 0.0])
