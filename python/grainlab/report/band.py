"""The shear band of a biaxial run, as the report shows it: :func:`band_from_numbers`
reads the figures' bands back from ``summary.json`` (docs/report.md, "How the angles
are computed").
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields
from typing import Any

from grainlab.postprocess.band import BandNumbers

__all__ = ["ACCEPTANCE", "band_from_numbers"]

#: What "found" means for the bands the report shows.
ACCEPTANCE = "the figures' acceptance tests (thickness, prominence, crossing, significance), grains away from the boundary"


def band_from_numbers(numbers: Mapping[str, Any] | None) -> BandNumbers | None:
    """The :class:`BandNumbers` of their JSON form (numbers written as None, or
    missing in an older ``summary.json``, come back as NaN); None stays None."""
    if not numbers:
        return None
    values: dict[str, Any] = {}
    for f in fields(BandNumbers):
        value = numbers.get(f.name)
        if f.type in ("float", float):
            values[f.name] = float(value) if isinstance(value, int | float) else math.nan
        elif f.type in ("bool", bool):
            values[f.name] = bool(value)
        elif f.type in ("int", int):
            values[f.name] = int(value or 0)
        else:
            values[f.name] = "" if value is None else str(value)
    if values["found"] and not math.isfinite(values["inclination_deg"]) and math.isfinite(values["angle_deg"]):
        values["inclination_deg"] = min(values["angle_deg"], 180.0 - values["angle_deg"])
    if not values["found"] and not values["reason"]:
        values["reason"] = "not accepted by ShearBand"
    return BandNumbers(**values)
