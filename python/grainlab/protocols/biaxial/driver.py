"""The biaxial run's driver: a new run or a resumed one, phase by phase, with
checkpoints, the partial results file and the outputs; what a stop, a full
disk or a rerun in the same folder does (docs/file-formats.md, crash safety)."""

from __future__ import annotations

import contextlib
import json
import os
import time
from pathlib import Path
from typing import Any

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
from grainlab.protocols.biaxial.outputs import BiaxialResult, _summary, _write_outputs
from grainlab.protocols.biaxial.phases import (
    _check_shear_plan,
    _consolidate,
    _generate,
    _install_boundary,
    _shear,
    _start_shear,
    _threads,
)
from grainlab.protocols.biaxial.rates import check_density_scaling, check_strain_rate
from grainlab.protocols.biaxial.state import BiaxialError, _Run
from grainlab.protocols.config import BiaxialConfig
from grainlab.simulation import Simulation

#: Files that only a biaxial run writes: a new run refuses a folder holding any of
#: them (``--resume`` continues that run, or finishes its outputs).
RUN_FILES = (RESULTS_FILE, RESULTS_FILE + PARTIAL_SUFFIX, CHECKPOINT_FILE)
#: The run's other outputs (``report.html`` is ``grainlab biaxial``'s): a new run
#: refuses a folder that already holds one, which another run or the user wrote.
OUTPUT_FILES = ("timeseries.csv", "summary.json", "report.html", "fig[0-9][0-9]_*.png", "fig[0-9][0-9]_*.svg")
#: Name of the checkpoint array that holds the partial results file (:meth:`ResultsWriter.publish`).
_RESULTS_IMAGE = "results_partial"
#: HDF5 filter of run.h5's snapshot arrays (with byte shuffling): lossless, read by any
#: HDF5 reader; a paper-scale run's snapshots shrink to about two thirds (6.1 to 4.1 MB).
RESULTS_COMPRESSION = "gzip"


def _saved_config(saved: Any) -> dict[str, Any] | None:
    """A checkpoint's configuration resolved as this grainlab would (keys added
    since it was written take their defaults), or None when it cannot be."""
    try:
        return BiaxialConfig.from_dict(saved).to_dict()
    except (ValueError, TypeError, AttributeError):
        return None


#: Keys that set how a run is executed, not one bit of what it computes (the
#: engine gives the same bits on any thread count): a run resumes under other values.
EXECUTION_KEYS = frozenset({"run.threads", "run.checkpoint_interval"})


def _config_difference(saved: Any, config: BiaxialConfig) -> str | None:
    """The keys other than :data:`EXECUTION_KEYS` on which a run's saved
    configuration and ``config`` differ, with both values; None when they agree."""
    resolved = _saved_config(saved)
    if resolved is None:
        return "the run's saved configuration cannot be read by this grainlab"
    old, new = flatten_keys(resolved), flatten_keys(config.to_dict())
    keys = [k for k in dict.fromkeys([*old, *new]) if old.get(k) != new.get(k) and k not in EXECUTION_KEYS]
    if not keys:
        return None
    return "; ".join(f"{k} = {old.get(k)!r} in the run, {new.get(k)!r} now" for k in keys)


def _refuse_differing(out: Path, saved: Any, config: BiaxialConfig) -> None:
    difference = _config_difference(saved, config)
    if difference is not None:
        raise ValueError(
            f"--resume: the configuration differs from the one {out} was started with: {difference} "
            "(resume with the run's own configuration, or start a new run in another folder)"
        )


def _disk_full(out: Path, error: BaseException) -> BiaxialError:
    checkpoint = out / CHECKPOINT_FILE
    kept = (
        f"the last checkpoint, {checkpoint}, is intact: free some space and continue with --resume"
        if checkpoint.exists()
        else "no checkpoint was written yet: free some space and run again (with --resume it starts over)"
    )
    return BiaxialError(f"{out}: the disk is full (no space left on device while writing the results); {kept}")


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


def _finished_run(out: Path, config: BiaxialConfig) -> BiaxialResult | None:
    """``--resume`` without a checkpoint: the result of the run that finished in
    ``out`` (its outputs finished first if a stop left them unfinished), or None
    for a run stopped before its first checkpoint, which starts over."""
    from grainlab.io.hdf5 import read_results

    if (out / RESULTS_FILE).exists():
        results = read_results(out / RESULTS_FILE)
        _refuse_differing(out, results.config, config)
        summary_path = out / "summary.json"
        if summary_path.exists():
            return BiaxialResult(out, json.loads(summary_path.read_text(encoding="utf-8")))
        try:
            return BiaxialResult(out, _write_outputs(out))
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


def _reopen_results(out: Path, run: _Run, checkpoint: Any) -> ResultsWriter | None:
    """The results writer of a resumed run, as it was at the checkpoint; None
    when the run's ``run.h5`` is already final (only the outputs remain)."""
    final, partial = out / RESULTS_FILE, out / (RESULTS_FILE + PARTIAL_SUFFIX)
    if final.exists():
        if run.phase == "done":
            partial.unlink(missing_ok=True)  # a stop right after run.h5 was written
            return None
        raise ValueError(
            f"--resume: {final} exists, but {out / CHECKPOINT_FILE} is of a run still in its {run.phase!r} "
            "phase; the folder holds two different runs: move one away"
        )
    image = checkpoint.arrays.get(_RESULTS_IMAGE)
    if image is not None:  # the partial file as it was at the checkpoint, whatever became of it since
        return ResultsWriter.restore(
            out, np.asarray(image, dtype=np.uint8).tobytes(), compression=RESULTS_COMPRESSION, buffered=True
        )
    if not partial.exists():
        raise ValueError(
            f"--resume: {partial} is missing and {out / CHECKPOINT_FILE} (written by an earlier grainlab) "
            "cannot rebuild it; start the run again in a new folder"
        )
    return ResultsWriter.resume(
        out, timeseries_rows=run.rows, snapshots=run.snapshots or [], compression=RESULTS_COMPRESSION, buffered=True
    )


def run_biaxial(
    config: BiaxialConfig,
    out_dir: str | os.PathLike[str],
    *,
    resume: bool = False,
    progress: bool = False,
) -> BiaxialResult:
    """Runs (or, with ``resume``, continues) the biaxial test into ``out_dir``.

    ``resume`` continues a run from wherever it stopped: from its last
    checkpoint (the partial results file is restored from it, so a kill or a
    full disk while it was written does not matter), or, for a run whose
    ``run.h5`` is final, by writing the outputs a stop left unwritten; a run
    that finished returns its result, and one stopped before its first
    checkpoint starts over. A new run refuses a folder that holds another
    run's files (:data:`RUN_FILES`, :data:`OUTPUT_FILES`). A full disk stops
    the run with a :class:`BiaxialError` that keeps the last checkpoint.
    ``progress`` shows each phase's progress on stderr (off by default; see
    :func:`grainlab._progress.progress_bar`).
    """
    out = Path(out_dir)
    started = time.perf_counter()
    check_strain_rate(config)  # a rate refused needs no warning about its inertia
    check_density_scaling(config)
    threads = _threads(config)
    if resume and not out.exists():
        raise ValueError(f"--resume: {out} does not exist: nothing to resume")
    ensure_output_folder(out, create=not resume)
    with writer_lock(out):  # one writer per folder: a second run on it is refused at once
        return _run_locked(config, out, resume=resume, progress=progress, started=started, threads=threads)


def _run_locked(config: BiaxialConfig, out: Path, *, resume: bool, progress: bool, started: float,
                threads: int) -> BiaxialResult:
    """:func:`run_biaxial` once it holds the folder's writer lock."""
    checkpoint_path = out / CHECKPOINT_FILE
    if resume and not checkpoint_path.exists():
        finished = _finished_run(out, config)
        if finished is not None:
            return finished
        resume = False  # stopped before its first checkpoint: starts over
    writer: ResultsWriter | None = None
    try:
        if resume:
            checkpoint = read_checkpoint(checkpoint_path)
            saved = dict(checkpoint.protocol_state)
            _refuse_differing(out, saved.get("config"), config)
            sim = Simulation.from_bytes(checkpoint.engine_state)
            sim.threads = threads  # the bits do not depend on it: a resumed run takes the count asked now
            run = _Run(**{k: v for k, v in saved.items() if k != "config" and k != "elapsed_s"})
            elapsed_before = float(saved.get("elapsed_s", 0.0))
            writer = _reopen_results(out, run, checkpoint)
        else:
            partial = out / (RESULTS_FILE + PARTIAL_SUFFIX)
            if partial.exists() and not checkpoint_path.exists() and not (out / RESULTS_FILE).exists():
                partial.unlink()  # a run stopped before its first checkpoint: nothing to keep or resume
            if any((out / name).exists() for name in RUN_FILES):
                raise ValueError(
                    f"--out: {out} already holds a run; use --resume to continue it or choose another folder"
                )
            refuse_overwrite(out, OUTPUT_FILES, why="a biaxial run writes its own")
            writer = ResultsWriter(out, kind="biaxial", compression=RESULTS_COMPRESSION, buffered=True)  # HDF5 never writes the disk itself
            writer.write_config(config.to_dict())
            sim, run = _generate(config, threads, progress)
            elapsed_before = 0.0

        if writer is not None:
            results = writer  # the writer as the checkpoints see it

            def save() -> None:
                state = run.to_dict()
                state["config"] = config.to_dict()
                state["elapsed_s"] = elapsed_before + time.perf_counter() - started
                state["rows"] = results.n_rows
                state["snapshots"] = list(results.snapshot_names)
                image = np.frombuffer(results.publish(), dtype=np.uint8)
                write_checkpoint(checkpoint_path, sim.to_bytes(), state, arrays={_RESULTS_IMAGE: image})

            if not resume:
                save()
            if run.phase == "consolidate":
                _consolidate(sim, run, config, progress)
                save()
            if run.phase == "boundary":
                _install_boundary(sim, run, config, progress)
                _start_shear(sim, run, config)
                _check_shear_plan(sim, run, config)
                save()
            if run.phase == "shear":
                _shear(sim, run, config, writer, save, progress)
                save()
            total = elapsed_before + time.perf_counter() - started
            summary = _summary(run, config, writer.read_timeseries(), total)
            summary["threads"] = sim.threads  # the count the run ended with (any count reruns it bitwise)
            writer.write_summary(summary)
            writer.write_phases(run.wall_time)
            writer.finalize()
        summary = _write_outputs(out)
    except BaseException as error:
        _stop_writer(writer, error)
        if is_disk_full(error):
            raise _disk_full(out, error) from error
        raise
    checkpoint_path.unlink(missing_ok=True)
    return BiaxialResult(out, summary)
