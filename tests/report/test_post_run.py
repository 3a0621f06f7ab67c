"""The work after a biaxial run (figures, summary.json, report.html), done in worker processes
by ``grainlab biaxial``, gives the files that one process alone gives (slow: the quick run)."""

from __future__ import annotations

import json
import re
import shutil

import pytest

import grainlab.plot.workers as workers
from grainlab.protocols.biaxial.outputs import write_outputs
from grainlab.report import write_report

pytestmark = pytest.mark.slow


def _svg(data: bytes) -> bytes:
    """An SVG without its date and the random salt of matplotlib's element ids."""
    return re.sub(rb"(id=\"|#)[A-Za-z0-9_]*[0-9a-f]{8,}", rb"\1ID", re.sub(rb"<dc:date>[^<]*</dc:date>", b"", data))


def _page(path, folder) -> str:
    """report.html without what names its folder or the moment it was written."""
    text = path.read_text().replace(str(folder.resolve()), "FOLDER").replace(folder.name, "FOLDER")
    return re.sub(r"Report generated \S+", "", text)


def test_the_quick_run_drawn_in_one_process_gives_the_same_files(quick_biaxial_run, tmp_path, monkeypatch):
    if workers.worker_count(10) < 2:
        pytest.skip("one core: grainlab biaxial drew everything in one process already")
    folder = tmp_path / "quick"
    folder.mkdir()
    shutil.copy2(quick_biaxial_run / "run.h5", folder / "run.h5")
    monkeypatch.setattr(workers, "available_cores", lambda: 1)  # no workers: the serial path
    write_outputs(folder)
    write_report(folder)
    names = sorted(p.name for p in quick_biaxial_run.iterdir())
    assert sorted(p.name for p in folder.iterdir()) == names
    for name in names:
        mine, theirs = (folder / name).read_bytes(), (quick_biaxial_run / name).read_bytes()
        if name.endswith(".svg"):
            assert _svg(mine) == _svg(theirs), name
        elif name == "summary.json":
            a, b = json.loads(mine), json.loads(theirs)
            a["fabric"].pop("results_path"), b["fabric"].pop("results_path")
            assert a == b
        elif name == "report.html":
            assert _page(folder / name, folder) == _page(quick_biaxial_run / name, quick_biaxial_run)
        else:  # run.h5, timeseries.csv and the PNG figures: the same bytes
            assert mine == theirs, name
