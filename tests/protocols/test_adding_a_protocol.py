"""A protocol written from ARCHITECTURE.md's "Adding a protocol" alone: the consolidated sample
pressed by the top wall at a constant speed (its own controller) until sigma_v reaches a target
(its own operation, whose flag a snapshot and the stop act on); its physics, its resume's bits."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

from grainlab.io.hdf5 import read_results
from grainlab.protocols import operations as ops
from grainlab.protocols.config import SCHEMAS, Config, Section, SectionOf, key, register_test
from grainlab.protocols.runner import RunResult, Stage, run_protocol
from grainlab.protocols.specimen import CONSOLIDATE, SpecimenProtocol, SpecimenRun
from grainlab.protocols.triggers import And, EveryStop, Flag, WallClock
from grainlab.simulation import Simulation

RECORD_STEPS = 200


@dataclass(frozen=True)
class PressSection(Section):
    prefix: ClassVar[str] = "press"
    speed: float = key("number", 2e-4, "the top wall's speed, m/s", minimum=0.0, exclusive_minimum=True)
    target: float = key("stress", 300e3, "the vertical stress that ends the pressing", minimum=0.0)


@dataclass(frozen=True)
class PressConfig(Config):
    press = SectionOf(PressSection)


@pytest.fixture(scope="module", autouse=True)
def schema() -> Any:  # registered while this module's tests run
    yield register_test("press_example", PressSection.keys(), lambda values, given: None, PressConfig)
    SCHEMAS.pop("press_example")


@dataclass
class PressRun(SpecimenRun):
    start_step: int = -1
    height0: float = 0.0


def vertical_stress(sim: Simulation, run: PressRun) -> tuple[float, float, float]:
    left, right, bottom, top = (sim.wall(run.walls[k]).points[0] for k in ("left", "right", "bottom", "top"))
    width, height = float(right[0] - left[0]), float(top[1] - bottom[1])
    return sim.wall(run.walls["top"]).normal_stress(width), width, height


class PressTop(ops.Operation):
    """Controller: the top wall moves down at ``speed`` over the steps ahead."""

    acts_before_run = True

    def __init__(self, wall_id: int, speed: float) -> None:
        super().__init__(EveryStop(RECORD_STEPS))
        self.wall_id, self.speed = wall_id, speed

    def act(self, loading: ops.Loading) -> None:
        loading.sim.wall(self.wall_id).velocity = (0.0, -self.speed)


class UntilStress(ops.Operation):
    """Raises :attr:`reached` at the first stop with sigma_v at or above ``target``."""

    def __init__(self, run: PressRun, target: float) -> None:
        super().__init__(EveryStop(RECORD_STEPS))
        self.run, self.target, self.reached = run, target, Flag()

    def act(self, loading: ops.Loading) -> None:
        if vertical_stress(loading.sim, self.run)[0] >= self.target:
            self.reached.raise_at(loading.sim.step_count)


def press(context: Any) -> None:
    sim, run, config = context.sim, context.state, context.config
    if run.start_step < 0:  # the stage's start (a resumed run keeps its own): the walls stopped
        for wall_id in run.walls.values():
            sim.wall(wall_id).velocity = (0.0, 0.0)
        run.start_step, run.height0 = sim.step_count, vertical_stress(sim, run)[2]

    def measure() -> dict[str, float]:
        sigma_v, width, height = vertical_stress(sim, run)
        grains = float(np.pi * np.sum(sim.radii[: run.n_grains] ** 2))
        return {"step": float(sim.step_count - run.start_step), "vertical_stress_pa": sigma_v,
                "axial_strain": (run.height0 - height) / run.height0, "porosity": 1.0 - grains / (width * height)}
    until = UntilStress(run, config.press.target)
    every = EveryStop(RECORD_STEPS)
    clock = WallClock(config.run.checkpoint_interval)
    checkpoint = ops.Checkpoint(And(every, clock), context.save, run.wall_time, "press")
    ops.run_loading(sim, [
        until,
        ops.Records(every, context.writer, measure, {"step": "", "vertical_stress_pa": "Pa", "axial_strain": "",
                                                 "porosity": ""}),
        ops.Snapshots(until.reached, context.writer, lambda step: "pressed", lambda: sim.snapshot()),
        checkpoint,
        ops.Stop(until.reached),
        PressTop(run.walls["top"], config.press.speed),
    ], checkpoint)


def summarise(run: PressRun, config: PressConfig, series: dict[str, Any], wall_time_s: float) -> dict[str, Any]:
    return {"final_vertical_stress_pa": float(series["vertical_stress_pa"][-1]), "height0_m": run.height0,
            "time_step_s": run.consolidation["time_step_s"], "wall_time_s": wall_time_s}


class PressProtocol(SpecimenProtocol[PressConfig, PressRun, RunResult]):
    name = "press_example"
    stages = (CONSOLIDATE, Stage("press", press, "the top wall pressed down until sigma_v reaches press.target"))
    state_type = PressRun
    summarise = summarise
    outputs = staticmethod(lambda out: dict(read_results(out / "run.h5").summary))
    result_type = RunResult


def _config(*extra: str) -> PressConfig:
    return SCHEMAS["press_example"].resolve(overrides=["run.threads=1", *extra], quick=True)


@pytest.fixture(scope="module")
def pressed(tmp_path_factory: Any) -> Any:
    out = tmp_path_factory.mktemp("press") / "run"
    run_protocol(PressProtocol(_config()), out)
    return out


def test_the_top_wall_presses_the_sample_until_the_target_stress(pressed: Any) -> None:
    results, target = read_results(pressed / "run.h5"), 300e3
    series, s, sigma = results.timeseries, results.summary, results.timeseries["vertical_stress_pa"]
    # a record every RECORD_STEPS steps, the last the first at or above the target, where the run stopped
    np.testing.assert_array_equal(series["step"], RECORD_STEPS * np.arange(1, len(sigma) + 1))
    assert sigma[-1] >= target and np.all(sigma[:-1] < target) and len(sigma) > 3
    assert results.snapshot_names == ["pressed"] and s["final_vertical_stress_pa"] == sigma[-1]
    # the wall moved at its speed: the strain grows by speed * dt * RECORD_STEPS / H0 each record
    expected = 2e-4 * s["time_step_s"] * RECORD_STEPS / s["height0_m"]
    assert np.diff(series["axial_strain"]) == pytest.approx(expected, rel=1e-6)
    # confined compression packs the grains denser; the stress grows well past sigma_0
    assert np.all(np.diff(series["porosity"]) < 0)
    assert sigma[-1] > 2.5 * 100e3 and sigma[len(sigma) // 2] > sigma[0]


def test_a_stopped_press_resumes_to_the_same_bits(pressed: Any, tmp_path: Any, monkeypatch: Any) -> None:
    stop_and_resume(PressProtocol(_config("run.checkpoint_interval=1e-6")), tmp_path / "run", 4, monkeypatch)
    assert_same_run(pressed, tmp_path / "run")
