"""``grainlab view``: the self-contained viewer page, its data, and the page in headless chromium
(Playwright, as the reports' test_browser.py): offline, the slider and the colour change the
picture, hovering a grain shows the run's lambda of that grain, a clump's pebbles share one
colour and the clump one outline."""

from __future__ import annotations

import base64
import contextlib
import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from report_helpers import chromium_or_skip, parse

from grainlab.analysis import StabilityIndex
from grainlab.cli import main
from grainlab.io.hdf5 import read_results
from grainlab.viewer import open_in_browser, write_viewer


def _data(page) -> dict:
    text = page.read_text(encoding="utf-8")
    m = re.search(r'<script type="application/json" id="grainlab-data">(.*?)</script>', text, re.S)
    return json.loads(m.group(1))


def _decode(text: str, dtype: str) -> np.ndarray:
    return np.frombuffer(base64.b64decode(text), dtype="<" + dtype)


@pytest.fixture(scope="module")
def viewer_page(synthetic_results, tmp_path_factory):
    return write_viewer(synthetic_results, tmp_path_factory.mktemp("viewer") / "viewer.html")


def test_the_page_needs_nothing_outside_itself(viewer_page):
    text = viewer_page.read_text(encoding="utf-8")
    page = parse(text)
    for tag, attrs in page.tags:
        assert "src" not in attrs and "href" not in attrs, (tag, attrs)  # inline script and style only
    assert "http://" not in text and "https://" not in text and "@import" not in text
    assert viewer_page.stat().st_size < 200_000  # 3 snapshots of ~450 disks, quantised


def test_the_embedded_values_are_the_runs(viewer_page, synthetic_results):
    data = _data(viewer_page)
    results = read_results(synthetic_results / "run.h5")
    assert [s["name"] for s in data["snapshots"]] == results.snapshot_names
    last = results.snapshot(-1)
    arrays = data["snapshots"][-1]["arrays"]
    lam = StabilityIndex().compute(last).stability_index
    np.testing.assert_array_equal(_decode(arrays["lambda"], "f4"), lam.astype(np.float32))
    np.testing.assert_array_equal(_decode(arrays["x"], "f4"), last.positions[:, 0].astype(np.float32))
    assert _decode(arrays["ci"], data["index_dtype"]).size == last.n_contacts  # no wall or periodic ones
    first = data["snapshots"][0]["arrays"]
    assert not _decode(first["dx"], "f4").any()  # displacements are since the first snapshot
    # the synthetic band of simple shear at 60 degrees, found between the first and last snapshots
    band = data["snapshots"][-1]["band"]["first"]
    assert band is not None and abs(band["angle_deg"] % 180 - 60.0) < 10.0
    assert data["curve"]["x"] == "axial_strain" and data["curve"]["y"] == "stress_ratio"
    assert _decode(data["curve"]["ys"], "f4").max() == pytest.approx(4.0, rel=1e-3)  # the peak ratio


def test_view_command(synthetic_results, tmp_path, capsys):
    out = tmp_path / "page.html"
    assert main(["view", str(synthetic_results), "--out", str(out), "--no-open"]) == 0
    assert out.is_file() and "grainlab view:" in capsys.readouterr().out
    assert main(["view", str(tmp_path), "--no-open"]) == 2  # no run.h5 there
    assert "no run.h5 there" in capsys.readouterr().err


def test_nothing_is_opened_without_a_display(monkeypatch, tmp_path):
    import grainlab.viewer as viewer

    monkeypatch.setattr(viewer.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(viewer.webbrowser, "open", lambda *a, **k: pytest.fail("a browser was opened"))
    assert open_in_browser(tmp_path / "viewer.html") is False


def _pixels(page) -> str:
    return page.evaluate("document.getElementById('grains').toDataURL()")


@contextlib.contextmanager
def _in_chromium(page_file: Path, problems: list[str], requests: list[str]) -> Iterator[Any]:
    """The page open in headless chromium; console errors and warnings and page errors go to
    ``problems``, the URLs it requests to ``requests`` (skips without chromium)."""
    from playwright.sync_api import sync_playwright

    chromium = chromium_or_skip()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 1000})
            page.on("console", lambda m: problems.append(m.text) if m.type in ("error", "warning") else None)
            page.on("pageerror", lambda e: problems.append(str(e)))
            page.on("request", lambda r: requests.append(r.url))
            page.goto(page_file.resolve().as_uri(), wait_until="load")
            yield page
        finally:
            browser.close()


def test_the_page_in_chromium(viewer_page, synthetic_results):
    chromium_or_skip()
    results = read_results(synthetic_results / "run.h5")
    last = results.snapshot(-1)
    lam = StabilityIndex().compute(last).stability_index
    grains = np.flatnonzero((last.kind == 0) & (last.contact_counts() >= 3))
    k = int(grains[np.argmax(lam[grains])])  # a grain with a distinctive lambda
    problems: list[str] = []
    requests: list[str] = []
    with _in_chromium(viewer_page, problems, requests) as page:
        assert page.evaluate("grainlabViewer.snapshotCount") == 3
        assert page.evaluate("grainlabViewer.current()") == 2  # opens on the last snapshot
        last_picture = _pixels(page)
        page.locator("#snapshot").fill("0")  # the slider: the first snapshot
        assert page.evaluate("grainlabViewer.current()") == 0
        first_picture = _pixels(page)
        assert first_picture != last_picture
        assert "0.00 %" in page.inner_text("#strain-label")
        page.locator("#snapshot").fill("2")
        assert _pixels(page) == last_picture  # the same snapshot, the same picture
        page.select_option("#mode", "strain")
        assert _pixels(page) != last_picture
        page.select_option("#mode", "lambda")
        x, y = page.evaluate(f"grainlabViewer.clientPosition({k})")
        page.mouse.move(x, y)
        assert page.is_visible("#tip")
        shown = page.inner_text("#tip td[data-key='λ']")
        particle = page.inner_text("#tip td[data-key='particle id']")
    assert problems == []
    assert all(url.startswith(("file:", "data:")) for url in requests), requests
    assert int(particle) == int(last.ids[k])
    assert float(shown) == pytest.approx(lam[k], abs=1e-6)


def test_walls_stored_with_a_snapshot_are_drawn(tmp_path):
    from grainlab.io.hdf5 import ResultsWriter
    from grainlab.io.walls import WALL_SEGMENT, WallGeometry
    from grainlab.snapshot import Snapshot
    from grainlab.viewer.data import viewer_data

    a, b = np.meshgrid(np.arange(10), np.arange(10), indexing="ij")
    pos = np.c_[a.ravel(), b.ravel()] * 1e-3 + 1e-3
    snap = Snapshot.from_geometry(pos, np.full(100, 0.5e-3), tolerance=1e-9, axial_strain=0.0)
    moved = Snapshot.from_geometry(pos * [1.0, 0.99], np.full(100, 0.5e-3), tolerance=1e-9, axial_strain=0.01)
    platens = WallGeometry(("bottom", "top"), [WALL_SEGMENT, WALL_SEGMENT], [[0.0, 0.0], [0.012, 0.0115]],
                           [[0.012, 0.0], [0.0, 0.0115]], [[0.0, 1.0], [0.0, -1.0]], [True, True])
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        out.append_rows({"axial_strain": [0.0, 0.01], "stress_ratio": [1.0, 2.0]})
        out.write_snapshot("strain_0.0000", snap, walls=platens)
        out.write_snapshot("strain_0.0100", moved)
    data = viewer_data(tmp_path)
    assert data["snapshots"][0]["walls"] == [[[0.0, 0.0], [0.012, 0.0]], [[0.012, 0.0115], [0.0, 0.0115]]]
    assert data["snapshots"][1]["walls"] is None
    dy = _decode(data["snapshots"][1]["arrays"]["dy"], "f4")
    np.testing.assert_allclose(dy, (pos[:, 1] * -0.01).astype(np.float32), rtol=1e-5, atol=1e-12)


def _clump_run(folder) -> tuple[np.ndarray, np.ndarray]:
    """Three trimers (grains 0-2, pebbles of radius 1 mm) and a disk (grain 3) in a row,
    settling by 10 um between two snapshots; returns the pebbles' positions and radii."""
    from grainlab.io.hdf5 import ResultsWriter
    from grainlab.snapshot import Snapshot

    offsets = np.array([[0.0, 0.7], [-0.6, -0.35], [0.6, -0.35]]) * 1e-3
    centres = np.array([[2e-3, 2e-3], [6e-3, 2e-3], [10e-3, 2e-3], [14e-3, 2e-3]])
    positions = np.r_[(centres[:3, None, :] + offsets).reshape(-1, 2), centres[3:]]
    radii = np.full(10, 1e-3)
    centroid = np.r_[np.repeat(centres[:3], 3, axis=0), centres[3:]]
    grain = {"grain": np.r_[np.repeat([0, 1, 2], 3), 3], "grain_angle": np.zeros(10)}
    with ResultsWriter(folder / "run.h5", kind="biaxial") as out:
        for k in range(2):
            down = [0.0, -1e-5 * k]
            fields = grain | {"grain_centroid": centroid + down}
            snap = Snapshot.from_geometry(
                positions + down, radii, tolerance=1e-9, axial_strain=1e-3 * k, particle_fields=fields
            )
            out.write_snapshot(f"strain_{k}", snap)
    return positions + down, radii


def test_clumps_are_drawn_one_colour_each_and_outlined(tmp_path):
    chromium_or_skip()
    positions, radii = _clump_run(tmp_path)
    page_file = write_viewer(tmp_path)
    pixels = """(points) => {
        const c = document.getElementById('grains'), r = c.getBoundingClientRect();
        const image = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        return points.map(([x, y]) => {
            const k = 4 * (Math.floor((y - r.top) * c.height / r.height) * c.width + Math.floor((x - r.left) * c.width / r.width));
            return [image[k], image[k + 1], image[k + 2]];
        });
    }"""
    problems: list[str] = []
    requests: list[str] = []
    with _in_chromium(page_file, problems, requests) as page:
        mode = page.eval_on_selector("#mode", "el => el.value")
        page.uncheck("#show-band")
        centre = [page.evaluate(f"grainlabViewer.clientPosition({i})") for i in range(10)]
        # client pixels per metre, from the disk and the first pebble
        per_m = (centre[9][0] - centre[0][0]) / (positions[9, 0] - positions[0, 0])
        tops = [[centre[i][0], centre[i][1] - radii[i] * per_m - 1.0] for i in (0, 3, 9)]
        colour = page.evaluate(pixels, centre + tops)
    colour, above = colour[:10], colour[10:]
    assert problems == [] and all(url.startswith(("file:", "data:")) for url in requests), (problems, requests)
    assert mode == "grains"  # a run with clumps opens coloured by grain
    assert colour[0] == colour[1] == colour[2] and colour[3] == colour[4] == colour[5]
    assert len({tuple(colour[0]), tuple(colour[3]), tuple(colour[6]), tuple(colour[9])}) == 4
    assert all(sum(rgb) < 300 for rgb in above[:2]), above  # the trimers' outlines, just above their top pebbles
    assert sum(above[2]) == 3 * 255, above  # no outline round the disk: the white page


def test_a_cemented_runs_cracks_are_a_layer_drawn_as_they_broke(tmp_path):
    """Two snapshots, one crack broken before each: the data say which are broken by
    each snapshot, and the page draws them (tension blue) where they are, and no more."""
    from grainlab.io.hdf5 import ResultsWriter
    from grainlab.protocols.cracks import crack_units
    from grainlab.snapshot import Snapshot
    from grainlab.viewer.data import viewer_data

    a, b = np.meshgrid(np.arange(10), np.arange(10), indexing="ij")
    pos = np.c_[a.ravel(), b.ravel()] * 1e-3 + 1e-3
    radii = np.full(100, 0.5e-3)
    crack = {name: np.zeros(2, dtype=np.int64 if name in ("step", "i", "j") else np.float64) for name in crack_units()}
    crack |= {"time_s": np.array([0.5, 1.5]), "x_m": np.array([1.5e-3, 8.5e-3]), "y_m": np.array([5.0e-3, 5.0e-3]),
              "normal_x": np.ones(2), "tension": np.array([1, 0], dtype=np.int8)}
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        out.append_rows({"axial_strain": [0.0, 0.01], "time_s": [1.0, 2.0]})
        for k in range(2):
            out.write_snapshot(f"strain_{k}", Snapshot.from_geometry(pos, radii, tolerance=1e-9, time=1.0 + k,
                                                                     axial_strain=0.01 * k))
        out.append_cracks(crack, crack_units())
    data = viewer_data(tmp_path)
    assert data["cracks"]["n"] == 2 and [s["n_cracks"] for s in data["snapshots"]] == [1, 2]
    np.testing.assert_allclose(_decode(data["cracks"]["angle"], "f4"), 0.5 * np.pi, rtol=1e-6)  # vertical
    chromium_or_skip()
    page_file = write_viewer(tmp_path)
    colour = """([x, y]) => {
        const c = document.getElementById('grains'), r = c.getBoundingClientRect();
        const k = 4 * (Math.floor((y - r.top) * c.height / r.height) * c.width + Math.floor((x - r.left) * c.width / r.width));
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        return [d[k], d[k + 1], d[k + 2]];
    }"""
    problems: list[str] = []
    with _in_chromium(page_file, problems, []) as page:
        # the crack centres sit between grains 10/11 (x 1.5 mm) and 80/81 (x 8.5 mm), at y = 5 mm
        def at(x_m: float) -> list[int]:
            x0, y0 = page.evaluate("grainlabViewer.clientPosition(0)")
            x1, _ = page.evaluate("grainlabViewer.clientPosition(90)")
            per_m = (x1 - x0) / 9e-3
            return page.evaluate(colour, [x0 + (x_m - 1e-3) * per_m, y0 - (5e-3 - 1e-3) * per_m])

        last = (at(1.5e-3), at(8.5e-3))
        page.locator("#snapshot").fill("0")
        first = (at(1.5e-3), at(8.5e-3))
        label = page.inner_text("#strain-label")
    # the test's own readbacks of the canvas draw chromium's hint to read it otherwise
    assert [p for p in problems if not p.startswith("Canvas2D: Multiple readback")] == []
    assert last[0][2] > 150 and last[0][0] < 100, last  # blue: the tension crack
    assert last[1][0] > 150 and last[1][2] < 100, last  # red: the shear crack, broken by the last snapshot
    assert first[0] == last[0] and first[1] != last[1], first  # not yet broken at the first
    assert "1 cracks so far" in label
