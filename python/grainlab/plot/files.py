"""Figure files: how a figure is written small (PNG at :data:`FIGURE_DPI` with a
256-colour palette, :func:`compact_png`; SVG with its rasterised particle maps
re-encoded the same way) and a page's copy of it (:func:`page_png`). The paper
style (:data:`PAPER_STYLE`) is what every figure is drawn and saved in.
:mod:`grainlab.plot` re-exports all of it; the figure workers
(:mod:`grainlab.plot.workers`) save through it.
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import io
import re
from collections import OrderedDict
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib as mpl
import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray
from PIL import Image
from scipy.spatial import cKDTree

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType  # matplotlib >= 3.9 (typing only)

__all__ = ["FIGURE_DPI", "PAGE_DPI", "PAPER_STYLE", "compact_png", "page_png", "paper_style", "save_figure",
           "scale_colors"]

#: Resolution of the figure files (PNG, and the raster particle maps inside SVGs), dots per inch.
FIGURE_DPI = 200
#: Resolution of a figure file's copy embedded in a page (report.html shows figures at 1.3 x 96 pixels per inch).
PAGE_DPI = 150

#: rcParams for paper figures: serif text, small sizes, thin lines, no clutter.
PAPER_STYLE: dict[RcKeyType, Any] = {
    "font.family": "serif",
    "font.size": 9,
    "axes.labelsize": 9,
    "axes.titlesize": 9,
    "legend.fontsize": 8,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "axes.linewidth": 0.8,
    "lines.linewidth": 1.2,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "savefig.bbox": "tight",
    "savefig.dpi": FIGURE_DPI,
    "svg.fonttype": "none",
    "figure.dpi": 100,
}


@contextlib.contextmanager
def paper_style() -> Iterator[None]:
    """Context manager applying :data:`PAPER_STYLE`."""
    with mpl.rc_context(PAPER_STYLE):
        yield


def compact_png(data: bytes, *, dpi: float | None = None, keep: ArrayLike | None = None) -> bytes:
    """A PNG image re-encoded small: at most ``dpi`` dots per inch (resampled
    down when its recorded resolution is higher), with a 256-colour palette
    (no dithering), transparency kept, the resolution recorded.

    ``keep`` ((k, 3) RGB values 0-255, k <= 192) are colours the palette holds
    exactly, e.g. the steps of a colour bar, so that a colour scale stays
    smooth; the other entries are fitted to the image (octree), which moves
    antialiased edges by a few levels at most. An opaque palette image
    without ``keep`` keeps its own palette (a smaller copy of a figure file).
    """
    fixed = np.zeros((0, 3), np.uint8) if keep is None else np.asarray(keep, dtype=np.uint8).reshape(-1, 3)
    if len(fixed) > 192:
        raise ValueError(f"keep: at most 192 colours, got {len(fixed)}")
    with Image.open(io.BytesIO(data)) as source:
        image = source.convert("RGBA")
        recorded = source.info.get("dpi")
        # a palette image resampled keeps its own palette (a colour bar stays as smooth as it was)
        own = source.getpalette() if source.mode == "P" and "transparency" not in source.info else None
    src_dpi = float(recorded[0]) if recorded else None
    out_dpi = src_dpi
    if dpi is not None and src_dpi is not None and src_dpi > dpi * 1.001:
        scale = dpi / src_dpi
        size = (max(1, round(image.width * scale)), max(1, round(image.height * scale)))
        image = image.resize(size, Image.Resampling.LANCZOS)
        out_dpi = dpi
    if int(np.asarray(image.getchannel("A")).min()) < 255:  # transparent pixels: an RGBA palette
        palette = image.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
    else:
        rgb = image.convert("RGB")
        if own is not None and keep is None:
            entries = np.asarray(own, dtype=np.uint8)
        else:
            fitted = rgb.quantize(colors=256 - len(fixed), method=Image.Quantize.FASTOCTREE)
            found = np.asarray(fitted.getpalette() or [], dtype=np.uint8)[: 3 * (256 - len(fixed))]
            entries = np.concatenate([fixed.reshape(-1), found])
        palette = _nearest_palette_image(np.asarray(rgb), entries.reshape(-1, 3))
    buffer = io.BytesIO()
    options: dict[str, Any] = {"format": "png", "optimize": True}
    if out_dpi is not None:
        options["dpi"] = (out_dpi, out_dpi)
    palette.save(buffer, **options)
    return buffer.getvalue()


def _nearest_palette_image(rgb: NDArray[np.uint8], entries: NDArray[np.uint8]) -> Image.Image:
    """The "P" image of ``rgb`` (H, W, 3) with each pixel the nearest of ``entries`` (k, 3):
    a colour of the palette maps to itself exactly (Pillow's own mapping is approximate)."""
    packed = (rgb[..., 0].astype(np.int64) << 16) | (rgb[..., 1].astype(np.int64) << 8) | rgb[..., 2]
    colours, inverse = np.unique(packed.reshape(-1), return_inverse=True)
    unique_rgb = np.c_[colours >> 16, (colours >> 8) & 255, colours & 255].astype(np.float64)
    _, nearest = cKDTree(entries.astype(np.float64)).query(unique_rgb)
    image = Image.fromarray(np.asarray(nearest, np.uint8)[inverse].reshape(rgb.shape[:2]), mode="P")
    image.putpalette(entries.reshape(-1).tolist())
    return image


#: Page copies of the latest figure files (:func:`page_png`), by the digest of the file's PNG.
_PAGE_COPIES_KEPT = 32
_page_copies: OrderedDict[bytes, bytes] = OrderedDict()


def _png_digest(png: bytes) -> bytes:
    return hashlib.blake2b(png, digest_size=24).digest()


def _keep_page_png(digest: bytes, page: bytes) -> None:
    """Keeps ``page``, the page copy of the PNG with ``digest`` (:func:`_png_digest`),
    made here or in a worker process (:mod:`grainlab.plot.workers`)."""
    _page_copies[digest] = page
    _page_copies.move_to_end(digest)
    while len(_page_copies) > _PAGE_COPIES_KEPT:
        _page_copies.popitem(last=False)


def page_png(png: bytes) -> bytes:
    """A figure file's PNG as a page embeds it: at most :data:`PAGE_DPI`, its palette
    kept (:func:`compact_png`). The copies of the latest figure files are kept, so
    that a report written after the figures does not make them again."""
    key = _png_digest(png)
    page = _page_copies.get(key)
    if page is None:
        page = compact_png(png, dpi=PAGE_DPI)
        _keep_page_png(key, page)
    return page


def scale_colors(fig: Figure, budget: int = 128) -> NDArray[np.uint8]:
    """(k, 3) RGB steps of the colour maps in ``fig`` (at most ``budget`` in
    all, shared between the maps; a map with fewer steps gives all of them):
    what :func:`compact_png` keeps exactly so that colour bars stay smooth."""
    cmaps: dict[str, Any] = {}
    for ax in fig.axes:
        for artist in [*ax.collections, *ax.images]:
            cmap = getattr(artist, "cmap", None)
            if cmap is not None and getattr(artist, "get_array", lambda: None)() is not None:
                cmaps.setdefault(cmap.name, cmap)
    if not cmaps:
        return np.zeros((0, 3), np.uint8)
    share = max(2, budget // len(cmaps))
    steps = [cmap(np.linspace(0.0, 1.0, min(cmap.N, share)))[:, :3] for cmap in cmaps.values()]
    colours = np.round(255.0 * np.concatenate(steps)).astype(np.uint8)
    return np.unique(colours, axis=0)[:budget]


_SVG_PNG = re.compile(rb'(href="data:image/png;base64,)([A-Za-z0-9+/=\s]+)(")')


def _compact_svg(svg: bytes) -> bytes:
    """The SVG with each embedded PNG (the rasterised particle maps) re-encoded by :func:`compact_png`."""

    def recode(m: re.Match[bytes]) -> bytes:
        png = compact_png(base64.b64decode(m.group(2)))
        return m.group(1) + base64.b64encode(png) + m.group(3)

    return _SVG_PNG.sub(recode, svg)


def save_figure(
    fig_or_ax: Any, path: str | Path, formats: Sequence[str] = ("png", "svg")
) -> list[Path]:
    """Write the figure as ``path`` with each suffix in ``formats``; returns the paths.

    PNG and SVG files are made small (:func:`compact_png`; module docstring);
    other formats are written as matplotlib writes them.
    """
    fig = (
        fig_or_ax.figure
        if hasattr(fig_or_ax, "figure") and not isinstance(fig_or_ax, Figure)
        else fig_or_ax
    )
    base = Path(path)
    base.parent.mkdir(parents=True, exist_ok=True)
    written = []
    with paper_style():
        for fmt in formats:
            kind = fmt.lstrip(".")
            out = base.with_suffix("." + kind)
            buffer = io.BytesIO()
            if kind == "png":  # re-encoded below: stored uncompressed here, the pixels are the same
                fig.savefig(buffer, format=kind, pil_kwargs={"compress_level": 0})
            else:
                fig.savefig(buffer, format=kind)
            data = buffer.getvalue()
            if kind == "png":
                data = compact_png(data, keep=scale_colors(fig))
            elif kind == "svg":
                data = _compact_svg(data)
            out.write_bytes(data)
            written.append(out)
    return written
