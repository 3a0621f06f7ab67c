"""The paper-scale campaign's verdicts, shipped with grainlab in ``paper_scale/``.

docs/reproduction.md quotes their tables (a test keeps them equal); ``report.html``
shows each claim's ensemble verdict beside a run's own value.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from typing import Any

__all__ = ["CAMPAIGNS", "paper_scale_verdicts", "stored_claims"]

#: The stored campaign documents, by name.
CAMPAIGNS = ("main", "readings", "rates", "rate1", "rate05", "study", "study_readings")


@cache
def stored_claims(name: str = "main") -> dict[str, Any] | None:
    """The stored ``claims.json`` document of campaign ``name`` (:data:`CAMPAIGNS`);
    None when this installation has none."""
    if name not in CAMPAIGNS:
        raise ValueError(f"name: expected one of {', '.join(CAMPAIGNS)}, got {name!r}")
    path = resources.files("grainlab.reproduction") / "paper_scale" / f"{name}.json"
    if not path.is_file():
        return None
    data = json.loads(path.read_text(encoding="utf-8"))
    if not isinstance(data, dict):
        raise ValueError(f"{path}: a stored campaign is a JSON object, got {type(data).__name__}")
    return data


def paper_scale_verdicts(document: dict[str, Any] | None = None) -> dict[str, dict[str, Any]]:
    """Claim id -> ``{"verdict", "mean", "ci95", "n", "seeds"}`` of the main
    ensemble's claims (``document`` defaults to the stored ``main``); empty when
    none is stored."""
    doc = stored_claims("main") if document is None else document
    if not doc:
        return {}
    seeds = len(doc.get("seeds", []))
    return {row["id"]: {"verdict": row["verdict"], "mean": row.get("mean"), "ci95": row.get("ci95"),
                        "n": row.get("n"), "seeds": seeds} for row in doc.get("claims", [])}
