"""Figures drawn in worker processes (grainlab.plot.workers): the same files as drawn here,
errors named, nothing of the calling script run again, page copies as made here."""

from __future__ import annotations

import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from grainlab import plot
from grainlab.plot import PAGE_DPI, compact_png, curve_tasks, page_png
from grainlab.plot.workers import FigurePool, FigureTask, worker_count

needs_two_cores = pytest.mark.skipif(worker_count(2) < 2, reason="needs two cores for two worker processes")


def _timeseries(n: int = 120) -> dict[str, np.ndarray]:
    eps = np.linspace(0.0, 0.05, n)
    return {
        "axial_strain": eps,
        "stress_ratio": 1.0 + 2.5 * (1.0 - np.exp(-eps / 0.01)),
        "volumetric_strain": 0.004 * np.sin(40.0 * eps) - 0.1 * eps,
        "coordination_number": 3.9 - 10.0 * eps,
    }


def svg_content(svg: bytes) -> bytes:
    """An SVG without what differs from one save to the next (the random ids matplotlib
    salts its element ids with, and the date)."""
    svg = re.sub(rb"<dc:date>[^<]*</dc:date>", b"", svg)
    return re.sub(rb"(id=\"|#)[A-Za-z0-9_]*[0-9a-f]{8,}", rb"\1ID", svg)


@needs_two_cores
def test_workers_write_the_files_drawn_here_byte_for_byte(tmp_path):
    tasks = curve_tasks(_timeseries())
    with FigurePool(0) as here:
        assert not here.parallel
        serial = here.draw(tasks, tmp_path / "here").result()
    with FigurePool(2, tasks=len(tasks)) as pool:
        assert pool.parallel
        parallel = pool.draw(tasks, tmp_path / "workers").result()
    assert list(parallel) == list(serial) == [t.name for t in tasks]  # the order of the tasks
    for name, files in serial.items():
        assert [p.name for p in parallel[name]] == [p.name for p in files] == [f"{name}.png", f"{name}.svg"]
        png, svg = files
        assert parallel[name][0].read_bytes() == png.read_bytes()
        assert svg_content(parallel[name][1].read_bytes()) == svg_content(svg.read_bytes())


@pytest.mark.parametrize("workers", [0, 2])
def test_a_failing_figure_is_named_and_the_others_are_written(tmp_path, workers):
    ts = _timeseries()
    good = curve_tasks(ts)[0]
    # a real drawing function given values of the wrong length: it refuses them
    bad = FigureTask("fig_bad", good.make, (ts["axial_strain"], ts["stress_ratio"][:10], "y", False, None))
    with FigurePool(workers, tasks=2) as pool:
        pending = pool.draw([bad, good], tmp_path)
        with pytest.raises(ValueError, match=r"values: expected shape \(120,\), got \(10,\)") as raised:
            pending.result()
    assert "while drawing the figure fig_bad" in raised.value.__notes__
    if pool.parallel:  # the worker's own traceback comes along
        assert "Traceback" in str(raised.value.__cause__)
    assert (tmp_path / f"{good.name}.png").stat().st_size > 1000
    assert not (tmp_path / "fig_bad.png").exists()


def test_a_failure_nobody_waited_for_is_raised_when_the_pool_closes(tmp_path):
    ts = _timeseries()
    bad = FigureTask("fig_bad", curve_tasks(ts)[0].make, (ts["axial_strain"], ts["stress_ratio"][:3], "y", False, None))
    with pytest.raises(ValueError, match="values: expected shape") as raised, FigurePool(tasks=1) as pool:
        pool.draw([bad], tmp_path)
    assert "while drawing the figure fig_bad" in raised.value.__notes__


def test_nested_figure_functions_draw_in_the_open_pool(tmp_path):
    with FigurePool(0) as pool:
        files = plot.biaxial_curves(_timeseries(), tmp_path, workers=3)  # the open pool, not three workers
        assert pool._pending and pool._pending[-1].claimed
    assert sorted(p.name for p in files) == sorted(
        f"{n}.{s}" for n in ("fig08_stress_ratio", "fig10_volumetric_strain", "fig18_coordination_number")
        for s in ("png", "svg")
    )


@pytest.mark.parametrize("workers", [0, 2])
def test_page_copies_made_with_the_figures_are_the_copies_made_here(tmp_path, workers):
    with FigurePool(workers, tasks=3, page_copies=True) as pool:
        files = pool.draw(curve_tasks(_timeseries(90)), tmp_path).result()
    for png, _ in files.values():
        data = png.read_bytes()
        kept = plot.files._page_copies.get(plot.files._png_digest(data))
        assert kept is not None
        assert kept == compact_png(data, dpi=PAGE_DPI) == page_png(data)


def test_worker_count_follows_cores_and_tasks(monkeypatch):
    import grainlab.plot.workers as workers

    monkeypatch.setattr(workers, "available_cores", lambda: 1)
    assert worker_count(10) == 0  # one core: everything here
    monkeypatch.setattr(workers, "available_cores", lambda: 8)
    assert worker_count(10) == workers.MAX_WORKERS
    assert worker_count(3) == 3 and worker_count(10, 2) == 2 and worker_count(10, 0) == 0
    with pytest.raises(ValueError, match="workers: 0 .* or more, got -1"):
        worker_count(3, -1)


#: A script without the ``if __name__ == "__main__":`` guard that draws figures at its top level.
UNGUARDED = """\
from pathlib import Path
import numpy as np
from grainlab import plot
print("script ran", flush=True)
eps = np.linspace(0.0, 0.02, 50)
ts = {{"axial_strain": eps, "stress_ratio": 1 + 100 * eps, "volumetric_strain": -eps, "coordination_number": 4 - eps}}
files = plot.biaxial_curves(ts, Path({out!r}), workers=2)
print("figures", len(files), flush=True)
"""


@needs_two_cores
def test_workers_do_not_run_the_calling_script_again(tmp_path):
    script = tmp_path / "unguarded.py"
    script.write_text(UNGUARDED.format(out=str(tmp_path / "out")))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["script ran", "figures 6"]
    assert len(list(Path(tmp_path / "out").glob("fig*.png"))) == 3


#: Starts a worker on a long task, prints its process id and kills itself.
KILLED = """\
import os, signal, time
from grainlab.plot.workers import FigurePool
pool = FigurePool(2, tasks=2)
pool.submit(time.sleep, 30)
time.sleep(3)
print(*pool._executor._processes, flush=True)
os.kill(os.getpid(), signal.SIGKILL)
"""


@needs_two_cores
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="workers end with their parent on Linux")
def test_workers_end_when_the_process_that_started_them_is_killed(tmp_path):
    script = tmp_path / "killed.py"
    script.write_text(KILLED)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == -9
    pids = [int(p) for p in done.stdout.split()]
    assert pids
    deadline = time.monotonic() + 10
    alive = pids
    while alive and time.monotonic() < deadline:
        time.sleep(0.1)
        alive = [p for p in pids if Path(f"/proc/{p}").exists()]
    assert not alive, f"workers {alive} outlived the process that started them"
