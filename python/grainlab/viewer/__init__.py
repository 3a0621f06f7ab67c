"""An interactive page of a run: ``grainlab view DIR`` writes ``DIR/viewer.html``.

One self-contained HTML file (docs/report.md, "The viewer").

>>> from grainlab.viewer import write_viewer  # doctest: +SKIP
>>> write_viewer("results/quick")  # doctest: +SKIP
PosixPath('results/quick/viewer.html')
"""

from __future__ import annotations

import html
import json
import os
import sys
import webbrowser
from importlib import resources
from pathlib import Path

from grainlab.io.results import write_text_atomic
from grainlab.viewer.data import viewer_data

__all__ = ["VIEWER_FILE", "open_in_browser", "write_viewer"]

#: File name of the page in a run folder.
VIEWER_FILE = "viewer.html"

_BODY = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>
{css}</style>
</head>
<body>
<h1 id="title"></h1>
<p id="source"></p>
<div class="controls">
  <label>colour by
    <select id="mode">
      <option value="lambda" selected>stability index &lambda;</option>
      <option value="contacts">number of contacts</option>
      <option value="displacement">displacement</option>
      <option value="rotation">rotation</option>
      <option value="strain">local shear strain</option>
      <option value="porosity">local porosity</option>
      <option value="chains">force chains</option>
      <option value="grains">grain (a clump's pebbles alike)</option>
    </select>
  </label>
  <label><input type="checkbox" id="show-contacts"> contact network</label>
  <label><input type="checkbox" id="show-band" checked> shear band outline</label>
  <label id="cracks-control" hidden><input type="checkbox" id="show-cracks" checked> cracks</label>
</div>
<div class="controls">
  <label>snapshot <input type="range" id="snapshot" min="0" max="0" step="1" value="0"></label>
  <button type="button" id="play">&#9654; play</button>
  <span id="strain-label"></span>
</div>
<div id="legend"></div>
<div class="layout">
  <canvas id="grains" width="560" height="560" aria-label="the grains of the snapshot"></canvas>
  <div>
    <canvas id="curve" width="420" height="300" aria-label="stress-strain curve"></canvas>
    <p class="note">Displacement, rotation and local shear strain are measured since the first
    snapshot; the local porosity is each grain's power cell's, and a force chain is Peters et
    al.'s (docs/fabric.md). Membrane disks are grey. Dashed: the outlines of the accepted shear band (red) and
    its conjugate (orange). Hover a grain for its values; click the curve to go to a snapshot.</p>
  </div>
</div>
<div id="tip" hidden></div>
<script type="application/json" id="grainlab-data">{data}</script>
<script>
{js}</script>
</body>
</html>
"""


def _resource(name: str) -> str:
    return resources.files("grainlab.viewer").joinpath(name).read_text(encoding="utf-8")


def write_viewer(run: str | os.PathLike[str], out: str | os.PathLike[str] | None = None) -> Path:
    """Write the viewer page of ``run`` (a run folder or its ``run.h5``); returns its path.

    ``out`` defaults to ``viewer.html`` beside ``run.h5``. Raises ValueError when
    the run has no snapshots, :class:`~grainlab.io.FileFormatError` when
    ``run.h5`` is missing or unreadable.
    """
    path = Path(run)
    h5 = path / "run.h5" if path.is_dir() else path
    target = Path(out) if out is not None else h5.parent / VIEWER_FILE
    data = viewer_data(h5)
    text = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")
    page = _BODY.format(
        title=html.escape(data["title"]), css=_resource("page.css"), data=text, js=_resource("page.js")
    )
    write_text_atomic(target, page)
    return target


def open_in_browser(page: Path) -> bool:
    """Open ``page`` in the default browser when there is one that can show it; True if opened.

    Nothing is opened on a Linux machine without a display (no ``DISPLAY`` or
    ``WAYLAND_DISPLAY``), where only a text browser could start.
    """
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return False
    try:
        webbrowser.get()
    except webbrowser.Error:
        return False
    return bool(webbrowser.open(page.resolve().as_uri()))
