"""Operations: what a loading does at its stops, each on its own trigger
(:mod:`grainlab.protocols.triggers`): a :class:`Loading` runs the engine from
one stop to the next, the operations acting in the list's order where their
triggers fire, and those that :attr:`~Operation.acts_before_run` as it leaves a
stop (docs/protocols.md, "Operations and triggers")."""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from typing import ClassVar
from typing import Protocol as TypingProtocol

from grainlab._interrupt import raise_if_interrupted
from grainlab.io.hdf5 import ResultsWriter
from grainlab.io.walls import WallGeometry
from grainlab.protocols.triggers import Trigger
from grainlab.simulation import Simulation
from grainlab.snapshot import Snapshot

__all__ = ["Bar", "Checkpoint", "Loading", "Operation", "Progress", "RecordCount", "Records", "Snapshots",
           "Stop", "run_loading"]


class Operation(ABC):
    """Acts (:meth:`act`) at each stop where :attr:`trigger` fires, when the engine reaches it."""

    #: True: acts as the engine leaves the stop instead, setting the motion of the steps ahead.
    acts_before_run: ClassVar[bool] = False

    def __init__(self, trigger: Trigger) -> None:
        self.trigger = trigger

    @abstractmethod
    def act(self, loading: Loading) -> None: ...


class Loading:
    """The engine run from stop to stop, ``operations`` acting at each (docs/protocols.md)."""

    def __init__(self, sim: Simulation, operations: Sequence[Operation]) -> None:
        self.sim = sim
        self.operations = list(operations)
        self.next_stop = sim.step_count
        self._stopped = False

    def stop(self) -> None:
        """Ends the loading at this stop, before the operations after the caller act."""
        self._stopped = True

    def run(self) -> None:
        arriving = [op for op in self.operations if not op.acts_before_run]
        leaving = [op for op in self.operations if op.acts_before_run]
        while True:
            step = self.sim.step_count
            stops = [s for s in (op.trigger.next_step(step) for op in self.operations) if s is not None]
            if not stops:
                raise ValueError(f"a loading at step {step} with no stop ahead and no stop rule that ended it")
            self.next_stop = min(stops)
            for op in leaving:
                if op.trigger(step):
                    op.act(self)
            self.sim.run(self.next_stop - step)
            for op in arriving:
                if op.trigger(self.next_stop):
                    op.act(self)
                if self._stopped:
                    return
            raise_if_interrupted()


class Bar(TypingProtocol):
    """A progress display (:func:`grainlab._progress.progress_bar`)."""

    def update(self, n: float = 1) -> None: ...
    def set_postfix_str(self, text: str = "", refresh: bool = True) -> None: ...
    def close(self) -> None: ...


class RecordCount(TypingProtocol):
    """A run state's count of the scheduled records taken (saved in its checkpoints)."""

    next_record: int


class Records(Operation):
    """Writer: ``measure()`` appended to the time series (in ``units``), at most once
    a step (:attr:`values` is the last record); each scheduled one counted in
    ``count.next_record``. ``buffered``: the records are kept until :meth:`flush`
    appends them at once (a loading with no checkpoint inside)."""

    def __init__(self, trigger: Trigger, writer: ResultsWriter, measure: Callable[[], dict[str, float]],
                 units: Mapping[str, str], count: RecordCount | None = None, *, buffered: bool = False) -> None:
        super().__init__(trigger)
        self.writer, self.measure, self.units, self.count = writer, measure, units, count
        self.values: dict[str, float] = {}
        self.step = -1
        self.kept: list[dict[str, float]] | None = [] if buffered else None

    def write(self, step: int) -> dict[str, float]:
        """The record of ``step``, taken and written (or kept) unless it was already."""
        if step != self.step:
            self.values, self.step = self.measure(), step
            if self.kept is None:
                self.writer.append_timeseries(self.values, units=self.units)
            else:
                self.kept.append(self.values)
        return self.values

    def flush(self) -> None:
        """The records kept so far appended to the time series."""
        if self.kept:
            self.writer.append_rows({name: [r[name] for r in self.kept] for name in self.kept[0]}, units=self.units)
            self.kept.clear()

    def act(self, loading: Loading) -> None:
        self.write(loading.sim.step_count)
        if self.count is not None:
            self.count.next_record += 1


class Snapshots(Operation):
    """Writer: the state ``take()`` stored as the snapshot ``name_of(step)``, with the
    walls ``walls()`` when given."""

    def __init__(self, trigger: Trigger, writer: ResultsWriter, name_of: Callable[[int], str],
                 take: Callable[[], Snapshot], walls: Callable[[], WallGeometry] | None = None) -> None:
        super().__init__(trigger)
        self.writer, self.name_of, self.take, self.walls = writer, name_of, take, walls

    def store(self, name: str, step: int) -> None:
        walls = None if self.walls is None else self.walls()
        self.writer.write_snapshot(name, self.take(), step=step, walls=walls)

    def act(self, loading: Loading) -> None:
        step = loading.sim.step_count
        self.store(self.name_of(step), step)


class Checkpoint(Operation):
    """Writer: a checkpoint (``save()``), the stage's wall time booked first in
    ``wall_time[stage]`` (counted on from what it holds)."""

    def __init__(self, trigger: Trigger, save: Callable[[], None], wall_time: dict[str, float], stage: str) -> None:
        super().__init__(trigger)
        self.save, self.wall_time, self.stage = save, wall_time, stage
        self.started = time.perf_counter() - wall_time.get(stage, 0.0)

    def book(self) -> None:
        """The stage's wall time so far into ``wall_time``."""
        self.wall_time[self.stage] = time.perf_counter() - self.started

    def act(self, loading: Loading) -> None:
        self.book()
        self.save()


class Progress(Operation):
    """Writer: the progress ``bar`` moved to ``position()``, ``postfix()`` beside it."""

    def __init__(self, trigger: Trigger, bar: Bar, position: Callable[[int], float],
                 postfix: Callable[[], str], done: float = 0.0) -> None:
        super().__init__(trigger)
        self.bar, self.position, self.postfix, self.done = bar, position, postfix, done

    def act(self, loading: Loading) -> None:
        reached = self.position(loading.sim.step_count)
        self.bar.update(reached - self.done)
        self.done = reached
        self.bar.set_postfix_str(self.postfix())


class Stop(Operation):
    """Stop rule: the loading ends where the trigger fires."""

    def act(self, loading: Loading) -> None:
        loading.stop()


def run_loading(sim: Simulation, operations: Sequence[Operation], checkpoint: Checkpoint,
                bar: Bar | None = None) -> None:
    """Runs ``operations`` as a :class:`Loading`; the stage's wall time is booked
    (``checkpoint``) and the progress bar closed at its end."""
    try:
        Loading(sim, operations).run()
    finally:
        if bar is not None:
            bar.close()
    checkpoint.book()
