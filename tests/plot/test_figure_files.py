"""Figure files stay small and still show the grains (grainlab.plot.save_figure, compact_png)."""

from __future__ import annotations

import base64
import io
import re

import matplotlib as mpl
import numpy as np
import pytest
from PIL import Image

from grainlab import plot

N_GRAINS = 3000


def _packing(n: int = N_GRAINS, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """``n`` disks on a jittered square lattice 50 x 60 mm: the size of a biaxial map."""
    rng = np.random.default_rng(seed)
    cols = int(np.ceil(np.sqrt(n * 5 / 6)))
    k = np.arange(n)
    spacing = 0.05 / cols
    pos = np.c_[(k % cols + 0.5) * spacing, (k // cols + 0.5) * spacing]
    pos += rng.uniform(-0.05, 0.05, pos.shape) * spacing
    radii = rng.uniform(0.35, 0.48, n) * spacing
    return pos, radii


def _rgb(png: bytes) -> np.ndarray:
    with Image.open(io.BytesIO(png)) as image:
        return np.asarray(image.convert("RGBA").convert("RGB"), dtype=np.int64)


def _left_right_colours(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Median colour of the coloured (not grey, white or black) pixels in the left and right thirds."""
    saturated = (rgb.max(axis=2) - rgb.min(axis=2)) > 40
    w = rgb.shape[1]
    left, right = saturated[:, : w // 3], saturated[:, 2 * w // 3 :]
    assert left.mean() > 0.15 and right.mean() > 0.15, "the map is (nearly) blank"
    return np.median(rgb[:, : w // 3][left], axis=0), np.median(rgb[:, 2 * w // 3 :][right], axis=0)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A map of 3000 grains, lambda 0 in the left half and 1 in the right half, saved as PNG + SVG."""
    pos, radii = _packing()
    values = np.where(pos[:, 0] < 0.025, 0.0, 1.0)
    ax = plot.particle_map(pos, radii, values, vmin=0.0, vmax=1.0, colorbar=False)
    png, svg = plot.save_figure(ax, tmp_path_factory.mktemp("fig") / "map")
    return png, svg


def test_files_of_a_few_thousand_grains_stay_small(files):
    png, svg = files
    # drawn as before (PNG at 300 dpi in full colour, SVG with one path per disk): 0.67 MB and several MB
    assert png.stat().st_size < 200_000
    assert svg.stat().st_size < 250_000


def test_svg_holds_the_grains_as_one_image_and_vector_axes(files):
    _, svg = files
    text = svg.read_text(encoding="utf-8")
    images = re.findall(r'<image\b[^>]*href="data:image/png;base64,([A-Za-z0-9+/=\s]+)"', text)
    assert len(images) == 1
    assert text.count("<path") < N_GRAINS / 10  # axes and ticks, not one path per disk
    assert "x (m)" in text  # labels stay text (svg.fonttype none)
    left, right = _left_right_colours(_rgb(base64.b64decode(images[0])))
    dark, bright = (255 * np.asarray(mpl.colormaps["viridis"]([0.0, 1.0]))[:, :3]).round()
    assert np.abs(left - dark).max() <= 3 and np.abs(right - bright).max() <= 3


def test_png_shows_the_grains_in_their_colours(files):
    png, _ = files
    data = png.read_bytes()
    with Image.open(io.BytesIO(data)) as image:
        assert image.mode == "P" and image.info["dpi"][0] == pytest.approx(plot.FIGURE_DPI, rel=1e-3)
    left, right = _left_right_colours(_rgb(data))
    dark, bright = (255 * np.asarray(mpl.colormaps["viridis"]([0.0, 1.0]))[:, :3]).round()
    assert np.abs(left - dark).max() <= 3 and np.abs(right - bright).max() <= 3


def test_compact_png_keeps_the_given_colours_exactly():
    rng = np.random.default_rng(0)
    scale = (255 * np.asarray(mpl.colormaps["viridis"](np.linspace(0, 1, 128)))[:, :3]).round().astype(np.uint8)
    image = rng.integers(0, 256, (64, 256, 3), dtype=np.uint8)  # noise: more colours than a palette holds
    image[:32] = np.repeat(scale, 2, axis=0)[None, :, :]  # a colour bar, 2 pixels per step
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="png", dpi=(200, 200))
    out = _rgb(plot.compact_png(buffer.getvalue(), keep=scale))
    assert np.array_equal(out[:32], image[:32].astype(np.int64))
    assert np.abs(out[32:] - image[32:]).mean() < 20  # the rest approximated


def test_compact_png_resamples_to_a_lower_resolution_and_keeps_its_palette(files):
    png, _ = files
    data = png.read_bytes()
    small = plot.compact_png(data, dpi=100)
    with Image.open(io.BytesIO(data)) as big, Image.open(io.BytesIO(small)) as little:
        assert little.info["dpi"][0] == pytest.approx(100, rel=1e-3)
        assert abs(little.width - big.width / 2) <= 1 and abs(little.height - big.height / 2) <= 1
        assert set(np.asarray(little).reshape(-1)) <= set(range(256))
        assert little.getpalette() == big.getpalette()
    assert len(small) < len(data)
    left, right = _left_right_colours(_rgb(small))
    assert right.sum() > left.sum() + 200  # yellow on the right, dark purple on the left


def test_scale_colors_of_a_figure():
    pos, radii = _packing(200)
    ax = plot.particle_map(pos, radii, np.arange(200) % 4, discrete=True)
    colours = plot.scale_colors(ax.figure)
    assert colours.shape == (4, 3)  # the four steps of the discrete map, nothing else
    with pytest.raises(ValueError, match="keep: at most 192"):
        plot.compact_png(b"", keep=np.zeros((193, 3)))
