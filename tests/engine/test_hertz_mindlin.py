"""Hertz-Mindlin from Python: the force and time step of ``ContactModel.hertz_mindlin``
against the closed forms, bad input refused with one line before any work, and the
biaxial test run with ``material.contact_law = hertz_mindlin``. The engine's impact
oracles are in crates/grainlab-core/tests/hertz_mindlin.rs; docs/contact-law.md,
"Hertz-Mindlin", gives the law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab import ContactModel, Simulation, cli

E, NU = 70.0e9, 0.25
E_STAR = E / (2 * (1 - NU**2))
G_STAR = E / (4 * (2 - NU) * (1 + NU))


def two_disks(overlap: float, model: ContactModel, radius: float = 1e-3) -> Simulation:
    sim = Simulation([[0.0, 0.0], [2 * radius - overlap, 0.0]], [radius, radius], density=2650.0, time_step=1e-7)
    sim.set_contact_model(0, 0, model)
    return sim


def test_the_contact_force_is_hertzs_and_the_time_step_takes_the_tangent_stiffnesses():
    r, overlap = 1e-3, 2e-6
    sim = two_disks(overlap, ContactModel.hertz_mindlin(E, NU, 0.5, 0.4), r)
    r_star = r / 2
    hertz = 4 / 3 * E_STAR * math.sqrt(r_star) * overlap**1.5
    contacts = sim.contacts()
    assert contacts.normal_force[0] == pytest.approx(hertz, rel=1e-9)
    # each disk has one contact: min(sqrt(m / S_n), sqrt(I / (k_t r^2))), I = m r^2 / 2
    a = math.sqrt(r_star * overlap)
    mass = 2650.0 * math.pi * r**2
    expected = min(math.sqrt(mass / (2 * E_STAR * a)), math.sqrt(0.5 * mass / (8 * G_STAR * a)))
    assert sim.critical_time_step(1.0) == pytest.approx(expected, rel=1e-12)
    # the law comes back from the engine as it went
    assert sim.contact_model(0, 0) == ContactModel.hertz_mindlin(E, NU, 0.5, 0.4)


def test_each_contact_reports_its_laws_tangent_normal_stiffness():
    """``Contacts.normal_stiffness`` is dF_n/d(overlap) at the overlap: Hertz's 2 E* a
    (the slope of 4/3 E* sqrt(R*) overlap^1.5), and kn for the linear law."""
    r, overlap = 1e-3, 2e-6
    hertz = two_disks(overlap, ContactModel.hertz_mindlin(E, NU, 0.5, 0.4), r).contacts()
    assert hertz.normal_stiffness[0] == pytest.approx(2 * E_STAR * math.sqrt(r / 2 * overlap), rel=1e-12)
    # the slope of the reported force between two overlaps
    step = 1e-10
    forces = [two_disks(d, ContactModel.hertz_mindlin(E, NU, 0.5, 0.4), r).contacts().normal_force[0]
              for d in (overlap - step, overlap + step)]
    assert (forces[1] - forces[0]) / (2 * step) == pytest.approx(hertz.normal_stiffness[0], rel=1e-6)
    linear = two_disks(overlap, ContactModel(8.45e7, 2.0e7, 0.5), r).contacts()
    assert linear.normal_stiffness.tolist() == [8.45e7]


def test_a_free_disk_counts_one_hertz_contact_at_the_largest_overlap_allowed():
    r = 1e-3
    # every pair of groups Hertz-Mindlin (the fallback takes the stiffest model of any group pair)
    model = ContactModel.hertz_mindlin(E, NU, 1.0, 0.0)
    sim = Simulation([[0.0, 0.0]], [r], density=2650.0, time_step=1e-7, contact_model=model)
    ratio = sim.max_overlap_ratio
    a = math.sqrt(0.5 * r * ratio * r)  # R* = r / 2 between two such disks
    stiffest = max(2 * E_STAR * a, 8 * G_STAR * a)
    mass = 2650.0 * math.pi * r**2
    expected = min(math.sqrt(mass / stiffest), math.sqrt(0.5 * mass / stiffest))
    assert sim.critical_time_step(1.0) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"poisson_ratio": 0.5}, "poisson_ratio: 0.5 is outside (-1, 0.5)"),
        ({"poisson_ratio": -1.0}, "poisson_ratio: -1 is outside (-1, 0.5)"),
        ({"restitution": 0.0}, "restitution: 0 is outside (0, 1]"),
        ({"restitution": 1.5}, "restitution: 1.5 is outside (0, 1]"),
        ({"youngs_modulus": 0.0}, "youngs_modulus"),
        ({"law": "hooke"}, 'unknown law "hooke" (known: linear, hertz_mindlin)'),
        ({"normal_damping_ratio": 0.2}, "damped by its restitution"),
    ],
)
def test_bad_law_parameters_are_refused_with_one_line(fields, message):
    from dataclasses import replace

    sim = two_disks(1e-6, ContactModel())
    model = replace(ContactModel.hertz_mindlin(E, NU, 0.5, 0.4), **fields)
    with pytest.raises(ValueError) as error:
        sim.set_contact_model(0, 0, model)
    assert message in str(error.value) and "\n" not in str(error.value)
    assert sim.contact_model(0, 0) == ContactModel()  # nothing was changed


@pytest.mark.parametrize(
    ("command", "setting", "message"),
    [
        ("biaxial", "material.poisson_ratio=0.5", "material.poisson_ratio"),
        ("biaxial", "material.restitution=0", "material.restitution"),
        ("biaxial", "material.contact_law=hooke", "material.contact_law"),
        ("biaxial", "material.contact_damping=0.1", "hertz_mindlin is damped by material.restitution"),
        ("simple_shear", "material.restitution=1.5", "material.restitution"),
    ],
)
def test_bad_law_settings_are_one_line_before_any_folder(tmp_path, capsys, command, setting, message):
    out = tmp_path / "run"
    head = ["biaxial"] if command == "biaxial" else ["run", command]
    argv = [*head, "--quick", "--out", str(out), "--set", setting]
    if "contact_law" not in setting:
        argv += ["--set", "material.contact_law=hertz_mindlin"]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
    assert not out.exists()


@pytest.mark.slow
def test_a_biaxial_run_with_hertz_mindlin_consolidates_and_shears(tmp_path):
    from grainlab.protocols import biaxial
    from grainlab.protocols.biaxial.config import resolve

    tiny = ["sample.grading=uniform_by_number", "sample.d_min=0.5mm", "sample.d_max=1mm", "sample.width=10mm",
            "sample.height=10mm", "shear.snapshot_strains=[0, 0.005]", "shear.strain_rate=20%/min", "run.threads=1"]
    config = resolve(overrides=[*tiny, "material.contact_law=hertz_mindlin", "shear.final_strain=0.01"])
    result = biaxial.run_biaxial(config, tmp_path / "run", progress=False)
    summary = result.summary
    # consolidated to sigma_0 (a dashpot at the servo platens never let it settle) and
    # sheared to 1 %: the deviator rose, every record finite
    assert summary["peak_stress_ratio"] > 1.2
    assert np.isfinite(summary["final_stress_ratio"])


@pytest.mark.slow
def test_simple_shear_with_hertz_mindlin_holds_its_normal_stress(tmp_path):
    """The cell's stress control reads each contact's tangent stiffness (2 E* a), so a
    Hertz-Mindlin packing in simple shear holds sigma_yy at its target as a linear one does."""
    out = tmp_path / "run"
    assert cli.main(["run", "simple_shear", "--quick", "--out", str(out), "--set",
                     "material.contact_law=hertz_mindlin"]) == 0
    series = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True)
    sheared = series[series["shear_strain"] >= 0.1]
    target = 100.0e3  # simple_shear.normal_stress auto: consolidation.pressure, 100 kPa
    assert len(sheared) > 10
    assert np.all(np.abs(sheared["normal_stress_pa"] / target - 1.0) < 0.05)
    assert abs(float(np.mean(sheared["normal_stress_pa"])) / target - 1.0) < 0.01
    assert float(np.mean(sheared["friction_coefficient"])) > 0.1
