"""Each test's loading phase against the biaxial test's, in particle-steps per second.

Every test runs on the quick sample (563 grains; the biaxial and cyclic tests add
the membrane's disks; ``--sample default``: the paper's 3,518) with one engine thread, in a fresh folder, in turn, so that
a drift of the machine's speed falls on all of them alike (alternated
repetitions). Each run's loading phase is timed by the run itself
(``summary.json``'s ``wall_time_by_phase_s``: ``shear`` for the biaxial and
cyclic and simple-shear tests, ``load`` for the oedometer), and its steps are the difference of
the first and last records' ``step`` (the oedometer's summary's ``load_steps``:
it records at the load steps' ends only); the figure is particles x steps / seconds.
Medians over ``--repeat`` rounds, then each test's ratio to the biaxial test on
the same disks (the cyclic test: with the membrane; the constant-volume test,
the oedometer and periodic simple shear, on a sample of the biaxial test's
size: grains alone, between rigid walls, ``boundary.kind = walls``); the
last line printed is one JSON object.

    python benchmarks/protocol_speed.py --repeat 5       # about 7 minutes
    python benchmarks/protocol_speed.py --sample default --tests oedometer --repeat 3
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

#: name -> (command after ``grainlab``, the loading phase's name, the biaxial variant it is
#: compared with: the same disks, grains alone or grains and membrane). The strain path is 3 %
#: for each strain-driven test (the cyclic: 3 cycles of +/- 0.25 %).
TESTS: dict[str, tuple[list[str], str, str]] = {
    "biaxial": (["biaxial", "--set", "shear.final_strain=0.03"], "shear", "biaxial"),
    "biaxial, walls": (["biaxial", "--set", "shear.final_strain=0.03", "--set", "boundary.kind=walls"], "shear",
                       "biaxial, walls"),
    "cyclic": (["run", "cyclic", "--set", "cyclic.cycles=3", "--set", "cyclic.strain_amplitude=0.0025"], "shear",
               "biaxial"),
    "constant volume": (["biaxial", "--set", "shear.final_strain=0.03", "--set", "shear.volume=constant"], "shear",
                        "biaxial, walls"),
    "oedometer": (["run", "oedometer"], "load", "biaxial, walls"),
    # the biaxial test's sample size (30 x 60 mm quick, 75 x 150 mm default) in a periodic cell, 30 % of shear
    "simple shear": (["run", "simple_shear", "--set", "sample.height=0.06", "--set", "simple_shear.final_strain=0.3",
                      "--set", "simple_shear.snapshot_strains=[0, 0.3]"], "shear", "biaxial, walls"),
}
#: Every run's options; the monotonic tests also take two snapshots only, as the others.
COMMON = ["--no-report", "--no-progress", "--set", "run.threads=1"]
SNAPSHOTS = ["--set", "shear.snapshot_strains=[0, 0.03]"]
#: On the default sample (3,518 grains) a third of the strain path, for the same time.
DEFAULT_SAMPLE = {"shear.final_strain=0.03": "shear.final_strain=0.01", "cyclic.cycles=3": "cyclic.cycles=1",
                  "shear.snapshot_strains=[0, 0.03]": "shear.snapshot_strains=[0, 0.01]",
                  "sample.height=0.06": "sample.height=0.15", "simple_shear.final_strain=0.3": "simple_shear.final_strain=0.1",
                  "simple_shear.snapshot_strains=[0, 0.3]": "simple_shear.snapshot_strains=[0, 0.1]"}


def one_run(name: str, quick: bool) -> float:
    """Particle-steps per second of the loading phase of one run of test ``name``."""
    args, phase, _ = TESTS[name]
    common = COMMON + (SNAPSHOTS if args[0] == "biaxial" else []) + (["--quick"] if quick else [])
    args = [a if quick else DEFAULT_SAMPLE.get(a, a) for a in [*args, *common]]
    common = []
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        subprocess.run([sys.executable, "-m", "grainlab", *args, *common, "--out", str(out)], check=True,
                       stdout=subprocess.DEVNULL)
        summary = json.loads((out / "summary.json").read_text())
        steps = np.asarray(read_results(out / "run.h5").timeseries["step"])
        # the oedometer records at the load steps' ends only: its summary counts the loading's steps
        loading = summary["load_steps"] if "load_steps" in summary else float(steps[-1] - steps[0])
        particles = summary["n_particles"] + summary.get("n_membrane_disks", 0)
        return particles * loading / summary["wall_time_by_phase_s"][phase]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sample", choices=("quick", "default"), default="quick",
                        help="the quick sample (563 grains, 3 %% of strain path) or the default one "
                             "(3,518 grains, 1 %%; the oedometer's nine load steps take longer there)")
    parser.add_argument("--tests", nargs="+", choices=list(TESTS), default=list(TESTS),
                        help="the tests to run (each with the biaxial variant it is compared with)")
    args = parser.parse_args(argv)
    names = [n for n in TESTS if n in args.tests or n in {TESTS[t][2] for t in args.tests}]
    if args.repeat < 1:
        parser.error("--repeat must be positive")
    rates: dict[str, list[float]] = {name: [] for name in names}
    for k in range(args.repeat):
        for name in names:
            rates[name].append(one_run(name, args.sample == "quick"))
        print(f"round {k + 1}: " + ", ".join(f"{n} {v[-1]:.3g}" for n, v in rates.items()), flush=True)
    medians = {name: statistics.median(v) for name, v in rates.items()}
    ratios = {name: value / medians[TESTS[name][2]] for name, value in medians.items()}
    for name, value in medians.items():
        print(f"{name:16s} {value:.3g} particle-steps/s ({ratios[name]:.2f}x {TESTS[name][2]})")
    print(json.dumps({"medians": medians, "ratios": ratios, "runs": rates}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
