"""Nested configuration tables as flat ``section.name`` keys."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any


def flatten_keys(
    table: Mapping[str, Any],
    prefix: str = "",
    *,
    leaf: Callable[[Mapping[str, Any]], bool] | None = None,
) -> dict[str, Any]:
    """``{"a": {"b": 1}}`` -> ``{"a.b": 1}``, in the table's order; a nested
    mapping for which ``leaf`` is true stays a value.

    >>> flatten_keys({"sample": {"width": 0.075, "seed": 1}, "note": "x"})
    {'sample.width': 0.075, 'sample.seed': 1, 'note': 'x'}
    """
    flat: dict[str, Any] = {}
    for name, value in table.items():
        key = f"{prefix}{name}"
        if isinstance(value, Mapping) and not (leaf is not None and leaf(value)):
            flat.update(flatten_keys(value, key + ".", leaf=leaf))
        else:
            flat[key] = value
    return flat
