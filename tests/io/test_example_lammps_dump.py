"""examples/06_lammps_dump.py on the LAMMPS-written pile: its numbers against an
independent calculation from the raw dump files (plain NumPy, no grainlab reader),
LAMMPS's own contact count, and the paper's definitions written out longhand."""

from __future__ import annotations

import contextlib
import io
import re
import runpy
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "06_lammps_dump.py"
DATA = ROOT / "tests" / "data" / "lammps_dump"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("example06")
    module = runpy.run_path(str(EXAMPLE), run_name="example")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        result = module["main"](out)
    return result, printed.getvalue()


@pytest.fixture(scope="module")
def raw():
    """The pile read straight from the text files (9 header lines each)."""
    atoms = np.loadtxt(DATA / "atoms.dump", skiprows=9)  # id type x y radius vx vy fx fy omegaz tqz
    rows = np.loadtxt(DATA / "contacts.dump", skiprows=9)  # index id1 id2 dist force fx fy p1 p2 p4
    row_of = {int(a): k for k, a in enumerate(atoms[:, 0])}
    i = np.array([row_of[int(a)] for a in rows[:, 1]])
    j = np.array([row_of[int(b)] for b in rows[:, 2]])
    grain = atoms[:, 1] == 1
    xy = atoms[:, 2:4]
    d = xy[j] - xy[i]
    theta_ij = np.arctan2(d[:, 1], d[:, 0])  # direction from i's centre to j's
    return {"grain": grain, "i": i, "j": j, "theta": theta_ij, "force": rows[:, 4]}


def _printed(text: str, label: str) -> float:
    return float(re.search(re.escape(label) + r"\s*=\s*(\S+)", text).group(1))


def test_coordination_numbers(run, raw):
    result, text = run
    g, i, j = raw["grain"], raw["i"], raw["j"]
    n_grains = int(g.sum())
    grain_grain = g[i] & g[j]
    with_wall = g[i] ^ g[j]
    assert result["Z"] == pytest.approx(2 * grain_grain.sum() / n_grains, rel=1e-12)
    # LAMMPS's compute contact/atom, averaged over the mobile disks (log.lammps): 3.208
    assert result["Z_with_walls"] == pytest.approx(3.208, abs=1e-12)
    assert result["Z_with_walls"] == pytest.approx(
        (2 * grain_grain.sum() + with_wall.sum()) / n_grains, rel=1e-12
    )
    # rattlers: grains with < 2 grain-grain contacts, removed until none is left
    alive = g.copy()
    while True:
        keep = grain_grain & alive[i] & alive[j]
        counts = np.bincount(i[keep], minlength=g.size) + np.bincount(j[keep], minlength=g.size)
        drop = alive & (counts < 2)
        if not drop.any():
            break
        alive &= ~drop
    assert result["n_rattlers"] == int(n_grains - alive.sum())
    assert result["mechanical_Z"] == pytest.approx(2 * keep.sum() / alive.sum(), rel=1e-12)
    assert _printed(text, "coordination number Z") == pytest.approx(result["Z"], abs=5e-5)


def _eq7(theta: np.ndarray, weights: np.ndarray, bins: int = 18) -> tuple[float, float]:
    """Eq. 7-8 as printed, each contact counted in both directions, bins in degrees."""
    both = np.degrees(np.concatenate([theta, theta + np.pi])) % 360.0
    w = np.concatenate([weights, weights])
    counts, _ = np.histogram(both, bins=bins, range=(0.0, 360.0), weights=w)
    dt = 360.0 / bins
    s = sum(counts[g - 1] * np.sin(np.radians((2 * g - 1) * dt)) for g in range(1, bins + 1))
    c = sum(counts[g - 1] * np.cos(np.radians((2 * g - 1) * dt)) for g in range(1, bins + 1))
    a = 2 * np.sin(np.radians(dt)) / (counts.sum() * np.radians(dt)) * np.hypot(s, c)
    return float(a), float(np.degrees(0.5 * np.arctan2(s, c)) % 180.0)


def test_anisotropies(run, raw):
    result, text = run
    g, i, j = raw["grain"], raw["i"], raw["j"]
    pp = g[i] & g[j]  # the fabric measures leave boundary contacts out by default
    theta = raw["theta"][pp]
    a, direction = _eq7(theta, np.ones(theta.size))
    assert result["a_binned"] == pytest.approx(a, rel=1e-9)
    assert result["theta_a_binned_deg"] == pytest.approx(direction, abs=1e-9)
    a_n, direction_n = _eq7(theta, raw["force"][pp])
    assert result["a_n_binned"] == pytest.approx(a_n, rel=1e-9)
    assert result["theta_n_binned_deg"] == pytest.approx(direction_n, abs=1e-9)
    # the headline a is exact: twice the eigenvalue gap of the 2D fabric tensor (trace 1),
    # theta_a its major axis; a_n the same with the normal forces as weights
    for key, w in (("a", np.ones(theta.size)), ("a_n", raw["force"][pp])):
        n = np.c_[np.cos(theta), np.sin(theta)]
        phi = (n * w[:, None]).T @ n / w.sum()
        (low, high), vectors = np.linalg.eigh(phi)
        assert result[key] == pytest.approx(2 * (high - low), rel=1e-9)
        major = np.degrees(np.arctan2(vectors[1, 1], vectors[0, 1])) % 180.0
        theta_key = "theta_a_deg" if key == "a" else "theta_n_deg"
        assert abs((result[theta_key] - major + 90.0) % 180.0 - 90.0) < 1e-9
    assert result["a_fourier"] == result["a"]
    assert _printed(text, "contact-normal anisotropy a") == pytest.approx(result["a"], abs=5e-5)


def _lambda_longhand(angles_deg: list[float]) -> float:
    """Sec. 5 as written: each contact in turn as the reference of n equally spaced
    positions; sum of the minimum angles of the contacts (in angular order) to them."""
    n = len(angles_deg)
    if n < 2:
        return 1.0
    phi = sorted(a % 360.0 for a in angles_deg)
    best = np.inf
    for k in range(n):
        total = 0.0
        for m in range(n):
            diff = abs(phi[(k + m) % n] - (phi[k] + 360.0 * m / n)) % 360.0
            total += min(diff, 360.0 - diff)
        best = min(best, total)
    return best / 360.0


def test_stability_index(run, raw):
    result, text = run
    g, i, j = raw["grain"], raw["i"], raw["j"]
    angles: dict[int, list[float]] = {int(p): [] for p in np.flatnonzero(g)}
    theta = np.degrees(raw["theta"])
    for c in range(len(i)):  # every contact, walls included: all active contacts (Sec. 5)
        if g[i[c]]:
            angles[int(i[c])].append(theta[c])
        if g[j[c]]:
            angles[int(j[c])].append(theta[c] + 180.0)
    lam = {p: _lambda_longhand(a) for p, a in angles.items()}
    two_or_more = [lam[p] for p, a in angles.items() if len(a) >= 2]
    assert result["mean_lambda"] == pytest.approx(np.mean(two_or_more), rel=1e-9)
    assert result["mean_lambda_all"] == pytest.approx(np.mean(list(lam.values())), rel=1e-9)
    assert _printed(text, "mean stability index lambda") == pytest.approx(
        result["mean_lambda"], abs=5e-5
    )


def test_polar_plots_are_written(run):
    result, text = run
    assert len(result["figures"]) == 2
    for path in map(Path, result["figures"]):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert str(path) in text
