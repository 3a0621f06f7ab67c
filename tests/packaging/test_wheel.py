"""The release wheel as a user gets it (``make wheel``; .github/workflows/release.yml
builds the other platforms').

The wheel is built here as the release builds it: maturin, abi3 (one wheel for every
CPython from 3.11), linked by zig against glibc 2.17 (manylinux2014). It is installed
into a fresh virtual environment with no cargo or rustc on PATH and runs
``grainlab biaxial --quick`` there. The engine picks its AVX2 kernels at run time, so
the one x86_64 wheel serves every x86_64 processor: run under a processor emulator
(qemu-user) with AVX2 switched off, the wheel's engine executes no AVX2 (ymm)
instruction at all, and with AVX2 on it does, and both runs end in the same bits as
the run on this machine's own processor.

The build takes about a minute and the quick biaxial test about as much: ``slow``
(CI runs them). The emulator test skips when qemu-x86_64 is missing (Debian:
apt-get install qemu-user) unless GRAINLAB_REQUIRE_QEMU=1, as .ci/run sets it.
"""

from __future__ import annotations

import json
import os
import platform
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
import yaml
from external_tools import tool_or_skip

import grainlab

ROOT = Path(__file__).resolve().parents[2]
SAME_BITS = Path(__file__).with_name("same_bits.py")
#: The oldest glibc the Linux wheel runs on (manylinux2014).
GLIBC = (2, 17)


def _no_rust_path(venv: Path) -> str:
    """PATH with the virtual environment first and no folder holding cargo, rustc or rustup."""
    folders = [str(venv / "bin")]
    for folder in os.environ.get("PATH", "").split(os.pathsep):
        if folder and not any((Path(folder) / tool).exists() for tool in ("cargo", "rustc", "rustup")):
            folders.append(folder)
    return os.pathsep.join(folders)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The Linux wheel, built as ``make wheel`` builds it (its own cargo target folder
    under target/, so that the build does not disturb the development build's)."""
    out = tmp_path_factory.mktemp("dist")
    env = {**os.environ, "CARGO_TARGET_DIR": str(ROOT / "target" / "wheel"),
           "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])}
    done = subprocess.run(
        [sys.executable, "-m", "maturin", "build", "--release", "--zig", "--compatibility", "manylinux2014",
         "--out", str(out)],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=1800,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    (built,) = out.glob("grainlab-*.whl")
    return built


@pytest.fixture(scope="module")
def venv(wheel: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh virtual environment with the wheel installed, and nothing built: every
    package from a wheel, no cargo or rustc on PATH."""
    folder = tmp_path_factory.mktemp("venv") / "env"
    subprocess.run([sys.executable, "-m", "venv", str(folder)], check=True, timeout=300)
    env = {**os.environ, "PATH": _no_rust_path(folder)}
    env.pop("PYTHONPATH", None)
    subprocess.run([str(folder / "bin" / "python"), "-m", "pip", "install", "--quiet", "--only-binary=:all:",
                    str(wheel)], check=True, env=env, timeout=900)
    return folder


def _run(venv: Path, *args: str, cwd: Path, timeout: float = 900) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PATH": _no_rust_path(venv)}
    env.pop("PYTHONPATH", None)
    return subprocess.run(list(args), cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


@pytest.mark.slow
def test_the_wheel_is_abi3_and_manylinux2014(wheel):
    machine = platform.machine()
    assert wheel.name.startswith(f"grainlab-{grainlab.__version__}-cp311-abi3-")
    assert f"manylinux2014_{machine}" in wheel.name and f"manylinux_2_17_{machine}" in wheel.name
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        assert "grainlab/_core.abi3.so" in names and "grainlab/py.typed" in names
        assert not [n for n in names if n.endswith(".so") and n != "grainlab/_core.abi3.so"]
        engine = archive.read("grainlab/_core.abi3.so")
    # the glibc symbol versions the engine needs: none newer than manylinux2014's 2.17
    needed = {tuple(map(int, v)) for v in re.findall(rb"GLIBC_(\d+)\.(\d+)", engine)}
    assert needed and max(needed) <= GLIBC, sorted(needed)


@pytest.mark.slow
def test_pip_takes_the_wheel_for_a_glibc_2_17_machine(wheel, tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--dry-run", "--no-deps", "--only-binary=:all:", "--target",
         str(tmp_path), "--platform", f"manylinux2014_{platform.machine()}", "--python-version", "3.11",
         str(wheel)],
        capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"Would install grainlab-{grainlab.__version__}" in done.stdout


@pytest.mark.slow
def test_the_wheel_runs_the_quick_biaxial_test_with_no_rust_on_path(venv, tmp_path):
    path = _no_rust_path(venv)
    assert shutil.which("cargo", path=path) is None and shutil.which("rustc", path=path) is None
    python = str(venv / "bin" / "python")
    where = _run(venv, python, "-c", "import grainlab; print(grainlab.__file__)", cwd=tmp_path)
    assert where.returncode == 0 and where.stdout.startswith(str(venv)), where.stdout + where.stderr
    version = _run(venv, "grainlab", "--version", cwd=tmp_path)
    assert version.stdout.splitlines()[0] == f"grainlab {grainlab.__version__}"
    done = _run(venv, "grainlab", "biaxial", "--quick", "--out", "results", "--no-progress", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    summary = json.loads((tmp_path / "results" / "summary.json").read_text(encoding="utf-8"))
    assert summary["grainlab_version"] == grainlab.__version__ and summary["n_particles"] > 300
    assert 1.5 < summary["peak_stress_ratio"] < 6.0
    assert (tmp_path / "results" / "report.html").stat().st_size > 100_000


def _qemu_or_skip() -> str:
    if platform.machine() != "x86_64":
        pytest.skip("the AVX2 kernels are x86_64's")
    return tool_or_skip("qemu-x86_64", "GRAINLAB_REQUIRE_QEMU", "apt-get install qemu-user")


def _engine_ymm_instructions(log: Path, maps: str) -> tuple[int, int]:
    """(instructions, of which on ymm registers) the emulator translated inside the
    engine's executable mappings (``MAP first-last`` lines of same_bits.py --maps)."""
    ranges = [tuple(int(a, 16) for a in line.split()[1].split("-")) for line in maps.splitlines()
              if line.startswith("MAP ")]
    assert ranges, maps
    total = ymm = 0
    with open(log, encoding="utf-8", errors="replace") as lines:
        for line in lines:
            match = re.match(r"0x([0-9a-f]+):\s+(.*)", line)
            if match and any(lo <= int(match.group(1), 16) < hi for lo, hi in ranges):
                total += 1
                ymm += "ymm" in match.group(2)
    return total, ymm


@pytest.mark.slow
def test_without_avx2_the_wheel_runs_the_scalar_path_to_the_same_bits(venv, tmp_path):
    qemu = _qemu_or_skip()
    python = str(venv / "bin" / "python")
    native = _run(venv, python, str(SAME_BITS), cwd=tmp_path)
    assert native.returncode == 0, native.stderr
    runs = {}
    for cpu in ("max", "max,-avx2"):  # the emulator's every feature, then the same less AVX2
        log = tmp_path / f"{cpu}.log"
        done = _run(venv, qemu, "-cpu", cpu, "-d", "in_asm", "-D", str(log), python, str(SAME_BITS), "--maps",
                    cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        runs[cpu] = (done.stdout.splitlines()[0], _engine_ymm_instructions(log, done.stdout))
        log.unlink()
    with_avx2, without_avx2 = runs["max"], runs["max,-avx2"]
    assert with_avx2[1][1] > 0, "with AVX2 the engine ran no AVX2 kernel"
    assert without_avx2[1][0] > 10_000 and without_avx2[1][1] == 0, without_avx2
    assert native.stdout.splitlines()[0] == with_avx2[0] == without_avx2[0]


def test_the_release_workflow_builds_every_platform_and_the_sdist_on_a_tag():
    workflow = yaml.safe_load((ROOT / ".github" / "workflows" / "release.yml").read_text(encoding="utf-8"))
    assert workflow[True]["push"]["tags"] == ["v*"]  # YAML reads the key "on" as True
    jobs = workflow["jobs"]
    assert {m["target"] for m in jobs["linux"]["strategy"]["matrix"]["include"]} == {"x86_64", "aarch64"}
    assert {m["target"] for m in jobs["macos"]["strategy"]["matrix"]["include"]} == {"x86_64", "aarch64"}
    builds = {name: next(s for s in job["steps"] if str(s.get("uses", "")).startswith("PyO3/maturin-action"))
              for name, job in jobs.items() if name != "release"}
    assert builds["linux"]["with"]["manylinux"] == "2014"  # the glibc of make wheel and the test above
    assert builds["windows"]["with"]["target"] == "x64" and builds["sdist"]["with"]["command"] == "sdist"
    for name in ("linux", "macos", "windows"):
        assert "--release" in builds[name]["with"]["args"]
        run = "\n".join(s.get("run", "") for s in jobs[name]["steps"])
        assert "grainlab --version" in run and "tests/packaging/same_bits.py" in run, name
    assert set(jobs["release"]["needs"]) == {"linux", "macos", "windows", "sdist"}
