"""A campaign: many independent runs, each in its own folder, in local processes or
on a Dask cluster, resumable and failure-isolated (docs/study.md, "Execution,
resuming, failures, seeds").
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import time
import traceback
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from grainlab._child import die_with_parent
from grainlab._cores import available_cores
from grainlab.io.results import write_json_atomic, write_text_atomic

RESULT_FILE = "result.json"


def derive_seed(campaign_seed: int, kind: str, params: Mapping[str, Any]) -> int:
    """A seed in ``[0, 2**31)`` from the campaign seed, the run's kind and parameters.

    Stable across processes, machines and Python versions (SHA-256 of canonical
    JSON; floats by ``repr``), independent of the order of ``params``.

    >>> derive_seed(0, "packing", {"porosity": 0.12}) == derive_seed(0, "packing", {"porosity": 0.12})
    True
    >>> derive_seed(0, "packing", {"porosity": 0.12}) != derive_seed(1, "packing", {"porosity": 0.12})
    True
    """
    canonical = json.dumps(
        {"campaign_seed": int(campaign_seed), "kind": kind, "params": _canonical(params)},
        sort_keys=True,
        separators=(",", ":"),
    )
    return int.from_bytes(hashlib.sha256(canonical.encode()).digest()[:8], "big") % (2**31)


def _canonical(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _canonical(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_canonical(v) for v in value]
    if isinstance(value, float):
        return repr(value)
    return value


@dataclass(frozen=True)
class Run:
    """One run of a campaign: its folder name, task kind, parameters and seed."""

    name: str
    kind: str
    params: dict[str, Any]
    seed: int
    labels: dict[str, Any] = field(default_factory=dict)
    """Columns copied to the summary row as they are (e.g. the varied parameters)."""

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "kind": self.kind, "params": self.params, "seed": self.seed,
                "labels": self.labels}


def make_run(name: str, kind: str, params: Mapping[str, Any], campaign_seed: int,
             labels: Mapping[str, Any] | None = None) -> Run:
    """A :class:`Run` with its seed derived from ``campaign_seed`` and ``params``."""
    task_of(kind)  # an unknown kind is refused here, before any run
    params = dict(params)
    return Run(name, kind, params, derive_seed(campaign_seed, kind, params), dict(labels or {}))


# ---- tasks -------------------------------------------------------------------


def _packing_task(run: Run, run_dir: Path, threads: int) -> dict[str, Any]:
    from grainlab.study.packing import run_packing

    params = {"threads": threads, **run.params}
    params.setdefault("seed", run.seed)
    return run_packing(params, run_dir)


def _protocol_task(run: Run, run_dir: Path, threads: int) -> dict[str, Any]:
    """A run of the registered protocol ``run.kind`` (:mod:`grainlab.protocols.registry`)
    in ``run_dir/<kind>``, resumed from its checkpoint when a stop left one."""
    from grainlab.protocols.registry import resolve_config, run_named

    params = dict(run.params)
    config_file = params.pop("config_file", None)
    quick = bool(params.pop("quick", False))
    params.setdefault("sample.seed", run.seed)
    params.setdefault("run.threads", threads)
    config = resolve_config(run.kind, config_file, params, quick=quick)
    out = run_dir / run.kind
    resume = (out / "checkpoint.h5").exists()
    if not resume and out.exists():
        # a run killed before its first checkpoint, or after its last: start it again
        import shutil

        shutil.rmtree(out)
    result = run_named(run.kind, config, out, resume=resume, progress=False)
    row = {k: v for k, v in result.summary.items() if isinstance(v, int | float | str | bool) or v is None}
    row["status"] = "ok"
    return row


#: Run kinds besides the protocols: ``task(run, run_dir, threads) -> dict`` of scalar results.
TASKS: dict[str, Callable[[Run, Path, int], dict[str, Any]]] = {
    "packing": _packing_task,
}


def task_of(kind: str) -> Callable[[Run, Path, int], dict[str, Any]]:
    """The task of run kind ``kind``: one of :data:`TASKS`, or a protocol of
    :data:`grainlab.protocols.registry.PROTOCOLS` (run by its name)."""
    if kind in TASKS:
        return TASKS[kind]
    from grainlab.protocols.registry import PROTOCOLS

    if kind in PROTOCOLS:
        return _protocol_task
    raise ValueError(f"kind: unknown run kind {kind!r}; known: {', '.join([*TASKS, *sorted(PROTOCOLS)])}")


def execute_run(run: Run | Mapping[str, Any], out_dir: str | os.PathLike[str], threads: int = 1) -> dict[str, Any]:
    """Runs one run into ``out_dir/runs/NAME`` and returns its row; never raises
    for a failure of the run itself (the row has ``status = "failed"`` and ``error``).

    The row is written to ``result.json`` atomically only when the run succeeded.
    """
    if not isinstance(run, Run):
        run = Run(**run)
    run_dir = Path(out_dir) / "runs" / run.name
    run_dir.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    base = {"name": run.name, "kind": run.kind, "seed": run.seed, **run.labels}
    try:
        result = task_of(run.kind)(run, run_dir, threads)
    except Exception as error:  # noqa: BLE001 - one failing run must not stop the others
        message = f"{type(error).__name__}: {error}"
        write_text_atomic(run_dir / "error.txt", traceback.format_exc())
        return {**base, "status": "failed", "error": message, "wall_time_s": time.perf_counter() - started}
    row = {**base, **result}
    row.setdefault("wall_time_s", time.perf_counter() - started)
    row.setdefault("status", "ok")
    row.setdefault("error", "")
    (run_dir / "error.txt").unlink(missing_ok=True)
    write_json_atomic(run_dir / RESULT_FILE, {"run": run.to_dict(), "row": row})
    return row


def load_finished(run: Run, out_dir: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The row of a finished run with the same kind, parameters and seed, or None."""
    path = Path(out_dir) / "runs" / run.name / RESULT_FILE
    if not path.exists():
        return None
    try:
        saved = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    if not isinstance(saved, dict) or not isinstance(saved.get("row"), dict):
        return None  # not a result file of this grainlab: run again
    same = saved.get("run", {})
    if same.get("kind") != run.kind or same.get("seed") != run.seed or same.get("params") != json.loads(
        json.dumps(run.params)
    ):
        return None
    row: dict[str, Any] = saved["row"]
    return row


# ---- execution -----------------------------------------------------------------


#: How long a campaign waits to connect to a ``--scheduler`` address before giving up.
SCHEDULER_TIMEOUT_S = 10.0


@dataclass
class CampaignResult:
    """Rows in run order, and how the campaign went."""

    rows: list[dict[str, Any]]
    skipped: list[str]
    executed: list[str]
    failed: list[str]
    wall_time_s: float
    table: Path | None = None


def run_campaign(
    runs: Sequence[Run],
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | Any | None = None,
    progress: bool = False,
    table_name: str = "summary.csv",
    columns: Sequence[str] = (),
    threads: int | None = None,
) -> CampaignResult:
    """Runs every unfinished run of ``runs`` and writes the summary table atomically.

    ``workers``: local processes (default: the number of cores). ``scheduler``: a
    Dask scheduler address (``"tcp://host:8786"``) or a ``dask.distributed.Client``;
    then Dask runs the tasks and ``workers`` is ignored. ``threads``: engine threads
    per run (default: cores // workers, at least 1, so workers x threads <= cores).
    """
    names = [r.name for r in runs]
    if len(set(names)) != len(names):
        dupes = sorted({n for n in names if names.count(n) > 1})
        raise ValueError(f"runs: duplicate run names {dupes}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    rows: dict[str, dict[str, Any]] = {}
    skipped: list[str] = []
    todo: list[Run] = []
    for run in runs:
        row = load_finished(run, out)
        if row is not None:
            rows[run.name] = row
            skipped.append(run.name)
        else:
            todo.append(run)
    cores = available_cores()  # taskset and cgroup affinity count
    n_workers = max(1, int(workers)) if workers else cores
    if threads is None:
        threads = max(1, cores // n_workers) if scheduler is None else 1
    failed: list[str] = []

    from grainlab._progress import progress_bar

    bar = progress_bar(len(runs), "campaign", enabled=progress, unit="run", initial=len(skipped))
    bar.set_postfix_str(f"failed 0, skipped {len(skipped)}")

    def record(run: Run, row: dict[str, Any]) -> None:
        rows[run.name] = row
        if row.get("status") == "failed":
            failed.append(run.name)
        bar.set_postfix_str(f"failed {len(failed)}, skipped {len(skipped)}", refresh=False)
        bar.update(1)
        # the table so far, so an interrupted campaign leaves a consistent one
        write_table(out / table_name, [rows[r.name] for r in runs if r.name in rows], columns)

    try:
        if todo:
            if scheduler is not None:
                _run_dask(todo, out, scheduler, threads, record)
            else:
                _run_local(todo, out, n_workers, threads, record)
    finally:
        bar.close()
    ordered = [rows[r.name] for r in runs if r.name in rows]
    table = write_table(out / table_name, ordered, columns)
    return CampaignResult(ordered, skipped, [r.name for r in todo], failed, time.perf_counter() - started, table)


def _failure_row(run: Run, error: BaseException) -> dict[str, Any]:
    return {"name": run.name, "kind": run.kind, "seed": run.seed, **run.labels, "status": "failed",
            "error": f"{type(error).__name__}: {error}"}


def _run_local(todo: Sequence[Run], out: Path, workers: int, threads: int,
               record: Callable[[Run, dict[str, Any]], None]) -> None:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # spawn: the engine's thread pool must not be forked
    context = multiprocessing.get_context("spawn")
    # the workers end with this process: a killed campaign leaves none writing on into its runs
    with ProcessPoolExecutor(max_workers=min(workers, len(todo)), mp_context=context,
                             initializer=die_with_parent, initargs=(os.getpid(),)) as pool:
        futures = {pool.submit(execute_run, run, str(out), threads): run for run in todo}
        for future in as_completed(futures):
            run = futures[future]
            try:
                row = future.result()
            except Exception as error:  # noqa: BLE001 - a worker process died
                row = _failure_row(run, error)
            record(run, row)


def _run_dask(todo: Sequence[Run], out: Path, scheduler: str | Any, threads: int,
              record: Callable[[Run, dict[str, Any]], None]) -> None:
    try:
        from dask.distributed import Client, as_completed
    except ImportError as error:  # pragma: no cover - depends on the environment
        raise ValueError(
            "--scheduler: Dask is not installed; pip install 'grainlab[cluster]'"
        ) from error
    own = not isinstance(scheduler, Client)
    if isinstance(scheduler, Client):
        client = scheduler
    else:
        try:
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT_S)
        except (OSError, TimeoutError) as error:
            raise ValueError(
                f"--scheduler: cannot reach a Dask scheduler at {scheduler} within {SCHEDULER_TIMEOUT_S:g} s "
                f"({error}); check the address and that the scheduler is running"
            ) from None
    try:
        futures = [
            client.submit(execute_run, run, str(out), threads, key=f"grainlab-{out.name}-{run.name}-{run.seed}",
                          pure=False)
            for run in todo
        ]
        by_key = {f.key: run for f, run in zip(futures, todo, strict=True)}
        for future in as_completed(futures):
            run = by_key[future.key]
            try:
                row = future.result()
            except Exception as error:  # noqa: BLE001 - a worker died or lost the task
                row = _failure_row(run, error)
            record(run, row)
    finally:
        if own:
            client.close()


# ---- the table -------------------------------------------------------------------


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    return str(value)


def write_table(path: str | os.PathLike[str], rows: Iterable[Mapping[str, Any]], columns: Sequence[str] = ()) -> Path:
    """CSV of ``rows`` written atomically: ``columns`` first, then every other key met, in order."""
    rows = list(rows)
    names = list(columns)
    for row in rows:
        for key in row:
            if key not in names:
                names.append(key)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(names)
    for row in rows:
        writer.writerow([_cell(row.get(k)) for k in names])
    return write_text_atomic(path, buffer.getvalue())


def read_table(path: str | os.PathLike[str]) -> list[dict[str, str]]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))
