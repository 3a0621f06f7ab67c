"""Sweep plans: a TOML file naming a base config and the parameters to vary.

The plan's keys, modes and units: docs/study.md, "`grainlab sweep` and the plan
format". Every value is validated before any run starts; errors name the key.
"""

from __future__ import annotations

import itertools
import math
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from grainlab._mapping import flatten_keys
from grainlab.study.campaign import CampaignResult, Run, make_run

PLAN_KEYS = ("base", "mode", "seed", "config", "quick", "fixed", "vary", "name")


class PlanError(ValueError):
    """A sweep plan key or value is not allowed (the message names the key)."""


@dataclass(frozen=True)
class Plan:
    base: str
    mode: str
    seed: int
    fixed: dict[str, Any]
    vary: dict[str, list[Any]]
    config: str | None = None
    quick: bool = False

    def runs(self) -> list[Run]:
        """The plan's runs, named ``run_0000``, ... with the varied values as labels."""
        names = list(self.vary)
        if not names:
            combos: list[tuple[Any, ...]] = [()]
        elif self.mode == "grid":
            combos = list(itertools.product(*(self.vary[k] for k in names)))
        else:
            combos = list(zip(*(self.vary[k] for k in names), strict=True))
        runs = []
        for index, combo in enumerate(combos):
            varied = dict(zip(names, combo, strict=True))
            params = {**self.fixed, **varied}
            if self.base != "packing":
                if self.config is not None:
                    params["config_file"] = self.config
                if self.quick:
                    params["quick"] = True
            runs.append(make_run(f"run_{index:04d}", self.base, params, self.seed, labels=varied))
        return runs


def _is_range(value: Mapping[str, Any]) -> bool:
    return "start" in value and "stop" in value


def _expand(key: str, value: Any) -> list[Any]:
    if isinstance(value, list):
        if not value:
            raise PlanError(f"vary.{key}: an empty list")
        return value
    if isinstance(value, Mapping):
        extra = set(value) - {"start", "stop", "num", "step"}
        if extra or not _is_range(value):
            raise PlanError(
                f"vary.{key}: a range needs start, stop and num or step (got keys {sorted(value)})"
            )
        start, stop = value["start"], value["stop"]
        for part in ("start", "stop"):
            if isinstance(value[part], bool) or not isinstance(value[part], int | float):
                raise PlanError(f"vary.{key}.{part}: expected a number, got {value[part]!r}")
        if ("num" in value) == ("step" in value):
            raise PlanError(f"vary.{key}: give exactly one of num or step")
        if "num" in value:
            num = value["num"]
            if isinstance(num, bool) or not isinstance(num, int) or num < 1:
                raise PlanError(f"vary.{key}.num: expected an integer >= 1, got {num!r}")
            if num == 1:
                return [start]
            return [start + (stop - start) * k / (num - 1) for k in range(num)]
        step = value["step"]
        if isinstance(step, bool) or not isinstance(step, int | float) or step == 0 or (stop - start) * step < 0:
            raise PlanError(f"vary.{key}.step: expected a non-zero number going from start to stop, got {step!r}")
        count = int(math.floor((stop - start) / step + 1e-9)) + 1
        values = [start + k * step for k in range(count)]
        return [int(v) if isinstance(start, int) and isinstance(step, int) else v for v in values]
    raise PlanError(f"vary.{key}: expected a list or a range table {{start, stop, num|step}}, got {value!r}")


def _check_values(base: str, params: dict[str, Any], key_prefix: str) -> None:
    if base == "packing":
        from dataclasses import fields

        from grainlab.study.packing import PackingParams

        known = {f.name for f in fields(PackingParams)}
        for key in params:
            if key not in known:
                raise PlanError(f"{key_prefix}{key}: unknown packing parameter; known: {', '.join(sorted(known))}")
        try:
            PackingParams.from_mapping(params)
        except ValueError as error:
            raise PlanError(f"{key_prefix}{error}") from None
    else:
        from grainlab.protocols.config import ConfigError
        from grainlab.protocols.registry import SCHEMAS

        for key, value in params.items():
            try:
                SCHEMAS[base].coerce(key, value)
            except ConfigError as error:
                raise PlanError(f"{key_prefix}{error}") from None


def parse_plan(text: str, *, base_dir: str | os.PathLike[str] | None = None, source: str = "plan") -> Plan:
    """Parses and validates a plan from TOML text; raises :class:`PlanError` naming the key."""
    try:
        table = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise PlanError(f"{source}: not valid TOML ({error})") from None
    for key in table:
        if key not in PLAN_KEYS:
            raise PlanError(f"{key}: unknown plan key; known: {', '.join(PLAN_KEYS)}")
    from grainlab.protocols.registry import PROTOCOLS

    bases = ", ".join(repr(b) for b in ("packing", *sorted(PROTOCOLS)))
    if "base" not in table:
        raise PlanError(f"base: missing; expected one of {bases}")
    base = table["base"]
    if base != "packing" and base not in PROTOCOLS:
        raise PlanError(f"base: expected one of {bases}, got {base!r}")
    mode = table.get("mode", "grid")
    if mode not in ("grid", "zip"):
        raise PlanError(f"mode: expected 'grid' or 'zip', got {mode!r}")
    seed = table.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise PlanError(f"seed: expected an integer >= 0, got {seed!r}")
    quick = table.get("quick", False)
    if not isinstance(quick, bool):
        raise PlanError(f"quick: expected true or false, got {quick!r}")
    config = table.get("config")
    if base == "packing" and (config is not None or quick):
        tests = ", ".join(repr(b) for b in sorted(PROTOCOLS))
        raise PlanError(f"{'config' if config is not None else 'quick'}: only for the base of a test ({tests})")
    if config is not None:
        if not isinstance(config, str):
            raise PlanError(f"config: expected a path, got {config!r}")
        path = Path(config)
        if not path.is_absolute() and base_dir is not None:
            path = Path(base_dir) / path
        if not path.exists():
            raise PlanError(f"config: file {str(path)!r} not found")
        config = str(path.resolve())
    for section in ("fixed", "vary"):
        if section in table and not isinstance(table[section], Mapping):
            raise PlanError(f"{section}: expected a table")
    fixed = flatten_keys(table.get("fixed", {}), leaf=_is_range)
    vary = {key: _expand(key, value) for key, value in flatten_keys(table.get("vary", {}), leaf=_is_range).items()}
    both = set(fixed) & set(vary)
    if both:
        raise PlanError(f"{sorted(both)[0]}: both in [fixed] and [vary]")
    if mode == "zip" and vary:
        lengths = {k: len(v) for k, v in vary.items()}
        if len(set(lengths.values())) > 1:
            raise PlanError(f"vary: mode 'zip' needs lists of equal length, got {lengths}")
    _check_values(base, fixed, "fixed.")
    for key, values in vary.items():
        for value in values:
            _check_values(base, {**fixed, key: value}, "vary.")
    return Plan(base, mode, seed, fixed, vary, config, quick)


def load_plan(path: str | os.PathLike[str]) -> Plan:
    """Reads a plan file (docs/study.md)."""
    p = Path(path)
    try:
        text = p.read_text()
    except FileNotFoundError:
        raise PlanError(f"{p}: plan file not found") from None
    return parse_plan(text, base_dir=p.parent, source=str(p))


def run_sweep(plan: Plan | str | os.PathLike[str], out_dir: str | os.PathLike[str], *,
              workers: int | None = None, scheduler: Any = None,
              progress: bool = False) -> CampaignResult:
    """Runs (or resumes) a sweep; ``sweep.csv`` in ``out_dir``, each run in ``runs/run_NNNN``."""
    from grainlab.io.results import write_text_atomic
    from grainlab.study.campaign import run_campaign

    if not isinstance(plan, Plan):
        source = Path(plan)
        plan = load_plan(source)
        Path(out_dir).mkdir(parents=True, exist_ok=True)
        write_text_atomic(Path(out_dir) / "plan.toml", source.read_text())
    columns = ["name", *plan.vary, "status", "wall_time_s", "seed", "error"]
    return run_campaign(plan.runs(), out_dir, workers=workers, scheduler=scheduler, progress=progress,
                        table_name="sweep.csv", columns=columns)
