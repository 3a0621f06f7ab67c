"""Triggers: when a stage records, stores a snapshot or writes a checkpoint.

A stage that loads a sample along a control variable (the biaxial test's axial
strain, a shear strain, a number of cycles) schedules its records and
snapshots on engine steps: :class:`Every` fires at each increment of the
variable, :class:`At` at given values, and :func:`schedule_steps` turns
triggers into the engine steps they fall on. :class:`WallClock` fires once
every so many seconds of wall time (the checkpoints).

>>> schedule_steps([Every(0.25), At([0.1, 0.6])], final=1.0, steps_per_unit=100)
[10, 25, 50, 60, 75, 100]
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = ["At", "Every", "WallClock", "schedule_steps"]


@dataclass(frozen=True)
class Every:
    """Fires at every ``increment`` of the control variable: ``increment``, ``2 increment``,
    ... up to the final value (the last multiple within it)."""

    increment: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.increment) and self.increment > 0):
            raise ValueError(f"increment: must be a positive number, got {self.increment!r}")

    def values(self, final: float) -> list[float]:
        return [k * self.increment for k in range(1, int(round(final / self.increment)) + 1)]


@dataclass(frozen=True)
class At:
    """Fires at the given values of the control variable (those above 0 and within the final one)."""

    at: tuple[float, ...]

    def __init__(self, at: Iterable[float]) -> None:
        object.__setattr__(self, "at", tuple(float(v) for v in at))

    def values(self, final: float) -> list[float]:
        return [v for v in self.at if 0 < v <= final + 1e-12]


def schedule_steps(triggers: Iterable[Every | At], *, final: float, steps_per_unit: float) -> list[int]:
    """The engine steps (counted from the stage's start) on which ``triggers`` fire,
    each once, in order: a value ``v`` falls on step ``round(v * steps_per_unit)``."""
    steps = {round(v * steps_per_unit) for trigger in triggers for v in trigger.values(final)}
    return sorted(steps)


class WallClock:
    """Fires when more than ``seconds`` of wall time have passed since it last fired
    (or was made): ``if trigger(): save()``."""

    def __init__(self, seconds: float) -> None:
        if not seconds > 0:
            raise ValueError(f"seconds: must be positive, got {seconds!r}")
        self.seconds = float(seconds)
        self._last = time.perf_counter()

    def __call__(self) -> bool:
        now = time.perf_counter()
        if now - self._last > self.seconds:
            self._last = now
            return True
        return False
