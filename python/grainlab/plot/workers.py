"""Figures drawn side by side in worker processes, written as :func:`grainlab.plot.save_figure` writes them.

A :class:`FigureTask` names a figure file and a function of plain data that makes
its ``Figure``; :meth:`FigurePool.draw` draws tasks in ``spawn``-ed workers (the same
files as in one process) and :meth:`FigurePool.submit` runs any other function there.
How workers start, stop and report errors: docs/analysis.md, "Figures (`grainlab.plot`)".
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from contextvars import ContextVar, Token
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any, TypeVar

from grainlab._child import die_with_parent
from grainlab._cores import available_cores

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["MAX_WORKERS", "FigurePool", "FigureTask", "PendingFigures", "figure_pool", "worker_count"]

#: Most worker processes a pool starts (a biaxial run has ten figures; more
#: workers than that cost their start-up and gain little).
MAX_WORKERS = 4

T = TypeVar("T")

@dataclass(frozen=True)
class FigureTask:
    """One figure file: ``make(*args, **kwargs)`` returns the ``Figure``, saved as
    ``out_dir / name`` with each suffix of ``formats``. ``make`` must be a
    module-level function and its arguments picklable (they travel to a worker).
    ``cost`` is how long it takes to draw, relative to the others: workers take
    the costliest first, so that they finish together."""

    name: str
    make: Callable[..., Figure]
    args: tuple[Any, ...] = ()
    kwargs: Mapping[str, Any] = field(default_factory=dict)
    formats: tuple[str, ...] = ("png", "svg")
    cost: float = 1.0


#: What a worker sends back for one figure: the files written and, when asked
#: for, the PNG file's digest and its page copy (:func:`grainlab.plot.page_png`).
_Drawn = tuple[list[Path], tuple[bytes, bytes] | None]


def _draw_and_save(task: FigureTask, out_dir: Path, page_copy: bool) -> _Drawn:
    from grainlab.plot.files import PAGE_DPI, _png_digest, compact_png, save_figure

    paths = save_figure(task.make(*task.args, **task.kwargs), out_dir / task.name, task.formats)
    png = next((p for p in paths if p.suffix == ".png"), None)
    if not page_copy or png is None:
        return paths, None
    data = png.read_bytes()
    return paths, (_png_digest(data), compact_png(data, dpi=PAGE_DPI))


def _start_worker(parent: int) -> None:
    """A worker's set-up: Ctrl-C is for the process that started it; on Linux it is
    killed when that process ends, however it ends (a killed run leaves no worker
    drawing on into its folder)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent(parent)


#: Environment of the workers: one thread for the numerical libraries (the workers
#: are the parallelism; BLAS threads of each would only compete for the same cores).
_WORKER_ENVIRONMENT = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@contextlib.contextmanager
def _starting_workers() -> Iterator[None]:
    """While workers start: ``__main__`` shows neither a file nor a module name, so
    that ``spawn`` does not run the calling script again in them (their tasks are
    grainlab's functions: nothing of the script is needed there), and the
    environment they inherit holds :data:`_WORKER_ENVIRONMENT` (where not set)."""
    main = sys.modules.get("__main__")
    saved: dict[str, Any] = {}
    if main is not None:
        saved = {key: main.__dict__[key] for key in ("__file__", "__spec__") if key in main.__dict__}
        main.__dict__.pop("__file__", None)
        main.__dict__["__spec__"] = None
    added = [key for key in _WORKER_ENVIRONMENT if key not in os.environ]
    os.environ.update({key: _WORKER_ENVIRONMENT[key] for key in added})
    try:
        yield
    finally:
        for key in added:
            os.environ.pop(key, None)
        if main is not None:
            main.__dict__.pop("__spec__", None)
            main.__dict__.update(saved)


def worker_count(tasks: int, workers: int | None = None) -> int:
    """Worker processes a pool for ``tasks`` tasks starts: none (everything runs
    here) with ``workers=0``, on one core or inside another pool's worker; else
    the smallest of ``workers`` (default :data:`MAX_WORKERS`), the cores this
    process may use and ``tasks``."""
    if workers is not None and workers < 0:
        raise ValueError(f"workers: 0 (none: draw here) or more, got {workers}")
    cores = available_cores()
    if cores < 2 or multiprocessing.parent_process() is not None:
        return 0
    return max(min(workers if workers is not None else MAX_WORKERS, cores, tasks), 0)


class PendingFigures:
    """Figures submitted to a :class:`FigurePool`; :meth:`result` waits for them."""

    def __init__(self, futures: Sequence[tuple[str, Future[_Drawn]]]) -> None:
        self._futures = list(futures)
        self.claimed = False

    def result(self) -> dict[str, list[Path]]:
        """``{figure name: files written}`` in the order submitted; the first
        failure is raised again (docs/analysis.md), after the others have finished."""
        self.claimed = True
        files: dict[str, list[Path]] = {}
        failure: BaseException | None = None
        from grainlab.plot.files import _keep_page_png

        for name, future in self._futures:
            try:
                files[name], page = future.result()
            except Exception as error:  # noqa: PERF203 - every figure is waited for
                if failure is None:
                    error.add_note(f"while drawing the figure {name}")
                    failure = error
                continue
            if page is not None:
                _keep_page_png(*page)
        if failure is not None:
            raise failure
        return files


#: The pool of the innermost ``with FigurePool()`` block (figure functions called inside it draw there).
_current: ContextVar[FigurePool | None] = ContextVar("grainlab_figure_pool", default=None)


class FigurePool:
    """Worker processes for figures (docs/analysis.md); use it as a context manager.

    ``workers``: the most processes to start (default :data:`MAX_WORKERS`; 0:
    none, every task runs here); ``tasks``: how many tasks are expected, so that
    no more workers start than there is work for; ``page_copies``: each PNG's
    copy for a page (:func:`grainlab.plot.page_png`) is made where the figure was
    drawn, for a report written next. Workers start with the first submission.
    Inside the ``with`` block the pool is the current one (:func:`figure_pool`);
    leaving the block waits for every task and raises the first failure of
    figures nobody waited for.
    """

    def __init__(self, workers: int | None = None, *, tasks: int = MAX_WORKERS, page_copies: bool = False) -> None:
        self.workers = worker_count(tasks, workers)
        self.page_copies = page_copies
        self._executor: ProcessPoolExecutor | None = None
        self._pending: list[PendingFigures] = []
        self._tokens: list[Token[FigurePool | None]] = []

    @property
    def parallel(self) -> bool:
        """Whether tasks run in worker processes (False: here, when submitted)."""
        return self.workers > 0

    def __enter__(self) -> FigurePool:
        self._tokens.append(_current.set(self))
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        _current.reset(self._tokens.pop())
        self.close(cancel=error is not None)
        if error is None:
            for pending in self._pending:
                if not pending.claimed:
                    pending.result()

    def close(self, cancel: bool = False) -> None:
        """Waits for the running tasks and stops the workers; ``cancel`` drops the tasks not started."""
        if self._executor is not None:
            self._executor.shutdown(wait=True, cancel_futures=cancel)
            self._executor = None

    def submit(self, function: Callable[..., T], *args: Any) -> Future[T]:
        """``function(*args)`` in a worker (a module-level function, picklable
        arguments), or here and now without workers; its future."""
        if not self.parallel:
            done: Future[T] = Future()
            try:
                done.set_result(function(*args))
            except Exception as error:
                done.set_exception(error)
            return done
        if self._executor is None:
            self._executor = ProcessPoolExecutor(
                max_workers=self.workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_start_worker,
                initargs=(os.getpid(),),
            )
        with _starting_workers():  # a submission may start a worker
            return self._executor.submit(function, *args)

    def draw(self, tasks: Sequence[FigureTask], out_dir: str | Path) -> PendingFigures:
        """Starts drawing ``tasks`` into ``out_dir`` (created), the costliest first in
        workers, in their order here; their files come back in the order of ``tasks``."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        order = sorted(range(len(tasks)), key=lambda k: -tasks[k].cost) if self.parallel else range(len(tasks))
        futures = {k: self.submit(_draw_and_save, tasks[k], out, self.page_copies) for k in order}
        pending = PendingFigures([(task.name, futures[k]) for k, task in enumerate(tasks)])
        self._pending.append(pending)
        return pending


@contextlib.contextmanager
def figure_pool(
    workers: int | None = None, *, tasks: int = MAX_WORKERS, page_copies: bool = False
) -> Iterator[FigurePool]:
    """The current :class:`FigurePool` (of an enclosing ``with`` block, with its own
    settings), or a new one with these for this block."""
    pool = _current.get()
    if pool is not None:
        yield pool
        return
    with FigurePool(workers, tasks=tasks, page_copies=page_copies) as pool:
        yield pool
