"""The lateral boundaries of the biaxial test (docs/boundary.md, "The flexible
boundary of the biaxial test"): A, chains of bonded membrane disks outside the
sample's sides, walked clockwise around it as the engine's pressure chains
expect; B, the sample's outermost grains; C, rigid side walls."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any, Self

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from grainlab.simulation import FIX_Y, ContactModel, Simulation, Wall

#: Material group of membrane disks (grains are group 0, walls group 1).
MEMBRANE_GROUP = 2
#: Stiffness of the ties between second neighbours of a chain, as a fraction of the
#: bond stiffness: they only keep those pairs out of the contact law (a force of
#: 1e-6 of the membrane's at equal stretch, nothing the run can feel).
SLACK_TIE = 1.0e-6
#: Neighbouring membrane disks farther apart than this many disk diameters leave a
#: hole that grains pass through: the membrane has burst or folded through itself,
#: and the run stops with an error (at rest they are half a diameter apart).
MAX_NEIGHBOUR_DISTANCE_DIAMETERS = 2.0

#: How a saved boundary's field is read back, by its annotation.
_READ: dict[str, Callable[[Any], Any]] = {
    "int": int, "float": float, "bool": bool, "list[int]": lambda v: [int(k) for k in v],
    "tuple[int, int]": lambda v: (int(v[0]), int(v[1])),
}


@dataclass(frozen=True)
class _Saved:
    """A boundary as checkpoints store it: its fields, and its ``kind`` where it has one."""

    def to_dict(self) -> dict[str, Any]:
        kind = getattr(self, "kind", None)
        return asdict(self) | ({} if kind is None else {"kind": kind})

    @classmethod
    def from_dict(cls, saved: Mapping[str, Any]) -> Self:
        """The boundary :meth:`to_dict` gave."""
        return cls(**{f.name: _READ[str(f.type)](saved[f.name]) for f in fields(cls)})


@dataclass(frozen=True)
class Membrane(_Saved):
    """The two membrane chains of a biaxial sample."""

    left: list[int]
    """Particle indices of the left chain, bottom to top."""
    right: list[int]
    """Particle indices of the right chain, top to bottom."""
    radius: float
    """Membrane disk radius, m."""
    chains: tuple[int, int]
    """Engine pressure-chain ids of the left and right chains."""
    bottom_wall: int
    top_wall: int

    @property
    def particles(self) -> NDArray[np.int64]:
        return np.array(self.left + self.right, dtype=np.int64)

    @property
    def ends(self) -> list[int]:
        """The four end disks tied to the platens."""
        return [self.left[0], self.left[-1], self.right[0], self.right[-1]]


def _column(x: float, y0: float, y1: float, radius: float, spacing: float) -> NDArray[np.float64]:
    """Centres from ``y0 + r`` to ``y1 - r`` at most ``spacing`` apart."""
    span = (y1 - radius) - (y0 + radius)
    count = max(int(np.ceil(span / spacing)) + 1, 2)
    y = np.linspace(y0 + radius, y1 - radius, count)
    return np.column_stack([np.full(count, x), y])


def install_membrane(
    sim: Simulation,
    *,
    left_x: float,
    right_x: float,
    bottom: Wall,
    top: Wall,
    diameter: float,
    overlap: float,
    bond_stiffness: float,
    friction: float,
    grain_model: ContactModel,
    density: float,
    pressure: float,
) -> Membrane:
    """Adds the two membrane chains outside the faces ``x = left_x`` and
    ``x = right_x`` between the platens, bonds them, ties their ends to the
    platens (prescribed vertical velocity, currently zero) and loads them with
    the follower ``pressure``. The side walls must already be inactive."""
    r = 0.5 * diameter
    y0 = float(bottom.points[0, 1])
    y1 = float(top.points[0, 1])
    spacing = diameter * (1.0 - overlap)
    left = _column(left_x - r, y0, y1, r, spacing)
    right = _column(right_x + r, y0, y1, r, spacing)[::-1]
    first = sim.n_particles
    new = sim.add_particles(np.vstack([left, right]), np.full(len(left) + len(right), r), density)
    left_ids = [int(k) for k in new[: len(left)]]
    right_ids = [int(k) for k in new[len(left) :]]
    groups = sim.groups.copy()
    groups[first:] = MEMBRANE_GROUP
    sim.groups = groups
    for chain in (left_ids, right_ids):
        for a, b in zip(chain[:-1], chain[1:], strict=True):
            sim.add_bond(a, b, bond_stiffness, bond_stiffness)
        # second neighbours touch at rest (2 x spacing = diameter at the default
        # overlap of one half): a slack tie keeps them out of the contact law, so
        # that they do not resist the chain's wrinkles
        for a, b in zip(chain[:-2], chain[2:], strict=True):
            sim.add_bond(a, b, SLACK_TIE * bond_stiffness, SLACK_TIE * bond_stiffness)
    membrane_grain = ContactModel(
        grain_model.normal_stiffness, grain_model.shear_stiffness, friction
    )
    sim.set_contact_model(0, MEMBRANE_GROUP, membrane_grain)
    sim.set_contact_model(1, MEMBRANE_GROUP, ContactModel(grain_model.normal_stiffness, grain_model.shear_stiffness, 0.0))
    # The chain holds together by its bonds and wrinkles as the sample shortens, as
    # a latex membrane does; its disks from third neighbours on touch one another
    # (frictionless, at the grains' normal stiffness), so that a fold cannot pass
    # through the chain. A chain that crossed itself would enclose a lobe whose
    # follower load points outward and inflates it without bound; at the (hundred
    # times softer) bond stiffness the confining pressure closes a fold to half a
    # radius and the overlap guard stops the run.
    sim.set_contact_model(
        MEMBRANE_GROUP,
        MEMBRANE_GROUP,
        ContactModel(grain_model.normal_stiffness, grain_model.shear_stiffness, 0.0),
    )
    fixity = sim.fixity.copy()
    ends = [left_ids[0], left_ids[-1], right_ids[0], right_ids[-1]]
    fixity[ends] |= FIX_Y
    sim.fixity = fixity
    left_chain = sim.add_pressure_chain(left_ids, pressure, start_wall=bottom, end_wall=top)
    right_chain = sim.add_pressure_chain(right_ids, pressure, start_wall=top, end_wall=bottom)
    return Membrane(left_ids, right_ids, r, (left_chain, right_chain), bottom.id, top.id)


def set_platen_velocity(sim: Simulation, membrane: Membrane, speed: float) -> None:
    """Platens approach each other at ``speed`` each (m/s); the membrane's end
    disks follow their platen vertically."""
    sim.wall(membrane.bottom_wall).velocity = (0.0, speed)
    sim.wall(membrane.top_wall).velocity = (0.0, -speed)
    v = sim.velocities.copy()
    v[[membrane.left[0], membrane.right[-1]], 1] = speed
    v[[membrane.left[-1], membrane.right[0]], 1] = -speed
    sim.velocities = v


def _clockwise(sim: Simulation, boundary: Membrane | GrainBoundary, left: NDArray[np.float64],
               right: NDArray[np.float64]) -> NDArray[np.float64]:
    """The clockwise polygon of the points ``left`` (bottom to top) and ``right`` (top to
    bottom), each side's ends anchored on the platens below and above them."""
    y_bottom = float(sim.wall(boundary.bottom_wall).points[0, 1])
    y_top = float(sim.wall(boundary.top_wall).points[0, 1])
    return np.vstack([[[left[0, 0], y_bottom]], left, [[left[-1, 0], y_top]],
                      [[right[0, 0], y_top]], right, [[right[-1, 0], y_bottom]]])


def boundary_polygon(sim: Simulation, membrane: Membrane) -> NDArray[np.float64]:
    """The clockwise polygon around the sample: left chain (bottom to top), its
    anchors on the platens, right chain (top to bottom), its anchors."""
    return _clockwise(sim, membrane, sim.positions[membrane.left], sim.positions[membrane.right])


def shoelace_area(polygon: NDArray[np.float64]) -> float:
    """Area of a simple polygon (either orientation)."""
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def membrane_breach(sim: Simulation, membrane: Membrane) -> str | None:
    """``None`` while the membrane is a closed skin; else what broke it: the chain,
    the disk and the distance to its neighbour, when two neighbours are farther
    apart than :data:`MAX_NEIGHBOUR_DISTANCE_DIAMETERS` diameters."""
    x = sim.positions
    limit = MAX_NEIGHBOUR_DISTANCE_DIAMETERS * 2.0 * membrane.radius
    for side, chain in (("left", membrane.left), ("right", membrane.right)):
        gaps = np.linalg.norm(np.diff(x[chain], axis=0), axis=1)
        k = int(np.argmax(gaps))
        if gaps[k] > limit:
            return (
                f"the {side} membrane chain opened between disks {chain[k]} and {chain[k + 1]} "
                f"({gaps[k] * 1e3:.2f} mm apart, limit {limit * 1e3:.2f} mm)"
            )
    return None


def sample_area(sim: Simulation, membrane: Membrane) -> float:
    """Area enclosed by the membrane's inner surface: the polygon through the
    chains' centres, less the membrane radius times the chains' length."""
    polygon = boundary_polygon(sim, membrane)
    x = sim.positions
    length = sum(
        float(np.sum(np.linalg.norm(np.diff(x[chain], axis=0), axis=1))) for chain in (membrane.left, membrane.right)
    )
    return shoelace_area(polygon) - membrane.radius * length


# ---- variant B: the sample's own outermost grains -----------------------------


def outer_grains(
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
    grains: NDArray[np.int64],
    y0: float,
    y1: float,
    side: str,
    bin_height: float,
) -> list[int]:
    """The outermost grain of each horizontal slice ``bin_height`` high between
    ``y0`` and ``y1``: smallest ``x - r`` on the ``"left"``, largest ``x + r`` on
    the ``"right"``. Ordered clockwise around the sample (left: bottom to top,
    right: top to bottom), each grain once."""
    x = positions[grains]
    r = radii[grains]
    n_bins = max(int(np.ceil((y1 - y0) / bin_height)), 1)
    bins = np.clip(((x[:, 1] - y0) / (y1 - y0) * n_bins).astype(np.int64), 0, n_bins - 1)
    edge = x[:, 0] - r if side == "left" else -(x[:, 0] + r)
    order = np.lexsort((edge, bins))  # by bin, then most outward first
    first = np.ones(len(order), dtype=bool)
    first[1:] = bins[order][1:] != bins[order][:-1]
    chosen = grains[order[first]]  # one per occupied bin, bottom to top
    if side == "right":
        chosen = chosen[::-1]
    _, keep = np.unique(chosen, return_index=True)
    return [int(g) for g in chosen[np.sort(keep)]]


#: Two grains whose surfaces are closer than this many mean grain diameters are
#: neighbours along the boundary of variant B (a contact that opens for a moment
#: does not break the chain).
CONTOUR_GAP_DIAMETERS = 0.1


def _neighbour_lists(
    positions: NDArray[np.float64], radii: NDArray[np.float64], gap: float
) -> list[NDArray[np.int64]]:
    """For each disk, the disks whose surfaces are within ``gap`` of its own."""
    tree = cKDTree(positions)
    pairs = tree.query_pairs(2.0 * float(radii.max()) + gap, output_type="ndarray")
    if len(pairs):
        i, j = pairs[:, 0], pairs[:, 1]
        distance = np.linalg.norm(positions[i] - positions[j], axis=1)
        pairs = pairs[distance - radii[i] - radii[j] < gap]
    both = np.concatenate([pairs, pairs[:, ::-1]]) if len(pairs) else np.empty((0, 2), np.int64)
    order = np.argsort(both[:, 0], kind="stable")
    starts = np.searchsorted(both[order, 0], np.arange(len(positions) + 1))
    partners = both[order, 1]
    return [partners[starts[k] : starts[k + 1]] for k in range(len(positions))]


def outer_contour(
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
    grains: NDArray[np.int64],
    y0: float,
    y1: float,
    side: str,
    gap: float,
) -> list[int]:
    """The grains along one side of the sample's outer contour, each touching the
    next (surfaces within ``gap``): the paper's "particles at the edges of the
    sample which formed continuous boundaries". The walk: docs/boundary.md, "B: the
    outermost grains"; the sample lies on its right, as the engine's pressure
    chains expect. Raises ``ValueError`` when the contact network has no such path."""
    x = positions[grains]
    r = radii[grains]
    neighbours = _neighbour_lists(x, r, gap)
    connected = np.array([len(n) > 0 for n in neighbours])
    if side == "left":
        near_start, near_end, outward, back = x[:, 1] - r < y0 + gap, x[:, 1] + r > y1 - gap, -(x[:, 0] - r), (0.0, -1.0)
    elif side == "right":
        near_start, near_end, outward, back = x[:, 1] + r > y1 - gap, x[:, 1] - r < y0 + gap, x[:, 0] + r, (0.0, 1.0)
    else:
        raise ValueError(f"side: expected 'left' or 'right', got {side!r}")
    candidates = np.flatnonzero(near_start & connected)
    if len(candidates) == 0:
        raise ValueError(f"{side} contour: no grain touches the platen it starts from")
    current = int(candidates[np.argmax(outward[candidates])])
    heading_back = float(np.arctan2(back[1], back[0]))
    chain = [current]
    place = {current: 0}
    for _ in range(4 * len(grains)):
        if near_end[current]:
            return [int(grains[k]) for k in chain]
        partners = neighbours[current]
        d = x[partners] - x[current]
        turn = np.mod(heading_back - np.arctan2(d[:, 1], d[:, 0]), 2.0 * np.pi)
        turn[turn < 1e-12] = 2.0 * np.pi  # straight back only from a dead end
        pick = int(np.argmin(turn))
        following = int(partners[pick])
        heading_back = float(np.arctan2(-d[pick, 1], -d[pick, 0]))
        if following in place:
            for k in chain[place[following] + 1 :]:
                del place[k]
            del chain[place[following] + 1 :]
        else:
            place[following] = len(chain)
            chain.append(following)
        current = following
    raise ValueError(f"{side} contour: the walk did not reach the other platen")


@dataclass(frozen=True)
class GrainBoundary(_Saved):
    """Variant B: the confining pressure acts on the grains of the sample's outer
    contour, each touching the next, re-identified as the boundary changes (Kuhn
    1995; Cheung & O'Sullivan 2008)."""

    chains: tuple[int, int]
    bottom_wall: int
    top_wall: int
    n_grains: int
    bin_height: float
    """The mean grain diameter, m: the scale of the contour's contact gap."""
    pressure: float
    left: list[int]
    right: list[int]

    kind = "outer_particles"

    def identify(self, sim: Simulation) -> GrainBoundary:
        """Re-identifies the grains of the outer contour on each side
        (:func:`outer_contour`) and moves the follower loads onto them. Where the
        contact network has no path from platen to platen on a side, that side
        keeps its previous chain (or, at the first identification, takes the
        outermost grain of each slice ``bin_height`` high, :func:`outer_grains`)."""
        grains = np.arange(self.n_grains)
        y0 = float(sim.wall(self.bottom_wall).points[0, 1])
        y1 = float(sim.wall(self.top_wall).points[0, 1])
        x, r = sim.positions, sim.radii
        gap = CONTOUR_GAP_DIAMETERS * self.bin_height
        chains = []
        for side, previous in (("left", self.left), ("right", self.right)):
            try:
                chains.append(outer_contour(x, r, grains, y0, y1, side, gap))
            except ValueError:
                chains.append(previous or outer_grains(x, r, grains, y0, y1, side, self.bin_height))
        left, right = chains
        sim.set_pressure_chain(self.chains[0], left, self.pressure, start_wall=self.bottom_wall, end_wall=self.top_wall)
        sim.set_pressure_chain(self.chains[1], right, self.pressure, start_wall=self.top_wall, end_wall=self.bottom_wall)
        return GrainBoundary(
            self.chains, self.bottom_wall, self.top_wall, self.n_grains, self.bin_height, self.pressure, left, right
        )

    def polygon(self, sim: Simulation) -> NDArray[np.float64]:
        """Clockwise polygon through the chains' outer edges and their anchors on the platens."""
        x, r = sim.positions, sim.radii
        left = x[self.left] - np.column_stack([r[self.left], np.zeros(len(self.left))])
        right = x[self.right] + np.column_stack([r[self.right], np.zeros(len(self.right))])
        return _clockwise(sim, self, left, right)

    def area(self, sim: Simulation) -> float:
        return shoelace_area(self.polygon(sim))


def install_grain_boundary(
    sim: Simulation, *, n_grains: int, bottom: Wall, top: Wall, pressure: float, bin_height: float
) -> GrainBoundary:
    """Variant B: pressure chains on the outermost grains of each side."""
    placeholder = [0]
    left = sim.add_pressure_chain(placeholder, pressure, start_wall=bottom, end_wall=top)
    right = sim.add_pressure_chain(placeholder, pressure, start_wall=top, end_wall=bottom)
    boundary = GrainBoundary((left, right), bottom.id, top.id, n_grains, bin_height, pressure, [], [])
    return boundary.identify(sim)


@dataclass(frozen=True)
class WallBoundary(_Saved):
    """Variant C: the consolidation box's rigid side walls stay as the lateral
    boundary. Drained, each is servo-controlled to the confining ``pressure``
    (:meth:`control`, between records); at constant volume they move apart or
    together so that the box's area stays the area at the start of shearing
    (the undrained test's constant-volume analogue, as PFC's walled biaxial tests
    do it), and the stress they feel is the effective lateral stress."""

    left_wall: int
    right_wall: int
    bottom_wall: int
    top_wall: int
    pressure: float
    constant_volume: bool

    kind = "walls"

    def size(self, sim: Simulation) -> tuple[float, float]:
        """The box's width and height now, m."""
        width = float(sim.wall(self.right_wall).points[0, 0] - sim.wall(self.left_wall).points[0, 0])
        height = float(sim.wall(self.top_wall).points[0, 1] - sim.wall(self.bottom_wall).points[0, 1])
        return width, height

    def area(self, sim: Simulation) -> float:
        width, height = self.size(sim)
        return width * height

    def lateral_stress(self, sim: Simulation) -> float:
        """The mean normal stress on the side walls from the last step, Pa (compression positive)."""
        _, height = self.size(sim)
        return 0.5 * (sim.wall(self.left_wall).normal_stress(height) + sim.wall(self.right_wall).normal_stress(height))

    def control(self, sim: Simulation, steps: int, area0: float, max_speed_m_per_s: float) -> None:
        """Sets the side walls' motion for the next ``steps`` steps: at constant volume,
        the velocity that brings the box to ``area0`` at their end given the platens'
        velocities (each side wall half the width change); drained, the engine's servo
        to :attr:`pressure` (at most ``max_speed_m_per_s``)."""
        left, right = sim.wall(self.left_wall), sim.wall(self.right_wall)
        width, height = self.size(sim)
        if not self.constant_volume:
            for wall in (left, right):
                wall.servo(self.pressure, height, relaxation=0.5, max_speed_m_per_s=max_speed_m_per_s)
            return
        duration = steps * sim.time_step
        closing = float(sim.wall(self.bottom_wall).velocity[1] - sim.wall(self.top_wall).velocity[1])
        width_then = area0 / (height - closing * duration)
        speed = 0.5 * (width_then - width) / duration
        left.velocity = (-speed, 0.0)
        right.velocity = (speed, 0.0)
