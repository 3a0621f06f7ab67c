"""The cost of shaped grains in the paper's test: ``grainlab biaxial --quick`` with
disks and with clumps of a shape (default trimers, eta 0.3), alternated, and the
shearing phase's wall time per particle-step of each (every particle counts:
grains' pebbles and membrane disks), with their ratio.

The shearing phase is the run's loop with everything it does per step and per
record (the engine, the membrane's pressure, the records' measures); its steps
are the time series' last step less its first. Medians over ``--repeat`` pairs;
the last line printed is one JSON object.

    python benchmarks/shape_cost.py                       # trimers, eta 0.3, 1 pair (about 3 minutes)
    python benchmarks/shape_cost.py --shape dimer --eta 0.4 --repeat 3
"""

from __future__ import annotations

import argparse
import csv
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path


def shear_cost(settings: list[str]) -> dict[str, float]:
    """Seconds per particle-step of one quick biaxial run's shearing, and its counts."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        command = [sys.executable, "-m", "grainlab", "biaxial", "--quick", "--out", str(out), "--no-report"]
        for setting in settings:
            command += ["--set", setting]
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        summary = json.loads((out / "summary.json").read_text())
        with open(out / "timeseries.csv") as f:
            steps = [float(row["step"]) for row in csv.DictReader(f)]
    particles = summary["n_particles"] + summary.get("n_membrane_disks", 0)
    shear_steps = steps[-1] - steps[0]
    seconds = summary["wall_time_by_phase_s"]["shear"]
    return {"particles": particles, "steps": shear_steps, "shear_s": seconds,
            "ns_per_particle_step": 1e9 * seconds / (shear_steps * particles)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", default="trimer")
    parser.add_argument("--eta", type=float, default=0.3)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    shaped = [f"sample.shape={args.shape}", f"sample.shape_parameter={args.eta}"]
    runs: dict[str, list[dict[str, float]]] = {"disks": [], "shaped": []}
    for k in range(args.repeat):
        for name, settings in (("disks", []), ("shaped", shaped)):
            result = shear_cost(settings)
            runs[name].append(result)
            print(f"{name} run {k + 1}: {result['particles']} particles, {result['steps']:.0f} shearing steps, "
                  f"{result['shear_s']:.1f} s, {result['ns_per_particle_step']:.1f} ns per particle-step", flush=True)
    median = {name: statistics.median(r["ns_per_particle_step"] for r in rs) for name, rs in runs.items()}
    ratio = median["shaped"] / median["disks"]
    print(f"{args.shape}s (eta {args.eta:g}) cost {ratio:.2f}x disks per particle-step "
          f"({median['shaped']:.1f} against {median['disks']:.1f} ns, medians of {args.repeat})")
    print(json.dumps({"shape": args.shape, "eta": args.eta, "ns_disks": median["disks"],
                      "ns_shaped": median["shaped"], "ratio": ratio, "runs": runs}))


if __name__ == "__main__":
    main()
