"""One runner for every protocol: a protocol is a named list of stages over its
run state, and :func:`run_protocol` runs them into a results folder, owning what
every test needs and none should write again: the folder's lock, the results
file, the checkpoints, ``--resume``, interrupts and the full disk
(docs/protocols.md, which also shows how to add one)."""

from __future__ import annotations

import contextlib
import json
import os
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Generic, TypeVar
from typing import Protocol as TypingProtocol

import numpy as np

from grainlab._mapping import flatten_keys
from grainlab.io.hdf5 import PARTIAL_SUFFIX, ResultsWriter, read_checkpoint, write_checkpoint
from grainlab.io.results import (
    CHECKPOINT_FILE,
    RESULTS_FILE,
    ensure_output_folder,
    is_disk_full,
    refuse_overwrite,
    writer_lock,
)
from grainlab.simulation import Simulation

__all__ = [
    "DONE",
    "EXECUTION_KEYS",
    "RUNNER_KEYS",
    "RUN_FILES",
    "Protocol",
    "ProtocolError",
    "RunResult",
    "RunState",
    "Stage",
    "StageContext",
    "run_protocol",
]

#: The phase of a run whose stages have all run.
DONE = "done"
#: Files that only a run writes: a new run refuses a folder holding any of them
#: (``--resume`` continues that run, or finishes its outputs).
RUN_FILES = (RESULTS_FILE, RESULTS_FILE + PARTIAL_SUFFIX, CHECKPOINT_FILE)
#: Keys that set how a run is executed, not one bit of what it computes (the
#: engine gives the same bits on any thread count): a run resumes under other values.
EXECUTION_KEYS = frozenset({"run.threads", "run.checkpoint_interval"})
#: What the runner saves in a checkpoint beside the state (the state is read without them).
RUNNER_KEYS = frozenset({"config", "elapsed_s"})
#: Name of the checkpoint array that holds the partial results file (:meth:`ResultsWriter.publish`).
_RESULTS_IMAGE = "results_partial"


class ProtocolError(RuntimeError):
    """A run could not proceed (a stage's condition was not met, a full disk)."""


class RunState(TypingProtocol):
    """What a protocol's run state offers the runner: the phase it is in, the wall
    time of each stage, and a dict of JSON values saved in every checkpoint."""

    phase: str
    wall_time: dict[str, float]

    def to_dict(self) -> dict[str, Any]: ...


S = TypeVar("S", bound=RunState)
C = TypeVar("C")


@dataclass
class StageContext(Generic[C, S]):
    """What a stage works on: the simulation, the run state, the configuration,
    the results writer, ``save()`` (a checkpoint now) and whether to show progress.
    A stage may put a new simulation in :attr:`sim` (the Brazilian test's disc, carved
    from the consolidated sample): the checkpoints and the stages after it take that one."""

    sim: Simulation
    state: S
    config: C
    writer: ResultsWriter
    save: Callable[[], None]
    progress: bool


@dataclass(frozen=True)
class Stage(Generic[C, S]):
    """One stage of a protocol: ``run(context)`` runs while the state's phase is ``name``."""

    name: str
    run: Callable[[StageContext[C, S]], None]
    #: What the stage does, in a line (ARCHITECTURE.md's stage lists, ``grainlab protocols``).
    description: str = ""


@dataclass(frozen=True)
class RunResult:
    """A finished run: its folder and its summary."""

    out_dir: Path
    summary: dict[str, Any]


R = TypeVar("R", bound=RunResult)


class Protocol(ABC, Generic[C, S, R]):
    """A test as the runner runs it. Subclasses set :attr:`name` (also the results
    file's ``kind``), :attr:`stages`, :attr:`output_files`, and implement the
    abstract methods; ``config`` is the resolved configuration."""

    name: ClassVar[str]
    #: The stages in order (the first one runs on the state :meth:`start` returns).
    stages: ClassVar[tuple[Stage[Any, Any], ...]]
    #: The run's outputs besides :data:`RUN_FILES` (globs): a new run refuses a folder
    #: that already holds one, which another run or the user wrote.
    output_files: ClassVar[tuple[str, ...]] = ()
    #: HDF5 filter of run.h5's snapshot arrays.
    compression: ClassVar[str | None] = "gzip"

    def __init__(self, config: C) -> None:
        self.config = config

    # ---- before any work ----------------------------------------------------------
    def check(self) -> None:
        """Refuse (``ValueError``) or warn about the configuration before any work."""

    @abstractmethod
    def threads(self) -> int:
        """The engine thread count the configuration asks for."""

    @abstractmethod
    def config_dict(self) -> dict[str, Any]:
        """The configuration as the results file and the checkpoints store it."""

    @abstractmethod
    def resolve_saved(self, saved: Any) -> dict[str, Any] | None:
        """A saved configuration resolved as this grainlab would (keys added since it was
        written take their defaults), or None when it cannot be."""

    # ---- the run ------------------------------------------------------------------
    @abstractmethod
    def start(self, threads: int, progress: bool) -> tuple[Simulation, S]:
        """The simulation and the state of a new run, its phase the first stage's name."""

    @abstractmethod
    def state_from_dict(self, saved: Mapping[str, Any]) -> S:
        """The state a checkpoint saved (:meth:`RunState.to_dict`; without :data:`RUNNER_KEYS`)."""

    @abstractmethod
    def summary(self, context: StageContext[C, S], wall_time_s: float) -> dict[str, Any]:
        """The summary of a run whose stages have all run."""

    @abstractmethod
    def write_outputs(self, out: Path) -> dict[str, Any]:
        """The outputs written from the final ``run.h5`` (a stop while they are written
        finishes them with ``--resume``); returns the summary."""

    @abstractmethod
    def result(self, out: Path, summary: dict[str, Any]) -> R:
        """What the run returns."""

    # ---- derived ------------------------------------------------------------------
    def stage(self, phase: str) -> Stage[Any, Any]:
        for stage in self.stages:
            if stage.name == phase:
                return stage
        raise ProtocolError(f"{self.name}: a run in phase {phase!r}, which is none of its stages "
                            f"({', '.join(s.name for s in self.stages)})")

    def next_phase(self, phase: str) -> str:
        names = [s.name for s in self.stages]
        index = names.index(self.stage(phase).name)
        return names[index + 1] if index + 1 < len(names) else DONE


def config_difference(protocol: Protocol[Any, Any, Any], saved: Any) -> str | None:
    """The keys other than :data:`EXECUTION_KEYS` on which a run's saved
    configuration and the protocol's differ, with both values; None when they agree."""
    resolved = protocol.resolve_saved(saved)
    if resolved is None:
        return "the run's saved configuration cannot be read by this grainlab"
    # compared as stored (JSON: a tuple is a list)
    old, new = (flatten_keys(json.loads(json.dumps(c))) for c in (resolved, protocol.config_dict()))
    keys = [k for k in dict.fromkeys([*old, *new]) if old.get(k) != new.get(k) and k not in EXECUTION_KEYS]
    if not keys:
        return None
    return "; ".join(f"{k} = {old.get(k)!r} in the run, {new.get(k)!r} now" for k in keys)


def _refuse_differing(protocol: Protocol[Any, Any, Any], out: Path, saved: Any) -> None:
    difference = config_difference(protocol, saved)
    if difference is not None:
        raise ValueError(
            f"--resume: the configuration differs from the one {out} was started with: {difference} "
            "(resume with the run's own configuration, or start a new run in another folder)"
        )


def _disk_full(out: Path, error: BaseException) -> ProtocolError:
    checkpoint = out / CHECKPOINT_FILE
    kept = (
        f"the last checkpoint, {checkpoint}, is intact: free some space and continue with --resume"
        if checkpoint.exists()
        else "no checkpoint was written yet: free some space and run again (with --resume it starts over)"
    )
    return ProtocolError(f"{out}: the disk is full (no space left on device while writing the results); {kept}")


def _stop_writer(writer: ResultsWriter | None, error: BaseException) -> None:
    """Leave the partial results file closed, marked ``failed`` with the error
    unless the run was interrupted (then it stays ``running``). Neither may hide
    ``error``: on a full disk they may fail too, and the checkpoint keeps the file."""
    if writer is None or writer.closed:
        return
    if isinstance(error, Exception):
        text = "no space left on device" if is_disk_full(error) else f"{type(error).__name__}: {error}"
        with contextlib.suppress(Exception):
            writer.set_status("failed", error=text)
    with contextlib.suppress(Exception):
        writer.close()


def _finished_run(protocol: Protocol[Any, Any, R], out: Path) -> R | None:
    """``--resume`` without a checkpoint: the result of the run that finished in
    ``out`` (its outputs finished first if a stop left them unfinished), or None
    for a run stopped before its first checkpoint, which starts over."""
    from grainlab.io.hdf5 import read_results

    if (out / RESULTS_FILE).exists():
        results = read_results(out / RESULTS_FILE)
        _refuse_differing(protocol, out, results.config)
        summary_path = out / "summary.json"
        if summary_path.exists():
            return protocol.result(out, json.loads(summary_path.read_text(encoding="utf-8")))
        try:
            return protocol.result(out, protocol.write_outputs(out))
        except OSError as error:
            if is_disk_full(error):
                raise _disk_full(out, error) from error
            raise
    if (out / (RESULTS_FILE + PARTIAL_SUFFIX)).exists():
        return None
    raise ValueError(
        f"--resume: {out} holds no run: no {CHECKPOINT_FILE}, {RESULTS_FILE} or {RESULTS_FILE + PARTIAL_SUFFIX}; "
        "nothing to resume"
    )


def _reopen_results(protocol: Protocol[Any, Any, Any], out: Path, state: RunState,
                    checkpoint: Any) -> ResultsWriter | None:
    """The results writer of a resumed run, as it was at the checkpoint; None
    when the run's ``run.h5`` is already final (only the outputs remain)."""
    final, partial = out / RESULTS_FILE, out / (RESULTS_FILE + PARTIAL_SUFFIX)
    if final.exists():
        if state.phase == DONE:
            partial.unlink(missing_ok=True)  # a stop right after run.h5 was written
            return None
        raise ValueError(
            f"--resume: {final} exists, but {out / CHECKPOINT_FILE} is of a run still in its {state.phase!r} "
            "phase; the folder holds two different runs: move one away"
        )
    # the partial file as it was at the checkpoint, whatever became of it since
    image = checkpoint.arrays[_RESULTS_IMAGE]
    return ResultsWriter.restore(
        out, np.asarray(image, dtype=np.uint8).tobytes(), compression=protocol.compression, buffered=True
    )


def run_protocol(protocol: Protocol[Any, Any, R], out_dir: str | os.PathLike[str], *, resume: bool = False,
                 progress: bool = False) -> R:
    """Runs (or, with ``resume``, continues) ``protocol`` into ``out_dir``.

    ``resume`` continues a run from wherever it stopped: from its last
    checkpoint (the partial results file is restored from it, so a kill or a
    full disk while it was written does not matter), or, for a run whose
    ``run.h5`` is final, by writing the outputs a stop left unwritten; a run
    that finished returns its result, and one stopped before its first
    checkpoint starts over. A new run refuses a folder that holds another
    run's files (:data:`RUN_FILES`, the protocol's ``output_files``). A full
    disk stops the run with a :class:`ProtocolError` that keeps the last
    checkpoint. ``progress`` shows each stage's progress on stderr.
    """
    out = Path(out_dir)
    started = time.perf_counter()
    protocol.check()
    threads = protocol.threads()
    if resume and not out.exists():
        raise ValueError(f"--resume: {out} does not exist: nothing to resume")
    ensure_output_folder(out, create=not resume)
    with writer_lock(out):  # one writer per folder: a second run on it is refused at once
        return _run_locked(protocol, out, resume=resume, progress=progress, started=started, threads=threads)


def _run_locked(protocol: Protocol[Any, Any, R], out: Path, *, resume: bool, progress: bool, started: float,
                threads: int) -> R:
    checkpoint_path = out / CHECKPOINT_FILE
    if resume and not checkpoint_path.exists():
        finished = _finished_run(protocol, out)
        if finished is not None:
            return finished
        resume = False  # stopped before its first checkpoint: starts over
    writer: ResultsWriter | None = None
    try:
        if resume:
            checkpoint = read_checkpoint(checkpoint_path)
            saved = dict(checkpoint.protocol_state)
            _refuse_differing(protocol, out, saved.get("config"))
            sim = Simulation.from_bytes(checkpoint.engine_state)
            sim.threads = threads  # the bits do not depend on it: a resumed run takes the count asked now
            state = protocol.state_from_dict({k: v for k, v in saved.items() if k not in RUNNER_KEYS})
            elapsed_before = float(saved.get("elapsed_s", 0.0))
            writer = _reopen_results(protocol, out, state, checkpoint)
        else:
            partial = out / (RESULTS_FILE + PARTIAL_SUFFIX)
            if partial.exists() and not checkpoint_path.exists() and not (out / RESULTS_FILE).exists():
                partial.unlink()  # a run stopped before its first checkpoint: nothing to keep or resume
            if any((out / name).exists() for name in RUN_FILES):
                raise ValueError(
                    f"--out: {out} already holds a run; use --resume to continue it or choose another folder"
                )
            refuse_overwrite(out, protocol.output_files, why=f"a {protocol.name} run writes its own")
            writer = ResultsWriter(out, kind=protocol.name, compression=protocol.compression, buffered=True)
            writer.write_config(protocol.config_dict())
            sim, state = protocol.start(threads, progress)
            elapsed_before = 0.0

        if writer is not None:
            results = writer  # the writer as the checkpoints see it

            def save() -> None:  # the simulation in the context: a stage may put another there
                saved_state = state.to_dict()
                saved_state["config"] = protocol.config_dict()
                saved_state["elapsed_s"] = elapsed_before + time.perf_counter() - started
                image = np.frombuffer(results.publish(), dtype=np.uint8)
                # the context's simulation: a stage may have put a new one there
                write_checkpoint(checkpoint_path, context.sim.to_bytes(), saved_state, arrays={_RESULTS_IMAGE: image})

            context = StageContext(sim, state, protocol.config, writer, save, progress)
            if not resume:
                save()
            while state.phase != DONE:
                stage = protocol.stage(state.phase)
                stage.run(context)
                state.phase = protocol.next_phase(stage.name)
                save()
            summary = protocol.summary(context, elapsed_before + time.perf_counter() - started)
            summary["threads"] = context.sim.threads  # the count the run ended with (any count reruns it bitwise)
            writer.write_summary(summary)
            writer.write_phases(state.wall_time)
            writer.finalize()
        summary = protocol.write_outputs(out)
    except BaseException as error:
        _stop_writer(writer, error)
        if is_disk_full(error):
            raise _disk_full(out, error) from error
        raise
    checkpoint_path.unlink(missing_ok=True)
    return protocol.result(out, summary)
