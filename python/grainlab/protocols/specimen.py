"""What every test that makes a sample and consolidates it shares: the run
state's common part (:class:`SpecimenRun`), the sample's generation by radius
expansion (:func:`generate`, the ``sample.*`` keys) and the isotropic
consolidation in four servo-controlled walls (:func:`consolidate`, the
``consolidation.*`` keys), and the outputs written from a finished ``run.h5``
(:func:`write_run_outputs`), and the grains' contact law (:func:`contact_law`,
:func:`grain_model`). The biaxial test, the oedometer and the cyclic test start
with the generation and the consolidation; simple shear generates its sample
through :class:`SpecimenProtocol` and consolidates it in its periodic cell."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Self, TypeVar

import numpy as np
from numpy.typing import NDArray

import grainlab
from grainlab._cores import available_cores
from grainlab._interrupt import raise_if_interrupted
from grainlab._progress import progress_bar
from grainlab.analysis import fabric_summary
from grainlab.analysis.stress import love_weber_stress
from grainlab.io.results import RESULTS_FILE, timeseries_csv, write_json_atomic, write_text_atomic
from grainlab.protocols.config import Config, grain_shape
from grainlab.protocols.consolidate import BOX_WALLS, BoxState, servo_box
from grainlab.protocols.grains import clump_summary, grain_coordination, grain_count, grain_porosity
from grainlab.protocols.runner import (
    Protocol,
    ProtocolError,
    RunResult,
    RunState,
    Stage,
    StageContext,
)
from grainlab.samples import (
    PAPER_GRADING,
    GradingCurve,
    UniformByMass,
    UniformByNumber,
    expand_to_porosity,
    overlap_corrected_porosity,
)
from grainlab.simulation import ContactModel, Contacts, Simulation
from grainlab.snapshot import Snapshot

if TYPE_CHECKING:
    from grainlab.plot.workers import FigureTask

__all__ = ["CHUNK_STEPS", "CONSOLIDATE", "OUTPUT_FILES", "ConfiguredProtocol", "SpecimenError", "SpecimenProtocol",
           "SpecimenRun", "add_cement", "cement_sample",
           "consolidate",
           "damped_time_step_factor", "engine_columns",
           "engine_threads", "generate", "grain_model", "grain_columns", "platen_model", "run_summary",
           "write_run_outputs"]

#: Steps per engine call while a phase waits for a condition.
CHUNK_STEPS = 2000
#: A test's outputs besides run.h5 (``report.html`` is the command's): a new run refuses a
#: folder that already holds one, which another run or the user wrote.
OUTPUT_FILES = ("timeseries.csv", "summary.json", "report.html", "fig[0-9][0-9]_*.png", "fig[0-9][0-9]_*.svg")


class SpecimenError(ProtocolError):
    """The sample could not be made or consolidated (e.g. consolidation did not converge)."""


@dataclass
class SpecimenRun:
    """What every test's run state starts with (saved in every checkpoint): the
    phase, the grain count and density, the walls by name (engine ids), the wall
    time of each stage, the generated sample's numbers and the consolidation's."""

    phase: str
    n_grains: int
    grain_density: float
    walls: dict[str, int]
    wall_time: dict[str, float]
    sample: dict[str, Any]
    consolidation: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, saved: dict[str, Any]) -> Self:
        """The state :meth:`to_dict` gave."""
        return cls(**saved)


R = TypeVar("R", bound=SpecimenRun)
S = TypeVar("S", bound=RunState)
Result = TypeVar("Result", bound=RunResult)
C = TypeVar("C", bound=Config)


class ConfiguredProtocol(Protocol[C, S, Result]):
    """A protocol whose configuration is a :class:`Config` of the schema named as the
    protocol and whose state is of type :attr:`state_type`; it writes
    :data:`OUTPUT_FILES`, sums up with :attr:`summarise` and returns a
    :attr:`result_type`. Its subclass says how a run starts (:meth:`start`)."""

    state_type: ClassVar[type[Any]]
    output_files: ClassVar[tuple[str, ...]] = OUTPUT_FILES
    #: The summary of a run whose stages have all run: ``(state, config, time series, wall time)``.
    summarise: ClassVar[Callable[[Any, Any, dict[str, NDArray[np.float64]], float], dict[str, Any]]]
    #: The outputs written from the final ``run.h5``; returns the summary.
    outputs: ClassVar[Callable[[Path], dict[str, Any]]]
    #: What a run returns, from its folder and its summary.
    result_type: ClassVar[type[RunResult]]

    def threads(self) -> int:
        return engine_threads(self.config)

    def config_dict(self) -> dict[str, Any]:
        return self.config.to_dict()

    def resolve_saved(self, saved: Any) -> dict[str, Any] | None:
        try:
            return Config.from_dict(saved, self.name).to_dict()
        except (ValueError, TypeError, AttributeError):
            return None

    def state_from_dict(self, saved: Mapping[str, Any]) -> S:
        state: S = self.state_type.from_dict(dict(saved))
        return state

    def summary(self, context: StageContext[C, S], wall_time_s: float) -> dict[str, Any]:
        return type(self).summarise(context.state, self.config, context.writer.read_timeseries(), wall_time_s)

    def write_outputs(self, out: Path) -> dict[str, Any]:
        return type(self).outputs(out)

    def result(self, out: Path, summary: dict[str, Any]) -> Result:
        return type(self).result_type(out, summary)  # type: ignore[return-value]  # result_type is Result's class


class SpecimenProtocol(ConfiguredProtocol[C, R, Result]):
    """A :class:`ConfiguredProtocol` whose run starts by making the sample
    (:func:`generate`) into a state of type :attr:`state_type`, in the first stage's phase."""

    def start(self, threads: int, progress: bool) -> tuple[Simulation, R]:
        sim, run = generate(self.config, threads, progress, self.state_type, self.stages[0].name)
        return sim, run  # state_type is R's class


def grading(config: Config) -> UniformByNumber | UniformByMass | GradingCurve:
    kind = config.sample.grading
    d_min, d_max = config.sample.d_min, config.sample.d_max
    if kind == "uniform_by_number":
        return UniformByNumber(d_min, d_max)
    if kind == "uniform_by_mass":
        return UniformByMass(d_min, d_max)
    if kind == "curve":
        return GradingCurve(config.sample.sieve_sizes, config.sample.percent_passing)
    if (d_min, d_max) != (PAPER_GRADING.d_min, PAPER_GRADING.d_max):
        raise ValueError(
            "sample.grading: 'paper' is the 0.5-3 mm curve; with other sample.d_min/d_max "
            "choose 'uniform_by_number' or 'uniform_by_mass'"
        )
    return PAPER_GRADING


def engine_threads(config: Config) -> int:
    threads = config.run.threads
    return available_cores() if threads == "auto" else int(threads)


def _with_rolling(config: Config, model: ContactModel) -> ContactModel:
    """``model`` with the rolling resistance of ``config`` (off by default; a
    stiffness of 0 is the engine's rule, ``auto``)."""
    stiffness = config.material.rolling_stiffness
    return replace(
        model,
        rolling_friction=float(config.material.rolling_friction),
        rolling_stiffness=0.0 if stiffness == "auto" else float(stiffness),
        rolling_damping_ratio=float(config.material.rolling_damping),
    )


def damped_time_step_factor(config: Config) -> float:
    """What the contact dashpots (``material.contact_damping`` = zeta) take off the
    critical time step of central differences, ``sqrt(1 + z^2) - z`` for a mode
    damped at z of critical (exactly 1 without them). The shear dashpot damps the
    contact's sliding-and-rolling mode at z = sqrt(3) zeta: its coefficient is set
    with the pair's reduced mass m*, while that mode moves the mass m*/3 (each
    disk's 1/m + r^2/I = 3/m). That mode sets the factor, so that a run whose
    dashpots act after it consolidated is stable with the time step set then."""
    z = math.sqrt(3.0) * float(config.material.contact_damping)
    return math.sqrt(1.0 + z * z) - z


def contact_law(config: Config, friction: float) -> ContactModel:
    """The contact law of ``material.contact_law`` at Coulomb friction ``friction``:
    the linear springs ``material.normal_stiffness``/``shear_stiffness``, or
    Hertz-Mindlin from ``material.youngs_modulus``, ``poisson_ratio`` and
    ``restitution`` (docs/contact-law.md). The sample's radius expansion and the
    membrane's disks keep the linear springs: the first is geometry, the second a
    numerical boundary."""
    if config.material.contact_law == "hertz_mindlin":
        return ContactModel.hertz_mindlin(
            float(config.material.youngs_modulus), float(config.material.poisson_ratio),
            float(config.material.restitution), float(friction),
        )
    return ContactModel(config.material.normal_stiffness, config.material.shear_stiffness, friction)


def grain_model(config: Config) -> ContactModel:
    """The grains' contact law: Table 1's, with the rolling resistance and the contact
    dashpots of ``config`` (the platens' contacts have no dashpots: a dashpot's force
    on a moving servo wall would feed back into its control)."""
    damping = float(config.material.contact_damping)
    model = _with_rolling(config, contact_law(config, config.material.friction))
    return replace(model, normal_damping_ratio=damping, shear_damping_ratio=damping)


def platen_model(config: Config) -> ContactModel:
    """The grains' law at the platens (and the box's walls), without a dashpot
    (Hertz-Mindlin's restitution 1): a dashpot's force on a servo wall follows the
    wall's own velocity and feeds back into its control, which then never settles."""
    model = contact_law(config, config.material.platen_friction)
    return _with_rolling(config, replace(model, restitution=1.0))


def generate(config: Config, threads: int, progress: bool, state: type[R], phase: str,
             **fields: Any) -> tuple[Simulation, R]:
    """The sample of ``config`` made by radius expansion in four rigid walls (bottom,
    right, top, left), and a new run state of type ``state`` in ``phase`` (its own
    ``fields`` besides :class:`SpecimenRun`'s)."""
    start = time.perf_counter()
    box = (0.0, 0.0, config.sample.width, config.sample.height)
    sample = expand_to_porosity(
        box,
        config.sample.porosity,
        grading(config),
        seed=config.sample.seed,
        friction=config.sample.generation_friction,
        wall_friction=config.material.platen_friction,
        normal_stiffness=config.material.normal_stiffness,
        shear_stiffness=config.material.shear_stiffness,
        density=config.material.density,
        local_damping=config.material.local_damping,
        max_stress_pa=config.sample.max_generation_stress,
        threads=threads,
        progress=progress,
        keep_simulation=True,
        shape=grain_shape(config.values),
    )
    sim = sample.simulation
    n = sim.n_particles
    sim.densities = np.full(n, config.material.density)  # generation may scale densities
    info = {k: v for k, v in sample.to_dict().items() if isinstance(v, int | float | str | bool) or v is None}
    run = state(
        phase=phase,
        n_grains=n,
        grain_density=config.material.density,
        walls={"bottom": 0, "right": 1, "top": 2, "left": 3},
        wall_time={"generate": time.perf_counter() - start},
        sample=info,
        consolidation={},
        **fields,
    )
    return sim, run


def consolidate(
    sim: Simulation,
    run: SpecimenRun,
    config: Config,
    progress: bool,
    on_chunk: Callable[[BoxState, int], None] | None = None,
) -> None:
    """Servo-controls the box to the confining pressure until equilibrium;
    ``on_chunk(state, steps)`` after every chunk (``benchmarks/consolidation.py``)."""
    start = time.perf_counter()
    consolidation_model = contact_law(config, config.consolidation.friction)
    sim.set_contact_model(0, 0, consolidation_model)
    sim.set_contact_model(0, 1, platen_model(config))
    sim.local_damping = config.material.local_damping
    sim.time_step = config.run.time_step_safety * sim.critical_time_step(1.0) * damped_time_step_factor(config)
    target = config.consolidation.pressure
    tolerance = config.consolidation.tolerance
    limit = config.consolidation.unbalanced_force_ratio
    max_steps = config.consolidation.max_steps
    speed = 0.05 * config.sample.d_min / (100 * sim.time_step)  # at most d_min/20 per 100 steps
    bar = progress_bar(max_steps, "consolidating", enabled=progress, unit="step")

    def show(state: BoxState, steps: int) -> None:
        bar.update(CHUNK_STEPS)
        bar.set_postfix_str(f"sxx {state.stress_xx_pa / 1e3:.1f} kPa, syy {state.stress_yy_pa / 1e3:.1f} kPa, "
                            f"unbalanced {sim.unbalanced_force_ratio:.1e}")
        if on_chunk is not None:
            on_chunk(state, steps)

    walls = {name: sim.wall(run.walls[name]) for name in BOX_WALLS}
    state, steps, converged = servo_box(
        sim, walls, target, tolerance=tolerance, unbalanced_force_limit=limit, max_steps=max_steps,
        max_speed_m_per_s=speed, chunk_steps=CHUNK_STEPS, after_chunk=show,
    )
    if not converged:
        bar.close()
        raise SpecimenError(
            f"consolidation did not converge in {steps} steps: wall stresses {state.stress_xx_pa / 1e3:.1f} / "
            f"{state.stress_yy_pa / 1e3:.1f} kPa (target {target / 1e3:.1f} kPa +- {tolerance:.0%}), unbalanced "
            f"force ratio {sim.unbalanced_force_ratio:.2e} (limit {limit:.0e}); raise consolidation.max_steps"
        )
    sxx, syy, width, height = state.stress_xx_pa, state.stress_yy_pa, state.width_m, state.height_m
    bar.close()
    grains = np.arange(run.n_grains)
    radii = sim.radii[grains]
    area = width * height
    box = (float(sim.wall(run.walls["left"]).points[0, 0]), float(sim.wall(run.walls["bottom"]).points[0, 1]))
    # clumps: each one's union once (docs/samples.md, "Porosity: two readings")
    grain = sim.body_of_particles[grains] if len(sim.clumps) else None
    run.consolidation = {
        "steps": steps,
        "stress_xx_pa": sxx,
        "stress_yy_pa": syy,
        "width_m": width,
        "height_m": height,
        "porosity": grain_porosity(sim, run.n_grains, area),
        "porosity_overlap_corrected": overlap_corrected_porosity(
            sim.positions[grains], radii, (box[0], box[1], box[0] + width, box[1] + height), grain=grain
        ),
        "coordination_number": grain_coordination(sim),
        "unbalanced_force_ratio": sim.unbalanced_force_ratio,
        "time_step_s": sim.time_step,
    }
    cement_sample(sim, run, config)
    run.wall_time["consolidate"] = time.perf_counter() - start


def cement_sample(sim: Simulation, run: SpecimenRun, config: Config, period: tuple[float, float] | None = None) -> None:
    """Cements the grains' pairs within ``cement.gap`` with parallel bonds (docs/cemented.md,
    "Cemented samples"), when ``cement.bonds`` asks for it: stiffnesses ``auto`` make each
    bond's ``kn_bar A`` the contact law's ``kn`` (and ``ks``), strengths drawn with
    ``sample.seed``. ``period``: the grains in a periodic cell of that size whose corner
    is ``sim.cell.origin``. Records the count in ``run.consolidation["cement_bonds"]``
    (a sample of agglomerates, bonded within each since its start: the bonds made then)."""
    c = config.cement
    if config.values.get("sample.grains") == "agglomerate":
        run.consolidation["cement_bonds"] = run.sample["agglomerate_bonds"]
        return
    if c.bonds == "none":
        return
    from grainlab.cement import draw_strengths, pairs_within_gap

    n = run.n_grains
    positions, radii = sim.positions[:n], sim.radii[:n]
    if period is not None and sim.cell is not None:
        positions = positions - np.asarray(sim.cell.origin)
    body = sim.body_of_particles[:n] if len(sim.clumps) else None
    i, j = pairs_within_gap(positions, radii, c.gap, body=body, period=period)
    if len(i) == 0:
        raise SpecimenError(f"cement.gap: no two grains are within {c.gap:g} m of each other to cement")
    rng = np.random.default_rng([config.sample.seed, 0x43454D])  # "CEM": a stream of its own
    law = c.strength_distribution

    def strengths(mean: float) -> NDArray[np.float64]:
        return draw_strengths(rng, mean, c.strength_scatter * mean, len(i), law)  # type: ignore[arg-type]

    add_cement(sim, config, i, j, strengths(c.tensile_strength), strengths(c.cohesion))
    run.consolidation["cement_bonds"] = len(i)


def add_cement(sim: Simulation, config: Config, i: NDArray[np.int64], j: NDArray[np.int64],
               tensile_strength: NDArray[np.float64], cohesion: NDArray[np.float64]) -> None:
    """Parallel bonds of the ``cement.*`` keys between the particles ``i[k]`` and ``j[k]``
    with the strengths given: stiffnesses ``auto`` make each bond's ``kn_bar A`` the
    contact law's ``kn`` (and ``ks``)."""
    c = config.cement
    area = 2.0 * c.radius_multiplier * np.minimum(sim.radii[i], sim.radii[j])
    kn = config.material.normal_stiffness / area if c.normal_stiffness == "auto" else float(c.normal_stiffness)
    ks = config.material.shear_stiffness / area if c.shear_stiffness == "auto" else float(c.shear_stiffness)
    sim.add_cement_bonds(i, j, normal_stiffness=kn, shear_stiffness=ks, tensile_strength=tensile_strength,
                         cohesion=cohesion, friction_angle=c.friction_angle, radius_multiplier=c.radius_multiplier)


def engine_columns(sim: Simulation) -> dict[str, float]:
    """The columns every test's records read from the engine: the unbalanced force ratio
    and the energies (J)."""
    energy = sim.energy
    return {"unbalanced_force_ratio": sim.unbalanced_force_ratio, "kinetic_energy_j": energy.kinetic,
            "elastic_energy_j": energy.elastic, "friction_dissipated_j": energy.friction_dissipated,
            "damping_dissipated_j": energy.damping_dissipated, "boundary_work_j": energy.boundary_work,
            "wall_work_j": energy.wall_work}


def grain_columns(sim: Simulation, n: int, area: float, contacts: Contacts, snapshot: Snapshot) -> dict[str, float]:
    """The columns a walled test's records share, for the grains (the first ``n``
    particles; membrane disks follow): the Love-Weber stress over ``area`` (levers from
    each grain's centroid, the walls' contacts included), the coordination number of the
    unbonded grain-grain ``contacts`` per grain, :func:`engine_columns` and the fabric of
    ``snapshot`` (:func:`~grainlab.analysis.fabric_summary`)."""
    c, w = contacts, sim.wall_contacts()
    lw = love_weber_stress(sim.grain_centroids, c.i, c.j, c.point, -c.force_on_i, area, np.arange(sim.n_particles) < n,
                           wall_particle=w.particle, wall_point=w.point, wall_force_on_particle=w.force_on_particle)
    fabric = fabric_summary(snapshot)
    fabric.pop("coordination_number")  # the record's own, grain-grain contacts
    grain_contacts = int(np.count_nonzero((c.i < n) & (c.j < n) & ~c.bonded))
    return {"love_weber_xx_pa": float(lw[0, 0]), "love_weber_yy_pa": float(lw[1, 1]),
            "love_weber_xy_pa": float(lw[0, 1]), "coordination_number": 2.0 * grain_contacts / grain_count(sim, n),
            **engine_columns(sim), **fabric}


def _consolidate_stage(context: StageContext[Any, Any]) -> None:
    consolidate(context.sim, context.state, context.config, context.progress)


#: The stage of every test that consolidates its sample in the four walls (:func:`consolidate`).
CONSOLIDATE = Stage("consolidate", _consolidate_stage, "the four walls servo-controlled to sigma_0 until equilibrium")


def run_summary(run: SpecimenRun, fields: Mapping[str, Any], *, records: int, wall_time_s: float,
                **after_records: Any) -> dict[str, Any]:
    """A test's summary: the grain counts, its ``fields``, the time step, the record
    count, ``after_records``, the wall times and grainlab's version."""
    cement = {"cement_bonds": run.consolidation["cement_bonds"]} if "cement_bonds" in run.consolidation else {}
    return {"n_particles": run.n_grains, **clump_summary(run.sample), **cement, **fields,
            "time_step_s": run.consolidation["time_step_s"], "records": records, **after_records,
            "wall_time_s": wall_time_s, "wall_time_by_phase_s": dict(run.wall_time),
            "grainlab_version": grainlab.__version__}


def write_run_outputs(out: Path, figure_tasks: Callable[[dict[str, NDArray[np.float64]], dict[str, Any]],
                                                          list[FigureTask]], strain: str = "axial strain", *,
                      crack_map: bool = True,
                      files: Callable[[Path, dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """A finished run's ``timeseries.csv``, figures and ``summary.json``, from its ``run.h5``:
    the figures of ``figure_tasks(time series, summary)`` (and the crack map of a run
    with cracks, its ``axial_strain`` column named ``strain``, unless ``crack_map`` is
    False) drawn in the figure pool, and the test's own ``files(out, summary)``, before
    the summary is written (which says the outputs are complete); returns the summary."""
    from grainlab.io.hdf5 import read_results
    from grainlab.plot.workers import figure_pool
    from grainlab.protocols.cracks import crack_task

    results = read_results(out / RESULTS_FILE)
    raise_if_interrupted()
    summary = dict(results.summary)
    write_text_atomic(out / "timeseries.csv", timeseries_csv(results.timeseries))
    series = {name: np.asarray(values, dtype=np.float64) for name, values in results.timeseries.items()}
    cracks = crack_task(results, strain) if crack_map else None
    tasks = figure_tasks(series, summary) + ([cracks] if cracks is not None else [])
    with figure_pool(tasks=len(tasks), page_copies=True) as pool:
        pool.draw(tasks, out).result()
    if files is not None:
        files(out, summary)
    raise_if_interrupted()
    write_json_atomic(out / "summary.json", summary)
    return summary
