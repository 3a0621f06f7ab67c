"""Each test's loading phase against the biaxial test's, in particle-steps per second.

Every test runs on the quick sample (563 grains; the biaxial and cyclic tests add
the membrane's disks) with one engine thread, in a fresh folder, in turn, so that
a drift of the machine's speed falls on all of them alike (alternated
repetitions). Each run's loading phase is timed by the run itself
(``summary.json``'s ``wall_time_by_phase_s``: ``shear`` for the biaxial and
cyclic tests, ``load`` for the oedometer), and its steps are the difference of
the first and last records' ``step``; the figure is particles x steps / seconds.
Medians over ``--repeat`` rounds, then each test's ratio to the biaxial test's;
the last line printed is one JSON object.

    python benchmarks/protocol_speed.py --repeat 5       # about 5 minutes
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from grainlab.io.hdf5 import read_results

#: name -> (command after ``grainlab``, the loading phase's name). The strain path
#: is 3 % for each strain-driven test (the cyclic: 3 cycles of +/- 0.25 %).
TESTS: dict[str, tuple[list[str], str]] = {
    "biaxial": (["biaxial", "--set", "shear.final_strain=0.03"], "shear"),
    "constant volume": (["biaxial", "--set", "shear.final_strain=0.03", "--set", "shear.volume=constant"], "shear"),
    "cyclic": (["run", "cyclic", "--set", "cyclic.cycles=3", "--set", "cyclic.strain_amplitude=0.0025"], "shear"),
    "oedometer": (["run", "oedometer"], "load"),
}
#: Every run's options; the monotonic tests also take two snapshots only, as the others.
COMMON = ["--quick", "--no-report", "--no-progress", "--set", "run.threads=1"]
SNAPSHOTS = ["--set", "shear.snapshot_strains=[0, 0.03]"]


def one_run(name: str) -> float:
    """Particle-steps per second of the loading phase of one run of test ``name``."""
    args, phase = TESTS[name]
    common = COMMON + (SNAPSHOTS if args[0] == "biaxial" else [])
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        subprocess.run([sys.executable, "-m", "grainlab", *args, *common, "--out", str(out)], check=True,
                       stdout=subprocess.DEVNULL)
        summary = json.loads((out / "summary.json").read_text())
        steps = np.asarray(read_results(out / "run.h5").timeseries["step"])
        particles = summary["n_particles"] + summary.get("n_membrane_disks", 0)
        return particles * float(steps[-1] - steps[0]) / summary["wall_time_by_phase_s"][phase]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be positive")
    rates: dict[str, list[float]] = {name: [] for name in TESTS}
    for k in range(args.repeat):
        for name in TESTS:
            rates[name].append(one_run(name))
        print(f"round {k + 1}: " + ", ".join(f"{n} {v[-1]:.3g}" for n, v in rates.items()), flush=True)
    medians = {name: statistics.median(v) for name, v in rates.items()}
    for name, value in medians.items():
        print(f"{name:16s} {value:.3g} particle-steps/s ({value / medians['biaxial']:.2f}x the biaxial test)")
    print(json.dumps({"medians": medians, "ratios": {n: v / medians["biaxial"] for n, v in medians.items()},
                      "runs": rates}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
