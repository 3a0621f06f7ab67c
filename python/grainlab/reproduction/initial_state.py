r"""The state a biaxial run starts shearing from, set against the paper's (Sec. 6).

Z (all grains, mechanical, in measurement circles), the anisotropies against the
noise floor of an isotropic sample (:func:`isotropic_noise_floor`), the porosity
and the mean lambda; ``python -m grainlab.reproduction.initial_state RUNS`` (or
``--explore``) prints the table: docs/reproduction.md, "The initial state".
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from grainlab import _kernels
from grainlab.analysis import (
    ContactAnisotropy,
    CoordinationNumber,
    StabilityIndex,
    anisotropy_fourier,
)
from grainlab.analysis._util import finite_mean
from grainlab.columns import AXIAL_STRAIN
from grainlab.io.hdf5 import read_results
from grainlab.reproduction.verdicts import t_interval
from grainlab.samples import measurement_circle_porosity
from grainlab.snapshot import Snapshot

__all__ = [
    "CIRCLE_HEIGHTS",
    "CIRCLE_RADIUS_FRACTION",
    "EXPLORE_FILE",
    "EXPLORE_SETTINGS",
    "PAPER_A",
    "PAPER_A_N",
    "PAPER_Z",
    "InitialState",
    "NoiseFloor",
    "explore",
    "gap_for_coordination_number",
    "initial_state",
    "isotropic_noise_floor",
    "main",
    "prepared_state",
    "snapshot_initial_state",
]

#: The paper's isotropic state (Sec. 6): Z about 3.9 (Fig. 10), a and a_n (Figs. 6-7).
PAPER_Z = 3.9
PAPER_A = 0.0034
PAPER_A_N = 0.009

#: Heights of the measurement circles' centres on the sample's vertical axis, as
#: fractions of its height (three circles, as in PFC2D's biaxial examples).
CIRCLE_HEIGHTS = (0.25, 0.5, 0.75)
#: Radius of the measurement circles as a fraction of the sample width (of half its
#: height if that is smaller, so that the lowest and highest circles stay inside a
#: squatter sample): 0.4 x 75 mm = 30 mm, which keeps each circle 7.5 mm (2.5 d_max)
#: inside the 75 x 150 mm sample, away from the membrane and the platens. An
#: assumption: Table 1 and Sec. 6 say nothing of the circles.
CIRCLE_RADIUS_FRACTION = 0.4

#: Where ``--explore`` stores its results (the repository's stored results).
EXPLORE_FILE = Path(__file__).resolve().parent / "paper_scale" / "initial_state.json"

#: Side (m) of the square box of Table 1's area, 75 x 150 mm (the diagnostic setting).
SQUARE_SIDE_M = round(math.sqrt(0.075 * 0.150), 6)

#: Preparation settings Table 1 leaves open, each ``(name, overrides, why)``.
#: Table 1 fixes the grading, the porosity 0.12 of the expansion, kn, ks, the
#: shearing friction 0.9, density, damping and the 100 kPa.
EXPLORE_SETTINGS: tuple[tuple[str, dict[str, Any], str], ...] = (
    ("defaults", {}, "grainlab's choices: frictionless generation and consolidation"),
    ("generation_friction=0.1", {"sample.generation_friction": 0.1},
     "Table 1 gives no friction for the radius expansion; a little friction is a common PFC choice"),
    ("generation_friction=0.3", {"sample.generation_friction": 0.3},
     "as above: friction resists the expansion's rearrangements, which may leave a more even fabric"),
    ("generation_friction=0.5", {"sample.generation_friction": 0.5},
     "as above, near the most friction with which the expansion still reaches 0.12"),
    ("consolidation.friction=0.3", {"consolidation.friction": 0.3},
     "friction while the stress comes down from the expansion's (about 1.4 MPa) to 100 kPa: "
     "locked contacts may keep the expansion's higher Z"),
    ("consolidation.friction=0.9", {"consolidation.friction": 0.9},
     "as above with Table 1's friction, the paper naming no other"),
    ("friction=0.9 throughout", {"sample.generation_friction": 0.9, "consolidation.friction": 0.9},
     "Table 1's friction from the start, generation included"),
    ("unbalanced_force_ratio=1e-4", {"consolidation.unbalanced_force_ratio": 1.0e-4},
     "a stricter equilibrium ('additional cycles ... to static equilibrium', Sec. 6): "
     "the last rattlers settle, which may add contacts"),
    ("tolerance=0.1%", {"consolidation.tolerance": 0.001},
     "the wall stresses held closer to 100 kPa (Table 1 gives no tolerance): an overshoot "
     "below 100 kPa would open contacts"),
    ("diagnostic: square box", {"sample.width": SQUARE_SIDE_M, "sample.height": SQUARE_SIDE_M},
     "outside Table 1, a diagnostic, not a candidate: the 75 x 150 mm box's area as a square, "
     "to tell whether the vertical a0 comes from the grain layers along the walls (the long "
     "sides twice the platens' length); in a square box their bias cancels"),
)
# Not tried, with reasons: sample.max_generation_stress bounds the expansion's
# stress (5 MPa) but the expansion reaches porosity 0.12 at 1.44 MPa, so it does
# not bind (a lower bound would stop the expansion short of Table 1's 0.12);
# run.time_step_safety changes the integration, not the packing; boundary.* acts
# after the consolidation, which is what a preparation measures; the other keys
# are Table 1's.


# --------------------------------------------------------------------------- noise floor
@dataclass(frozen=True)
class NoiseFloor:
    r"""The distribution of the anisotropy estimate for N isotropic contact normals.

    ``a / scale`` is Rayleigh distributed with :math:`\sigma^2 = 2 / N`
    (docs/reproduction.md); ``scale`` is 1 for the exact estimate and
    :math:`\sin\Delta\theta / \Delta\theta` for Eq. 7 on bins of width
    :math:`\Delta\theta`.
    """

    #: N, the number of contacts (or the effective number of a force-weighted estimate).
    n_contacts: float
    #: The factor the binning applies (1 for the exact estimate).
    scale: float = 1.0

    @property
    def mean(self) -> float:
        """E[a] = scale sqrt(pi / N)."""
        return self.scale * math.sqrt(math.pi / self.n_contacts)

    @property
    def median(self) -> float:
        """median(a) = scale 2 sqrt(ln 2 / N)."""
        return self.scale * 2.0 * math.sqrt(math.log(2.0) / self.n_contacts)

    def probability_at_most(self, a: float) -> float:
        """P(a_estimate <= a) = 1 - exp(-N (a / scale)^2 / 4) (0 for a < 0)."""
        if a < 0:
            return 0.0
        x = a / self.scale
        return float(-math.expm1(-self.n_contacts * x * x / 4.0))

    def quantile(self, q: float) -> float:
        """The a below which a share ``q`` (in [0, 1)) of isotropic samples fall."""
        if not 0.0 <= q < 1.0:
            raise ValueError(f"q: must be in [0, 1), got {q!r}")
        return self.scale * 2.0 * math.sqrt(-math.log1p(-q) / self.n_contacts)


def isotropic_noise_floor(n_contacts: float, *, bins: int | None = None) -> NoiseFloor:
    """The noise floor of grainlab's anisotropy estimate for ``n_contacts`` isotropic normals.

    ``bins=None`` is the exact (headline) estimate ``anisotropy``; ``bins=18``
    the paper's Eq. 7 on 18 bins (``anisotropy_binned``). ``n_contacts`` may be
    an effective number (not an integer) for a force-weighted estimate.

    >>> floor = isotropic_noise_floor(6000)
    >>> round(floor.mean, 4), round(floor.median, 4), round(floor.probability_at_most(0.0034), 4)
    (0.0229, 0.0215, 0.0172)
    """
    n = float(n_contacts)
    if not (math.isfinite(n) and n >= 1.0):
        raise ValueError(f"n_contacts: must be a finite number >= 1, got {n_contacts!r}")
    if bins is None:
        return NoiseFloor(n)
    if int(bins) != bins or bins < 3:
        raise ValueError(f"bins: must be an integer >= 3, got {bins!r}")
    width = 2.0 * math.pi / int(bins)
    return NoiseFloor(n, math.sin(width) / width)


# --------------------------------------------------------------------------- the state
@dataclass(frozen=True)
class InitialState:
    """The measures of one starting state (see :func:`snapshot_initial_state`)."""

    #: Sample grains.
    n_grains: int
    #: Grain-grain contacts, N (those a, Z and the noise floor count).
    n_contacts: int
    #: Z = 2 N / n_grains over all grains (grain-grain contacts; the time series' column).
    coordination_number: float
    #: Z_m after iterative removal of grains with < 2 grain-grain contacts (the library's).
    mechanical_coordination_number: float
    #: Share of the grains removed as rattlers.
    rattler_share: float
    #: Z over the grains with at least one grain-grain contact, 2 N / (n_grains - N_0).
    coordination_number_contacting: float
    #: Z with the contacts with walls and membrane disks counted (each boundary body once
    #: per grain, CoordinationNumber(include_boundary=True)).
    coordination_number_with_boundary: float
    #: Shares of the grains with 0 and with 1 grain-grain contact.
    share_no_contact: float
    share_one_contact: float
    #: a, the exact estimate, and a by Eq. 7 on 18 bins.
    anisotropy: float
    anisotropy_binned: float
    #: theta_a of the exact estimate, degrees in [0, 180) (0: the major axis horizontal).
    anisotropy_direction_deg: float
    #: a, theta_a (degrees), the number of contacts and the noise floor's E[a] and
    #: P(a <= 0.0034) of the interior: the grain-grain contacts whose midpoints lie
    #: at least two largest grain diameters inside the grains' bounding box, away from
    #: the layers the walls and the membrane order (contacts along them).
    anisotropy_interior: float
    anisotropy_interior_direction_deg: float
    n_contacts_interior: int
    noise_mean_interior: float
    noise_p_paper_interior: float
    #: a_n, the exact estimate (NaN without forces).
    force_anisotropy: float
    #: The noise floor of a for N isotropic normals: E[a], and P(a <= the paper's 0.0034).
    noise_mean: float
    noise_p_paper: float
    #: Where this a lies in that distribution, P(a_iso <= a).
    noise_p_measured: float
    #: The same for a_n: the effective number of contacts, E[a_n], P(a_n <= 0.009).
    force_effective_contacts: float
    force_noise_mean: float
    force_noise_p_paper: float
    #: Nominal and overlap-corrected porosity in each measurement circle (bottom to top).
    circle_porosity: tuple[float, ...]
    circle_porosity_overlap_corrected: tuple[float, ...]
    #: Z over the grains whose centres lie in each circle (grain-grain contacts, rattlers in).
    circle_coordination_number: tuple[float, ...]
    #: The circles' radius (m) and the sample's width and height from the grains (m).
    circle_radius_m: float
    sample_width_m: float
    sample_height_m: float
    #: The whole sample's nominal porosity (NaN when no area is given).
    porosity: float
    #: Mean lambda over grains with >= 2 contacts (boundary contacts in, the library's
    #: mean_stability_index) and over the mechanically active grains (rattlers removed).
    mean_lambda: float
    mean_lambda_active: float
    #: Shares of the grains each of those means covers.
    share_lambda_grains: float
    share_active_grains: float
    #: The gap (m) below which pairs of grains must count as contacts for Z over all
    #: grains to reach the paper's 3.9 (0 when Z is 3.9 already; NaN when no pair
    #: within 2 d_max + 1e-4 m would do), and that gap over the mean grain diameter.
    gap_for_paper_z_m: float
    gap_for_paper_z_over_d: float

    @property
    def circle_porosity_mean(self) -> float:
        """Mean nominal porosity of the circles."""
        return float(np.mean(self.circle_porosity))

    @property
    def circle_porosity_overlap_corrected_mean(self) -> float:
        """Mean overlap-corrected porosity of the circles."""
        return float(np.mean(self.circle_porosity_overlap_corrected))

    @property
    def circle_coordination_number_mean(self) -> float:
        """Mean of the circles' Z."""
        return float(np.mean(self.circle_coordination_number))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready values, the circle means included."""
        out: dict[str, Any] = asdict(self)
        for key in ("circle_porosity", "circle_porosity_overlap_corrected", "circle_coordination_number"):
            out[key] = list(out[key])
            out[key + "_mean"] = getattr(self, key + "_mean")
        return out


def gap_for_coordination_number(
    positions: NDArray[np.float64], radii: NDArray[np.float64], target: float, *, reach: float = 1.0e-4
) -> float:
    """The smallest gap g (m) such that counting every pair with surface gap < g as a
    contact (overlapping pairs included) gives ``2 pairs / N >= target``; 0 when the
    overlapping pairs already do, NaN when the pairs within ``reach`` (m) do not."""
    from scipy.spatial import cKDTree

    n = len(radii)
    needed = math.ceil(target * n / 2.0 - 1e-9)
    if n < 2 or needed <= 0:
        return 0.0
    pairs = cKDTree(positions).query_pairs(2.0 * float(radii.max()) + reach, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    gap = np.hypot(*(positions[i] - positions[j]).T) - radii[i] - radii[j]
    gap = np.sort(gap[gap < reach])
    if gap.size < needed:
        return math.nan
    return float(max(gap[needed - 1], 0.0))


def _measures(
    snapshot: Snapshot,
) -> tuple[CoordinationNumber, float, ContactAnisotropy, StabilityIndex, ContactAnisotropy | None]:
    """Z (without and with the boundary), the contact normals' and (where there
    are forces) the normal forces' anisotropy, and lambda, on one thread."""
    with _kernels.kernel_threads(1):
        z = CoordinationNumber().compute(snapshot)
        z_boundary = CoordinationNumber(include_boundary=True).compute(snapshot).coordination_number
        normals = ContactAnisotropy().compute(snapshot)
        lam = StabilityIndex().compute(snapshot)
        forces = (
            ContactAnisotropy(weight="normal_force").compute(snapshot)
            if snapshot.normal_force is not None and float(np.sum(snapshot.normal_force)) > 0
            else None
        )
    return z, z_boundary, normals, lam, forces


def _interior(
    snapshot: Snapshot,
    grain_grain: NDArray[np.bool_],
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]],
    inset: float,
) -> NDArray[np.bool_]:
    """Which grain-grain contacts have their midpoint ``inset`` inside the bounding box."""
    lo, hi = bounds
    ci, cj = np.asarray(snapshot.contact_i), np.asarray(snapshot.contact_j)
    all_pos = np.asarray(snapshot.positions)
    mid = 0.5 * (all_pos[ci[grain_grain]] + all_pos[cj[grain_grain]])
    return np.asarray(np.all((mid > lo + inset) & (mid < hi - inset), axis=1), dtype=bool)


def _interior_anisotropy(
    snapshot: Snapshot, grain_grain: NDArray[np.bool_], interior: NDArray[np.bool_]
) -> tuple[float, float, Any]:
    """The anisotropy and direction of the interior grain-grain contacts' normals
    (on one thread) and the isotropic noise floor at their count."""
    angles = np.asarray(snapshot.contact_angles())[grain_grain][interior]
    with _kernels.kernel_threads(1):
        a_int, t_int = anisotropy_fourier(angles) if angles.size else (math.nan, math.nan)
    return float(a_int), float(t_int), isotropic_noise_floor(max(int(interior.sum()), 1))


def _force_noise(
    snapshot: Snapshot, forces: ContactAnisotropy | None, grain_grain: NDArray[np.bool_]
) -> tuple[float, float, float, float]:
    """The force anisotropy a_n, the force-weighted effective contact count and
    the noise floor's mean and probability of the paper's a_n at that count
    (NaN where there are no forces)."""
    a_n = n_eff = force_floor_mean = force_p = math.nan
    if forces is not None and snapshot.normal_force is not None:
        a_n = forces.anisotropy
        f = np.asarray(snapshot.normal_force)[grain_grain]
        if f.size and float(np.sum(f * f)) > 0:
            n_eff = float(np.sum(f) ** 2 / np.sum(f * f))
            force_floor = isotropic_noise_floor(max(n_eff, 1.0))
            force_floor_mean, force_p = force_floor.mean, force_floor.probability_at_most(PAPER_A_N)
    return a_n, n_eff, force_floor_mean, force_p


def _circles(
    pos: NDArray[np.float64],
    rad: NDArray[np.float64],
    grain_counts: NDArray[np.int64],
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]],
    radius: float,
) -> tuple[list[float], list[float], list[float]]:
    """Nominal and overlap-corrected porosity and mean contact count in the
    measurement circles of ``radius`` at :data:`CIRCLE_HEIGHTS` of the grains'
    bounding box ``bounds`` (lower and upper corners)."""
    lo, hi = bounds
    height = float(hi[1] - lo[1])
    nominal, corrected, circle_z = [], [], []
    for h in CIRCLE_HEIGHTS:
        centre = (0.5 * (lo[0] + hi[0]), lo[1] + h * height)
        nominal.append(measurement_circle_porosity(pos, rad, centre, radius))
        corrected.append(measurement_circle_porosity(pos, rad, centre, radius, overlap_corrected=True))
        inside = np.hypot(pos[:, 0] - centre[0], pos[:, 1] - centre[1]) < radius
        circle_z.append(float(grain_counts[inside].mean()) if inside.any() else math.nan)
    return nominal, corrected, circle_z


def snapshot_initial_state(
    snapshot: Snapshot,
    *,
    area: float | None = None,
    circle_radius_fraction: float = CIRCLE_RADIUS_FRACTION,
) -> InitialState:
    """The measures of ``snapshot`` (its sample grains; contacts with walls and
    membrane disks left out of Z, a and a_n, counted in lambda as the library does).

    ``area`` (m^2) is the sample's area for the whole-sample nominal porosity.
    The measurement circles sit on the vertical axis of the grains' bounding box
    at :data:`CIRCLE_HEIGHTS` of its height, of radius ``circle_radius_fraction``
    times its width (or half its height, if smaller). The analysis runs on one thread.
    """
    if not 0.0 < circle_radius_fraction <= 0.5:
        raise ValueError(f"circle_radius_fraction: must be in (0, 0.5], got {circle_radius_fraction!r}")
    z, z_boundary, normals, lam, forces = _measures(snapshot)
    sample = snapshot.is_sample
    n_grains = int(sample.sum())
    grain_grain = ~np.asarray(snapshot.is_boundary_contact)
    n_c = int(grain_grain.sum())
    counts = snapshot.contact_counts(include_boundary=False)
    floor = isotropic_noise_floor(max(n_c, 1))
    a_n, n_eff, force_floor_mean, force_p = _force_noise(snapshot, forces, grain_grain)
    pos = np.asarray(snapshot.positions)[sample]
    rad = np.asarray(snapshot.radii)[sample]
    lo, hi = (pos - rad[:, None]).min(axis=0), (pos + rad[:, None]).max(axis=0)
    width, height = float(hi[0] - lo[0]), float(hi[1] - lo[1])
    radius = circle_radius_fraction * min(width, 0.5 * height)
    grain_counts = counts[sample]
    nominal, corrected, circle_z = _circles(pos, rad, grain_counts, (lo, hi), radius)
    porosity = math.nan if area is None else float(1.0 - math.pi * float(np.sum(rad * rad)) / float(area))
    interior = _interior(snapshot, grain_grain, (lo, hi), 2.0 * float(2.0 * rad.max()))
    a_int, t_int, floor_int = _interior_anisotropy(snapshot, grain_grain, interior)
    rattler = np.asarray(z.rattlers)
    lam_grains = sample & (np.asarray(lam.n_contacts) >= 2)
    gap = gap_for_coordination_number(pos, rad, PAPER_Z)
    return InitialState(
        n_grains=n_grains,
        n_contacts=n_c,
        coordination_number=z.coordination_number,
        mechanical_coordination_number=z.mechanical_coordination_number,
        rattler_share=float(rattler[sample].mean()) if n_grains else math.nan,
        coordination_number_contacting=(
            float(2 * n_c / np.count_nonzero(grain_counts)) if np.any(grain_counts) else math.nan
        ),
        coordination_number_with_boundary=z_boundary,
        share_no_contact=float(np.mean(grain_counts == 0)) if n_grains else math.nan,
        share_one_contact=float(np.mean(grain_counts == 1)) if n_grains else math.nan,
        anisotropy=normals.anisotropy,
        anisotropy_binned=normals.anisotropy_binned,
        anisotropy_direction_deg=math.degrees(normals.direction),
        anisotropy_interior=float(a_int),
        anisotropy_interior_direction_deg=math.degrees(t_int),
        n_contacts_interior=int(interior.sum()),
        noise_mean_interior=floor_int.mean,
        noise_p_paper_interior=floor_int.probability_at_most(PAPER_A),
        force_anisotropy=float(a_n),
        noise_mean=floor.mean,
        noise_p_paper=floor.probability_at_most(PAPER_A),
        noise_p_measured=floor.probability_at_most(normals.anisotropy),
        force_effective_contacts=n_eff,
        force_noise_mean=force_floor_mean,
        force_noise_p_paper=force_p,
        circle_porosity=tuple(nominal),
        circle_porosity_overlap_corrected=tuple(corrected),
        circle_coordination_number=tuple(circle_z),
        circle_radius_m=radius,
        sample_width_m=width,
        sample_height_m=height,
        porosity=porosity,
        mean_lambda=lam.mean,
        mean_lambda_active=finite_mean(np.asarray(lam.stability_index), sample & ~rattler),
        share_lambda_grains=float(lam_grains.sum() / n_grains) if n_grains else math.nan,
        share_active_grains=float((sample & ~rattler).sum() / n_grains) if n_grains else math.nan,
        gap_for_paper_z_m=gap,
        gap_for_paper_z_over_d=gap / float(2.0 * rad.mean()) if rad.size else math.nan,
    )


def initial_state(run_dir: str | os.PathLike[str]) -> InitialState:
    """The measures of a finished run's first snapshot (0 % axial strain).

    The whole-sample porosity uses the run's sample area at its first record
    (``area_m2``, inside the membrane), as ``porosity_initial`` of its summary.
    """
    results = read_results(run_dir)
    if not results.snapshots:
        raise ValueError(f"{run_dir}: the run has no snapshot")
    first = min(results.snapshots, key=lambda s: abs(s.axial_strain or 0.0))
    snapshot = results.snapshot(first.name)
    area = None
    ts = results.timeseries
    if "area_m2" in ts and AXIAL_STRAIN in ts and len(ts["area_m2"]):
        area = float(ts["area_m2"][int(np.argmin(np.abs(ts[AXIAL_STRAIN])))])
    return snapshot_initial_state(snapshot, area=area)


def prepared_state(
    overrides: Mapping[str, Any] | None = None,
    seed: int = 1,
    *,
    threads: int = 1,
) -> tuple[InitialState, dict[str, float]]:
    """Generate and consolidate a biaxial sample only (as ``grainlab biaxial`` does,
    ``protocols/specimen.py``), and measure the consolidated state.

    ``overrides`` are configuration keys (``{"consolidation.friction": 0.9}``);
    ``seed`` sets ``sample.seed``. Returns the measures (whole-sample porosity in
    the consolidation box) and the preparation's own numbers: the generation's
    stress and porosities, the consolidation's steps, its porosities and
    unbalanced force ratio, and the wall time.
    """
    from grainlab.protocols.biaxial.config import resolve
    from grainlab.protocols.specimen import SpecimenRun, consolidate, generate

    values = dict(overrides or {})
    values["sample.seed"] = int(seed)
    values["run.threads"] = int(threads)
    config = resolve(overrides=values)
    start = time.perf_counter()
    with _kernels.kernel_threads(int(threads)):
        sim, run = generate(config, int(threads), False, SpecimenRun, "consolidate")
        consolidate(sim, run, config, progress=False)
    seconds = time.perf_counter() - start
    c = run.consolidation
    state = snapshot_initial_state(sim.snapshot(), area=float(c["width_m"] * c["height_m"]))
    extra = {
        "generation_stress_pa": float(run.sample.get("mean_wall_stress_pa", math.nan)),
        "porosity_generated": float(run.sample.get("porosity", math.nan)),
        "porosity_generated_overlap_corrected": float(run.sample.get("porosity_overlap_corrected", math.nan)),
        "coordination_number_generated": float(run.sample.get("coordination_number", math.nan)),
        "mechanical_coordination_number_generated": float(
            run.sample.get("mechanical_coordination_number", math.nan)
        ),
        "consolidation_steps": float(c["steps"]),
        "porosity_overlap_corrected": float(c["porosity_overlap_corrected"]),
        "unbalanced_force_ratio": float(c["unbalanced_force_ratio"]),
        "seconds": seconds,
    }
    return state, extra


# --------------------------------------------------------------------------- tables
#: Columns of the tables: (label, InitialState attribute or property, format).
COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("Z", "coordination_number", "{:.3f}"),
    ("Z_m", "mechanical_coordination_number", "{:.3f}"),
    ("rattl", "rattler_share", "{:.3f}"),
    ("n0", "share_no_contact", "{:.3f}"),
    ("Z_>=1", "coordination_number_contacting", "{:.3f}"),
    ("Z_bnd", "coordination_number_with_boundary", "{:.3f}"),
    ("Z_circ", "circle_coordination_number_mean", "{:.3f}"),
    ("a", "anisotropy", "{:.4f}"),
    ("th_a", "anisotropy_direction_deg", "{:.0f}"),
    ("a_int", "anisotropy_interior", "{:.4f}"),
    ("th_int", "anisotropy_interior_direction_deg", "{:.0f}"),
    ("E[a_int]", "noise_mean_interior", "{:.4f}"),
    ("a_n", "force_anisotropy", "{:.4f}"),
    ("N_c", "n_contacts", "{:.0f}"),
    ("E[a]", "noise_mean", "{:.4f}"),
    ("P<=.0034", "noise_p_paper", "{:.4f}"),
    ("P<=a", "noise_p_measured", "{:.3f}"),
    ("E[a_n]", "force_noise_mean", "{:.4f}"),
    ("n_circ", "circle_porosity_mean", "{:.4f}"),
    ("n_c_circ", "circle_porosity_overlap_corrected_mean", "{:.4f}"),
    ("n_whole", "porosity", "{:.4f}"),
    ("lam>=2", "mean_lambda", "{:.4f}"),
    ("lam_act", "mean_lambda_active", "{:.4f}"),
    ("gap/d", "gap_for_paper_z_over_d", "{:.4f}"),
)


def _value(row: Mapping[str, Any], key: str) -> float:
    v = row.get(key, math.nan)
    return float(v) if v is not None else math.nan


def mean_interval(values: Sequence[float], confidence: float = 0.95) -> tuple[float, float]:
    """(mean, half-width of the ``confidence`` t-interval); half-width NaN for one value."""
    x = np.asarray([v for v in values if math.isfinite(v)], dtype=np.float64)
    if x.size == 0:
        return math.nan, math.nan
    if x.size == 1:
        return float(x[0]), math.nan
    low, high = t_interval(x, confidence)
    return float(x.mean()), 0.5 * (high - low)


def format_table(rows: Sequence[tuple[str, Mapping[str, Any]]], *, interval: bool = True) -> str:
    """A text table: one line per ``(label, values)`` and the mean with its 95 % t-interval."""
    width = max([5, *(len(label) for label, _ in rows)])
    head = f"{'':{width}s} " + " ".join(f"{c[0]:>9s}" for c in COLUMNS)
    lines = [head]
    for label, row in rows:
        lines.append(f"{label:{width}s} " + " ".join(f"{c[2].format(_value(row, c[1])):>9s}" for c in COLUMNS))
    if interval and len(rows) > 1:
        means, halves = [], []
        for _, key, fmt in COLUMNS:
            m, h = mean_interval([_value(r, key) for _, r in rows])
            means.append(f"{fmt.format(m):>9s}")
            halves.append(f"{('+-' + fmt.format(h)) if math.isfinite(h) else '':>9s}")
        lines.append(f"{'mean':{width}s} " + " ".join(means))
        lines.append(f"{'95%':{width}s} " + " ".join(halves))
    return "\n".join(lines)


def noise_floor_check(rows: Sequence[Mapping[str, Any]]) -> str:
    """Whether the measured a follow the isotropic noise floor, for the whole sample and
    its interior: the mean of a / E[a] with its 95 % t-interval, the mean fabric vector
    ``(a cos 2 theta_a, a sin 2 theta_a)`` with its t-intervals (a systematic anisotropy,
    from the walls say, adds the same vector to every sample; noise averages out), and
    for the whole sample a Kolmogorov-Smirnov test of P(a_iso <= a), uniform on [0, 1]
    if the a follow the floor."""
    lines = []
    for label, a_key, t_key, e_key in (
        ("whole sample", "anisotropy", "anisotropy_direction_deg", "noise_mean"),
        ("interior", "anisotropy_interior", "anisotropy_interior_direction_deg", "noise_mean_interior"),
    ):
        a = np.array([_value(r, a_key) for r in rows])
        two = np.radians(2.0 * np.array([_value(r, t_key) for r in rows]))
        e = np.array([_value(r, e_key) for r in rows])
        ok = np.isfinite(a) & np.isfinite(two) & np.isfinite(e)
        if ok.sum() < 2:
            continue
        mean, half = mean_interval((a[ok] / e[ok]).tolist())
        mx, hx = mean_interval((a[ok] * np.cos(two[ok])).tolist())
        my, hy = mean_interval((a[ok] * np.sin(two[ok])).tolist())
        text = (f"{label} ({int(ok.sum())}): a / E[a] {mean:.3f} +- {half:.3f}; mean (a cos 2theta_a, "
                f"a sin 2theta_a) = ({mx:.4f} +- {hx:.4f}, {my:.4f} +- {hy:.4f})")
        if a_key == "anisotropy":
            p = [_value(r, "noise_p_measured") for r in rows]
            finite = [v for v in p if math.isfinite(v)]
            ks = stats.kstest(finite, "uniform")
            text += f"; KS of P(a_iso <= a) against uniform: D {ks.statistic:.3f}, p {ks.pvalue:.3f}"
        lines.append(text)
    return "\n".join(lines)


def run_folders(root: str | os.PathLike[str]) -> list[Path]:
    """The folders under ``root`` (or ``root`` itself) that hold a finished ``run.h5``."""
    base = Path(root)
    if (base / "run.h5").is_file():
        return [base]
    return sorted({p.parent for p in base.rglob("run.h5")}, key=_seed_order)


def _seed_order(path: Path) -> tuple[int, str]:
    for part in reversed(path.parts):
        if part.startswith("seed-") and part[5:].isdigit():
            return int(part[5:]), str(path)
    return sys.maxsize, str(path)


def _label(path: Path) -> str:
    for part in reversed(path.parts):
        if part.startswith("seed-"):
            return part
    return path.name


def _rounded(value: Any) -> Any:
    if isinstance(value, float):
        return float(f"{value:.6g}") if math.isfinite(value) else None
    if isinstance(value, list | tuple):
        return [_rounded(v) for v in value]
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    return value


# --------------------------------------------------------------------------- exploration
def _load(path: Path) -> dict[str, Any]:
    if path.is_file():
        data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
        return data
    return {
        "description": (
            "Consolidated states (generation by radius expansion to porosity 0.12, isotropic "
            "consolidation to 100 kPa) of the paper-scale sample under preparation settings Table 1 "
            "leaves open; grainlab.reproduction.initial_state --explore, one engine thread each."
        ),
        "results": [],
    }


def _save(path: Path, data: Mapping[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    os.replace(tmp, path)


def explore(
    path: str | os.PathLike[str] = EXPLORE_FILE,
    settings: Iterable[tuple[str, Mapping[str, Any], str]] = EXPLORE_SETTINGS,
    seeds: Sequence[int] = (1, 2, 3),
    *,
    prepare: Callable[..., tuple[InitialState, dict[str, float]]] = prepared_state,
    log: Callable[[str], None] = print,
) -> dict[str, Any]:
    """Prepare each setting with each seed (one thread) and append each result to
    ``path`` as it finishes; pairs already in the file are skipped. Returns the file's data."""
    out = Path(path)
    data = _load(out)
    done = {(r["setting"], r["seed"]) for r in data["results"]}
    for name, overrides, why in settings:
        for seed in seeds:
            if (name, int(seed)) in done:
                continue
            log(f"{name}, seed {seed}: preparing ...")
            try:
                state, extra = prepare(dict(overrides), int(seed), threads=1)
            except Exception as error:  # a failed preparation is a result too (e.g. no convergence)
                row: dict[str, Any] = {"setting": name, "overrides": dict(overrides), "why": why,
                                       "seed": int(seed), "error": f"{type(error).__name__}: {error}"}
                log(f"{name}, seed {seed}: failed: {row['error']}")
            else:
                row = {"setting": name, "overrides": dict(overrides), "why": why, "seed": int(seed),
                       **_rounded(state.to_dict()), **_rounded(extra)}
                log(f"{name}, seed {seed}: Z {state.coordination_number:.3f}, Z_m "
                    f"{state.mechanical_coordination_number:.3f}, a {state.anisotropy:.4f}, "
                    f"{extra['seconds']:.0f} s")
            data["results"].append(row)
            _save(out, data)
    return data


def exploration_table(data: Mapping[str, Any]) -> str:
    """Per setting: the mean of its seeds (and their number)."""
    names: dict[str, list[Mapping[str, Any]]] = {}
    for row in data["results"]:
        if "error" not in row:
            names.setdefault(row["setting"], []).append(row)
    rows = [(f"{name} (x{len(r)})", {c[1]: float(np.mean([_value(x, c[1]) for x in r])) for c in COLUMNS})
            for name, r in names.items()]
    return format_table(rows, interval=False)


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m grainlab.reproduction.initial_state RUNS [--explore]``."""
    parser = argparse.ArgumentParser(
        prog="python -m grainlab.reproduction.initial_state",
        description="The state biaxial runs start shearing from, against the paper's Z 3.9, a 0.0034.",
    )
    parser.add_argument("runs", nargs="?", help="folder holding finished runs (every run.h5 below it)")
    parser.add_argument("--explore", action="store_true",
                        help="prepare the settings Table 1 leaves open, seeds 1-3, one thread")
    parser.add_argument("--output", default=str(EXPLORE_FILE), help="the exploration's JSON file")
    parser.add_argument("--save", metavar="FILE", help="also write the runs' table (one row per run) as JSON")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--settings", nargs="+", metavar="NAME",
                        help="explore only these settings (names of EXPLORE_SETTINGS)")
    args = parser.parse_args(argv)
    if args.runs is None and not args.explore:
        parser.error("give a folder of runs, or --explore")
    if args.runs is not None:
        folders = run_folders(args.runs)
        if not folders:
            print(f"{args.runs}: no finished run (run.h5) found", file=sys.stderr)
            return 1
        rows = [(_label(f), initial_state(f).to_dict()) for f in folders]
        print(f"{len(rows)} finished runs under {args.runs}; the paper: Z {PAPER_Z}, a {PAPER_A}, "
              f"a_n {PAPER_A_N}")
        print(format_table(rows))
        print(noise_floor_check([r for _, r in rows]))
        if args.save:
            from grainlab.io.results import write_json_atomic

            write_json_atomic(args.save, {"description": "The state at 0 % axial strain of finished biaxial runs "
                                          "(python -m grainlab.reproduction.initial_state RUNS --save FILE).",
                                          "runs": [{"run": label, **row} for label, row in rows]})
    if args.explore:
        chosen = EXPLORE_SETTINGS
        if args.settings:
            known = {name for name, _, _ in EXPLORE_SETTINGS}
            unknown = sorted(set(args.settings) - known)
            if unknown:
                parser.error(f"--settings: unknown {unknown}; known: {sorted(known)}")
            chosen = tuple(x for x in EXPLORE_SETTINGS if x[0] in args.settings)
        data = explore(args.output, chosen, seeds=args.seeds, log=lambda s: print(s, flush=True))
        print(exploration_table(data))
        print(noise_floor_check([r for r in data["results"] if "error" not in r]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
