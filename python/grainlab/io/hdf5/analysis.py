"""The analysis group of a results file: products of the analysis stored with the run.

Stored and read as :class:`AnalysisItem` (what they are is
:mod:`grainlab.postprocess.products`'); docs/file-formats.md, "/analysis/<product>/<snapshot>".
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from grainlab.io.hdf5._layout import (
    _STATUSES,
    FORMAT,
    FORMAT_VERSION,
    _attr_str,
    _check_format,
    _check_name,
    _resolve_results_path,
)
from grainlab.io.hdf5.errors import ResultsFileError
from grainlab.io.results import atomic_path

__all__ = ["ANALYSIS_GROUP", "AnalysisItem", "read_analysis_item", "read_analysis_versions", "write_analysis"]

#: The group of a results file that holds the analysis products.
ANALYSIS_GROUP = "analysis"


@dataclass(frozen=True)
class AnalysisItem:
    """One stored product of one snapshot: scalar (or small array) attributes and arrays."""

    attrs: dict[str, Any] = field(default_factory=dict)
    arrays: dict[str, NDArray[Any]] = field(default_factory=dict)


def _plain(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace")
    if isinstance(value, np.generic):
        return value.item()
    return value


def _attr_value(where: str, value: Any) -> Any:
    if isinstance(value, bool | np.bool_):
        return np.bool_(value)
    if isinstance(value, int | np.integer):
        return np.int64(value)
    if isinstance(value, float | np.floating):
        return np.float64(value)
    if isinstance(value, str):
        return value
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf" and value.size <= 64:
        return value
    raise TypeError(f"{where}: {type(value).__name__} cannot be stored as an attribute")


def _read_version(group: h5py.Group) -> int:
    raw = group.attrs.get("version")
    return int(raw) if raw is not None else 0


def read_analysis_versions(f: h5py.File) -> dict[str, int]:
    """``product -> version`` of the products stored in an open results file (empty without any)."""
    group = f.get(ANALYSIS_GROUP)
    if group is None:
        return {}
    return {name: _read_version(group[name]) for name in group}


def read_analysis_item(f: h5py.File, product: str, item: str) -> AnalysisItem | None:
    """The stored ``item`` of ``product`` in an open results file, or None when not stored."""
    group = f.get(f"{ANALYSIS_GROUP}/{product}/{item}")
    if group is None:
        return None
    attrs = {key: _plain(value) for key, value in group.attrs.items()}
    arrays = {name: np.asarray(group[name][()]) for name in group}
    return AnalysisItem(attrs, arrays)


def write_analysis(
    path: str | os.PathLike[str], products: Mapping[str, tuple[int, Mapping[str, AnalysisItem]]]
) -> Path:
    """Store ``products`` (``product -> (version, {item: AnalysisItem})``) in the complete
    results file at ``path`` (a ``run.h5`` or its folder); returns the file's path.

    An item replaces the stored item of that name; a product stored under another
    version is replaced whole (its items were made by another rule). The file is
    written as a copy renamed over the original, so that an interruption leaves it
    as it was; its layout version becomes the current one.
    """
    final = _resolve_results_path(path)
    for product, (version, items) in products.items():
        _check_name("analysis product", product)
        if not isinstance(version, int) or version < 1:
            raise ValueError(f"analysis product {product!r}: version must be an integer >= 1, got {version!r}")
        for item in items:
            _check_name(f"analysis item of {product!r}", item)
    if not final.is_file():
        raise ResultsFileError(final, "file not found")
    with atomic_path(final) as tmp:
        shutil.copyfile(final, tmp)
        with h5py.File(tmp, "r+") as f:
            _check_format(f, final, FORMAT, {v: None for v in range(1, FORMAT_VERSION + 1)}, ResultsFileError)
            status = _attr_str(f.attrs, "status", "")
            if status != "complete":
                known = "/".join(_STATUSES)
                raise ResultsFileError(final, f"status {status!r} ({known}): products are stored in complete runs only")
            f.attrs["format_version"] = np.int64(FORMAT_VERSION)
            root = f.require_group(ANALYSIS_GROUP)
            for product, (version, items) in products.items():
                if product in root and _read_version(root[product]) != version:
                    del root[product]
                group = root.require_group(product)
                group.attrs["version"] = np.int64(version)
                for item, stored in items.items():
                    if item in group:
                        del group[item]
                    g = group.create_group(item)
                    for key, value in stored.attrs.items():
                        g.attrs[key] = _attr_value(f"/{ANALYSIS_GROUP}/{product}/{item}@{key}", value)
                    for name, values in stored.arrays.items():
                        data = np.asarray(values)
                        g.create_dataset(name, data=data, compression="gzip" if data.size > 256 else None)
    return final
