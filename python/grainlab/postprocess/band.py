"""The shear band of a biaxial run, found and accepted (or not) between two snapshots.

:func:`find_band`, :func:`find_field_band`, :func:`displacement_band` and
:func:`band_labels`: docs/analysis.md, "Figures of a biaxial run" and "Three
readings of the shear band".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from grainlab.analysis._util import finite_mean
from grainlab.analysis.band_acceptance import (
    CROSSING,
    candidate_reason,
    crossing_problems,
    permutation_p_value,
    significance_problems,
    slab_eta2,
)
from grainlab.analysis.band_readings import MIN_GRAINS, DisplacementBand
from grainlab.analysis.shear_band import ShearBand, Slab
from grainlab.analysis.stability import StabilityIndex
from grainlab.analysis.strain import LocalStrain, match_ids
from grainlab.snapshot import Snapshot

__all__ = [
    "LAMBDA_LIMIT",
    "READINGS",
    "BandNumbers",
    "BandSearch",
    "DisplacementZone",
    "band_labels",
    "displacement_band",
    "displacement_zone",
    "find_band",
    "find_field_band",
    "interior_grains",
    "lambda_indicator",
    "slab_members",
]

#: Band acceptance: minimum thickness (mean diameters), permutations (the crossing
#: fractions: :data:`~grainlab.analysis.band_acceptance.CROSSING`).
MIN_THICKNESS_D = 1.0
N_PERMUTATIONS = 19
#: Grains closer than this many mean diameters to the boundary are left out of the search.
EDGE_D = 1.0
#: Seed of the permutation test (fixed: the same run always gives the same p-value).
PERMUTATION_SEED = 20240611
#: Fig. 12's band is the zone of grains with lambda above this (:func:`lambda_indicator`).
LAMBDA_LIMIT = 0.5
#: The readings of :func:`band_labels`: local strain, displacement (Fig. 11), lambda (Fig. 12).
READINGS = ("strain", "displacement", "lambda")


@dataclass(frozen=True)
class BandNumbers:
    """The shear band between the initial snapshot and ``snapshot``."""

    #: Snapshot compared with ``reference``.
    snapshot: str
    reference: str
    axial_strain: float
    #: Whether the band passed the acceptance tests (docs/analysis.md).
    found: bool
    #: Why it was not accepted ("" when found); names the candidate's numbers.
    reason: str
    #: Band direction, degrees in [0, 180), CCW from +x (NaN when not found).
    angle_deg: float
    #: Inclination to the horizontal (the sigma_3 direction), degrees in [0, 90].
    inclination_deg: float
    thickness_m: float
    thickness_diameters: float
    #: (peak - background) / peak of the strain profile.
    contrast: float
    #: Grains whose centre lies inside the band.
    n_grains: int
    #: Mean lambda of grains with >= 2 contacts inside / outside the band.
    mean_lambda_inside: float
    mean_lambda_outside: float
    #: Permutation p-value of the band's eta² (1/20 is the smallest possible).
    p_value: float
    #: Band excess strain / largest excess elsewhere on its profile (ShearBand.prominence).
    prominence: float = math.nan
    #: The second (conjugate) band: accepted or not, and its numbers (NaN when
    #: there is no candidate); same conventions as the first band's fields.
    second_found: bool = False
    second_reason: str = ""
    second_angle_deg: float = math.nan
    second_inclination_deg: float = math.nan
    second_thickness_diameters: float = math.nan
    second_contrast: float = math.nan
    second_prominence: float = math.nan


@dataclass(frozen=True)
class BandSearch:
    """What :func:`find_band` (or :func:`find_field_band`) found: the numbers and the
    accepted bands' slabs."""

    numbers: BandNumbers
    #: The accepted band (None when not found).
    band: Slab | None
    #: (N,) displacement magnitude of every particle of the snapshot (m), NaN for membrane
    #: disks (all NaN for a field band: there is no reference state).
    displacement: NDArray[np.float64]
    #: The accepted second band (None when not found).
    second: Slab | None = None

    def labels(self, snapshot: Snapshot) -> NDArray[np.int32]:
        """(N,) per particle of ``snapshot`` (the one searched): 1 inside the accepted
        band, 2 inside the accepted second band and not the first, 0 elsewhere
        (membrane disks, and every particle when no band was accepted)."""
        labels = np.zeros(snapshot.n_particles, np.int32)
        grains = np.flatnonzero(snapshot.is_sample)
        pos = snapshot.positions[grains]
        if self.band is not None:
            labels[grains[self.band.members(pos)]] = 1
            if self.second is not None:
                second = grains[self.second.members(pos)]
                labels[second[labels[second] == 0]] = 2
        return labels


@dataclass(frozen=True)
class DisplacementZone:
    """Fig. 11's reading of the band (:func:`displacement_zone`): the best two-block
    split of the grains' displacements, accepted or not."""

    #: Whether the split passed :class:`~grainlab.analysis.DisplacementBand`'s tests.
    found: bool
    #: Why it was not accepted ("" when found).
    reason: str
    #: Share of the two-block fit's residual that the transition zone removes.
    residual_reduction: float
    #: The transition zone between the two blocks, accepted or not.
    zone: Slab
    #: (N,) per particle of the snapshot: 1 for the zone's grains, 0 elsewhere.
    members: NDArray[np.int32]

    @property
    def labels(self) -> NDArray[np.int32]:
        """(N,) :func:`band_labels`' reading: the zone's grains (1) when it was accepted, else 0."""
        return self.members if self.found else np.zeros_like(self.members)


def grains_only(snap: Snapshot) -> Snapshot:
    """The sample grains alone (no contacts): what the local strain is fitted on."""
    g = snap.is_sample
    return Snapshot(
        snap.positions[g],
        snap.radii[g],
        snap.ids[g],
        kind=snap.kind[g],
        box=snap.box,
        periodic=snap.periodic,
    )


def interior_grains(snap: Snapshot, d_mean: float) -> NDArray[np.bool_]:
    """(N_grains,) grains farther than :data:`EDGE_D` mean diameters from the boundary."""
    g = snap.is_sample
    pos = snap.positions[g]
    points = [snap.positions[~g]]
    wall = np.asarray(snap.contact_j) < 0
    if wall.any():
        if snap.contact_point is not None:
            points.append(np.asarray(snap.contact_point)[wall])
        else:
            owner = np.asarray(snap.contact_i)[wall]
            normals = np.asarray(snap.contact_normals())[wall]
            points.append(snap.positions[owner] + snap.radii[owner][:, None] * normals)
    boundary = np.vstack(points)
    if boundary.shape[0]:
        dist, _ = cKDTree(boundary).query(pos)
        return np.asarray(dist > EDGE_D * d_mean)
    inside = np.ones(pos.shape[0], bool)
    for axis in (0, 1):
        if not snap.periodic[axis] and pos.shape[0]:
            x = pos[:, axis]
            inside &= np.minimum(x - x.min(), x.max() - x) > EDGE_D * d_mean
    return inside


def find_band(
    reference: Snapshot,
    current: Snapshot,
    stability: StabilityIndex,
    *,
    name: str = "",
    reference_name: str = "",
    axial_strain: float = math.nan,
) -> BandSearch:
    """The shear band of ``current`` since ``reference``, accepted or not (module
    docstring); ``stability`` is ``current``'s computed :class:`StabilityIndex` (the
    means of lambda in and out of the band), ``name``, ``reference_name`` and
    ``axial_strain`` label the :class:`BandNumbers`. Twenty band fits (the band and
    its permutation test) on every call; a run's searches are stored in its
    ``run.h5`` (:mod:`grainlab.postprocess.products`)."""
    found = _search(reference, current, stability)
    numbers = replace(found.numbers, snapshot=name, reference=reference_name, axial_strain=axial_strain)
    return replace(found, numbers=numbers)


def _search(reference: Snapshot, current: Snapshot, stability: StabilityIndex) -> BandSearch:
    """:func:`find_band`'s search, its numbers unlabelled (no snapshot names, NaN strain)."""
    g = current.is_sample
    grains = grains_only(current)
    strain = LocalStrain().compute(grains_only(reference), grains)
    displacement = np.full(current.n_particles, np.nan)
    displacement[g] = strain.displacement_magnitude
    return _accepted_band(current, strain.excess_shear_strain, stability, displacement, _STRAIN_WORDS)


@dataclass(frozen=True)
class _Words:
    """How the reasons of :func:`_accepted_band` name the field searched."""

    #: "only 7 grains away from the boundary have {having}"
    having: str
    #: "against 19 random rearrangements of the {values}"
    values: str


_STRAIN_WORDS = _Words("a local strain", "strain values")
_FIELD_WORDS = _Words("a finite value of the field", "field values")


def _accepted_band(
    snap: Snapshot,
    field: NDArray[np.float64],
    stability: StabilityIndex,
    displacement: NDArray[np.float64],
    words: _Words,
) -> BandSearch:
    """The band of the per-grain ``field`` (N_grains,) of ``snap`` and its acceptance
    (docs/analysis.md): the one code path of the strain band (:func:`find_band`) and
    of the band in any field (:func:`find_field_band`), its numbers unlabelled."""
    g = snap.is_sample
    pos, rad = snap.positions[g], snap.radii[g]
    d_mean = float(np.mean(2.0 * rad)) if rad.size else math.nan
    interior = interior_grains(snap, d_mean)
    valid = interior & np.isfinite(field)
    if int(valid.sum()) < 10:
        return _missing(
            displacement,
            f"only {int(valid.sum())} grains away from the boundary have {words.having} "
            "(at least 10 are needed)",
        )
    band = ShearBand(min_thickness=MIN_THICKNESS_D).compute(pos, field, rad, mask=interior)
    p_value = _p_value(band, pos, field, rad, interior, valid)
    problems = _band_problems(band, pos, d_mean)
    problems += significance_problems(p_value, N_PERMUTATIONS, words.values)
    if problems:
        reason = candidate_reason(band.angle_degrees, band.thickness_diameters, problems)
        return _missing(displacement, reason, p_value=p_value, prominence=band.prominence)
    members = slab_members(band, pos)
    lam, use = stability.stability_index[g], stability.n_contacts[g] >= 2
    numbers: dict[str, Any] = {
        "angle_deg": band.angle_degrees,
        "inclination_deg": band.inclination_degrees,
        "thickness_m": band.thickness,
        "thickness_diameters": band.thickness_diameters,
        "contrast": band.contrast,
        "n_grains": int(members.sum()),
        "mean_lambda_inside": finite_mean(lam, use & members),
        "mean_lambda_outside": finite_mean(lam, use & ~members),
        "p_value": p_value,
        "prominence": band.prominence,
    }
    second = band.second
    accepted_second: Slab | None = None
    if second is not None:
        second_problems = _band_problems(second, pos, d_mean)
        numbers.update(_second_numbers(second, second_problems))
        accepted_second = None if second_problems else second.slab
    return BandSearch(
        BandNumbers("", "", math.nan, True, "", **numbers), band.slab, displacement, accepted_second
    )


def _missing(displacement: NDArray[np.float64], reason: str, **numbers: Any) -> BandSearch:
    """A search that accepted no band, and why (its numbers unlabelled, NaN unless given)."""
    values: dict[str, Any] = {
        "angle_deg": math.nan,
        "inclination_deg": math.nan,
        "thickness_m": math.nan,
        "thickness_diameters": math.nan,
        "contrast": math.nan,
        "n_grains": 0,
        "mean_lambda_inside": math.nan,
        "mean_lambda_outside": math.nan,
        "p_value": math.nan,
    }
    values.update(numbers)
    return BandSearch(BandNumbers("", "", math.nan, False, reason, **values), None, displacement)


def _p_value(
    band: ShearBand,
    pos: NDArray[np.float64],
    field: NDArray[np.float64],
    rad: NDArray[np.float64],
    interior: NDArray[np.bool_],
    valid: NDArray[np.bool_],
) -> float:
    """The band's significance: its eta² against the bands found in
    :data:`N_PERMUTATIONS` random rearrangements of the same values (fixed seed)."""
    width = band.bin_width * float(np.mean(2.0 * rad[interior]))
    eta = slab_eta2(pos[valid], field[valid], band.normal, width)
    rng = np.random.default_rng(PERMUTATION_SEED)
    shuffled = field.copy()
    null = np.empty(N_PERMUTATIONS)
    for k in range(N_PERMUTATIONS):
        shuffled[valid] = rng.permutation(field[valid])
        trial = ShearBand(second=False).compute(pos, shuffled, rad, mask=interior)
        null[k] = slab_eta2(pos[valid], shuffled[valid], trial.normal, width)
    return permutation_p_value(eta, null)


def _second_numbers(second: ShearBand, problems: list[str]) -> dict[str, Any]:
    """The ``second_*`` fields of :class:`BandNumbers` for the candidate ``second``."""
    return {
        "second_found": not problems,
        "second_reason": (
            candidate_reason(second.angle_degrees, second.thickness_diameters, problems)
            if problems
            else ""
        ),
        "second_angle_deg": second.angle_degrees,
        "second_inclination_deg": second.inclination_degrees,
        "second_thickness_diameters": second.thickness_diameters,
        "second_contrast": second.contrast,
        "second_prominence": second.prominence,
    }


def slab_members(band: ShearBand | Slab, pos: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Grains whose centre lies inside the band's slab (boundary grains included)."""
    return (band if isinstance(band, Slab) else band.slab).members(pos)


def _band_problems(band: ShearBand, pos: NDArray[np.float64], d_mean: float) -> list[str]:
    """Why a candidate band fails acceptance tests 1 and 2 (docs/analysis.md); [] if it passes."""
    problems = [band.reason] if not band.found else []
    tangent = np.array([np.cos(band.angle), np.sin(band.angle)])
    s = (pos - band.center) @ band.normal
    return problems + crossing_problems(pos, tangent, s, band.thickness, d_mean, d_mean, CROSSING)


def lambda_indicator(stability: StabilityIndex) -> NDArray[np.float64]:
    """(N,) 1.0 for the grains whose lambda exceeds :data:`LAMBDA_LIMIT` (0.5),
    0.0 for the others, NaN for membrane disks: the field of Fig. 12's band.

    0- and 1-contact grains have lambda = 1 (they cannot be stable) and count as
    above the limit, as the paper's maps colour them."""
    lam = np.asarray(stability.stability_index, dtype=np.float64)
    return np.where(np.isfinite(lam), (lam > LAMBDA_LIMIT).astype(np.float64), np.nan)


def find_field_band(
    snapshot: Snapshot,
    field: ArrayLike,
    stability: StabilityIndex | None = None,
    *,
    name: str = "",
    axial_strain: float = math.nan,
) -> BandSearch:
    """The band of a per-grain ``field`` of ``snapshot``, accepted as the strain band is.

    ``field`` is (N,) per particle (membrane disks' entries not read) or
    (N_grains,) per sample grain; NaN entries are left out. The search and its
    acceptance are :func:`find_band`'s, on ``field``; ``stability`` (computed with
    the defaults when None) gives the means of lambda in and out of the band.
    Without a reference state :attr:`BandSearch.displacement` is NaN and
    :attr:`BandNumbers.reference` empty. Fig. 12's band is that of
    :func:`lambda_indicator` (why the indicator: docs/analysis.md, "Three readings
    of the shear band").
    """
    g = snapshot.is_sample
    values = np.asarray(field, dtype=np.float64)
    n_grains = int(g.sum())
    if values.shape == (snapshot.n_particles,):
        values = values[g]
    elif values.shape != (n_grains,):
        raise ValueError(
            f"field: expected shape ({snapshot.n_particles},) (particles) or ({n_grains},) "
            f"(grains), got {values.shape}"
        )
    if stability is None:
        stability = StabilityIndex().compute(snapshot)
    found = _accepted_band(
        snapshot, values.copy(), stability, np.full(snapshot.n_particles, np.nan), _FIELD_WORDS
    )
    return replace(found, numbers=replace(found.numbers, snapshot=name, axial_strain=axial_strain))


def displacement_band(reference: Snapshot, current: Snapshot) -> DisplacementBand | None:
    """:class:`~grainlab.analysis.DisplacementBand` of ``current``'s grains since
    ``reference`` (Fig. 11's reading; grains only, matched by id, membrane disks
    left out), indexed like ``current``'s grains; None when fewer than
    :data:`~grainlab.analysis.band_readings.MIN_GRAINS` grains are matched."""
    ref, cur = grains_only(reference), grains_only(current)
    to_ref = match_ids(ref, cur)
    matched = to_ref >= 0
    if int(matched.sum()) < MIN_GRAINS:
        return None
    disp = np.full((cur.n_particles, 2), np.nan)
    disp[matched] = cur.minimum_image(cur.positions[matched] - ref.positions[to_ref[matched]])
    return DisplacementBand().compute(cur.positions, disp, cur.radii)


def displacement_zone(reference: Snapshot, current: Snapshot) -> DisplacementZone | None:
    """:func:`displacement_band` as a :class:`DisplacementZone` of ``current``'s particles
    (what the results file stores of it); None when it is None."""
    moved = displacement_band(reference, current)
    if moved is None:
        return None
    members = np.zeros(current.n_particles, np.int32)
    members[np.flatnonzero(current.is_sample)[np.asarray(moved.members)]] = 1
    return DisplacementZone(moved.found, moved.reason, float(moved.residual_reduction), moved.slab, members)


def band_labels(reference: Snapshot, current: Snapshot, reading: str = "strain") -> NDArray[np.int32]:
    """(N,) per particle of ``current``: 1 inside the accepted shear band, 2 inside
    its accepted conjugate band, 0 elsewhere (membrane disks, and every particle
    when no band passes the tests), the band read as ``reading`` (one of
    :data:`READINGS`) says: ``"strain"`` (:func:`find_band`), ``"displacement"``
    (:func:`displacement_band`, Fig. 11: label 1 only) or ``"lambda"``
    (:func:`find_field_band` on :func:`lambda_indicator`, Fig. 12). Found anew;
    a run's are stored in its ``run.h5`` (:class:`~grainlab.postprocess.products.RunProducts`).
    """
    if reading not in READINGS:
        raise ValueError(f"reading: must be one of {', '.join(map(repr, READINGS))}, got {reading!r}")
    if reading == "displacement":
        zone = displacement_zone(reference, current)
        return np.zeros(current.n_particles, np.int32) if zone is None else zone.labels
    stability = StabilityIndex().compute(current)
    if reading == "lambda":
        return find_field_band(current, lambda_indicator(stability), stability).labels(current)
    return find_band(reference, current, stability).labels(current)
