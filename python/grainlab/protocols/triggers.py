"""Triggers: on which steps an operation of a loading acts
(:mod:`grainlab.protocols.operations`): ``trigger(step)`` says whether it acts at
a stop, ``trigger.next_step(step)`` where the loading must stop next for it
(docs/protocols.md, "Operations and triggers")."""

from __future__ import annotations

import bisect
import time
from abc import ABC, abstractmethod
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = ["And", "EveryStop", "Flag", "OnSteps", "Periodic", "Trigger", "WallClock", "schedule_steps"]


def schedule_steps(every: float, at: Iterable[float] = (), *, final: float, steps_per_unit: float) -> list[int]:
    """The engine steps (counted from the loading's start) of a plan in a control
    variable (an axial or a shear strain): each multiple of ``every`` up to ``final``
    and each value of ``at`` above 0 and within it, a value ``v`` on step
    ``round(v * steps_per_unit)``, each step once, in order.

    >>> schedule_steps(0.25, [0.1, 0.6], final=1.0, steps_per_unit=100)
    [10, 25, 50, 60, 75, 100]
    """
    values = [k * every for k in range(1, int(round(final / every)) + 1)]
    values += [float(v) for v in at if 0 < v <= final + 1e-12]
    return sorted({round(v * steps_per_unit) for v in values})


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
