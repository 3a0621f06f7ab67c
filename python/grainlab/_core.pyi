"""Types of the compiled engine module ``grainlab._core`` (crates/grainlab-py).

The engine's own API is :class:`grainlab.Simulation`; this module is the thin
glue it wraps. Per-particle arrays are in the user's particle order, copies
marked read-only; arrays passed in must be C-contiguous NumPy arrays of the
dtype given (float64, uint8, int64, bool). Units are SI (docs/conventions.md).
"""

from collections.abc import Sequence
from typing import Any, Literal, TypedDict, final

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "__version__",
    "MAX_GROUPS",
    "SimulationUnstableError",
    "Engine",
    "density_scaling_factor",
    "detect_contacts",
    "contact_normals",
    "stability_index",
    "stability_index_of_contacts",
    "angular_histogram",
    "fourier_moment",
    "fabric_tensor",
    "rattlers",
    "clump_mass_properties",
]

__version__: str
#: Number of material groups: groups are ``0..MAX_GROUPS``.
MAX_GROUPS: int

class SimulationUnstableError(RuntimeError):
    """The simulation blew up (NaN or runaway overlap); the message names the particles."""

# The dicts the engine returns (names private: they exist only for the type checker).

class _Parameters(TypedDict):
    time_step: float
    local_damping: float
    gravity: tuple[float, float]
    max_overlap_ratio: float
    skin: float

class _ContactModel(TypedDict):
    normal_stiffness: float
    shear_stiffness: float
    friction: float
    normal_damping_ratio: float
    shear_damping_ratio: float
    rolling_friction: float
    rolling_stiffness: float
    rolling_damping_ratio: float
    enabled: bool
    law: str
    youngs_modulus: float
    poisson_ratio: float
    restitution: float

class _Cell(TypedDict):
    origin: tuple[float, float]
    a: tuple[float, float]
    b: tuple[float, float]
    periodic: tuple[bool, bool]
    velocity_gradient: tuple[tuple[float, float], tuple[float, float]]
    area: float

class _WallState(TypedDict, total=False):
    # every wall: kind, inward_normal, velocity, force, contact_count,
    # displacement, group, active, control; a segment has a and b, a line
    # point and normal; a servo wall its four servo parameters
    kind: Literal["segment", "line"]
    a: tuple[float, float]
    b: tuple[float, float]
    point: tuple[float, float]
    normal: tuple[float, float]
    inward_normal: tuple[float, float]
    velocity: tuple[float, float]
    force: tuple[float, float]
    contact_count: int
    displacement: tuple[float, float]
    group: int
    active: bool
    control: Literal["velocity", "servo"]
    target_stress: float
    loaded_length: float
    relaxation: float
    max_speed: float

class _PressureChain(TypedDict):
    particles: list[int]
    pressure: float
    start_wall: int | None
    end_wall: int | None

class _ContactArrays(TypedDict):
    # one row per contact
    point: NDArray[np.float64]
    normal: NDArray[np.float64]
    overlap: NDArray[np.float64]
    normal_force: NDArray[np.float64]
    shear_force: NDArray[np.float64]
    sliding: NDArray[np.bool_]
    rolling_moment: NDArray[np.float64]
    normal_stiffness: NDArray[np.float64]

class _Contacts(_ContactArrays):
    i: NDArray[np.uint32]
    j: NDArray[np.uint32]
    bonded: NDArray[np.bool_]

class _WallContacts(_ContactArrays):
    wall: NDArray[np.uint32]
    particle: NDArray[np.uint32]

class _Measurements(TypedDict):
    step: int
    contact_count: int
    wall_contact_count: int
    mean_unbalanced_force_ratio: float

class _Energy(TypedDict):
    kinetic: float
    elastic: float
    friction_dissipated: float
    viscous_dissipated: float
    rolling_dissipated: float
    damping_dissipated: float
    wall_work: float
    external_work: float
    boundary_work: float
    bond_released: float
    balance: float

#: A 2-vector argument: any sequence of two floats (a tuple, a list, a NumPy array).
_Point = Sequence[float] | NDArray[np.float64]

@final
class Engine:
    """The engine's simulation state and step."""

    def __new__(
        cls,
        positions: NDArray[np.float64],
        radii: NDArray[np.float64],
        density: NDArray[np.float64],
        normal_stiffness: float,
        shear_stiffness: float,
        friction: float,
        time_step: float,
        threads: int,
    ) -> Engine: ...
    def add_particles(
        self,
        positions: NDArray[np.float64],
        radii: NDArray[np.float64],
        density: NDArray[np.float64],
    ) -> None: ...

    # running
    def run(self, steps: int) -> None: ...
    def critical_time_step(self, safety: float) -> float: ...
    @property
    def step_count(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def threads(self) -> int: ...
    def set_threads(self, threads: int) -> None: ...
    @property
    def neighbor_builds(self) -> int: ...
    @property
    def n_particles(self) -> int: ...

    # parameters
    @property
    def parameters(self) -> _Parameters: ...
    def set_parameters(
        self, time_step: float, local_damping: float, gravity: _Point, max_overlap_ratio: float
    ) -> None: ...
    def set_skin(self, skin: float) -> None: ...
    def set_contact_model(
        self,
        group_a: int,
        group_b: int,
        normal_stiffness: float,
        shear_stiffness: float,
        friction: float,
        normal_damping_ratio: float,
        shear_damping_ratio: float,
        rolling_friction: float = 0.0,
        rolling_stiffness: float = 0.0,
        rolling_damping_ratio: float = 0.0,
        enabled: bool = True,
        law: str = "linear",
        youngs_modulus: float = 0.0,
        poisson_ratio: float = 0.0,
        restitution: float = 1.0,
    ) -> None: ...
    def contact_model(self, group_a: int, group_b: int) -> _ContactModel: ...

    # particle state: (N, 2) and (N,) arrays
    @property
    def positions(self) -> NDArray[np.float64]: ...
    @property
    def velocities(self) -> NDArray[np.float64]: ...
    @property
    def forces(self) -> NDArray[np.float64]: ...
    @property
    def external_forces(self) -> NDArray[np.float64]: ...
    @property
    def rotations(self) -> NDArray[np.float64]: ...
    @property
    def angular_velocities(self) -> NDArray[np.float64]: ...
    @property
    def torques(self) -> NDArray[np.float64]: ...
    @property
    def external_torques(self) -> NDArray[np.float64]: ...
    @property
    def radii(self) -> NDArray[np.float64]: ...
    @property
    def densities(self) -> NDArray[np.float64]: ...
    @property
    def masses(self) -> NDArray[np.float64]: ...
    @property
    def inertias(self) -> NDArray[np.float64]: ...
    @property
    def groups(self) -> NDArray[np.uint8]: ...
    @property
    def fixity(self) -> NDArray[np.uint8]: ...
    def set_positions(self, positions: NDArray[np.float64]) -> None: ...
    def set_velocities(self, velocities: NDArray[np.float64]) -> None: ...
    def set_external_forces(self, external_forces: NDArray[np.float64]) -> None: ...
    def set_rotations(self, rotations: NDArray[np.float64]) -> None: ...
    def set_angular_velocities(self, angular_velocities: NDArray[np.float64]) -> None: ...
    def set_external_torques(self, external_torques: NDArray[np.float64]) -> None: ...
    def set_radii(self, radii: NDArray[np.float64]) -> None: ...
    def set_densities(self, densities: NDArray[np.float64]) -> None: ...
    def set_groups(self, groups: NDArray[np.uint8]) -> None: ...
    def set_fixity(self, fixity: NDArray[np.uint8]) -> None: ...

    # periodic cell
    def set_cell(self, origin: _Point, a: _Point, b: _Point, periodic: tuple[bool, bool]) -> None: ...
    def clear_cell(self) -> None: ...
    def set_velocity_gradient(self, gradient: NDArray[np.float64]) -> None: ...
    @property
    def cell(self) -> _Cell | None: ...

    # walls
    def add_segment_wall(self, a: _Point, b: _Point, group: int) -> int: ...
    def add_line_wall(self, point_on_line: _Point, normal: _Point, group: int) -> int: ...
    @property
    def n_walls(self) -> int: ...
    def set_wall_velocity(self, wall_id: int, velocity: _Point) -> None: ...
    def set_wall_servo(
        self,
        wall_id: int,
        target_stress: float,
        loaded_length: float,
        relaxation: float,
        max_speed: float,
    ) -> None: ...
    def move_wall(self, wall_id: int, displacement: _Point) -> None: ...
    def wall_state(self, wall_id: int) -> _WallState: ...
    def set_wall_active(self, wall_id: int, active: bool) -> None: ...

    # pressure chains
    def add_pressure_chain(
        self,
        particles: Sequence[int],
        pressure: float,
        start_wall: int | None = None,
        end_wall: int | None = None,
    ) -> int: ...
    def set_pressure_chain(
        self,
        chain_id: int,
        particles: Sequence[int],
        pressure: float,
        start_wall: int | None = None,
        end_wall: int | None = None,
    ) -> None: ...
    def pressure_chain(self, chain_id: int) -> _PressureChain: ...
    @property
    def n_pressure_chains(self) -> int: ...

    # bonds
    def add_bond(
        self,
        i: int,
        j: int,
        normal_stiffness: float,
        shear_stiffness: float,
        rest_length: float | None = None,
    ) -> None: ...
    @property
    def n_bonds(self) -> int: ...

    # cement (breakable bonds)
    def add_cement_bonds(
        self,
        i: NDArray[np.int64],
        j: NDArray[np.int64],
        kind: str,
        radius_multiplier: NDArray[np.float64],
        normal_stiffness: NDArray[np.float64],
        shear_stiffness: NDArray[np.float64],
        tensile_strength: NDArray[np.float64],
        cohesion: NDArray[np.float64],
        friction_angle: NDArray[np.float64],
    ) -> None: ...
    @property
    def n_cement_bonds(self) -> int: ...
    def cement_bonds(self) -> dict[str, Any]: ...
    def take_bond_breaks(self) -> dict[str, Any]: ...

    # bodies
    def add_bodies(
        self,
        pebbles: list[list[int]],
        angles: list[float],
        masses: list[tuple[float, float, float, float] | None],
    ) -> None: ...
    @property
    def body_of_particles(self) -> NDArray[np.uint32]: ...
    @property
    def clumps(self) -> dict[str, NDArray[Any]]: ...
    def set_clump_velocities(
        self, velocities: NDArray[np.float64], angular_velocities: NDArray[np.float64]
    ) -> None: ...
    def scale_clumps(self, factors: NDArray[np.float64]) -> None: ...

    # contacts and diagnostics
    def contacts(self) -> _Contacts: ...
    def wall_contacts(self) -> _WallContacts: ...
    @property
    def measurements(self) -> _Measurements: ...
    @property
    def energy(self) -> _Energy: ...

    # state
    def to_bytes(self) -> bytes: ...
    @staticmethod
    def from_bytes(data: bytes) -> Engine: ...

def density_scaling_factor(
    strain_rate: float, density: float, min_radius: float, pressure: float
) -> float:
    """The Eq. 16 density scaling factor ``I = strain_rate * sqrt(density * r_min^2 / pressure)``."""

# analysis kernels (crates/grainlab-py/src/analysis.rs); threads = 0: all cores

def detect_contacts(
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
    tolerance: float,
    x_period: tuple[float, float] | None,
    y_period: tuple[float, float] | None,
    threads: int,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Contact pairs ``(i, j)`` from geometry: centre distance ``< r_i + r_j + tolerance``."""

def contact_normals(
    positions: NDArray[np.float64],
    contact_i: NDArray[np.int64],
    contact_j: NDArray[np.int64],
    x_length: float | None,
    y_length: float | None,
    threads: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit normals ``(Nc, 2)`` from ``i`` towards ``j`` and their angles ``(Nc,)`` in ``[0, 2 pi)``."""

def stability_index(
    owner: NDArray[np.int64], angles: NDArray[np.float64], n_particles: int, threads: int
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """lambda ``(N,)`` and contact counts ``(N,)`` from contact ends (owner, angle)."""

def stability_index_of_contacts(
    contact_i: NDArray[np.int64],
    contact_j: NDArray[np.int64],
    angles: NDArray[np.float64],
    n_particles: int,
    threads: int,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """lambda ``(N,)`` and contact counts ``(N,)`` from particle-particle contacts."""

def angular_histogram(
    angles: NDArray[np.float64],
    weights: NDArray[np.float64] | None,
    bins: int,
    edge_tolerance: float,
    threads: int,
) -> NDArray[np.float64]:
    """Histogram ``(bins,)`` of contact normals, each counted in both directions."""

def fourier_moment(
    angles: NDArray[np.float64], weights: NDArray[np.float64] | None, threads: int
) -> tuple[float, float, float]:
    """``(sum w sin 2 theta, sum w cos 2 theta, sum w)``."""

def fabric_tensor(
    normals: NDArray[np.float64], weights: NDArray[np.float64] | None, threads: int
) -> tuple[NDArray[np.float64], float]:
    """The fabric tensor ``(2, 2)`` and the weight total."""

def rattlers(
    contact_i: NDArray[np.int64],
    contact_j: NDArray[np.int64],
    n_particles: int,
    min_contacts: int,
    candidates: NDArray[np.bool_] | None,
    threads: int,
) -> NDArray[np.bool_]:
    """``(N,)`` bool mask of the rattlers, removed iteratively."""

# bodies (crates/grainlab-py/src/body.rs)

def clump_mass_properties(
    offsets: NDArray[np.float64], radii: NDArray[np.float64], density: float
) -> tuple[float, float, tuple[float, float], float, NDArray[np.float64]]:
    """The clump's union area (m^2), mass (kg per m), centroid (m), moment of
    inertia about it (kg m^2 per m) and its pebbles' offsets from the centroid."""
