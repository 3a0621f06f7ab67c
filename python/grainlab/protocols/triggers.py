"""Triggers: on which steps an operation of a loading acts
(:mod:`grainlab.protocols.operations`).

A loading runs the engine from one *stop* to the next. Each operation has a
trigger: asked ``trigger(step)`` at every stop, it says whether the operation
acts there, and ``trigger.next_step(step)`` says where the loading must stop
next for it (None: it needs no stop of its own). :class:`OnSteps` fires on
given steps, :class:`Periodic` on every multiple of a period, :class:`EveryStop`
at each stop, :class:`Flag` where an operation raised it, :class:`WallClock`
once so many seconds of wall time have passed, :class:`And` where all of its
triggers fire.

A loading along a control variable (the axial strain, a shear strain) plans its
records and snapshots in that variable: :class:`Every` at each increment of it,
:class:`At` at given values, and :func:`schedule_steps` turns those into the
engine steps they fall on.

>>> schedule_steps([Every(0.25), At([0.1, 0.6])], final=1.0, steps_per_unit=100)
[10, 25, 50, 60, 75, 100]
"""

from __future__ import annotations

import bisect
import math
import time
from abc import ABC, abstractmethod
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = ["And", "At", "Every", "EveryStop", "Flag", "OnSteps", "Periodic", "Trigger", "WallClock", "schedule_steps"]


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
    """The engine steps (counted from the loading's start) on which ``triggers`` fire,
    each once, in order: a value ``v`` falls on step ``round(v * steps_per_unit)``."""
    steps = {round(v * steps_per_unit) for trigger in triggers for v in trigger.values(final)}
    return sorted(steps)


class Trigger(ABC):
    """When an operation acts: ``trigger(step)`` at each stop of the loading."""

    @abstractmethod
    def __call__(self, step: int) -> bool: ...

    def next_step(self, step: int) -> int | None:
        """The first step after ``step`` at which the loading must stop for this trigger
        (None: it asks for no stop of its own)."""
        return None


class OnSteps(Trigger):
    """Fires on the engine steps ``offset + s`` for each ``s`` of ``steps``."""

    def __init__(self, steps: Iterable[int], offset: int = 0) -> None:
        self.steps = sorted({offset + int(s) for s in steps})

    def __call__(self, step: int) -> bool:
        k = bisect.bisect_left(self.steps, step)
        return k < len(self.steps) and self.steps[k] == step

    def next_step(self, step: int) -> int | None:
        k = bisect.bisect_right(self.steps, step)
        return self.steps[k] if k < len(self.steps) else None


@dataclass(frozen=True)
class Periodic(Trigger):
    """Fires on the steps ``phase + k period``, and stops the loading on each."""

    period: int
    phase: int = 0

    def __call__(self, step: int) -> bool:
        return (step - self.phase) % self.period == 0

    def next_step(self, step: int) -> int | None:
        return step + self.period - (step - self.phase) % self.period


@dataclass(frozen=True)
class EveryStop(Trigger):
    """Fires at every stop of the loading; with ``at_most``, makes the loading stop at
    least every ``at_most`` steps (counted from its last stop, whatever made it)."""

    at_most: int | None = None

    def __call__(self, step: int) -> bool:
        return True

    def next_step(self, step: int) -> int | None:
        return None if self.at_most is None else step + self.at_most


class Flag(Trigger):
    """Fires on the step an operation raised it (:meth:`raise_at`)."""

    def __init__(self) -> None:
        self.step = -1

    def raise_at(self, step: int) -> None:
        self.step = step

    def __call__(self, step: int) -> bool:
        return step == self.step


class WallClock(Trigger):
    """Fires when more than ``seconds`` of wall time have passed since it last fired
    (or was made)."""

    def __init__(self, seconds: float) -> None:
        if not seconds > 0:
            raise ValueError(f"seconds: must be positive, got {seconds!r}")
        self.seconds = float(seconds)
        self._last = time.perf_counter()

    def __call__(self, step: int) -> bool:
        now = time.perf_counter()
        if now - self._last > self.seconds:
            self._last = now
            return True
        return False


class And(Trigger):
    """Fires where each of ``triggers`` fires, asked in order (a later one only where
    the earlier fire: ``And(OnSteps(...), WallClock(30))`` reads the clock on those
    steps alone); stops the loading where the first asks."""

    def __init__(self, *triggers: Trigger) -> None:
        self.triggers = triggers

    def __call__(self, step: int) -> bool:
        return all(trigger(step) for trigger in self.triggers)

    def next_step(self, step: int) -> int | None:
        return self.triggers[0].next_step(step)
