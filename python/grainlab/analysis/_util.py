"""Small shared helpers for the analysis classes (not public API)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab import _kernels
from grainlab.analysis._compute import NotComputedError as NotComputedError  # re-exported
from grainlab.snapshot import BOUNDARY_COUNTING, TWO_PI, Snapshot, boundary_end_groups

#: The angles (rad) of each contact's end on i and on j, two (Nc,) arrays.
EndAngles = tuple[NDArray[np.float64], NDArray[np.float64]]


def contact_ends(
    snapshot: Snapshot,
    *,
    include_boundary: bool,
    boundary: str = "each",
    end_angles: EndAngles | None = None,
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]:
    """Owner particle and contact angle of every contact *end* on a sample particle:
    ``owner (K,)``, ``angle (K,)`` in [0, 2 pi) and the (Nc,) mask of the contacts used.

    A particle-particle contact gives two ends (theta on i, theta + pi on j), a
    wall contact one; ends on membrane particles are dropped, and with
    ``include_boundary=False`` the contacts with walls or membrane particles.
    ``boundary="body"`` merges a particle's ends on one boundary body into one at
    the normal-force-weighted mean direction (docs/fabric.md, "Boundary
    contacts"). Order: the ends on the ``i`` side of the used contacts, in list
    order, then those on the ``j`` side (:func:`contact_ends_in_list_order`: each
    contact's two ends together). ``end_angles`` ((Nc,), (Nc,)) gives the angle of
    each contact's end on i and on j instead (a rigid body's contacts seen from its
    centroid, docs/fabric.md, "Measures per body"); the j angles of wall contacts
    are not read.
    """
    owner, ends, keep, _ = _contact_ends(snapshot, include_boundary, boundary, end_angles)
    return owner, ends, keep


def contact_ends_in_list_order(
    snapshot: Snapshot,
    *,
    include_boundary: bool,
    boundary: str = "each",
    end_angles: EndAngles | None = None,
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]:
    """:func:`contact_ends` (the same ends, bit for bit) in the order of the contact
    list: contact ``c`` gives its end on ``i``, then on ``j``, before contact ``c + 1``'s
    (a merged boundary end sits at the particle's first contact with that body)."""
    owner, ends, keep, source = _contact_ends(snapshot, include_boundary, boundary, end_angles)
    order = np.argsort(source, kind="stable")  # a contact's i end before its j end
    return owner[order], ends[order], keep


def _contact_ends(
    snapshot: Snapshot, include_boundary: bool, boundary: str, end_angles: EndAngles | None = None
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.int64]]:
    """:func:`contact_ends`, with the (K,) index of the contact each end comes
    from (of a merged end, the smallest of its group)."""
    if boundary not in BOUNDARY_COUNTING:
        raise ValueError(f"boundary: must be 'body' or 'each', got {boundary!r}")
    ci = np.asarray(snapshot.contact_i)
    cj = np.asarray(snapshot.contact_j)
    if end_angles is None:
        angle = np.asarray(snapshot.contact_angles())
        angle_j = angle + np.pi
        angle_j[angle_j >= TWO_PI] -= TWO_PI
    else:
        angle, angle_j = (np.asarray(a, dtype=np.float64) for a in end_angles)
    if _kernels.compiled() and not has_boundary(snapshot):
        # no wall, no membrane: every contact gives two ends and nothing merges
        owner = np.concatenate([ci, cj])
        index = np.arange(ci.size, dtype=np.int64)
        source = np.concatenate([index, index])
        return owner, np.concatenate([angle, angle_j]), np.ones(ci.shape, bool), source
    keep = np.ones(ci.shape, bool) if include_boundary else ~snapshot.is_boundary_contact
    sample = snapshot.is_sample
    pp = keep & (cj >= 0)
    on_i = keep & sample[ci]
    on_j = pp & sample[np.where(cj >= 0, cj, 0)]
    owner = np.concatenate([ci[on_i], cj[on_j]])
    ends = np.concatenate([angle[on_i], angle_j[on_j]])
    index = np.arange(ci.size, dtype=np.int64)
    source = np.concatenate([index[on_i], index[on_j]])
    if boundary == "body" and include_boundary and owner.size:
        keys = snapshot.boundary_body_keys()
        key = np.concatenate([keys[on_i, 0], keys[on_j, 1]])
        groups = boundary_end_groups(owner, key)
        if np.any(groups != np.arange(owner.size)):
            force = snapshot.normal_force
            weight = (
                np.ones(owner.size)
                if force is None
                else np.maximum(np.concatenate([force[on_i], force[on_j]]), 0.0)
            )
            ends = _merged_angles(ends, groups, weight)
            earliest = np.full(owner.size, ci.size, dtype=np.int64)
            np.minimum.at(earliest, groups, source)
            first = groups == np.arange(owner.size)
            owner, ends, source = owner[first], ends[first], earliest[first]
    return owner, ends, keep, source


def has_boundary(snapshot: Snapshot) -> bool:
    """Whether ``snapshot`` has a wall contact or a membrane particle (else every
    particle is in the sample and no contact is a boundary contact)."""
    cj = np.asarray(snapshot.contact_j)
    return bool(cj.size and cj.min() < 0) or bool(np.any(~snapshot.is_sample))


def repeated_boundary_contacts(snapshot: Snapshot, used: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """(Nc,) mask of the ``used`` contacts that are a sample particle's second or
    later contact with the same boundary body (a wall, one membrane chain)."""
    ci = np.asarray(snapshot.contact_i)
    cj = np.asarray(snapshot.contact_j)
    keys = snapshot.boundary_body_keys()
    sample = snapshot.is_sample
    on_i = sample[ci]
    owner = np.where(on_i, ci, np.where(cj >= 0, cj, 0))
    on_sample = on_i | ((cj >= 0) & sample[owner])
    key = np.where(used & on_sample, np.where(on_i, keys[:, 0], keys[:, 1]), -1)
    return np.asarray(boundary_end_groups(owner, key) != np.arange(ci.size), dtype=bool)


def _merged_angles(
    angles: NDArray[np.float64], groups: NDArray[np.int64], weight: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Each end's angle replaced by its group's weighted mean direction, in [0, 2 pi)
    (ends alone in their group keep their angle exactly)."""
    n = angles.size
    c, s = np.cos(angles), np.sin(angles)
    total = np.bincount(groups, weights=weight, minlength=n)
    w = np.where(total[groups] > 0.0, weight, 1.0)  # a group without force: unweighted
    mx = np.bincount(groups, weights=w * c, minlength=n)[groups]
    my = np.bincount(groups, weights=w * s, minlength=n)[groups]
    length = np.hypot(mx, my)
    ok = length > 1e-12 * np.bincount(groups, weights=w, minlength=n)[groups]
    merged = np.mod(np.where(ok, np.arctan2(my, mx), angles[groups]), TWO_PI)
    merged[merged >= TWO_PI] = 0.0
    alone = np.bincount(groups, minlength=n)[groups] == 1
    return np.where(alone, angles, merged)


def finite_mean(values: NDArray[np.float64], mask: NDArray[np.bool_] | None = None) -> float:
    """Mean of the finite entries (under ``mask``); NaN when there are none."""
    v = np.asarray(values, dtype=np.float64)
    ok = np.isfinite(v)
    if mask is not None:
        ok &= mask
    return float(v[ok].mean()) if ok.any() else float("nan")


def sample_bounds(snapshot: Snapshot) -> NDArray[np.float64]:
    """(2, 2) ``[[xlo, xhi], [ylo, yhi]]`` of the region a snapshot's measures
    refer to, m: the snapshot's box when it has one, else the rectangle
    bounding every disk (``min(x - r) .. max(x + r)``, all particles)."""
    if snapshot.box is not None:
        return np.array(snapshot.box, dtype=np.float64)
    x = np.asarray(snapshot.positions)
    r = np.asarray(snapshot.radii)[:, None]
    if x.shape[0] == 0:
        raise ValueError("positions: a snapshot without particles has no region")
    return np.column_stack([(x - r).min(axis=0), (x + r).max(axis=0)])


def grain_contacts(snapshot: Snapshot, include_boundary: bool = False) -> NDArray[np.bool_]:
    """(Nc,) mask of the contacts a network measure uses: contacts between two
    sample grains (no wall, no membrane particle) by default; with
    ``include_boundary`` also the sample grains' contacts with walls and
    membrane particles (a contact between two membrane particles never)."""
    ci = np.asarray(snapshot.contact_i)
    cj = np.asarray(snapshot.contact_j)
    if not include_boundary:
        return np.asarray(~snapshot.is_boundary_contact, dtype=bool)
    sample = snapshot.is_sample
    return np.asarray(sample[ci] | ((cj >= 0) & sample[np.where(cj >= 0, cj, 0)]), dtype=bool)


def principal_stresses(
    stress: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Major and minor principal values and the major direction of symmetric
    (..., 2, 2) tensors: ``s1 = p + R``, ``s2 = p - R`` with ``p = (sxx + syy)/2``,
    ``R = sqrt(((sxx - syy)/2)^2 + sxy^2)``, direction
    ``0.5 atan2(2 sxy, sxx - syy)`` in [0, pi) rad (0 for an isotropic tensor)."""
    s = np.asarray(stress, dtype=np.float64)
    sxx, syy, sxy = s[..., 0, 0], s[..., 1, 1], 0.5 * (s[..., 0, 1] + s[..., 1, 0])
    p = 0.5 * (sxx + syy)
    radius = np.hypot(0.5 * (sxx - syy), sxy)
    return p + radius, p - radius, axial_direction(np.arctan2(2.0 * sxy, sxx - syy))


def axial_direction(doubled: Any) -> Any:
    """The direction in [0, pi) rad of an axis whose doubled angle is ``doubled``
    (rad, any range); within 1e-12 rad of pi it is 0 (round-off of a doubled
    angle near 2 pi, such as a horizontal axis, would otherwise give pi)."""
    theta = np.mod(0.5 * np.asarray(doubled, dtype=np.float64), np.pi)
    return np.where(theta > np.pi - 1e-12, 0.0, theta)


def json_number(x: float | None) -> float | None:
    """``x`` as a JSON number: None for None, NaN and inf."""
    return None if x is None or not math.isfinite(x) else float(x)


def random_subset(
    p: NDArray[np.float64], v: NDArray[np.float64], k: int, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """At most ``k`` rows of ``p`` and ``v`` (a random subset when there are more)."""
    if p.shape[0] <= k:
        return p, v
    pick = rng.choice(p.shape[0], size=k, replace=False)
    return p[pick], v[pick]
