"""The user's main job timed as a new user runs it: ``grainlab biaxial --out DIR``
(the paper's Table 1 test at its 2 %/min, generation to 10 % axial strain, then the
figures and the report), end to end.

Each repetition runs the command in a fresh folder and prints the process's wall
time, the run's time per phase (from its summary.json), the time after the run
(figures and report) and the size of the results folder and of report.html.
Medians over ``--repeat`` runs; the last line printed is one JSON object.

    python benchmarks/biaxial_default.py                # 1 repetition (about 8 minutes)
    python benchmarks/biaxial_default.py --repeat 3
    python benchmarks/biaxial_default.py --quick        # the --quick variant
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def one_run(quick: bool) -> dict[str, float]:
    """Seconds and sizes of one ``grainlab biaxial`` run in a fresh folder."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        command = [sys.executable, "-m", "grainlab", "biaxial", "--out", str(out)] + (["--quick"] if quick else [])
        start = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        process_s = time.perf_counter() - start
        summary = json.loads((out / "summary.json").read_text())
        sizes = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
        result = {"process_s": process_s, "run_s": summary["wall_time_s"],
                  "after_run_s": process_s - summary["wall_time_s"],
                  "folder_mb": sizes / 1e6, "report_mb": (out / "report.html").stat().st_size / 1e6}
        result.update({f"{name}_s": s for name, s in summary["wall_time_by_phase_s"].items()})
        result["peak_stress_ratio"] = summary["peak_stress_ratio"]
        return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--quick", action="store_true", help="the --quick variant instead of the default")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be positive")
    runs = []
    for k in range(args.repeat):
        r = one_run(args.quick)
        runs.append(r)
        phases = ", ".join(f"{key[:-2]} {v:.1f}" for key, v in r.items()
                           if key.endswith("_s") and key not in ("process_s", "run_s", "after_run_s"))
        print(f"run {k + 1}: process {r['process_s']:.1f} s = run {r['run_s']:.1f} s ({phases}) + figures and "
              f"report {r['after_run_s']:.1f} s; folder {r['folder_mb']:.2f} MB, report.html {r['report_mb']:.2f} MB; "
              f"peak ratio {r['peak_stress_ratio']:.3f}", flush=True)
    medians = {key: statistics.median(r[key] for r in runs) for key in runs[0]}
    print(json.dumps(medians))
    return 0


if __name__ == "__main__":
    sys.exit(main())
