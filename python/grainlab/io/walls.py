"""The walls (platens) of a run at one instant, as stored in ``run.h5``
(``/snapshots/<name>/walls``, docs/file-formats.md) and exported.

>>> import numpy as np
>>> w = WallGeometry(("bottom",), np.array([0]), np.array([[0.0, 0.0]]), np.array([[0.02, 0.0]]),
...                  np.array([[0.0, 1.0]]), np.array([True]))
>>> w.segments().tolist()
[[[0.0, 0.0], [0.02, 0.0]]]
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

__all__ = ["WALL_LINE", "WALL_SEGMENT", "WallGeometry", "read_wall_group", "write_wall_group"]

#: ``kind`` code of a segment wall.
WALL_SEGMENT = 0
#: ``kind`` code of an infinite line wall.
WALL_LINE = 1
_KINDS = {"segment": WALL_SEGMENT, "line": WALL_LINE}
_STR = h5py.string_dtype("utf-8")


@dataclass(frozen=True)
class WallGeometry:
    """Every wall of a simulation at one instant (W walls; arrays in SI units)."""

    #: Wall names (``"bottom"``, ``"top"``, ... or ``"wall_<id>"``), (W,).
    names: tuple[str, ...]
    #: :data:`WALL_SEGMENT` or :data:`WALL_LINE` per wall, (W,) int.
    kind: NDArray[np.int8]
    #: First point of a segment, the point of a line, (W, 2) m.
    a: NDArray[np.float64]
    #: Second point of a segment (``a`` for a line), (W, 2) m.
    b: NDArray[np.float64]
    #: Unit normal towards the particles, (W, 2).
    inward_normal: NDArray[np.float64]
    #: Whether the wall has contacts (inactive walls stay put and touch nothing), (W,) bool.
    active: NDArray[np.bool_]

    def __post_init__(self) -> None:
        w = len(self.names)
        object.__setattr__(self, "names", tuple(str(n) for n in self.names))
        for name, shape, dtype in (("kind", (w,), np.int8), ("a", (w, 2), np.float64),
                                   ("b", (w, 2), np.float64), ("inward_normal", (w, 2), np.float64),
                                   ("active", (w,), np.bool_)):
            value = np.asarray(getattr(self, name), dtype=dtype)
            if value.shape != shape:
                raise ValueError(f"walls.{name}: expected shape {shape}, got {value.shape}")
            object.__setattr__(self, name, value)
        bad = ~np.isin(self.kind, list(_KINDS.values()))
        if bad.any():
            raise ValueError(f"walls.kind: unknown code {int(self.kind[bad][0])} (0 segment, 1 line)")

    def __len__(self) -> int:
        return len(self.names)

    @classmethod
    def from_simulation(cls, sim: Any, names: Mapping[int, str] | None = None) -> WallGeometry:
        """The walls of a :class:`grainlab.Simulation` now; ``names`` maps wall ids to names."""
        walls = list(sim.walls)
        names = dict(names or {})
        a, b, kind = [], [], []
        for w in walls:
            p = np.asarray(w.points, dtype=np.float64)
            kind.append(_KINDS[w.kind])
            a.append(p[0])
            b.append(p[1] if len(p) > 1 else p[0])
        return cls(
            names=tuple(names.get(w.id, f"wall_{w.id}") for w in walls),
            kind=np.array(kind, dtype=np.int8),
            a=np.array(a, dtype=np.float64).reshape(-1, 2),
            b=np.array(b, dtype=np.float64).reshape(-1, 2),
            inward_normal=np.array([w.inward_normal for w in walls], dtype=np.float64).reshape(-1, 2),
            active=np.array([w.active for w in walls], dtype=bool),
        )

    def segments(self, bounds: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """(K, 2, 2) end points of the active walls: segments as they are, lines clipped to
        ``bounds`` ``[[xmin, ymin], [xmax, ymax]]`` (lines are left out without bounds)."""
        out = []
        for k in np.flatnonzero(self.active):
            if self.kind[k] == WALL_SEGMENT:
                out.append([self.a[k], self.b[k]])
            elif bounds is not None:
                tangent = np.array([-self.inward_normal[k, 1], self.inward_normal[k, 0]])
                reach = float(np.hypot(*(bounds[1] - bounds[0])))
                centre = 0.5 * (bounds[0] + bounds[1])
                foot = self.a[k] + np.dot(centre - self.a[k], tangent) * tangent
                out.append([foot - reach * tangent, foot + reach * tangent])
        return np.array(out, dtype=np.float64).reshape(-1, 2, 2)


def write_wall_group(group: h5py.Group, walls: WallGeometry) -> None:
    """Store ``walls`` as datasets of ``group`` (``name``, ``kind``, ``a``, ``b``, ``inward_normal``, ``active``)."""
    if not isinstance(walls, WallGeometry):
        raise TypeError(f"walls: expected a WallGeometry, got {type(walls).__name__}")
    group.create_dataset("name", data=np.array(walls.names, dtype=_STR), dtype=_STR)
    for name, units in (("kind", ""), ("a", "m"), ("b", "m"), ("inward_normal", ""), ("active", "")):
        group.create_dataset(name, data=getattr(walls, name)).attrs["units"] = units
    group.attrs["n_walls"] = np.int64(len(walls))


def read_wall_group(group: h5py.Group) -> WallGeometry:
    """The :class:`WallGeometry` stored by :func:`write_wall_group`."""
    return WallGeometry(
        names=tuple(str(n) for n in group["name"].asstr()[()]),
        kind=group["kind"][()],
        a=group["a"][()],
        b=group["b"][()],
        inward_normal=group["inward_normal"][()],
        active=group["active"][()],
    )
