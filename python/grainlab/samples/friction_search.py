"""Radius expansion with the generation friction chosen by a bracketed search:
friction lets the packing jam looser, so the state at a target porosity is
monotone in the friction, and :func:`expand_with_friction_search` bisects on it
for a packing whose mean wall stress lies in a band. docs/samples.md, "The
generation friction search", gives the trials' outcomes (:data:`TRIAL_OUTCOMES`),
the algorithm and its cost.

Example
-------
>>> from grainlab.samples import expand_with_friction_search, UniformByNumber
>>> found = expand_with_friction_search((0.0, 0.0, 0.012, 0.012), 0.2, UniformByNumber(0.5e-3, 1.0e-3),
...                                     seed=1, stress_band_pa=(1e4, 1e6), progress=False)
>>> found.sample.jammed and found.sample.mean_wall_stress_pa >= 1e4
True
>>> found.friction == found.sample.friction
True
"""

from __future__ import annotations

import json
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

from numpy.typing import ArrayLike

from grainlab.samples._checks import in_range
from grainlab.samples.expansion import MAX_STRESS_PA, ExpansionError, Sample, expand_to_porosity
from grainlab.samples.grading import PAPER_GRADING, Grading

__all__ = ["TRIAL_OUTCOMES", "FrictionSearch", "FrictionSearchError", "FrictionTrial", "expand_with_friction_search"]

#: Trial outcomes and their rank: 0 the loose side (more friction), 1 accepted, >= 2 the dense side.
TRIAL_OUTCOMES: dict[str, int] = {
    "stress_free": 0,
    "unsettled": 0,
    "below_band": 0,
    "in_band": 1,
    "above_band": 2,
    "stopped": 3,
}

#: The fewest contacts per disk (d + 1 in d = 2) with which a frictional disk network can be rigid.
MIN_MECHANICAL_COORDINATION = 3.0


@dataclass(frozen=True)
class FrictionTrial:
    """One radius expansion of the search, at one generation friction."""

    friction: float
    outcome: str
    """One of :data:`TRIAL_OUTCOMES`."""
    mean_wall_stress_pa: float
    """Mean wall stress at the end (where the expansion stopped for ``stopped``), Pa."""
    mechanical_coordination_number: float
    """``Z_m`` of the packing (NaN for ``stopped``)."""
    coordination_number: float
    """``Z`` of the packing (NaN for ``stopped``)."""
    steps: int
    wall_time_s: float
    message: str = ""
    """The :class:`ExpansionError` message for ``stopped``."""

    @property
    def rank(self) -> int:
        """0 loose side, 1 accepted, >= 2 dense side (:data:`TRIAL_OUTCOMES`)."""
        return TRIAL_OUTCOMES[self.outcome]

    @property
    def stress_bearing(self) -> bool:
        return self.outcome in ("in_band", "above_band")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    def describe(self) -> str:
        """``"0.05: in_band, 218 kPa, Z_m 3.93"``."""
        text = f"{self.friction:.4g}: {self.outcome}, {self.mean_wall_stress_pa / 1e3:.3g} kPa"
        return text if math.isnan(self.mechanical_coordination_number) else (
            f"{text}, Z_m {self.mechanical_coordination_number:.2f}")


class FrictionSearchError(ValueError):
    """No generation friction in the range makes the target stress-bearing.

    ``trials`` are the expansions run (:class:`FrictionTrial`), ``target`` the
    nominal porosity asked for.
    """

    def __init__(self, message: str, *, target: float, trials: Sequence[FrictionTrial]) -> None:
        super().__init__(message)
        self.target = target
        self.trials = tuple(trials)


@dataclass(frozen=True, eq=False)
class FrictionSearch:
    """The packing a friction search chose, and every trial it ran (in the order run)."""

    sample: Sample
    """The accepted packing; its :attr:`~Sample.friction` is the generation friction chosen."""
    trials: tuple[FrictionTrial, ...]
    friction_range: tuple[float, float]
    stress_band_pa: tuple[float, float]
    friction_tolerance: float
    min_mechanical_coordination: float

    @property
    def friction(self) -> float:
        """The generation friction chosen."""
        return self.sample.friction

    @property
    def accepted(self) -> FrictionTrial:
        """The trial of the accepted packing."""
        return next(t for t in reversed(self.trials) if t.friction == self.sample.friction)

    @property
    def in_band(self) -> bool:
        """Whether the accepted packing's stress is inside the band (false: the least friction
        already bears more, or the stress jumps across the band within ``friction_tolerance``)."""
        return self.accepted.outcome == "in_band"

    @property
    def monotone(self) -> bool:
        """Whether the trials, sorted by friction, have non-decreasing rank and, among the
        stress-bearing ones, non-decreasing stress (the relation the bisection relies on)."""
        ordered = sorted(self.trials, key=lambda t: t.friction)
        ranks = [t.rank for t in ordered]
        stresses = [t.mean_wall_stress_pa for t in ordered if t.stress_bearing]
        return all(a <= b for a, b in zip(ranks, ranks[1:], strict=False)) and all(
            a <= b for a, b in zip(stresses, stresses[1:], strict=False))

    @property
    def wall_time_s(self) -> float:
        return float(sum(t.wall_time_s for t in self.trials))

    @property
    def steps(self) -> int:
        return int(sum(t.steps for t in self.trials))

    def summary(self) -> str:
        """One line: the friction chosen, its stress, and the trials."""
        where = "in" if self.in_band else "outside"
        return (
            f"generation friction {self.friction:.4g} (mean wall stress "
            f"{self.sample.mean_wall_stress_pa / 1e3:.3g} kPa, {where} the band "
            f"{self.stress_band_pa[0] / 1e3:.3g}-{self.stress_band_pa[1] / 1e3:.3g} kPa) after "
            f"{len(self.trials)} expansion(s), {self.wall_time_s:.1f} s; trials "
            + "; ".join(t.describe() for t in self.trials)
        )

    def trials_json(self) -> str:
        """The trials as compact JSON (a list of :meth:`FrictionTrial.to_dict`)."""
        return json.dumps([t.to_dict() for t in self.trials], separators=(",", ":"))

    def to_dict(self) -> dict[str, Any]:
        return {
            "friction": self.friction,
            "in_band": self.in_band,
            "monotone": self.monotone,
            "friction_range": list(self.friction_range),
            "stress_band_pa": list(self.stress_band_pa),
            "friction_tolerance": self.friction_tolerance,
            "min_mechanical_coordination": self.min_mechanical_coordination,
            "trials": [t.to_dict() for t in self.trials],
            "sample": self.sample.to_dict(),
        }


def _pair(name: str, value: Any, minimum: float, strict_minimum: bool) -> tuple[float, float]:
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected two numbers (low, high), got {value!r}") from None
    bad_low = low <= minimum if strict_minimum else low < minimum
    if not (math.isfinite(low) and math.isfinite(high)) or bad_low or not low < high:
        bound = f"> {minimum:g}" if strict_minimum else f">= {minimum:g}"
        raise ValueError(f"{name}: expected finite numbers {bound} with low < high, got ({low!r}, {high!r})")
    return low, high


def _checked_limits(
    stress_high: float, max_stress_pa: float, friction_tolerance: float, min_mechanical_coordination: float
) -> tuple[float, float]:
    """The band's upper end against the stress bound, the tolerance and the least ``Z_m``, checked."""
    if stress_high > max_stress_pa:
        raise ValueError(
            f"stress_band_pa: the band's upper end {stress_high:.4g} Pa exceeds max_stress_pa = "
            f"{max_stress_pa:.4g} Pa, beyond which the expansion stops; lower the band or raise max_stress_pa"
        )
    return (in_range("friction_tolerance", friction_tolerance, "(0, inf)"),
            in_range("min_mechanical_coordination", min_mechanical_coordination, "[0, inf)"))


class _Search:
    """The search's trials: one radius expansion per friction (``expand``), each
    judged against the stress band and the least mechanical coordination number."""

    def __init__(
        self, expand: Callable[[float], Sample], band: tuple[float, float], min_mechanical_coordination: float
    ) -> None:
        self.expand = expand
        self.band = band
        self.min_mechanical_coordination = min_mechanical_coordination
        self.trials: list[FrictionTrial] = []

    def trial(self, friction: float) -> tuple[FrictionTrial, Sample | None]:
        """The expansion with ``friction``, its outcome recorded; the sample unless it stopped."""
        started = time.perf_counter()
        try:
            with warnings.catch_warnings():
                # an unsettled trial is an outcome of the search, not a warning to the caller
                warnings.filterwarnings("ignore", message="expand_to_porosity: unbalanced force ratio",
                                        category=RuntimeWarning)
                sample = self.expand(friction)
        except ExpansionError as error:
            if not self.trials:
                raise  # too dense for the stress bound even with the least friction
            done = FrictionTrial(friction, "stopped", error.stress_pa, math.nan, math.nan, error.steps,
                                 time.perf_counter() - started, str(error))
            self.trials.append(done)
            return done, None
        done = FrictionTrial(friction, self.outcome(sample), sample.mean_wall_stress_pa,
                             sample.mechanical_coordination_number, sample.coordination_number, sample.steps,
                             sample.wall_time_s)
        self.trials.append(done)
        return done, sample

    def bisect(self, low: float, high: float, tolerance: float, best: Sample | None) -> Sample | None:
        """Bisects the friction between a loose ``low`` and a dense ``high`` until a
        trial lands in the band or the bracket is narrower than ``tolerance``: that
        sample, else the stress-bearing one of least friction (``best`` so far), else None."""
        while high - low > tolerance:
            middle = 0.5 * (low + high)
            done, sample = self.trial(middle)
            if done.outcome == "in_band":
                return sample
            if done.rank == 0:
                low = middle
            else:
                high = middle
                if done.stress_bearing:
                    best = sample
        return best

    def too_loose(self, porosity: float, last: FrictionTrial) -> FrictionSearchError:
        """The error of a target still loose at the largest friction (``last``)."""
        return FrictionSearchError(
            f"porosity: nominal porosity {porosity:.4f} is looser than radius expansion jams even with the "
            f"largest generation friction allowed: with friction {last.friction:g} the packing ends "
            f"{last.outcome} (mean wall stress {last.mean_wall_stress_pa:.3g} Pa, Z_m "
            f"{last.mechanical_coordination_number:.2f}; a stress-bearing packing needs at least "
            f"{self.band[0]:.3g} Pa and Z_m >= {self.min_mechanical_coordination:g}). Aim for a denser target "
            "or raise friction_range's upper end.",
            target=porosity, trials=self.trials,
        )

    def nothing_bears(
        self, porosity: float, friction_range: tuple[float, float], max_stress_pa: float
    ) -> FrictionSearchError:
        """The error when no friction of the range gives a stress-bearing packing."""
        loose = max((t for t in self.trials if t.rank == 0), key=lambda t: t.friction)
        dense = min((t for t in self.trials if t.rank > 0), key=lambda t: t.friction)
        return FrictionSearchError(
            f"porosity: no generation friction in [{friction_range[0]:g}, {friction_range[1]:g}] makes nominal "
            f"porosity {porosity:.4f} stress-bearing within max_stress_pa = {max_stress_pa / 1e6:.3g} MPa: at "
            f"friction {loose.friction:.4g} the packing ends {loose.outcome}, at {dense.friction:.4g} the "
            f"expansion stopped ({dense.message}). Widen stress_band_pa or raise max_stress_pa.",
            target=porosity, trials=self.trials,
        )

    def outcome(self, sample: Sample) -> str:
        """Where a settled or unsettled packing stands against the band."""
        stress, z_m = sample.mean_wall_stress_pa, sample.mechanical_coordination_number
        low, high = self.band
        if not sample.equilibrium_reached:
            return "unsettled"
        if not sample.jammed:
            return "stress_free"
        if stress < low or not z_m >= self.min_mechanical_coordination:
            return "below_band"
        return "in_band" if stress <= high else "above_band"


def expand_with_friction_search(
    box: ArrayLike = (0.0, 0.0, 0.075, 0.15),
    porosity: float = 0.12,
    grading: Grading = PAPER_GRADING,
    *,
    friction_range: Sequence[float] = (0.0, 0.9),
    stress_band_pa: Sequence[float] = (1.0e5, 3.0e5),
    friction_tolerance: float = 5.0e-3,
    min_mechanical_coordination: float = MIN_MECHANICAL_COORDINATION,
    progress: bool = False,
    keep_simulation: bool = False,
    **expansion: Any,
) -> FrictionSearch:
    """Radius expansion to a target nominal porosity with the generation friction chosen so
    that the packing there is stress-bearing (docs/samples.md: criterion, algorithm, cost).

    Parameters
    ----------
    box, porosity, grading : as :func:`~grainlab.samples.expand_to_porosity`
    friction_range : ``(mu_min, mu_max)``, the bracket (default 0 to Table 1's 0.9)
    stress_band_pa : ``(low, high)`` mean wall stress aimed at, Pa (default 100-300 kPa:
        the paper's consolidation stress, 100 kPa, up to about what the frictionless
        expansion locks in at 0.15 in the paper's box); ``high`` must not exceed
        ``max_stress_pa``
    friction_tolerance : stop bisecting when the bracket is narrower than this
    min_mechanical_coordination : least ``Z_m`` of a stress-bearing packing (default 3)
    progress, keep_simulation : as :func:`~grainlab.samples.expand_to_porosity`
        (only the accepted packing keeps its simulation)
    **expansion : any other keyword of :func:`~grainlab.samples.expand_to_porosity`
        (``seed``, ``max_stress_pa``, ``threads``, ...), except ``friction``

    Raises
    ------
    ValueError
        bad input, naming the field, before any work.
    ExpansionError
        the target needs more than ``max_stress_pa`` even at ``mu_min``.
    FrictionSearchError
        (a ValueError) the packing is still on the loose side at ``mu_max``, or no
        friction in the range gives a stress-bearing packing within the stress bound.
    """
    if "friction" in expansion:
        raise ValueError("friction: chosen by the search; give friction_range = (low, high) instead")
    porosity = in_range("porosity", porosity, "(0, 1)")
    mu_min, mu_max = _pair("friction_range", friction_range, 0.0, strict_minimum=False)
    stress_low, stress_high = _pair("stress_band_pa", stress_band_pa, 0.0, strict_minimum=True)
    max_stress_pa = float(expansion.get("max_stress_pa", MAX_STRESS_PA))
    friction_tolerance, min_mechanical_coordination = _checked_limits(
        stress_high, max_stress_pa, friction_tolerance, min_mechanical_coordination
    )
    search = _Search(
        lambda friction: expand_to_porosity(
            box, porosity, grading, friction=friction, progress=progress,
            keep_simulation=keep_simulation, **expansion,
        ),
        (stress_low, stress_high),
        min_mechanical_coordination,
    )
    trial, trials = search.trial, search.trials

    def result(sample: Sample) -> FrictionSearch:
        return FrictionSearch(sample, tuple(trials), (mu_min, mu_max), (stress_low, stress_high),
                              friction_tolerance, min_mechanical_coordination)

    first, sample = trial(mu_min)
    if first.stress_bearing:
        return result(sample)  # type: ignore[arg-type]
    last, sample = trial(mu_max)
    if last.rank == 0:
        raise search.too_loose(porosity, last)
    if last.outcome == "in_band":
        return result(sample)  # type: ignore[arg-type]
    best = search.bisect(mu_min, mu_max, friction_tolerance, sample if last.stress_bearing else None)
    if best is None:
        raise search.nothing_bears(porosity, (mu_min, mu_max), max_stress_pa)
    return result(best)
