"""Per-step speed of the biaxial test's shear phase (the paper-scale sample:
grains, the membrane's bonded disks, two platens and the pressure chain).

The sample is built once, through the biaxial run's own phases (generation,
consolidation, the membrane, the start of shear), and its engine state at the
start of shear is kept in a file (``--state``, built when missing). Each
timed run loads that state, takes ``--warmup`` steps, then times ``--steps``
shear steps; the thread counts alternate (1 2 1 2 ...), so that the machine's
noise falls on all of them alike. Prints every run, the median particle-steps
per second per thread count, and one JSON line.

With ``--builds A B`` the runs are made by two builds of the Rust example
``biaxial_step`` (crates/grainlab-core/examples/biaxial_step.rs) instead of
the installed engine, alternately A B A B at each thread count, with their
ratio B / A: keep a copy of the old build before changing the engine::

    cargo build --release -p grainlab-core --example biaxial_step
    cp target/release/examples/biaxial_step /tmp/biaxial-step-old
    # ... change the engine, build again ...
    python benchmarks/biaxial_step.py --builds /tmp/biaxial-step-old \\
        target/release/examples/biaxial_step

Usage: ``python benchmarks/biaxial_step.py [--threads 1 2] [--repeat 5]
[--steps 2000] [--quick] [--state PATH] [--builds A B]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from grainlab.protocols.biaxial.config import resolve
from grainlab.protocols.biaxial.phases import check_shear_plan, install_boundary, start_shear
from grainlab.protocols.biaxial.state import BiaxialRun
from grainlab.protocols.specimen import consolidate, engine_threads, generate
from grainlab.simulation import Simulation


def build_state(path: Path, quick: bool) -> None:
    """Runs the biaxial protocol to the start of shear and writes the engine state."""
    config = resolve(quick=quick)
    sim, run = generate(config, engine_threads(config), False, BiaxialRun, "consolidate")
    consolidate(sim, run, config, progress=False)
    install_boundary(sim, run, config, progress=False)
    start_shear(sim, run, config)
    check_shear_plan(sim, run, config)
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile(dir=path.parent, delete=False) as f:
        f.write(sim.to_bytes())
    os.replace(f.name, path)


def time_engine(state: bytes, threads: int, warmup: int, steps: int) -> float:
    """Particle-steps per second of the installed engine over ``steps`` shear steps."""
    sim = Simulation.from_bytes(state)
    sim.threads = threads
    sim.run(warmup)
    start = time.perf_counter()
    sim.run(steps)
    return sim.n_particles * steps / (time.perf_counter() - start)


def time_build(binary: str, state: Path, threads: int, warmup: int, steps: int) -> float:
    """Particle-steps per second of one run of a build of the ``biaxial_step`` example."""
    out = subprocess.run(
        [binary, str(state), str(threads), str(steps), str(warmup)], check=True, capture_output=True, text=True
    ).stdout
    match = re.search(r"particle_steps_per_s=([0-9.eE+-]+)", out)
    if match is None:
        raise RuntimeError(f"{binary}: no particle_steps_per_s in {out!r}")
    return float(match.group(1))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--warmup", type=int, default=200)
    parser.add_argument("--quick", action="store_true", help="the --quick sample instead of the paper-scale one")
    parser.add_argument("--state", type=Path, help="the engine state at the start of shear (built when missing)")
    parser.add_argument("--builds", nargs=2, metavar=("A", "B"), help="two builds of the biaxial_step example")
    args = parser.parse_args(argv)
    default = Path(tempfile.gettempdir()) / f"grainlab-biaxial-shear-start{'-quick' if args.quick else ''}.state"
    state_path = args.state or default
    if not state_path.exists():
        print(f"building the sample to the start of shear: {state_path}", flush=True)
        build_state(state_path, args.quick)
    state = state_path.read_bytes()
    n = Simulation.from_bytes(state).n_particles
    print(f"{n} particles; load average {os.getloadavg()[0]:.2f}", flush=True)
    labels = ["A", "B"] if args.builds else ["engine"]
    runs: dict[tuple[str, int], list[float]] = {}
    for _ in range(args.repeat):
        for threads in args.threads:
            for label in labels:
                if args.builds:
                    binary = args.builds[labels.index(label)]
                    rate = time_build(binary, state_path, threads, args.warmup, args.steps)
                else:
                    rate = time_engine(state, threads, args.warmup, args.steps)
                runs.setdefault((label, threads), []).append(rate)
                print(f"{label} {threads} thread(s): {rate:.4e} particle-steps/s", flush=True)
    result: dict[str, object] = {"particles": n, "load_average_end": os.getloadavg()[0]}
    for (label, threads), rates in runs.items():
        result[f"{label}_{threads}"] = statistics.median(rates)
        print(f"median {label} {threads} thread(s): {statistics.median(rates):.4e} ({len(rates)} runs)")
    if args.builds:
        for threads in args.threads:
            ratio = statistics.median(runs[("B", threads)]) / statistics.median(runs[("A", threads)])
            result[f"ratio_{threads}"] = ratio
            print(f"B / A at {threads} thread(s): {ratio:.3f}")
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
