"""examples/07_notebook.ipynb executed by nbclient (a real Jupyter kernel) on the synthetic run:
the figures of .plot() are shown, Results / Snapshot / measures show short tables."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parents[2] / "examples" / "07_notebook.ipynb"


def _outputs(cell) -> list[dict]:
    return list(cell.get("outputs", []))


def test_the_example_notebook_runs_and_shows_its_figures(synthetic_results, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.setenv("GRAINLAB_RUN", str(synthetic_results))
    monkeypatch.setenv("PYTHONWARNINGS", "error::DeprecationWarning:grainlab")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=600, startup_timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    client.execute()
    code = [c for c in nb.cells if c.cell_type == "code"]
    for cell in code:
        errors = [o for o in _outputs(cell) if o["output_type"] == "error"]
        assert not errors, errors
        streams = "".join(o.get("text", "") for o in _outputs(cell) if o.get("name") == "stderr")
        assert "Warning" not in streams, streams
    by_source = {c.source.splitlines()[-1]: c for c in code}
    # .plot() displays its figure: a PNG in the cell's outputs
    for last_line in ("lam.plot();", "fabric.plot();"):
        images = [o for o in _outputs(by_source[last_line]) if "image/png" in o.get("data", {})]
        assert len(images) == 1, [o.get("data", {}).keys() for o in _outputs(by_source[last_line])]
    # rich, short representations
    for last_line, title in (("results", "grainlab results"), ("snap", "Snapshot("), ("lam", "StabilityIndex(")):
        (shown,) = [o for o in _outputs(by_source[last_line]) if o["output_type"] == "execute_result"]
        html = shown["data"]["text/html"]
        assert title in html and len(html) < 6000
        assert len(shown["data"]["text/plain"]) < 300
    printed = "".join(o.get("text", "") for o in _outputs(code[1]))
    assert printed.startswith("Results(") and "peak stress ratio 4.00" in printed


def test_outside_a_notebook_plots_leave_pyplot_alone():
    import matplotlib.pyplot as plt

    from grainlab._notebook import in_notebook, new_figure

    before = plt.get_fignums()
    fig = new_figure(figsize=(2, 2))
    assert not in_notebook() and plt.get_fignums() == before
    assert fig.get_size_inches().tolist() == [2.0, 2.0]
    assert os.environ.get("MPLBACKEND", "") != "module://matplotlib_inline.backend_inline"
