"""Where the biaxial test's consolidation spends its steps: the default sample
(Table 1, seed 1) is generated, then consolidated as ``grainlab biaxial`` does,
and every chunk of 2,000 steps prints the wall stresses and the mean unbalanced
force ratio. The last lines give the step at which both wall stresses were first
within ``consolidation.tolerance`` of the target, the step at which the phase
ended (the unbalanced force ratio below ``consolidation.unbalanced_force_ratio``
as well), the wall time, and the consolidated sample's porosity and
coordination number; then one JSON line.

    python benchmarks/consolidation.py
    python benchmarks/consolidation.py consolidation.unbalanced_force_ratio=1e-2

Arguments are ``key=value`` overrides of the biaxial configuration, as
``grainlab biaxial --set``.
"""

from __future__ import annotations

import json
import sys
import time

from grainlab.protocols.biaxial.config import resolve
from grainlab.protocols.consolidate import BoxState
from grainlab.protocols.specimen import SpecimenRun, consolidate, engine_threads, generate


def main(argv: list[str] | None = None) -> int:
    overrides = sys.argv[1:] if argv is None else argv
    config = resolve(overrides=overrides)
    sim, run = generate(config, engine_threads(config), False, SpecimenRun, "consolidate")
    target = config["consolidation.pressure"]
    tolerance = config["consolidation.tolerance"]
    first_within: list[int] = []

    def show(state: BoxState, steps: int) -> None:
        within = all(abs(s / target - 1) < tolerance for s in (state.stress_xx_pa, state.stress_yy_pa))
        if within and not first_within:
            first_within.append(steps)
        print(f"{steps:8d} steps: sxx {state.stress_xx_pa / 1e3:7.2f} kPa, syy {state.stress_yy_pa / 1e3:7.2f} "
              f"kPa, unbalanced force ratio {sim.unbalanced_force_ratio:.2e}", flush=True)

    start = time.perf_counter()
    consolidate(sim, run, config, progress=False, on_chunk=show)
    seconds = time.perf_counter() - start
    c = run.consolidation
    result = {
        "overrides": list(overrides),
        "stresses_within_tolerance_at_step": first_within[0] if first_within else None,
        "steps": c["steps"],
        "seconds": seconds,
        "porosity": c["porosity"],
        "coordination_number": c["coordination_number"],
        "unbalanced_force_ratio": c["unbalanced_force_ratio"],
    }
    print(f"stresses within {tolerance:.0%} of {target / 1e3:.0f} kPa after {result['stresses_within_tolerance_at_step']} "
          f"steps; equilibrium (unbalanced force ratio {c['unbalanced_force_ratio']:.2e}) after {c['steps']} steps, "
          f"{seconds:.1f} s; porosity {c['porosity']:.4f}, coordination number {c['coordination_number']:.3f}")
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
