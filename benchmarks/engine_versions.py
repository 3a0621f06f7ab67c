"""Two builds of the engine side by side on the common throughput case.

Runs two builds of the Rust example ``throughput`` (crates/grainlab-core/
examples/throughput.rs: the 4,000-disk sheared periodic packing of
``throughput.py``, from Rust alone) alternately, A B A B ..., at each thread
count, so that the machine's noise falls on both alike, and prints the median
particle-steps per second of each, their ratio (B / A) and every single run.
With ``--busy`` a spinning process keeps one core busy during every run (the
"shared machine" case: compare 2 threads with it against 1 thread without).

Keep a copy of the old build before changing the engine::

    cargo build --release -p grainlab-core --example throughput
    cp target/release/examples/throughput /tmp/throughput-old
    # ... change the engine, build again ...
    python benchmarks/engine_versions.py /tmp/throughput-old \\
        target/release/examples/throughput --threads 1 2 --repeat 5

Instruction counts are steadier than times on a loaded machine: ``--count``
also runs each build once under ``valgrind --tool=callgrind`` (1,000 steps,
one thread) and prints the instructions executed. ``--rolling-friction MU``
gives both builds' contact model rolling resistance (the example's
``--rolling-friction=MU``; both builds must know it). ``--b-option OPT`` adds
an option of the example to B's runs only: one build against itself with and
without it, e.g. the cost of rigid trimers per pebble-step against disks::

    python benchmarks/engine_versions.py target/release/examples/throughput \
        target/release/examples/throughput --b-option=--trimers --repeat 5

The last line printed is one JSON object with the medians and ratios.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path


def spin(stop_at: float) -> None:
    """Keeps one core busy until ``stop_at`` (time.time())."""
    x = 0
    while time.time() < stop_at:
        x += 1


def options(rolling_friction: float) -> list[str]:
    """The example's options after threads and steps."""
    return [f"--rolling-friction={rolling_friction!r}"] if rolling_friction > 0.0 else []


def run_once(
    binary: str, threads: int, steps: int, rolling_friction: float = 0.0, extra: tuple[str, ...] = ()
) -> float:
    """Particle-steps per second of one run of ``binary`` (``extra``: more options)."""
    out = subprocess.run(
        [binary, str(threads), str(steps), *options(rolling_friction), *extra],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    match = re.search(r"particle_steps_per_s=([0-9.eE+-]+)", out)
    if match is None:
        raise RuntimeError(f"{binary}: no particle_steps_per_s in {out!r}")
    return float(match.group(1))


def instructions(binary: str, steps: int, rolling_friction: float = 0.0) -> int:
    """Instructions executed by one single-thread run (callgrind)."""
    done = subprocess.run(
        ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", binary, "1", str(steps),
         *options(rolling_friction)],
        check=True,
        capture_output=True,
        text=True,
    )
    match = re.search(r"refs:\s+([0-9,]+)", done.stderr)
    if match is None:
        raise RuntimeError(f"{binary}: no instruction count in valgrind's output")
    return int(match.group(1).replace(",", ""))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a", help="the first (old) build of the throughput example")
    parser.add_argument("b", help="the second (new) build")
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--busy", action="store_true", help="keep one core busy during every run")
    parser.add_argument("--count", action="store_true", help="also count instructions (valgrind)")
    parser.add_argument(
        "--rolling-friction", type=float, default=0.0, metavar="MU",
        help="rolling resistance mu_r of both builds' contact model (0: none)",
    )
    parser.add_argument(
        "--b-option", action="append", default=[], metavar="OPT",
        help="an option of the example for B's runs only (repeatable), e.g. --trimers",
    )
    args = parser.parse_args(argv)
    for name in (args.a, args.b):
        if not Path(name).is_file():
            raise SystemExit(f"no such build: {name}")
    if args.repeat < 1 or args.steps < 1:
        raise SystemExit("--repeat and --steps must be >= 1")
    if not args.rolling_friction >= 0.0:
        raise SystemExit(f"--rolling-friction: must be >= 0, got {args.rolling_friction}")

    runs: dict[str, list[float]] = {}
    for _ in range(args.repeat):
        for threads in args.threads:
            for label, binary, extra in (("a", args.a, ()), ("b", args.b, tuple(args.b_option))):
                hog = None
                if args.busy:
                    hog = multiprocessing.Process(target=spin, args=(time.time() + 600,))
                    hog.start()
                try:
                    speed = run_once(binary, threads, args.steps, args.rolling_friction, extra)
                finally:
                    if hog is not None:
                        hog.terminate()
                        hog.join()
                runs.setdefault(f"{label}_{threads}", []).append(speed)

    summary: dict[str, float | int] = {}
    busy = " (one core kept busy)" if args.busy else ""
    print(f"particle-steps/s, medians of {args.repeat} alternated runs{busy}:")
    for threads in args.threads:
        a = statistics.median(runs[f"a_{threads}"])
        b = statistics.median(runs[f"b_{threads}"])
        summary[f"a_{threads}"], summary[f"b_{threads}"] = a, b
        summary[f"ratio_{threads}"] = b / a
        print(f"  {threads} thread(s): A {a:.3e}  B {b:.3e}  B/A {b / a:.2f}x")
        for label in ("a", "b"):
            singles = " ".join(f"{v:.2e}" for v in runs[f"{label}_{threads}"])
            print(f"    {label.upper()}: {singles}")
    if args.count:
        for label, binary in (("a", args.a), ("b", args.b)):
            summary[f"instructions_{label}"] = instructions(binary, 1000, args.rolling_friction)
        ratio = summary["instructions_b"] / summary["instructions_a"]
        print(
            f"  instructions, 1 thread, 1,100 steps: A {summary['instructions_a']:,}"
            f"  B {summary['instructions_b']:,}  B/A {ratio:.3f}"
        )
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
