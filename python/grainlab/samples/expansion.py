"""Radius expansion: the paper's way of making a dense sample inside rigid walls
(Sec. 6): the disks placed at half their radii, grown by increments that slow as
the wall stress rises, then cycled to equilibrium. docs/samples.md, "Radius
expansion", gives the steps, the stopping rules and the density scaling.

Example
-------
>>> from grainlab.samples import expand_to_porosity, UniformByNumber
>>> s = expand_to_porosity((0.0, 0.0, 0.012, 0.012), 0.16, UniformByNumber(0.5e-3, 1.0e-3),
...                        seed=1, progress=False)
>>> abs(s.porosity - 0.16) < 1e-12
True
>>> s.coordination_number > 3
True
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab import paper
from grainlab.analysis.fabric import CoordinationNumber
from grainlab.analysis.per_body import BodyCoordination
from grainlab.samples._checks import in_range, positive_lengths
from grainlab.samples.grading import PAPER_GRADING, Grading
from grainlab.samples.placement import random_placement
from grainlab.samples.porosity import (
    check_box,
    nominal_porosity,
    overlap_corrected_porosity,
    particle_count,
)
from grainlab.shapes import ShapeTemplate
from grainlab.simulation import DEFAULT_TIME_STEP_SAFETY

__all__ = ["WALL_NAMES", "ExpansionError", "Sample", "expand_to_porosity"]

#: Order of the four walls in :attr:`Sample.wall_points` and in the returned simulation.
WALL_NAMES = ("bottom", "right", "top", "left")

#: Table 1 of the paper.
_KN = paper.NORMAL_STIFFNESS_N_PER_M
_DENSITY = paper.DENSITY_KG_PER_M3
_DAMPING = paper.LOCAL_DAMPING
#: Default stress bound of the expansion (mean wall stress in equilibrium), Pa.
MAX_STRESS_PA = 5.0e6


#: The fields of a :class:`Sample` that :meth:`Sample.to_dict` leaves out (arrays, the
#: simulation) or gives first (a clump sample's shape).
_NOT_SCALARS = ("positions", "radii", "wall_points", "shape", "shape_parameter", "grain", "simulation")


class ExpansionError(ValueError):
    """The target porosity could not be reached within the stress bound.

    Attributes give where the expansion stopped: ``porosity`` (nominal),
    ``porosity_overlap_corrected``, ``stress_pa`` (mean wall stress it needed,
    in equilibrium when ``equilibrium`` is true), ``target``, ``steps``
    (DEM steps run until then) and ``engine_stopped`` (true when the engine's
    overlap limit stopped it, not the stress bound).
    """

    def __init__(
        self,
        message: str,
        *,
        porosity: float,
        porosity_overlap_corrected: float,
        stress_pa: float,
        target: float,
        equilibrium: bool,
        steps: int = 0,
        engine_stopped: bool = False,
    ) -> None:
        super().__init__(message)
        self.porosity = porosity
        self.porosity_overlap_corrected = porosity_overlap_corrected
        self.stress_pa = stress_pa
        self.target = target
        self.equilibrium = equilibrium
        self.steps = steps
        self.engine_stopped = engine_stopped


@dataclass(frozen=True, eq=False)
class Sample:
    """A generated sample: where it really is, and how it got there.

    Positions and radii are in the order of the drawn diameters; particle ``k``
    here is particle ``k`` of :attr:`simulation`. Walls are, in order,
    :data:`WALL_NAMES` (ids 0..3 of the simulation), each a segment
    ``[[ax, ay], [bx, by]]`` with the particles on its left, reaching
    :data:`WALL_OVERHANG` of the box's shorter side beyond its corners.
    """

    positions: NDArray[np.float64]
    """(N, 2) centres, m."""
    radii: NDArray[np.float64]
    """(N,) radii, m."""
    box: tuple[float, float, float, float]
    """``(xmin, ymin, xmax, ymax)``, m: the walls' lines."""
    wall_points: NDArray[np.float64]
    """(4, 2, 2) wall end points (bottom, right, top, left), m."""
    porosity_target: float
    """The nominal porosity asked for."""
    porosity: float
    """Nominal porosity ``1 - sum(pi r^2) / A`` reached."""
    porosity_overlap_corrected: float
    """``1 - |union of disks| / A`` (see :func:`overlap_corrected_porosity`)."""
    wall_stresses_pa: NDArray[np.float64]
    """(4,) normal stress on each wall (compression positive), Pa."""
    mean_wall_stress_pa: float
    """Mean of :attr:`wall_stresses_pa`, Pa: the stress locked in by the expansion."""
    coordination_number: float
    """``2 Nc / N`` (particle-particle contacts, rattlers included); for clumps
    per grain, ``2 Nc / N_grains`` (CEGEO's Z_c: a pair of grains touching at two
    pebbles counts twice)."""
    mechanical_coordination_number: float
    """``Z_m``: ``2 Nc / N`` over the particles left once rattlers (fewer than 2
    contacts) are removed iteratively (:class:`grainlab.analysis.CoordinationNumber`);
    for clumps the contacts per grain over the grains left once rattler grains
    (fewer than 2 touching grains) are removed
    (:class:`grainlab.analysis.BodyCoordination`); NaN when none is left."""
    mean_overlap_ratio: float
    """Mean contact overlap over the smallest radius."""
    max_overlap_ratio: float
    """Largest contact overlap over the smaller radius of its pair."""
    unbalanced_force_ratio: float
    """Mean unbalanced force ratio at the end."""
    equilibrium_reached: bool
    """Whether cycling ended at rest: the unbalanced force ratio below the threshold asked
    for, or a stress-free packing (see :attr:`jammed`)."""
    jammed: bool
    """Whether the packing carries load. False when the disks at this porosity do not
    fill the box under load (a target looser than the protocol's jamming porosity):
    cycling then stops once the contacts' rms overlap is below
    ``stress_free_overlap`` times the smallest radius."""
    radius_factor: float
    """``f``: final radii are ``f * d / 2`` of the drawn diameters ``d``."""
    seed: int | None
    grading: str
    """Name of the grading the diameters came from."""
    friction: float
    """Particle-particle friction during generation."""
    wall_friction: float
    threads: int
    steps: int
    """DEM steps run (growth and equilibrium)."""
    wall_time_s: float
    shape: str = "disk"
    """The grains' shape (:func:`grainlab.shapes.shape_template`'s name, "disk" for disks)."""
    shape_parameter: float = 0.0
    """Its eta (0 for disks)."""
    grain: NDArray[np.int64] | None = None
    """(N,) each particle's grain (body), for a sample of clumps; None for disks."""
    simulation: Any = field(default=None, repr=False, compare=False)
    """The live :class:`grainlab.Simulation` when asked for (``keep_simulation=True``)."""

    @property
    def n_particles(self) -> int:
        return len(self.radii)

    @property
    def n_grains(self) -> int:
        """Grains (bodies): the disks, or the clumps."""
        return self.n_particles if self.grain is None else int(self.grain.max()) + 1

    def summary(self) -> str:
        """One line: where the sample is."""
        grains = (f"{self.n_particles} disks" if self.grain is None else
                  f"{self.n_grains} {self.shape}s (eta {self.shape_parameter:g}, {self.n_particles} pebbles)")
        return (
            f"{grains}, porosity {self.porosity:.4f} nominal / "
            f"{self.porosity_overlap_corrected:.4f} overlap-corrected (target {self.porosity_target:.4f}), "
            f"wall stress {self.mean_wall_stress_pa / 1e3:.1f} kPa, Z {self.coordination_number:.2f}, "
            f"mean overlap {100 * self.mean_overlap_ratio:.1f}% of r_min, "
            f"unbalanced {self.unbalanced_force_ratio:.1e}, {self.wall_time_s:.1f} s"
            + ("" if self.jammed else " (not jammed: stress-free at this porosity)")
        )

    def to_dict(self) -> dict[str, Any]:
        """The scalar results (JSON-ready), without positions, radii or the simulation."""
        grains = {} if self.grain is None else {
            "n_grains": self.n_grains, "shape": self.shape, "shape_parameter": self.shape_parameter,
        }
        scalars = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in _NOT_SCALARS}
        return {"n_particles": self.n_particles, **grains, **scalars, "box": list(self.box),
                "wall_stresses_pa": self.wall_stresses_pa.tolist()}


#: Each wall reaches this fraction of the box's shorter side beyond its corners,
#: so that walls moved by a servo (consolidation) still close the corners.
WALL_OVERHANG = 0.2


def _wall_points(box: tuple[float, float, float, float]) -> NDArray[np.float64]:
    x0, y0, x1, y1 = box
    e = WALL_OVERHANG * min(x1 - x0, y1 - y0)
    # each segment runs counter-clockwise around the box, so the inside is on its
    # left; each overhangs its corners by e, so that the corners stay closed when
    # the walls move apart
    return np.array(
        [
            [[x0 - e, y0], [x1 + e, y0]],
            [[x1, y0 - e], [x1, y1 + e]],
            [[x1 + e, y1], [x0 - e, y1]],
            [[x0, y1 + e], [x0, y0 - e]],
        ]
    )


class _Box:
    """The rigid box around a simulation, and the measurements taken through it."""

    def __init__(self, sim: Any, box: tuple[float, float, float, float]) -> None:
        self.sim = sim
        self.box = box
        x0, y0, x1, y1 = box
        self.area = (x1 - x0) * (y1 - y0)
        self.lengths = (x1 - x0, y1 - y0, x1 - x0, y1 - y0)
        self.walls = [sim.add_segment_wall(a, b) for a, b in _wall_points(box)]
        #: Each particle's grain when the grains are clumps (porosities by grain), else None.
        self.grain: NDArray[np.int64] | None = None

    def wall_stresses(self) -> NDArray[np.float64]:
        return np.array([w.normal_stress(length) for w, length in zip(self.walls, self.lengths, strict=True)])

    def mean_stress(self) -> float:
        return float(self.wall_stresses().mean())

    def porosities(self) -> tuple[float, float]:
        r, p, g = self.sim.radii, self.sim.positions, self.grain
        if g is None:
            return nominal_porosity(r, self.area), overlap_corrected_porosity(p, r, self.box)
        return (nominal_porosity(r, self.area, positions=p, grain=g),
                overlap_corrected_porosity(p, r, self.box, grain=g))


def expand_to_porosity(
    box: ArrayLike = (0.0, 0.0, 0.075, 0.15), porosity: float = 0.12, grading: Grading = PAPER_GRADING, *,
    seed: int | None = 0, n_particles: int | None = None, diameters: ArrayLike | None = None,
    friction: float = 0.0, wall_friction: float = 0.0,
    normal_stiffness: float = _KN, shear_stiffness: float = _KN, density: float = _DENSITY,
    local_damping: float = _DAMPING, initial_scale: float = 0.5,
    growth_per_increment: float = 1.0e-2, steps_per_increment: int = 50, growth_stress_scale_pa: float = 1.0e5,
    equilibrium_ratio: float = 1.0e-4, stress_free_overlap: float = 1.0e-5, max_equilibrium_steps: int = 300_000,
    max_stress_pa: float = MAX_STRESS_PA, time_step_safety: float = DEFAULT_TIME_STEP_SAFETY,
    density_scaling: bool = True, threads: int = 1, progress: bool = False, keep_simulation: bool = False,
    shape: ShapeTemplate | None = None,
) -> Sample:
    """Generates a sample by radius expansion inside rigid walls to a target nominal porosity.

    Parameters
    ----------
    box : ``(xmin, ymin, xmax, ymax)``, m (Table 1: 75 x 150 mm)
    porosity : target *nominal* porosity, in (0, 1) (Table 1: 0.12)
    grading : where diameters come from (default :data:`PAPER_GRADING`)
    seed : seeds ``numpy.random.default_rng``; the same seed gives the same
        sample bit for bit (whatever ``threads`` is)
    n_particles : default :func:`particle_count` of the box, porosity and grading
    diameters : (N,) m, drawn beforehand (then ``grading`` only names them and
        ``n_particles`` must be None)
    friction, wall_friction : particle-particle and particle-wall friction
        while generating (default 0 for both)
    normal_stiffness, shear_stiffness : contact kn, ks (N/m; Table 1: 8.45e7)
    density : kg/m^3 (Table 1: 2e8); local_damping : alpha (Table 1: 0.8)
    initial_scale : placed radius over final radius (the paper halves: 0.5)
    growth_per_increment, steps_per_increment, growth_stress_scale_pa : the
        growth (docs/samples.md, step 4); equilibrium_ratio, stress_free_overlap,
        max_equilibrium_steps : the end (step 5; past the last, the sample comes
        with ``equilibrium_reached = False`` and a warning)
    max_stress_pa : stress bound (mean wall stress in equilibrium), Pa
    time_step_safety : time step = this x the critical step, re-evaluated every increment
    density_scaling : give every disk the largest disk's mass while generating
    threads : engine worker threads (the sample does not depend on them)
    progress : show the progress on stderr (off by default)
    keep_simulation : return the live simulation in :attr:`Sample.simulation` (walls 0..3:
        bottom, right, top, left; the generation friction still on: set the test's own)
    shape : each grain's shape (:func:`grainlab.shapes.shape_template`): clumps at random
        angles, the grading giving their circumscribed diameters, the porosity their
        unions (docs/samples.md, "Samples of shaped grains"); None: disks

    Raises
    ------
    ValueError
        bad input, naming the field, before any work; :class:`PlacementError` when
        placement at ``initial_scale`` cannot fit the grains; :class:`ExpansionError`
        when the target needs a mean wall stress above ``max_stress_pa`` (or overlaps
        beyond the engine's limit), with the densest porosity reached and its stress.
    """
    started = time.perf_counter()
    settings = _Settings.checked(
        box=box, porosity=porosity, grading=grading, friction=friction, wall_friction=wall_friction,
        normal_stiffness=normal_stiffness, shear_stiffness=shear_stiffness, density=density,
        local_damping=local_damping, initial_scale=initial_scale, growth_per_increment=growth_per_increment,
        steps_per_increment=steps_per_increment, growth_stress_scale_pa=growth_stress_scale_pa,
        equilibrium_ratio=equilibrium_ratio, stress_free_overlap=stress_free_overlap,
        max_equilibrium_steps=max_equilibrium_steps, max_stress_pa=max_stress_pa,
        time_step_safety=time_step_safety, threads=threads,
    )
    clumps = _clump_shape(shape)
    rng = np.random.default_rng(seed)
    d = _diameters(settings, grading, diameters, n_particles, rng, clumps)
    expansion = _Expansion.placed(settings, d, rng, density_scaling, progress, clumps)
    expansion.grow()
    return Sample(
        **expansion.finish(settings, density_scaling),
        **_grains_of(clumps, expansion.walls.grain),
        radius_factor=expansion.radius_factor,
        seed=seed,
        grading=grading.name,
        friction=settings.friction,
        wall_friction=settings.wall_friction,
        threads=settings.threads,
        steps=expansion.steps,
        wall_time_s=time.perf_counter() - started,
        simulation=expansion.sim if keep_simulation else None,
    )


def _clump_shape(shape: ShapeTemplate | None) -> ShapeTemplate | None:
    """The template of clumps to grow (None for disks: no shape, or one of one disk)."""
    if shape is not None and not isinstance(shape, ShapeTemplate):
        raise TypeError(f"shape: expected a ShapeTemplate (grainlab.shapes.shape_template) or None, got {shape!r}")
    return shape if shape is not None and shape.n_pebbles > 1 else None


def _grains_of(clumps: ShapeTemplate | None, grain: NDArray[np.int64] | None) -> dict[str, Any]:
    """A :class:`Sample`'s shape fields."""
    if clumps is None:
        return {"shape": "disk", "shape_parameter": 0.0, "grain": None}
    return {"shape": clumps.name, "shape_parameter": clumps.eta, "grain": grain}


@dataclass(frozen=True)
class _Settings:
    """The checked parameters of :func:`expand_to_porosity` (its docstring says what each is)."""

    box: tuple[float, float, float, float]
    porosity: float
    friction: float
    wall_friction: float
    normal_stiffness: float
    shear_stiffness: float
    density: float
    local_damping: float
    initial_scale: float
    growth_per_increment: float
    steps_per_increment: int
    growth_stress_scale_pa: float
    equilibrium_ratio: float
    stress_free_overlap: float
    max_equilibrium_steps: int
    max_stress_pa: float
    time_step_safety: float
    threads: int

    @property
    def area(self) -> float:
        x0, y0, x1, y1 = self.box
        return (x1 - x0) * (y1 - y0)

    @classmethod
    def checked(cls, *, box: ArrayLike, porosity: float, grading: Grading, **values: Any) -> _Settings:
        """The settings, or a ``ValueError`` naming the first bad one, before any work."""
        box = check_box(box)
        porosity = in_range("porosity", porosity, "(0, 1)")
        if not isinstance(grading, Grading):
            raise TypeError(
                f"grading: expected a Grading (UniformByNumber, UniformByMass, GradingCurve), got {grading!r}"
            )
        v: dict[str, Any] = {name: in_range(name, value, _RANGES.get(name, "(0, inf)")) for name, value in values.items()}
        for name in ("steps_per_increment", "max_equilibrium_steps", "threads"):
            v[name] = int(v[name])
        return cls(box=box, porosity=porosity, **v)


#: The range of each of :class:`_Settings`' numbers but the positive ones.
_RANGES = {"friction": "[0, inf)", "wall_friction": "[0, inf)", "local_damping": "[0, 1)", "initial_scale": "(0, 1]",
           "steps_per_increment": "[1, inf)", "max_equilibrium_steps": "[0, inf)", "time_step_safety": "(0, 1]",
           "threads": "[1, inf)"}


def _diameters(
    settings: _Settings,
    grading: Grading,
    diameters: ArrayLike | None,
    n_particles: int | None,
    rng: np.random.Generator,
    clumps: ShapeTemplate | None = None,
) -> NDArray[np.float64]:
    """The diameters given, or ``n_particles`` drawn from the grading: by default as
    many as fill the box at the porosity, disks (:func:`particle_count`) or grains of
    the ``clumps`` shape's area (so that the grains keep the grading's sizes)."""
    if diameters is not None:
        if n_particles is not None:
            raise ValueError("n_particles: give either n_particles or diameters, not both")
        d = np.array(positive_lengths("diameters", diameters, "diameter"))
        if len(d) == 0:
            raise ValueError("diameters: expected at least one diameter")
        return d
    if n_particles is not None:
        n = int(n_particles)
    elif clumps is None:
        n = particle_count(settings.area, settings.porosity, grading)
    else:  # grains of the shape's area, a fraction of their circumscribed disk's, fill the box
        n = round((1.0 - settings.porosity) * settings.area / (grading.mean_disk_area() * clumps.area / math.pi))
    if n < 1:
        raise ValueError(f"n_particles: must be >= 1, got {n}")
    return grading.sample(n, rng)


def _clump_pebbles(shape: ShapeTemplate, centres: NDArray[np.float64], sizes: NDArray[np.float64],
                   angles: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The pebbles (centres (N K, 2), radii (N K,)) of clumps of ``shape`` with
    circumscribed radii ``sizes`` at ``centres``, each turned by its angle."""
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    ox, oy = shape.offsets[:, 0][None, :], shape.offsets[:, 1][None, :]
    world = np.empty((len(centres), shape.n_pebbles, 2))
    world[..., 0] = centres[:, None, 0] + sizes[:, None] * (c * ox - s * oy)
    world[..., 1] = centres[:, None, 1] + sizes[:, None] * (s * ox + c * oy)
    return world.reshape(-1, 2), (sizes[:, None] * shape.radii[None, :]).reshape(-1)


class _Expansion:
    """The disks placed at ``initial_scale`` in the box, the simulation that grows
    them, and the growth itself: :meth:`grow`, then :meth:`finish`."""

    #: Progress bar resolution.
    TICKS = 1000

    def __init__(self, settings: _Settings, sim: Any, final_radii: NDArray[np.float64], radius_factor: float,
                 progress: bool) -> None:
        from grainlab._progress import progress_bar

        self.settings = settings
        self.sim = sim
        self.walls = _Box(sim, settings.box)
        self.final_radii = final_radii
        self.radius_factor = radius_factor
        self.scale = settings.initial_scale
        self.steps = 0
        self.status = "unsettled"
        self.r_min = float(final_radii.min())
        self.bar = progress_bar(self.TICKS, "radius expansion", enabled=progress,
                                bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}{postfix}")

    @classmethod
    def placed(cls, settings: _Settings, d: NDArray[np.float64], rng: np.random.Generator, density_scaling: bool,
               progress: bool, clumps: ShapeTemplate | None = None) -> _Expansion:
        """Final radii scaled by one common factor so that the final nominal porosity is
        exactly the target; the disks (or the clumps' circumscribed disks, the clumps
        at random angles) placed at random at ``initial_scale`` of them."""
        import grainlab
        from grainlab.simulation import WALL_GROUP

        s = settings
        x0, y0, x1, y1 = s.box
        # a grain's area over its circumscribed radius squared: pi, or the clump template's
        shape_area = math.pi if clumps is None else clumps.area
        radius_factor = math.sqrt((1.0 - s.porosity) * s.area / (shape_area * float(np.sum((0.5 * d) ** 2))))
        final_radii = radius_factor * 0.5 * d
        if 2.0 * final_radii.max() > min(x1 - x0, y1 - y0):
            raise ValueError(
                f"box: the largest final disk (diameter {2 * final_radii.max():.4g} m) does not fit in "
                f"the box ({x1 - x0:.4g} x {y1 - y0:.4g} m)"
            )
        positions, _ = random_placement(s.box, 2.0 * final_radii, rng, scale=s.initial_scale)
        model = grainlab.ContactModel(s.normal_stiffness, s.shear_stiffness, s.friction)
        if clumps is None:
            pebbles, sizes = positions, s.initial_scale * final_radii
        else:
            angles = rng.uniform(0.0, 2.0 * math.pi, len(d))
            pebbles, sizes = _clump_pebbles(clumps, positions, s.initial_scale * final_radii, angles)
        sim = grainlab.Simulation(pebbles, sizes, density=s.density, contact_model=model,
                                  threads=s.threads, local_damping=s.local_damping)
        sim.set_contact_model(0, WALL_GROUP, grainlab.ContactModel(s.normal_stiffness, s.shear_stiffness,
                                                                   s.wall_friction))
        expansion = cls(s, sim, final_radii, radius_factor, progress)
        per_grain = 1
        if clumps is not None:
            per_grain = clumps.n_pebbles
            sim.add_bodies(np.arange(len(sizes)).reshape(len(d), per_grain).tolist(), angles=angles)
            expansion.walls.grain = np.repeat(np.arange(len(d)), per_grain)
        if density_scaling:
            # every grain the largest one's mass (a clump's density is its pebbles')
            sim.densities = np.repeat(s.density * (final_radii.max() / final_radii) ** 2, per_grain)
        return expansion

    def resize(self, scale: float) -> None:
        """The grains at ``scale`` of their final size: the disks' radii, or each clump
        grown about its centroid by the ratio to the current scale (``scale_clumps``)."""
        if self.walls.grain is None:
            self.sim.radii = self.final_radii if scale == 1.0 else scale * self.final_radii
        else:
            self.sim.scale_clumps(np.full(len(self.final_radii), scale / self.scale))
        self.scale = scale

    def relax(self, limit: int) -> tuple[str, int]:
        """Cycles at fixed radii until equilibrium (``"equilibrium"``), until the contacts
        carry no load (``"stress-free"``), or for ``limit`` steps (``"unsettled"``)."""
        s, sim = self.settings, self.sim
        done = 0
        while done < limit:
            chunk = min(4 * s.steps_per_increment, limit - done)
            sim.time_step = sim.critical_time_step(s.time_step_safety)
            sim.run(chunk)
            done += chunk
            ratio = sim.unbalanced_force_ratio
            self.bar.set_postfix_str(f"unbalanced {ratio:.1e}, stress {self.walls.mean_stress() / 1e3:.0f} kPa")
            if ratio < s.equilibrium_ratio:
                return "equilibrium", done
            energy = sim.energy
            # rms overlap of the linear contacts from their elastic energy sum(kn delta^2 / 2)
            n_contacts = sim.contact_count + sum(w.contact_count for w in self.walls.walls)
            rms_overlap = math.sqrt(2.0 * max(energy.elastic, 0.0) / (s.normal_stiffness * max(n_contacts, 1)))
            if rms_overlap < s.stress_free_overlap * self.r_min:
                return "stress-free", done
            if energy.kinetic > energy.elastic:
                # no load-bearing network: free disks feel no local damping and would fly
                # for ever; stop them, and let the remaining contacts push apart
                sim.velocities = np.zeros((sim.n_particles, 2))
                sim.angular_velocities = np.zeros(sim.n_particles)
        return "unsettled", done

    def fail(self, stress: float, equilibrium: bool, engine_error: Exception | None = None) -> ExpansionError:
        """The error for a target that needs more than ``max_stress_pa`` (or that the engine stopped)."""
        s = self.settings
        n_nom, n_cor = self.walls.porosities()
        reached = (
            f"the densest packing reached has nominal porosity {n_nom:.4f} (overlap-corrected {n_cor:.4f})"
        )
        if engine_error is None:
            state = "in equilibrium" if equilibrium else "while growing"
            message = (
                f"porosity: cannot reach nominal porosity {s.porosity:.4f} within max_stress_pa = "
                f"{s.max_stress_pa / 1e6:.3g} MPa: {reached} and needed a mean wall stress of "
                f"{stress / 1e6:.3g} MPa {state}. Raise max_stress_pa or aim for a higher porosity."
            )
        else:
            message = (
                f"porosity: cannot reach nominal porosity {s.porosity:.4f}: {reached}, at a mean wall "
                f"stress of {stress / 1e6:.3g} MPa, when the engine stopped ({engine_error}). "
                "Aim for a higher porosity or generate with less friction."
            )
        return ExpansionError(
            message,
            porosity=n_nom,
            porosity_overlap_corrected=n_cor,
            stress_pa=stress,
            target=s.porosity,
            equilibrium=equilibrium,
            steps=self.steps,
            engine_stopped=engine_error is not None,
        )

    def grow(self) -> None:
        """Grows the radii by increments that shrink as the wall stress rises, relaxing
        whenever the stress passes ``max_stress_pa`` (an error if it stays above), then
        cycles the final packing to equilibrium."""
        import grainlab

        s, sim, bar = self.settings, self.sim, self.bar
        total_growth = -math.log(self.scale)
        try:
            stress = 0.0
            while self.scale < 1.0:
                growth = s.growth_per_increment / (1.0 + max(stress, 0.0) / s.growth_stress_scale_pa)
                self.resize(min(1.0, self.scale * math.exp(growth)))
                sim.time_step = sim.critical_time_step(s.time_step_safety)
                sim.run(s.steps_per_increment)
                self.steps += s.steps_per_increment
                stress = self.walls.mean_stress()
                bar.moveto(int(self.TICKS * (1.0 - math.log(1.0 / self.scale) / total_growth))
                           if total_growth > 0 else self.TICKS)
                bar.set_postfix_str(f"stress {stress / 1e3:.0f} kPa, Z {sim.coordination_number:.2f}")
                if stress > s.max_stress_pa:
                    status, used = self.relax(s.max_equilibrium_steps)
                    self.steps += used
                    stress = self.walls.mean_stress()
                    if stress > s.max_stress_pa:
                        raise self.fail(stress, status == "equilibrium")
            bar.moveto(self.TICKS)
            bar.set_description_str("equilibrium")
            self.status, used = self.relax(s.max_equilibrium_steps)
            self.steps += used
        except grainlab.SimulationUnstableError as error:
            bar.close()
            raise self.fail(self.walls.mean_stress(), False, error) from error
        bar.close()

    def finish(self, settings: _Settings, density_scaling: bool) -> dict[str, Any]:
        """The packing's measures (a ``Sample``'s fields) and a clean hand-over: Table 1
        density back, at rest, a time step for the real masses."""
        sim, status = self.sim, self.status
        wall_stresses = self.walls.wall_stresses()
        stress = float(wall_stresses.mean())
        settled = status != "unsettled"
        if stress > settings.max_stress_pa:
            raise self.fail(stress, status == "equilibrium")
        ratio = sim.unbalanced_force_ratio
        if not settled:
            warnings.warn(
                f"expand_to_porosity: unbalanced force ratio {ratio:.2e} still above equilibrium_ratio = "
                f"{settings.equilibrium_ratio:.1e} after max_equilibrium_steps = {settings.max_equilibrium_steps}",
                RuntimeWarning,
                stacklevel=3,
            )
        contacts = sim.contacts()
        radii = sim.radii
        if len(contacts):
            mean_overlap = float(contacts.overlap.mean() / radii.min())
            max_overlap = float(np.max(contacts.overlap / np.minimum(radii[contacts.i], radii[contacts.j])))
        else:
            mean_overlap = max_overlap = 0.0
        n_nom, n_cor = self.walls.porosities()
        if self.walls.grain is None:
            coordination = sim.coordination_number
            mechanical = CoordinationNumber().compute(sim.snapshot()).mechanical_coordination_number
        else:
            bodies = BodyCoordination().compute(sim.snapshot())
            coordination, mechanical = bodies.contact_coordination_number, bodies.mechanical_contact_coordination_number
        if density_scaling:
            sim.densities = np.full(len(radii), settings.density)
        sim.velocities = np.zeros((len(radii), 2))
        sim.angular_velocities = np.zeros(len(radii))
        sim.time_step = sim.critical_time_step(0.5)
        positions_out = np.array(sim.positions)
        radii_out = np.array(radii)
        for array in (positions_out, radii_out, wall_stresses):
            array.flags.writeable = False
        return {
            "positions": positions_out,
            "radii": radii_out,
            "box": settings.box,
            "wall_points": _wall_points(settings.box),
            "porosity_target": settings.porosity,
            "porosity": n_nom,
            "porosity_overlap_corrected": n_cor,
            "wall_stresses_pa": wall_stresses,
            "mean_wall_stress_pa": stress,
            "coordination_number": coordination,
            "mechanical_coordination_number": mechanical,
            "mean_overlap_ratio": mean_overlap,
            "max_overlap_ratio": max_overlap,
            "unbalanced_force_ratio": ratio,
            "equilibrium_reached": settled,
            "jammed": status == "equilibrium" and len(contacts) > 0 and stress > 0.0,
        }
