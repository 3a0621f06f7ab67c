"""Figures of a biaxial run (paper Figs. 6, 7, 9, 11-14) from a synthetic run.h5 with a known band."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from grainlab import plot
from grainlab.io.hdf5 import ResultsWriter, read_results, snapshot_name
from grainlab.plot.biaxial import COUNT_CAP
from grainlab.postprocess import (
    FIGURES,
    FabricFigures,
    MissingColumnError,
    fabric_figures,
    fabric_numbers,
)
from grainlab.snapshot import Snapshot

D = 1.0e-3  # lattice spacing of the synthetic grains, m
BAND_ANGLE = 60.0  # degrees, CCW from +x
BAND_WIDTH = 6.0 * D
SNAPSHOTS = (0.0, 0.005, 0.01, 0.02)
#: Simple shear imposed inside the band at each snapshot strain (none at 0.5 %).
BAND_SHEAR = {0.0: 0.0, 0.005: 0.0, 0.01: 0.04, 0.02: 0.08}


def _grains(nx: int, ny: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Jittered triangular lattice (spacing D), radii 0.48-0.54 D: Z of about 4."""
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    pos = np.c_[((i + 0.5 * (j % 2)) * D).ravel(), (j * D * np.sqrt(3.0) / 2.0).ravel()]
    pos += rng.normal(0.0, 0.04 * D, pos.shape)
    return pos, rng.uniform(0.48, 0.54, nx * ny) * D


def _membrane(grains: np.ndarray, r: float = 0.25 * D) -> np.ndarray:
    """A chain of small disks around the grains, touching the outer ones."""
    lo = grains.min(axis=0) - 0.5 * D - r + 0.02 * D
    hi = grains.max(axis=0) + 0.5 * D + r - 0.02 * D
    ys = np.arange(lo[1], hi[1], 2 * r)
    xs = np.arange(lo[0] + 2 * r, hi[0] - r, 2 * r)
    return np.vstack(
        [
            np.c_[np.full_like(ys, lo[0]), ys],
            np.c_[np.full_like(ys, hi[0]), ys],
            np.c_[xs, np.full_like(xs, lo[1])],
            np.c_[xs, np.full_like(xs, hi[1])],
        ]
    )


def _deformed(
    pos: np.ndarray, center: np.ndarray, eps: float, gamma: float, rng: np.random.Generator
) -> np.ndarray:
    """Biaxial background (compression along y, dilation along x), a band of simple
    shear ``gamma`` of thickness BAND_WIDTH at BAND_ANGLE through ``center``, small noise."""
    beta = np.radians(BAND_ANGLE)
    t = np.array([np.cos(beta), np.sin(beta)])
    n = np.array([-np.sin(beta), np.cos(beta)])
    x = pos - center
    u = x @ np.array([[0.6 * eps, 0.0], [0.0, -eps]]).T
    u += gamma * np.clip(x @ n, -BAND_WIDTH / 2, BAND_WIDTH / 2)[:, None] * t
    return pos + u + rng.normal(0.0, 0.003 * D, pos.shape)


def write_run(
    path: Path,
    *,
    columns: tuple[str, ...] | None = None,
    rising: bool = False,
    snapshots: tuple[float, ...] = SNAPSHOTS,
    nx: int = 24,
    ny: int = 48,
) -> Path:
    """A run.h5 like a biaxial run's: grains + membrane disks, a stress ratio peaking at 1 %
    (or still ``rising`` at the end), snapshots at ``snapshots`` with the band from 1 %."""
    rng = np.random.default_rng(7)
    grains, radii = _grains(nx, ny, rng)
    membrane = _membrane(grains)
    pos0 = np.vstack([grains, membrane])
    rad = np.r_[radii, np.full(len(membrane), 0.25 * D)]
    kind = np.r_[np.zeros(len(grains), np.int8), np.ones(len(membrane), np.int8)]
    center = grains.mean(axis=0)
    eps = np.linspace(0.0, 0.02, 81)
    x = eps / 0.01
    q = 1.0 + 150.0 * eps if rising else 1.0 + 3.0 * x * np.exp(1.0 - x)  # peak 4 at 1 %
    shape = (q - 1.0) / (q.max() - 1.0)
    ts = {
        "axial_strain": eps,
        "stress_ratio": q,
        "anisotropy": 0.3 * shape,
        "force_anisotropy": 0.6 * shape,
        "mean_stability_index": 0.25 + 0.05 * shape,
        "coordination_number": 4.0 - 0.5 * shape,
    }
    if columns is not None:
        ts = {k: v for k, v in ts.items() if k in columns}
    with ResultsWriter(path, kind="biaxial", overwrite=True) as writer:
        writer.append_rows(ts)
        for e in snapshots:
            pos = pos0 if e == 0.0 else _deformed(pos0, center, e, BAND_SHEAR[e], rng)
            snap = Snapshot.from_geometry(pos, rad, kind=kind, tolerance=0.03 * D, axial_strain=e)
            # normal forces favouring vertical contacts more and more (a_n grows)
            theta = snap.contact_angles()
            force = (
                10.0
                * (1.0 + 25.0 * e * np.cos(2.0 * theta - np.pi))
                * rng.uniform(0.8, 1.2, theta.size)
            )
            writer.write_snapshot(
                snapshot_name(e),
                snap.with_contacts(snap.contact_i, snap.contact_j, normal_force=force),
            )
    return path


class _MapSpy:
    """Records every particle map drawn (values and axes) while delegating to grainlab.plot."""

    def __init__(self) -> None:
        self.calls: list[tuple[np.ndarray, np.ndarray, object]] = []
        self._real = plot.particle_map

    def __call__(self, positions, radii, values, **kwargs):
        ax = self._real(positions, radii, values, **kwargs)
        self.calls.append((np.asarray(positions), np.asarray(values, dtype=float), ax))
        return ax


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("biaxial_run")
    write_run(folder / "run.h5")
    return folder


@pytest.fixture(scope="module")
def drawn(run_dir, tmp_path_factory):
    """fabric_figures on the synthetic run (default peak), drawn in this process with the maps recorded."""
    out = tmp_path_factory.mktemp("figures")
    spy = _MapSpy()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plot, "particle_map", spy)
        figures = fabric_figures(run_dir, out, workers=0)
    return figures, out, spy


def _mean_diameter(run_dir: Path, name: str) -> float:
    snap = read_results(run_dir).snapshot(name)
    return float(np.mean(snap.diameters[snap.is_sample]))


def _angle_error(angle_deg: float) -> float:
    return abs((angle_deg - BAND_ANGLE + 90.0) % 180.0 - 90.0)


def test_every_figure_is_written_as_png_and_svg(drawn):
    figures, out, _ = drawn
    assert isinstance(figures, FabricFigures) and isinstance(figures, dict)
    assert list(figures) == list(FIGURES)
    for name, files in figures.items():
        assert [p.name for p in files] == [f"{name}.png", f"{name}.svg"]
        assert all(p.parent == out for p in files)
        assert files[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert b"<svg" in files[1].read_bytes()[:500]
    assert len(figures.paths) == 2 * len(FIGURES)


def test_the_imposed_band_is_recovered(drawn, run_dir):
    n = drawn[0].numbers
    assert n.peak_snapshot == "strain_0.0100"
    for band in (n.band, n.band_final):
        assert band is not None and band.found, band
        d_mean = _mean_diameter(run_dir, band.snapshot)
        assert _angle_error(band.angle_deg) < 2.0
        assert band.inclination_deg == pytest.approx(BAND_ANGLE, abs=2.0)
        assert band.thickness_m == pytest.approx(BAND_WIDTH, abs=d_mean)
        assert band.thickness_diameters == pytest.approx(BAND_WIDTH / d_mean, abs=1.0)
        assert band.p_value <= 0.05 and band.reason == ""
        assert np.isfinite(band.mean_lambda_inside) and np.isfinite(band.mean_lambda_outside)
    assert n.band_found and n.band_angle_deg == n.band.angle_deg
    assert n.band_thickness_diameters == n.band.thickness_diameters
    assert n.mean_lambda_in_band == n.band.mean_lambda_inside


def test_peak_numbers_come_from_the_time_series_and_the_snapshots(drawn, run_dir):
    n = drawn[0].numbers
    ts = read_results(run_dir).timeseries
    k = int(np.argmax(ts["stress_ratio"]))
    assert n.peak_row == k and n.peak_in_interior
    assert n.peak_axial_strain == pytest.approx(0.01)
    assert n.peak_stress_ratio == pytest.approx(4.0)
    assert n.a_at_peak == ts["anisotropy"][k] and n.a_n_at_peak == ts["force_anisotropy"][k]
    assert n.mean_lambda_at_peak == ts["mean_stability_index"][k]
    assert [s.snapshot for s in n.states.values()] == [
        "strain_0.0000",
        "strain_0.0100",
        "strain_0.0200",
    ]
    # forces favour vertical contacts more and more
    assert n.states["initial"].a_n < n.states["peak"].a_n < n.states["final"].a_n
    assert n.states["final"].theta_n_deg == pytest.approx(90.0, abs=10.0)
    assert not n.notes
    summary = n.summary()
    json.dumps(summary, allow_nan=False)
    assert summary["band_angle_deg"] == pytest.approx(n.band.angle_deg)
    text = str(n)
    assert "shear band" in text and "a_n" in text


def test_maps_draw_membrane_disks_grey_and_outline_the_band(drawn, run_dir):
    _, _, spy = drawn
    snap = read_results(run_dir).snapshot(0)
    membrane = ~snap.is_sample
    # Fig. 11: 2 panels, Fig. 12: 3, Fig. 13: 3
    assert len(spy.calls) == 8
    for positions, values, _ in spy.calls:
        assert positions.shape[0] == snap.n_particles  # in mm
        assert np.isnan(values[membrane]).all()
        assert np.isfinite(values[~membrane]).mean() > 0.95
    lambda_values = [v for _, v, _ in spy.calls[2:5]]
    assert all(np.nanmax(v) <= 1.0 for v in lambda_values)
    counts = spy.calls[5:]
    assert all(np.nanmax(v) <= COUNT_CAP for _, v, _ in counts)
    outlined = [
        any(line.get_label() == "shear band" for line in ax.get_lines()) for _, _, ax in spy.calls
    ]
    # initial-state panels (first of Figs. 12 and 13) have no band; every other one has it
    assert outlined == [True, True, False, True, True, False, True, True]


def test_a_band_that_is_not_there_is_not_outlined(run_dir, tmp_path, monkeypatch):
    spy = _MapSpy()
    monkeypatch.setattr(plot, "particle_map", spy)
    figures = fabric_figures(run_dir, tmp_path, peak_snapshot="strain_0.0050", workers=0)
    n = figures.numbers
    assert n.band is not None and not n.band.found
    assert n.band.reason and np.isnan(n.band.angle_deg) and np.isnan(n.band_angle_deg)
    assert any("no shear band found at strain_0.0050" in note for note in n.notes)
    assert n.summary()["band_angle_deg"] is None
    assert n.band_final is not None and n.band_final.found  # the final state still has it
    assert set(figures) == set(FIGURES)
    first_peak_panel = spy.calls[0][2]  # Fig. 11 (a), the homogeneous state
    assert "chosen peak state" in first_peak_panel.get_title()
    assert "no shear band found" in first_peak_panel.get_title()
    assert not any(line.get_label() == "shear band" for line in first_peak_panel.get_lines())


def test_missing_column_is_named(tmp_path):
    path = write_run(
        tmp_path / "run.h5",
        columns=("axial_strain", "stress_ratio", "anisotropy", "mean_stability_index"),
        snapshots=(0.0, 0.01),
    )
    with pytest.raises(MissingColumnError, match="'force_anisotropy'"):
        fabric_numbers(path)
    with pytest.raises(ValueError, match="force_anisotropy"):
        fabric_figures(tmp_path)
    assert not list(tmp_path.glob("fig*"))


def test_a_run_without_an_interior_peak(tmp_path):
    write_run(tmp_path / "run.h5", rising=True)
    n = fabric_numbers(tmp_path)
    assert not n.peak_in_interior
    assert n.peak_row == 80 and n.peak_axial_strain == pytest.approx(0.02)
    assert any("no peak inside the record" in note for note in n.notes)
    assert n.peak_snapshot == "strain_0.0200"
    assert n.band is not None and n.band.found and n.band_final is None
    assert "no interior peak" in str(n)


def test_peak_snapshot_can_be_chosen(run_dir):
    assert fabric_numbers(run_dir, peak_snapshot="strain_0.0200").peak_snapshot == "strain_0.0200"
    assert fabric_numbers(run_dir, peak_snapshot=1).peak_snapshot == "strain_0.0050"
    with pytest.raises(ValueError, match="peak_snapshot: 'strain_9' is not a snapshot"):
        fabric_numbers(run_dir, peak_snapshot="strain_9")
    with pytest.raises(ValueError, match="peak_snapshot: index 7 out of range"):
        fabric_numbers(run_dir, peak_snapshot=7)


def test_a_single_snapshot_gives_no_band(tmp_path):
    write_run(tmp_path / "run.h5", snapshots=(0.0,), nx=10, ny=16)
    n = fabric_numbers(tmp_path)
    assert n.band is None and n.band_final is None and not n.band_found
    assert n.peak_snapshot == "strain_0.0000"
    assert any("only one snapshot" in note for note in n.notes)


@pytest.mark.slow
def test_quick_biaxial_run(tmp_path):
    from grainlab.cli import main

    run = tmp_path / "run"
    code = main(
        [
            "biaxial",
            "--quick",
            "--out",
            str(run),
            "--no-progress",
            "--set",
            "shear.final_strain=0.02",
            "--set",
            "shear.strain_rate=20%/min",
            "--set",
            "shear.snapshot_strains=[0,0.005,0.015]",
        ]
    )
    assert code in (0, None)
    figures = fabric_figures(run)
    assert set(FIGURES) <= set(figures)
    for files in figures.values():
        assert all(p.exists() and p.parent == run for p in files)
    n = figures.numbers
    assert n.states["initial"].snapshot == "strain_0.0000"
    assert n.states["final"].snapshot == "strain_0.0150"
    assert n.states["peak"].snapshot in ("strain_0.0050", "strain_0.0150")
    assert 0.0 <= n.a_at_peak < 1.0 and 0.0 <= n.a_n_at_peak < 1.5
    # the sample leaves isotropy: contacts and forces favour the vertical (loading) axis
    assert n.states["peak"].a > n.states["initial"].a
    assert n.states["peak"].theta_n_deg == pytest.approx(90.0, abs=30.0)
    assert n.band is not None
    if n.band.found:
        assert 0.0 <= n.band.angle_deg < 180.0 and n.band.thickness_diameters >= 1.0
    else:
        assert n.band.reason
    json.dumps(n.summary(), allow_nan=False)
