"""The engine from Python: build a simulation from NumPy arrays and run it.

All per-step work happens in the Rust engine (:mod:`grainlab._core`); this
module validates input, converts arrays and gives the state friendly names.
Conventions (docs/conventions.md): SI units, 2D disks of unit thickness
(``m = rho pi r^2``, ``I = m r^2 / 2``), angles in radians counter-clockwise,
stresses compression positive.

Example
-------
>>> import numpy as np
>>> from grainlab import Simulation
>>> sim = Simulation(positions=[[0.0, 0.0], [1.9e-3, 0.0]], radii=[1e-3, 1e-3], density=2650.0)
>>> sim.velocities = [[0.01, 0.0], [-0.01, 0.0]]
>>> sim.run(10_000)
>>> bool(sim.velocities[0, 0] < 0)  # the disks bounced apart
True
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Generic, Literal, TypeVar, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab import _core, paper
from grainlab.bodies import ClumpState, _points, clump_mass_properties
from grainlab.cement import BondBreaks, CementBonds, cement_arguments
from grainlab.snapshot import GRAIN_ANGLE_FIELD, GRAIN_CENTROID_FIELD, GRAIN_FIELD, Snapshot

#: Table 1 of the paper (:mod:`grainlab.paper`): contact stiffnesses (N/m), particle
#: friction, density (kg/m^3), local damping.
TABLE1_STIFFNESS_N_PER_M = paper.NORMAL_STIFFNESS_N_PER_M
TABLE1_FRICTION = paper.FRICTION
TABLE1_DENSITY_KG_PER_M3 = paper.DENSITY_KG_PER_M3
TABLE1_LOCAL_DAMPING = paper.LOCAL_DAMPING

#: The time step as a fraction of the critical one when none is given: PFC's 0.8. The one
#: default of every time step grainlab picks (a :class:`Simulation`, the radius expansion,
#: the biaxial test's ``run.time_step_safety``).
DEFAULT_TIME_STEP_SAFETY = 0.8

#: Bits of :attr:`Simulation.fixity`.
FIX_X, FIX_Y, FIX_ROTATION = 1, 2, 4

#: Number of material groups (contact models are set per pair of groups).
MAX_GROUPS = _core.MAX_GROUPS

#: Group that walls get by default, so particle-wall contacts can differ from particle-particle ones.
WALL_GROUP = 1

_STATE_MAGIC = b"GRAINLAB-ENGINE-STATE\n"


@dataclass(frozen=True)
class ContactModel:
    """The contact law with Coulomb friction between two material groups: linear
    (the default) or Hertz-Mindlin (``law="hertz_mindlin"``).

    ``normal_stiffness`` and ``shear_stiffness`` are *contact* stiffnesses kn, ks
    (N/m): ``Fn = kn * overlap``, ``dFs = -ks * ds`` (paper Eq. 2-4). The damping
    ratios are fractions of critical damping of optional viscous dashpots
    (``2 sqrt(m* k)``); they are independent of local damping.

    Rolling resistance (``rolling_friction``, ``rolling_stiffness``,
    ``rolling_damping_ratio``), off by default: docs/contact-law.md, "Rolling
    resistance (optional)". Hertz-Mindlin from ``youngs_modulus``, ``poisson_ratio``
    and ``restitution``, as LAMMPS's ``pair granular`` computes it: docs/contact-law.md,
    "Hertz-Mindlin"; the stiffnesses and damping ratios above are then not read
    (give the damping ratios 0). :meth:`hertz_mindlin` makes one.
    """

    @classmethod
    def hertz_mindlin(
        cls, youngs_modulus: float, poisson_ratio: float, restitution: float, friction: float, **rolling: float
    ) -> ContactModel:
        """Hertz-Mindlin between grains of Young's modulus ``youngs_modulus`` (Pa)
        and Poisson ratio ``poisson_ratio``, damped to the coefficient of
        restitution ``restitution``, with Coulomb friction ``friction``;
        ``rolling`` takes the rolling resistance's fields.

        >>> ContactModel.hertz_mindlin(70e9, 0.25, 0.5, 0.5).law
        'hertz_mindlin'
        """
        return cls(
            friction=friction, law="hertz_mindlin", youngs_modulus=youngs_modulus,
            poisson_ratio=poisson_ratio, restitution=restitution, **rolling,  # type: ignore[arg-type]
        )

    normal_stiffness: float = TABLE1_STIFFNESS_N_PER_M
    shear_stiffness: float = TABLE1_STIFFNESS_N_PER_M
    friction: float = TABLE1_FRICTION
    normal_damping_ratio: float = 0.0
    shear_damping_ratio: float = 0.0
    rolling_friction: float = 0.0
    rolling_stiffness: float = 0.0
    rolling_damping_ratio: float = 0.0
    enabled: bool = True
    """False: the two groups do not interact at all (they pass through each other)."""
    law: str = "linear"
    """The contact law: ``"linear"`` (the springs above) or ``"hertz_mindlin"``."""
    youngs_modulus: float = 0.0
    """Young's modulus E of the grains (Pa), read by Hertz-Mindlin only."""
    poisson_ratio: float = 0.0
    """Poisson ratio nu of the grains, in (-1, 0.5), read by Hertz-Mindlin only."""
    restitution: float = 1.0
    """Normal coefficient of restitution e in (0, 1] (1: elastic), read by Hertz-Mindlin only."""


def _tangent(normal: NDArray[np.float64]) -> NDArray[np.float64]:
    """``rot90(n) = (-n_y, n_x)`` of each row."""
    return np.column_stack([-normal[:, 1], normal[:, 0]])


@dataclass(frozen=True)
class Contacts:
    """Particle-particle contacts (and bonds) as parallel arrays, sorted by ``(i, j)``.

    One consistent state (docs/contact-law.md, "What `Simulation.contacts()` reports")
    in the Python side's one force convention (docs/conventions.md, "Contact forces"):
    ``normal`` from ``i`` to ``j``, ``normal_force`` compression positive,
    ``shear_force`` along ``(-n_y, n_x)`` and ``rolling_moment`` on ``i``
    (:attr:`force_on_i`), ``normal_stiffness`` the tangent stiffness
    ``dF_n / d(overlap)`` (N/m).

    Two touching disks held in place, ``i`` turning against ``j``: the rolling
    moment on ``i`` is ``-k_r dtheta`` while below its cap
    ``mu_r R* normal_force`` (here 0.05 N m):

    >>> from grainlab import ContactModel, Simulation
    >>> model = ContactModel(1e7, 1e7, 0.5, rolling_friction=0.1, rolling_stiffness=10.0)
    >>> sim = Simulation([[0.0, 0.0], [1.9e-3, 0.0]], [1e-3, 1e-3], 2650.0, contact_model=model)
    >>> sim.fixity = [7, 7]  # every degree of freedom prescribed: the spins stay
    >>> sim.angular_velocities = [1.0, 0.0]
    >>> sim.run(100)
    >>> c = sim.contacts()
    >>> dtheta = sim.rotations[0] - sim.rotations[1]
    >>> bool(abs(c.rolling_moment[0] - (-10.0 * dtheta)) < 1e-12)
    True
    """

    i: NDArray[np.uint32]
    j: NDArray[np.uint32]
    point: NDArray[np.float64]
    normal: NDArray[np.float64]
    overlap: NDArray[np.float64]
    normal_force: NDArray[np.float64]
    shear_force: NDArray[np.float64]
    sliding: NDArray[np.bool_]
    bonded: NDArray[np.bool_]
    rolling_moment: NDArray[np.float64]
    normal_stiffness: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.i)

    @property
    def force_on_i(self) -> NDArray[np.float64]:
        """(Nc, 2) force on particle ``i`` from ``j``, N (its opposite acts on ``j``)."""
        return -self.normal_force[:, None] * self.normal + self.shear_force[:, None] * _tangent(self.normal)


@dataclass(frozen=True)
class WallContacts:
    """Particle-wall contacts, in the same consistent state and the same convention
    as :class:`Contacts` with the wall as ``j`` (``normal`` from the particle to the
    wall; ``shear_force`` and ``rolling_moment`` on the particle)."""

    wall: NDArray[np.uint32]
    particle: NDArray[np.uint32]
    point: NDArray[np.float64]
    normal: NDArray[np.float64]
    overlap: NDArray[np.float64]
    normal_force: NDArray[np.float64]
    shear_force: NDArray[np.float64]
    sliding: NDArray[np.bool_]
    rolling_moment: NDArray[np.float64]
    normal_stiffness: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.wall)

    @property
    def force_on_particle(self) -> NDArray[np.float64]:
        """(Nw, 2) force of the wall on the particle, N."""
        return -self.normal_force[:, None] * self.normal + self.shear_force[:, None] * _tangent(self.normal)


@dataclass(frozen=True)
class Energy:
    """The energy ledger, J per m of thickness (docs/contact-law.md, "Energy bookkeeping"):
    ``kinetic`` and ``elastic`` at the last measured step; the dissipated and
    work terms summed since step 0; ``balance`` = kinetic + elastic + dissipated
    - work, constant in exact arithmetic."""

    kinetic: float
    elastic: float
    friction_dissipated: float
    viscous_dissipated: float
    rolling_dissipated: float
    """Dissipated by the contact law's rolling sub-model (0: the linear law resists no rolling)."""
    damping_dissipated: float
    wall_work: float
    external_work: float
    boundary_work: float
    """Work of the pressure chains' follower loads."""
    bond_released: float
    """Strain energy released by broken cement bonds (docs/cemented.md), counted with the dissipated terms."""
    balance: float


@dataclass(frozen=True)
class PeriodicCell:
    """The periodic cell: ``origin`` and cell vectors ``a`` and ``b`` (m), which
    directions are ``periodic``, the imposed ``velocity_gradient`` ``L[i][j] =
    dv_i/dx_j`` (1/s) and the cell's ``area`` (m^2)."""

    origin: tuple[float, float]
    a: tuple[float, float]
    b: tuple[float, float]
    periodic: tuple[bool, bool]
    velocity_gradient: tuple[tuple[float, float], tuple[float, float]]
    area: float


@dataclass(frozen=True)
class PressureChainState:
    """One pressure chain: its ``particles`` in order (the sample on their right),
    its ``pressure`` (Pa) and the walls anchoring its ends (ids, or None)."""

    particles: list[int]
    pressure: float
    start_wall: int | None
    end_wall: int | None


def _readonly(array: object) -> NDArray[Any]:
    """The engine's array itself (``asarray`` makes no copy of an array), marked read-only."""
    marked = np.asarray(array)
    marked.flags.writeable = False
    return marked


def _values(name: str, value: ArrayLike, n: int, dtype: Any = np.float64) -> NDArray[Any]:
    array = np.asarray(value)
    if array.ndim == 0:
        array = np.full(n, array)
    try:
        array = np.ascontiguousarray(array, dtype=dtype)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name}: expected {n} numbers ({error})") from None
    if array.ndim != 1 or len(array) != n:
        raise ValueError(f"{name}: expected a scalar or {n} values, got shape {array.shape}")
    if array.dtype.kind == "f" and not np.all(np.isfinite(array)):
        k = int(np.argwhere(~np.isfinite(array))[0, 0])
        raise ValueError(f"{name}[{k}]: must be finite, got {array[k]}")
    return array


def _vector(name: str, value: ArrayLike) -> tuple[float, float]:
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (2,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name}: expected two finite numbers, got {value!r}")
    return float(array[0]), float(array[1])


def _index_list(name: str, value: ArrayLike, n: int) -> list[int]:
    array = np.asarray(value)
    if array.ndim != 1 or array.size == 0 or array.dtype.kind not in "iu":
        raise ValueError(f"{name}: expected a non-empty 1D array of particle indices")
    if np.any((array < 0) | (array >= n)):
        k = int(np.argwhere((array < 0) | (array >= n))[0, 0])
        raise ValueError(f"{name}[{k}]: particle index {array[k]} out of range 0..{n - 1}")
    return [int(v) for v in array]


def _codes(name: str, value: ArrayLike, n: int, largest: int, meaning: str) -> NDArray[np.uint8]:
    """Per-particle integer codes in 0..largest as uint8; ``meaning`` (with ``{v}``
    for the bad value) says what a code out of range is."""
    array = _values(name, value, n, dtype=np.int64)
    if np.any((array < 0) | (array > largest)):
        k = int(np.argwhere((array < 0) | (array > largest))[0, 0])
        raise ValueError(f"{name}[{k}]: " + meaning.format(v=array[k]))
    return array.astype(np.uint8)


def _groups(name: str, value: ArrayLike, n: int) -> NDArray[np.uint8]:
    return _codes(name, value, n, MAX_GROUPS - 1, f"group {{v}} out of range 0..{MAX_GROUPS - 1}")


def _fixity(name: str, value: ArrayLike, n: int) -> NDArray[np.uint8]:
    return _codes(name, value, n, 7, "{v} is not a sum of 1 (x), 2 (y), 4 (rotation)")


#: The element type of a per-particle array (np.float64, np.uint8).
Element = TypeVar("Element", bound=np.generic)


class _ParticleArray(property, Generic[Element]):
    """A per-particle array of :class:`Simulation`: a property named after the
    engine's array, with the docstring ``doc``.

    Reading gives a read-only copy of the engine's array. With a
    ``convert(name, value, n)`` (``_points`` for (N, 2), ``_values`` for (N,),
    ``_groups``, ``_fixity``) the property is settable: a whole array assigned
    is checked and converted by it (errors name the property) and handed to the
    engine's ``set_<name>``; without, it is read-only (no setter).
    """

    def __init__(
        self, doc: str, *, convert: Callable[[str, ArrayLike, int], NDArray[Any]] | None = None
    ) -> None:
        super().__init__(self._read, None if convert is None else self._write, None, doc)
        self.__doc__ = doc  # a property subclass keeps its doc in the instance
        self._convert = convert
        self.name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        # property's own __set_name__ names the property in its errors ("has no setter");
        # typeshed's property lacks it though CPython's has it since 3.10
        super().__set_name__(owner, name)  # type: ignore[misc]
        self.name = name

    def _read(self, sim: Simulation) -> NDArray[Element]:
        return _readonly(getattr(sim._engine, self.name))

    def _write(self, sim: Simulation, value: ArrayLike) -> None:
        assert self._convert is not None  # _write is the setter only when there is a convert
        getattr(sim._engine, f"set_{self.name}")(self._convert(self.name, value, sim.n_particles))

    @overload
    def __get__(self, sim: None, owner: type | None = None) -> _ParticleArray[Element]: ...
    @overload
    def __get__(self, sim: Simulation, owner: type | None = None) -> NDArray[Element]: ...
    def __get__(
        self, sim: Simulation | None, owner: type | None = None
    ) -> NDArray[Element] | _ParticleArray[Element]:
        if sim is None:
            return self
        return self._read(sim)


def _wall_id(wall: Wall | int | None) -> int | None:
    if wall is None:
        return None
    return wall.id if isinstance(wall, Wall) else int(wall)


@dataclass(frozen=True)
class WallState:
    """One wall's state, read from the engine in one call (:attr:`Wall.state`).

    ``points`` are the end points ``(a, b)`` of a segment or the one ``(point,)``
    of a line (m); ``inward_normal`` points to the particles' side; ``force`` is
    the particles' force on the wall in the last step (N per m thickness),
    ``contact_count`` the particles touching it then; ``displacement`` (m) is the
    total since the wall was created, ``velocity`` (m/s) the current one.
    ``control`` is ``"velocity"`` or ``"servo"``; a servo wall has its settings
    (:meth:`Wall.servo`), the others None there.
    """

    id: int
    kind: Literal["segment", "line"]
    points: tuple[tuple[float, float], ...]
    inward_normal: tuple[float, float]
    velocity: tuple[float, float]
    force: tuple[float, float]
    contact_count: int
    displacement: tuple[float, float]
    group: int
    active: bool
    control: Literal["velocity", "servo"]
    target_stress_pa: float | None = None
    loaded_length_m: float | None = None
    relaxation: float | None = None
    max_speed_m_per_s: float | None = None

    @classmethod
    def _from_engine(cls, wall_id: int, state: _core._WallState) -> WallState:
        kind = state["kind"]
        return cls(
            id=wall_id,
            kind=kind,
            points=(state["a"], state["b"]) if kind == "segment" else (state["point"],),
            inward_normal=state["inward_normal"],
            velocity=state["velocity"],
            force=state["force"],
            contact_count=int(state["contact_count"]),
            displacement=state["displacement"],
            group=int(state["group"]),
            active=bool(state["active"]),
            control=state["control"],
            target_stress_pa=state.get("target_stress"),
            loaded_length_m=state.get("loaded_length"),
            relaxation=state.get("relaxation"),
            max_speed_m_per_s=state.get("max_speed"),
        )


class Wall:
    """A handle on one wall of a :class:`Simulation` (walls are owned by the engine).

    The *inward normal* points to the particles' side: for a segment ``a -> b``
    it is the left normal; for a line, the normal given. Stresses are compression
    positive along it. Each property below reads the wall's whole :attr:`state`
    from the engine; read :attr:`state` once to use several of its values.
    """

    def __init__(self, engine: _core.Engine, wall_id: int) -> None:
        self._engine = engine
        self.id = wall_id

    @property
    def state(self) -> WallState:
        """The wall's state now (:class:`WallState`), read from the engine in one call."""
        return WallState._from_engine(self.id, self._engine.wall_state(self.id))

    @property
    def kind(self) -> str:
        """``"segment"`` or ``"line"``."""
        return self.state.kind

    @property
    def points(self) -> NDArray[np.float64]:
        """End points ``[[ax, ay], [bx, by]]`` of a segment, or ``[point]`` of a line (m)."""
        return np.array(self.state.points)

    @property
    def inward_normal(self) -> NDArray[np.float64]:
        return np.array(self.state.inward_normal)

    @property
    def force(self) -> NDArray[np.float64]:
        """Force exerted by the particles on the wall in the last step (N per m thickness)."""
        return np.array(self.state.force)

    @property
    def contact_count(self) -> int:
        """Particles touching the wall in the last step."""
        return self.state.contact_count

    @property
    def displacement(self) -> NDArray[np.float64]:
        """Total displacement since the wall was created (m)."""
        return np.array(self.state.displacement)

    @property
    def velocity(self) -> NDArray[np.float64]:
        """Current velocity (m/s); setting it switches the wall to velocity control."""
        return np.array(self.state.velocity)

    @velocity.setter
    def velocity(self, value: ArrayLike) -> None:
        self._engine.set_wall_velocity(self.id, list(_vector("velocity", value)))

    @property
    def active(self) -> bool:
        """An inactive wall has no contacts and stays put (e.g. side walls replaced by a membrane)."""
        return self.state.active

    @active.setter
    def active(self, value: bool) -> None:
        self._engine.set_wall_active(self.id, bool(value))

    @property
    def control(self) -> str:
        """``"velocity"`` or ``"servo"``."""
        return self.state.control

    def normal_stress(self, loaded_length_m: float) -> float:
        """Normal stress from the last step's force over ``loaded_length_m``, compression positive (Pa)."""
        if not loaded_length_m > 0:
            raise ValueError(f"loaded_length_m: must be > 0, got {loaded_length_m}")
        state = self.state
        force, normal = np.array(state.force), np.array(state.inward_normal)
        return float(-np.dot(force, normal) / loaded_length_m)

    def servo(
        self,
        target_stress_pa: float,
        loaded_length_m: float,
        *,
        relaxation: float = 0.5,
        max_speed_m_per_s: float = 0.1,
    ) -> None:
        """Drives the wall along its inward normal to the target normal stress.

        PFC-style: each step ``u = G (sigma_target - sigma)``, with
        ``G = relaxation * length / (sum of contact kn * dt)``, capped at ``max_speed``.
        """
        self._engine.set_wall_servo(
            self.id, float(target_stress_pa), float(loaded_length_m), float(relaxation), float(max_speed_m_per_s)
        )

    def translate(self, displacement: ArrayLike) -> None:
        """Moves the wall at once by ``displacement`` (m), between steps."""
        self._engine.move_wall(self.id, list(_vector("displacement", displacement)))

    def __repr__(self) -> str:
        state = self.state
        return f"Wall(id={self.id}, kind={state.kind!r}, control={state.control!r})"


def _cell_of_snapshot(cell: PeriodicCell | None) -> dict[str, Any]:
    """A snapshot's ``box``, ``periodic`` and ``tilt`` of a periodic cell whose first
    vector lies along x; nothing for no cell or another one."""
    if cell is None or cell.a[1] != 0.0 or not any(cell.periodic):
        return {}
    (x0, y0), width, (lean, height) = cell.origin, cell.a[0], cell.b
    if not cell.periodic[1] and lean != 0.0:
        return {}
    return {
        "box": [[x0, x0 + width], [y0, y0 + height]],
        "periodic": cell.periodic,
        "tilt": lean,
    }


class Simulation:
    """A 2D disk DEM simulation (contacts with shear history and Coulomb friction,
    linear or Hertz-Mindlin per pair of material groups (:class:`ContactModel`),
    PFC local damping, leapfrog integration) run by the Rust engine.

    Parameters
    ----------
    positions : (N, 2) array, m
    radii : (N,) array, m, all > 0
    density : scalar or (N,) array, kg/m^3; required (the paper's Table 1 has the scaled
        density :data:`TABLE1_DENSITY_KG_PER_M3`, 2e8, which no real grain has)
    contact_model : model used between every pair of groups until
        :meth:`set_contact_model` says otherwise
    time_step : s; ``None`` picks ``time_step_safety`` (default
        :data:`DEFAULT_TIME_STEP_SAFETY`) times the critical step (:meth:`critical_time_step`)
    threads : worker threads (default: all cores); results are bitwise the
        same for every count (the work partition depends on the system only)
    local_damping : alpha of paper Eq. 5, in [0, 1)
    gravity : (gx, gy), m/s^2
    """

    def __init__(
        self,
        positions: ArrayLike,
        radii: ArrayLike,
        density: ArrayLike | None = None,
        *,
        contact_model: ContactModel | None = None,
        time_step: float | None = None,
        time_step_safety: float = DEFAULT_TIME_STEP_SAFETY,
        threads: int | None = None,
        local_damping: float = 0.0,
        gravity: ArrayLike = (0.0, 0.0),
    ) -> None:
        if density is None:
            raise ValueError(
                "density: give the grains' density in kg/m^3 (the paper's Table 1 uses the scaled "
                f"density grainlab.simulation.TABLE1_DENSITY_KG_PER_M3 = {TABLE1_DENSITY_KG_PER_M3:g})"
            )
        positions = _points("positions", positions)
        n = len(positions)
        radii = _values("radii", radii, n)
        density = _values("density", density, n)
        model = contact_model or ContactModel()
        threads = os.cpu_count() or 1 if threads is None else int(threads)
        if threads < 1:
            raise ValueError(f"threads: must be >= 1, got {threads}")
        provisional = 1.0 if time_step is None else float(time_step)
        self._engine = _core.Engine(
            positions,
            radii,
            density,
            float(model.normal_stiffness),
            float(model.shear_stiffness),
            float(model.friction),
            provisional,
            threads,
        )
        if model != ContactModel(model.normal_stiffness, model.shear_stiffness, model.friction):
            # dashpots, rolling resistance: the fields the engine's constructor does not take
            for a in range(MAX_GROUPS):
                for b in range(a, MAX_GROUPS):
                    self.set_contact_model(a, b, model)
        self._set_parameters(local_damping=local_damping, gravity=_vector("gravity", gravity))
        if time_step is None:
            self.time_step = self.critical_time_step(time_step_safety)

    # ---- construction helpers ----

    @classmethod
    def _from_engine(cls, engine: _core.Engine) -> Simulation:
        sim = cls.__new__(cls)
        sim._engine = engine
        return sim

    def _set_parameters(self, **changes: Any) -> None:
        p: dict[str, Any] = dict(self._engine.parameters)
        p.pop("skin")
        p.update(changes)
        self._engine.set_parameters(
            float(p["time_step"]), float(p["local_damping"]), list(p["gravity"]), float(p["max_overlap_ratio"])
        )

    def add_particles(self, positions: ArrayLike, radii: ArrayLike, density: ArrayLike) -> NDArray[np.int64]:
        """Appends disks at rest; returns their indices (the next ones). Existing
        contacts keep their history."""
        positions = _points("positions", positions)
        n = len(positions)
        first = self.n_particles
        self._engine.add_particles(positions, _values("radii", radii, n), _values("density", density, n))
        return np.arange(first, first + n)

    # ---- running ----

    def run(self, steps: int) -> None:
        """Runs ``steps`` steps in the engine (the loop stays in Rust; Ctrl-C
        interrupts between blocks of steps). The last step is measured:
        :attr:`energy`, :attr:`contact_count` and :attr:`unbalanced_force_ratio`
        refer to it."""
        steps = int(steps)
        if steps < 0:
            raise ValueError(f"steps: must be >= 0, got {steps}")
        self._engine.run(steps)

    def critical_time_step(self, safety: float = DEFAULT_TIME_STEP_SAFETY) -> float:
        """``safety * min_i min(sqrt(m_i / k_n,i), sqrt(I_i / (k_s,i r_i^2)))`` with the
        stiffnesses of each particle's current contacts summed (one contact of its
        stiffest model when it has none)."""
        return float(self._engine.critical_time_step(float(safety)))

    # ---- scalars ----

    @property
    def n_particles(self) -> int:
        return int(self._engine.n_particles)

    def __len__(self) -> int:
        return self.n_particles

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return float(self._engine.time)

    @property
    def step_count(self) -> int:
        return int(self._engine.step_count)

    @property
    def threads(self) -> int:
        """Worker threads; setting it, even mid-run, does not change any result."""
        return int(self._engine.threads)

    @threads.setter
    def threads(self, value: int) -> None:
        self._engine.set_threads(int(value))

    @property
    def time_step(self) -> float:
        """Time step (s)."""
        return float(self._engine.parameters["time_step"])

    @time_step.setter
    def time_step(self, value: float) -> None:
        self._set_parameters(time_step=float(value))

    @property
    def local_damping(self) -> float:
        """Local damping coefficient alpha (paper Eq. 5), in [0, 1)."""
        return float(self._engine.parameters["local_damping"])

    @local_damping.setter
    def local_damping(self, value: float) -> None:
        self._set_parameters(local_damping=float(value))

    @property
    def gravity(self) -> NDArray[np.float64]:
        return np.array(self._engine.parameters["gravity"])

    @gravity.setter
    def gravity(self, value: ArrayLike) -> None:
        self._set_parameters(gravity=_vector("gravity", value))

    @property
    def max_overlap_ratio(self) -> float:
        """An overlap above this fraction of the smaller radius stops the run."""
        return float(self._engine.parameters["max_overlap_ratio"])

    @max_overlap_ratio.setter
    def max_overlap_ratio(self, value: float) -> None:
        self._set_parameters(max_overlap_ratio=float(value))

    @property
    def skin(self) -> float:
        """Verlet skin (m); default 0.1 x the largest radius."""
        return float(self._engine.parameters["skin"])

    @skin.setter
    def skin(self, value: float) -> None:
        self._engine.set_skin(float(value))

    @property
    def neighbor_builds(self) -> int:
        """How many times the neighbour lists were built."""
        return int(self._engine.neighbor_builds)

    # ---- particle arrays (read-only copies; assign a whole array to change) ----

    positions = _ParticleArray[np.float64](
        """(N, 2) centres (m). Inside a periodic cell they are wrapped when the
        neighbour lists are rebuilt, so they may stray slightly outside between builds.
        Positions you set are a jump: the shear springs first take the last step's
        displacement and nothing from the jump (docs/contact-law.md).""",
        convert=_points,
    )
    velocities = _ParticleArray[np.float64](
        """(N, 2) velocities (m/s): half-step values v(n - 1/2) once stepped. Values
        you set are taken as full-step values: the next step kicks by dt/2 and adds
        no shear increment, and the shear springs first take the displacement the
        last step made at the old velocities (docs/contact-law.md).""",
        convert=_points,
    )
    rotations = _ParticleArray[np.float64](
        """(N,) rotation angles (rad, counter-clockwise).""", convert=_values
    )
    angular_velocities = _ParticleArray[np.float64](
        """(N,) angular velocities (rad/s, counter-clockwise).""", convert=_values
    )
    radii = _ParticleArray[np.float64](
        """(N,) radii (m); setting them updates masses and inertias.""", convert=_values
    )
    densities = _ParticleArray[np.float64]("""(N,) densities (kg/m^3).""", convert=_values)
    masses = _ParticleArray[np.float64]("""(N,) masses ``rho pi r^2`` (kg per m thickness).""")
    inertias = _ParticleArray[np.float64](
        """(N,) moments of inertia ``m r^2 / 2`` (kg m^2 per m thickness)."""
    )
    forces = _ParticleArray[np.float64](
        """(N, 2) resultant forces of the last step before damping (N)."""
    )
    torques = _ParticleArray[np.float64](
        """(N,) resultant torques of the last step before damping (N m)."""
    )
    external_forces = _ParticleArray[np.float64](
        """(N, 2) constant external forces applied every step (N).""", convert=_points
    )
    external_torques = _ParticleArray[np.float64](
        """(N,) constant external torques (N m).""", convert=_values
    )
    groups = _ParticleArray[np.uint8](
        """(N,) material groups in 0..15 (contact models are set per pair of groups).""",
        convert=_groups,
    )
    fixity = _ParticleArray[np.uint8](
        """(N,) prescribed degrees of freedom: sums of FIX_X (1), FIX_Y (2),
        FIX_ROTATION (4). A prescribed velocity keeps the value it has.""",
        convert=_fixity,
    )

    # ---- contact models ----

    def set_contact_model(self, group_a: int, group_b: int, model: ContactModel) -> None:
        """Sets the contact model between two material groups (both orders)."""
        self._engine.set_contact_model(
            int(group_a),
            int(group_b),
            float(model.normal_stiffness),
            float(model.shear_stiffness),
            float(model.friction),
            float(model.normal_damping_ratio),
            float(model.shear_damping_ratio),
            float(model.rolling_friction),
            float(model.rolling_stiffness),
            float(model.rolling_damping_ratio),
            bool(model.enabled),
            str(model.law),
            float(model.youngs_modulus),
            float(model.poisson_ratio),
            float(model.restitution),
        )

    def contact_model(self, group_a: int, group_b: int) -> ContactModel:
        return ContactModel(**self._engine.contact_model(int(group_a), int(group_b)))

    # ---- periodic cell ----

    def set_periodic_cell(
        self,
        lower: ArrayLike,
        upper: ArrayLike,
        periodic: tuple[bool, bool] = (True, True),
        *,
        tilt: float = 0.0,
    ) -> None:
        """A periodic cell ``[lower, upper)``; each side at least 3 x (largest
        diameter + skin) wide along its periodic directions.

        ``tilt`` (m) leans it into a parallelogram: the top edge is offset by
        ``tilt`` along x (LAMMPS's ``xy``), the cell vectors are ``a = (w, 0)``,
        ``b = (tilt, h)``. A cell sheared along x keeps ``|tilt| <= w / 2``: at
        each neighbour build the engine takes a whole ``a`` off ``b`` when it
        leans further (the same lattice of images; docs/engine.md, "Periodic
        cell")."""
        lo = _vector("lower", lower)
        hi = _vector("upper", upper)
        if not (hi[0] > lo[0] and hi[1] > lo[1]):
            raise ValueError(f"upper: must exceed lower in x and y, got lower={lo}, upper={hi}")
        flags = tuple(bool(p) for p in periodic)
        if len(flags) != 2:
            raise ValueError(f"periodic: expected two flags (x, y), got {periodic!r}")
        lean = float(tilt)
        if not np.isfinite(lean):
            raise ValueError(f"tilt: must be finite, got {tilt!r}")
        self._engine.set_cell(list(lo), [hi[0] - lo[0], 0.0], [lean, hi[1] - lo[1]], (flags[0], flags[1]))

    def set_velocity_gradient(self, gradient: ArrayLike) -> None:
        """Imposes a homogeneous deformation of the periodic cell: ``L[i][j] = dv_i/dx_j``
        (1/s). Particles are remapped affinely every step; their velocities are
        fluctuations about the flow ``L (x - origin)``."""
        g = np.ascontiguousarray(gradient, dtype=np.float64)
        if g.shape != (2, 2):
            raise ValueError(f"velocity_gradient: expected shape (2, 2), got {g.shape}")
        self._engine.set_velocity_gradient(g)

    @property
    def cell(self) -> PeriodicCell | None:
        """The periodic cell, or None."""
        cell = self._engine.cell
        return None if cell is None else PeriodicCell(**cell)

    # ---- walls ----

    def add_segment_wall(self, a: ArrayLike, b: ArrayLike, *, group: int = WALL_GROUP) -> Wall:
        """A straight wall from ``a`` to ``b`` (m); particles belong on its left side."""
        return Wall(self._engine, self._engine.add_segment_wall(list(_vector("a", a)), list(_vector("b", b)), int(group)))

    def add_line_wall(self, point: ArrayLike, normal: ArrayLike, *, group: int = WALL_GROUP) -> Wall:
        """An infinite one-sided wall through ``point`` with unit ``normal`` towards the particles."""
        return Wall(
            self._engine,
            self._engine.add_line_wall(list(_vector("point", point)), list(_vector("normal", normal)), int(group)),
        )

    @property
    def walls(self) -> list[Wall]:
        return [Wall(self._engine, k) for k in range(self._engine.n_walls)]

    def wall(self, wall_id: int) -> Wall:
        """The wall with id ``wall_id``."""
        n = self._engine.n_walls
        if not 0 <= int(wall_id) < n:
            raise ValueError(f"wall_id: unknown wall {wall_id}; valid ids are 0..{n - 1}")
        return Wall(self._engine, int(wall_id))

    # ---- follower loads ----

    def add_pressure_chain(
        self,
        particles: ArrayLike,
        pressure_pa: float,
        *,
        start_wall: Wall | int | None = None,
        end_wall: Wall | int | None = None,
    ) -> int:
        """A confining pressure on a chain of boundary particles that follows the
        boundary as it deforms (docs/boundary.md): particle ``k`` of the chain gets
        ``p / 2 * rotCW(x[k+1] - x[k-1])`` every step, pointing to the sample,
        which lies on the chain's right (walk the chain clockwise around the
        sample). The end particles carry the segment to their projection on
        ``start_wall`` / ``end_wall`` (e.g. the platens), so the loads sum to the
        pressure on the whole span. Returns the chain id."""
        return int(
            self._engine.add_pressure_chain(
                _index_list("particles", particles, self.n_particles),
                float(pressure_pa),
                _wall_id(start_wall),
                _wall_id(end_wall),
            )
        )

    def set_pressure_chain(
        self,
        chain_id: int,
        particles: ArrayLike,
        pressure_pa: float,
        *,
        start_wall: Wall | int | None = None,
        end_wall: Wall | int | None = None,
    ) -> None:
        """Replaces a pressure chain's particles, pressure and anchors (e.g. when the
        boundary particles are re-identified)."""
        self._engine.set_pressure_chain(
            int(chain_id),
            _index_list("particles", particles, self.n_particles),
            float(pressure_pa),
            _wall_id(start_wall),
            _wall_id(end_wall),
        )

    def pressure_chain(self, chain_id: int) -> PressureChainState:
        """A chain's ``particles`` (in order), ``pressure`` (Pa), ``start_wall``, ``end_wall``."""
        d = self._engine.pressure_chain(int(chain_id))
        return PressureChainState(list(d["particles"]), float(d["pressure"]), d["start_wall"], d["end_wall"])

    # ---- bonds ----

    def add_bond(
        self,
        i: int,
        j: int,
        normal_stiffness: float,
        shear_stiffness: float,
        rest_length: float | None = None,
    ) -> None:
        """Bonds particles ``i`` and ``j`` with linear normal and shear springs
        (N/m) that carry tension and never break; rest length defaults to their
        current distance. Bonded pairs are excluded from the frictional contact law."""
        self._engine.add_bond(int(i), int(j), float(normal_stiffness), float(shear_stiffness), rest_length)

    @property
    def n_bonds(self) -> int:
        return int(self._engine.n_bonds)

    def add_cement_bonds(
        self,
        i: ArrayLike,
        j: ArrayLike,
        *,
        normal_stiffness: ArrayLike,
        shear_stiffness: ArrayLike,
        tensile_strength: ArrayLike,
        cohesion: ArrayLike,
        friction_angle: ArrayLike = 0.0,
        radius_multiplier: ArrayLike = 1.0,
        kind: Literal["parallel", "contact"] = "parallel",
    ) -> None:
        """Cements the pairs ``(i[k], j[k])`` with bonds that break (docs/cemented.md),
        each stress-free at the pair's current distance and acting beside the
        contact law. ``kind="parallel"``: stiffnesses per area ``kn_bar``, ``ks_bar``
        (Pa/m), ``tensile_strength`` ``sigma_c`` and ``cohesion`` ``c`` (Pa),
        ``friction_angle`` ``phi_b`` (degrees), bond radius ``radius_multiplier`` times
        the smaller radius; ``kind="contact"``: stiffnesses in N/m, strengths in
        N, no moment. Each parameter is one value or one per pair (seeded
        strengths: :func:`grainlab.cement.draw_strengths`). Bad input is refused in one
        line before any bond is made (docs/cemented.md, "From Python")."""
        values = {
            "radius_multiplier": radius_multiplier,
            "normal_stiffness": normal_stiffness,
            "shear_stiffness": shear_stiffness,
            "tensile_strength": tensile_strength,
            "cohesion": cohesion,
            "friction_angle": friction_angle,
        }
        self._engine.add_cement_bonds(*cement_arguments(self.n_particles, i, j, kind, values))

    @property
    def n_cement_bonds(self) -> int:
        """Number of intact cement bonds."""
        return int(self._engine.n_cement_bonds)

    def cement_bonds(self) -> CementBonds:
        """The intact cement bonds, their forces and strengths (:class:`~grainlab.cement.CementBonds`)."""
        return CementBonds._from_engine(self._engine.cement_bonds())

    def take_bond_breaks(self) -> BondBreaks:
        """The cement bonds broken since the last call, in the order they broke
        (:class:`~grainlab.cement.BondBreaks`); the engine's log is emptied. The log
        is part of the saved state, so breaks not yet taken survive a checkpoint."""
        return BondBreaks._from_engine(self._engine.take_bond_breaks())

    # ---- bodies (docs/bodies.md) ----

    def add_bodies_by_label(self, labels: ArrayLike) -> list[int]:
        """Makes rigid bodies of the particles that share a label: ``labels`` (N,)
        integers, one per particle, -1 for a particle left as it is (as a file's
        body or molecule column gives them). The bodies are made in the order of
        their labels (:meth:`add_bodies`, frames at angle 0); returns the labels
        of the clumps made, in that order."""
        tags = np.asarray(labels)
        if tags.shape != (self.n_particles,) or tags.dtype.kind not in "iu":
            raise ValueError(
                f"labels: expected {self.n_particles} integers, one per particle, got {tags.dtype} {tags.shape}"
            )
        if tags.size and tags.min() < -1:
            k = int(np.argmin(tags))
            raise ValueError(f"labels[{k}]: a body label is >= 0 (or -1 for none), got {int(tags[k])}")
        names = [int(t) for t in np.unique(tags[tags >= 0])]
        groups = [np.flatnonzero(tags == t).tolist() for t in names]
        self.add_bodies(groups)
        return [t for t, g in zip(names, groups, strict=True) if len(g) > 1]

    def add_bodies(
        self,
        pebbles: Sequence[Sequence[int]],
        *,
        angles: ArrayLike | None = None,
        masses: Sequence[tuple[float, float, ArrayLike] | None] | None = None,
    ) -> None:
        """Makes rigid bodies of existing particles: ``pebbles[b]`` the particle
        indices of body ``b`` (one index leaves a disk as it is; two or more make
        a clump, moved as one rigid body with no contact between its pebbles).

        angles : (B,) each body frame's angle in the world (rad, default 0)
        masses : per body None (the exact union's mass and moment of inertia at
            the pebbles' common density) or ``(mass kg/m, moment of inertia
            kg m^2/m, centroid (2,) m)``

        A clump starts with the rigid motion of its pebbles' momentum and angular
        momentum. What is refused, in one line before any change: docs/bodies.md,
        "Clumps in a simulation".
        """
        lists = [[int(q) for q in body] for body in pebbles]
        for b, body in enumerate(lists):
            bad = [q for q in body if not 0 <= q < self.n_particles]
            if bad:
                raise ValueError(
                    f"bodies[{b}].pebbles: particle index {bad[0]} out of range 0..{self.n_particles - 1}"
                )
        n = len(lists)
        turns = [0.0] * n if angles is None else [float(a) for a in _values("angles", angles, n)]
        given: list[tuple[float, float, float, float] | None] = []
        for b, mass in enumerate([None] * n if masses is None else list(masses)):
            if mass is None:
                given.append(None)
                continue
            m, inertia, centroid = mass
            x, y = _vector(f"masses[{b}].centroid", centroid)
            given.append((float(m), float(inertia), x, y))
        if len(given) != n:
            raise ValueError(f"masses: expected {n} entries, one per body, got {len(given)}")
        self._engine.add_bodies(lists, turns, given)

    def add_clumps(
        self,
        offsets: ArrayLike,
        radii: ArrayLike,
        *,
        positions: ArrayLike,
        angles: ArrayLike,
        density: float,
    ) -> NDArray[np.int64]:
        """Appends one clump of a template per placement: the template's pebbles
        (``offsets`` (K, 2) m in its own frame, ``radii`` (K,) m) at
        ``positions[c] + R(angles[c]) offsets`` (positions (C, 2) m, angles (C,)
        rad), each clump's frame turned by its angle. Returns the new particles'
        indices, K per clump in order."""
        template = _points("offsets", offsets)
        k = len(template)
        sizes = _values("radii", radii, k)
        where = _points("positions", positions)
        turns = _values("angles", angles, len(where))
        clump_mass_properties(template, sizes, density=density)  # refuses a bad template first
        c, s = np.cos(turns), np.sin(turns)
        world = np.empty((len(where), k, 2))
        world[..., 0] = where[:, None, 0] + c[:, None] * template[:, 0] - s[:, None] * template[:, 1]
        world[..., 1] = where[:, None, 1] + s[:, None] * template[:, 0] + c[:, None] * template[:, 1]
        first = self.n_particles
        count = k * len(where)
        added = self.add_particles(world.reshape(-1, 2), np.tile(sizes, len(where)), np.full(count, float(density)))
        self.add_bodies([list(range(first + k * b, first + k * (b + 1))) for b in range(len(where))], angles=turns)
        return added

    @property
    def body_of_particles(self) -> NDArray[np.int64]:
        """The body of every particle: the clumps are bodies ``0..len(clumps)`` in
        the order they were made, then every disk is a body of its own."""
        return _readonly(np.asarray(self._engine.body_of_particles, dtype=np.int64))

    @property
    def grain_centroids(self) -> NDArray[np.float64]:
        """Every particle's grain centroid (N, 2), m: its clump's centroid for a pebble,
        its own centre for a disk (the origin of a grain's contact levers in the
        Love-Weber stress, docs/bodies.md)."""
        clumps = self.clumps
        centroid = np.array(self.positions)
        if len(clumps):
            body = self.body_of_particles
            pebble = body < len(clumps)
            centroid[pebble] = clumps.centroid_m[body[pebble]]
        return centroid

    @property
    def clumps(self) -> ClumpState:
        """The clumps' centroids, angles, velocities, masses and last resultants."""
        return ClumpState._from_engine(self._engine.clumps)

    def set_clump_velocities(self, velocities: ArrayLike, angular_velocities: ArrayLike) -> None:
        """Sets every clump's velocity (C, 2) m/s and angular velocity (C,) rad/s
        (full-step values, as :attr:`velocities`); its pebbles follow."""
        n = len(self.clumps)
        v = _points("velocities", velocities)
        if len(v) != n:
            raise ValueError(f"velocities: has {len(v)} rows but there are {n} clumps")
        self._engine.set_clump_velocities(v, _values("angular_velocities", angular_velocities, n))

    def scale_clumps(self, factors: ArrayLike) -> None:
        """Grows every clump by ``factors`` (C,) about its centroid: a similar body
        of the same density (pebble radii and offsets times the factor, mass times
        its square, moment of inertia times its fourth power), as radius expansion
        grows the disks (:attr:`radii`)."""
        self._engine.scale_clumps(_values("factors", factors, len(self.clumps)))

    # ---- contacts and diagnostics ----

    def contacts(self) -> Contacts:
        """Current particle-particle contacts (overlap > 0) and bonds, with the forces
        the next step will apply (the state is not changed)."""
        d = self._engine.contacts()
        # the engine reports both on j (0 - M: a moment of 0 stays +0)
        d["shear_force"] = -d["shear_force"]
        d["rolling_moment"] = 0.0 - d["rolling_moment"]
        return Contacts(**{k: _readonly(v) for k, v in d.items()})

    def wall_contacts(self) -> WallContacts:
        """Current particle-wall contacts, with the forces the next step will apply."""
        d = self._engine.wall_contacts()
        # the engine's normal points from the wall to the particle, its shear along rot90 of
        # that; its rolling moment is on the particle already
        d["normal"] = -d["normal"]
        d["shear_force"] = -d["shear_force"]
        return WallContacts(**{k: _readonly(v) for k, v in d.items()})

    @property
    def contact_count(self) -> int:
        """Particle-particle contacts at the last measured step."""
        return int(self._engine.measurements["contact_count"])

    @property
    def coordination_number(self) -> float:
        """``2 Nc / Np`` at the last measured step (particle-particle contacts only)."""
        return 2.0 * self.contact_count / max(self.n_particles, 1)

    @property
    def unbalanced_force_ratio(self) -> float:
        """Mean |resultant| over free particles / mean |contact force| (PFC's ratio), last measured step."""
        return float(self._engine.measurements["mean_unbalanced_force_ratio"])

    @property
    def energy(self) -> Energy:
        """The energy ledger (:class:`Energy`)."""
        return Energy(**self._engine.energy)

    def snapshot(self, *, kind: ArrayLike | None = None, **metadata: Any) -> Snapshot:
        """The current state as an analysis :class:`~grainlab.snapshot.Snapshot`.

        Contacts and wall contacts are in the snapshot's convention already
        (:meth:`contacts`, :meth:`wall_contacts`). ``kind`` gives each
        particle's :class:`~grainlab.snapshot.ParticleKind`; ``metadata`` may set
        ``time``, ``axial_strain`` and ``scalars`` (the run's control variables,
        :attr:`Snapshot.scalars`) and any other key. The particles'
        ``velocity`` (m/s, (N, 2)) and ``angular_velocity`` (rad/s, (N,)) travel
        as ``particle_fields``. A periodic cell whose first vector lies along x
        (an axis-aligned cell, or one leaned by simple shear along x) gives the
        snapshot its ``box``, ``periodic`` and ``tilt`` (the x of the second
        vector), so that branch vectors take the nearest image.
        """
        c = self.contacts()
        w = self.wall_contacts()
        time = metadata.pop("time", self.time)
        axial_strain = metadata.pop("axial_strain", None)
        scalars = metadata.pop("scalars", None)
        return Snapshot.from_engine_arrays(
            self.positions,
            self.radii,
            rotations=self.rotations,
            contact_i=c.i,
            contact_j=c.j,
            contact_point=c.point,
            contact_normal=c.normal,
            normal_force=c.normal_force,
            shear_force=c.shear_force,
            overlap=c.overlap,
            sliding=c.sliding,
            bonded=c.bonded,
            wall_i=w.particle,
            wall_id=w.wall,
            wall_point=w.point,
            wall_normal=w.normal,
            wall_normal_force=w.normal_force,
            wall_shear_force=w.shear_force,
            wall_overlap=w.overlap,
            wall_sliding=w.sliding,
            time=time,
            axial_strain=axial_strain,
            scalars=scalars,
            kind=kind,
            **_cell_of_snapshot(self.cell),
            particle_fields={
                "velocity": self.velocities,
                "angular_velocity": self.angular_velocities,
                **self._grain_fields(),
            },
            metadata=metadata,
        )

    def _grain_fields(self) -> dict[str, NDArray[Any]]:
        """The snapshot's grain fields (:data:`~grainlab.snapshot.GRAIN_FIELD`): every
        particle's body, and its body's centroid and angle (a disk's own centre and
        rotation); none without clumps, so that a disks' snapshot is as before."""
        clumps = self.clumps
        if not len(clumps):
            return {}
        body = self.body_of_particles
        pebble = body < len(clumps)
        angle = np.array(self.rotations)
        angle[pebble] = clumps.angle_rad[body[pebble]]
        return {GRAIN_FIELD: body, GRAIN_CENTROID_FIELD: self.grain_centroids, GRAIN_ANGLE_FIELD: angle}

    # ---- state ----

    def to_bytes(self) -> bytes:
        """The complete engine state (contact history and neighbour lists included)."""
        return bytes(self._engine.to_bytes())

    @classmethod
    def from_bytes(cls, data: bytes) -> Simulation:
        """Restores :meth:`to_bytes`; the run continues bitwise identically (on any thread count)."""
        return cls._from_engine(_core.Engine.from_bytes(data))

    def save(self, path: str | os.PathLike[str]) -> None:
        """Writes the complete state to ``path`` atomically (a temporary file, then a rename)."""
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        with open(tmp, "wb") as f:
            f.write(_STATE_MAGIC)
            f.write(self.to_bytes())
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Simulation:
        """Reads a state written by :meth:`save`."""
        data = Path(path).read_bytes()
        if not data.startswith(_STATE_MAGIC):
            raise ValueError(f"{path}: not a grainlab engine state file")
        return cls.from_bytes(data[len(_STATE_MAGIC) :])

    def __repr__(self) -> str:
        return (
            f"Simulation(n_particles={self.n_particles}, time_step={self.time_step:.3e}, "
            f"threads={self.threads}, step_count={self.step_count})"
        )
