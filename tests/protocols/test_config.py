"""Biaxial configuration: Table 1 defaults, units at the edge, errors naming the key."""

from __future__ import annotations

import re

import pytest

from grainlab.protocols.biaxial.config import BiaxialConfig, resolve
from grainlab.protocols.config import ConfigError


def test_defaults_are_table_1():
    c = resolve()
    assert c["sample.width"] == 0.075 and c["sample.height"] == 0.150
    assert c["sample.porosity"] == 0.12
    assert c["material.normal_stiffness"] == c["material.shear_stiffness"] == 8.45e7
    assert c["material.friction"] == 0.9 and c["material.platen_friction"] == 0.0
    assert c["material.local_damping"] == 0.8 and c["material.density"] == 2e8
    assert c["consolidation.pressure"] == 1e5
    assert c["shear.final_strain"] == 0.10
    assert c["shear.snapshot_strains"] == [0.0, 0.005, 0.007, 0.009, 0.015, 0.10]


def test_units_are_converted_to_si():
    c = resolve(overrides=["shear.strain_rate=2%/min", 'consolidation.pressure="0.2 MPa"', "sample.width=80mm"])
    assert c["shear.strain_rate"] == pytest.approx(0.02 / 60)
    assert c["consolidation.pressure"] == pytest.approx(2e5)
    assert c["sample.width"] == pytest.approx(0.08)


def test_toml_file_and_override_order(tmp_path):
    path = tmp_path / "test.toml"
    path.write_text('[sample]\nporosity = 0.15\nseed = 7\n[shear]\nfinal_strain = "5 %"\n')
    c = resolve(path, ["sample.seed=9"])
    assert c["sample.porosity"] == 0.15 and c["sample.seed"] == 9 and c["shear.final_strain"] == pytest.approx(0.05)
    assert resolve(path, quick=True)["sample.width"] == 0.03


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("sample.porosty=0.1", "unknown configuration key 'sample.porosty'"),
        ("sample.porosity=1.2", r"sample.porosity: 1.2 is out of range; expected a number in \(0, 1\)"),
        ("sample.porosity=0", "sample.porosity: 0 is out of range"),
        ("consolidation.pressure=-5", "consolidation.pressure: -5 is out of range"),
        ('consolidation.pressure="100 kPsi"', "consolidation.pressure: unknown unit 'kPsi'"),
        ("shear.strain_rate=2%/fortnight", "shear.strain_rate: unknown unit"),
        ("shear.final_strain=0.004", "shear.final_strain: 0.004 is below the first snapshot strain 0.005"),
        ("sample.grading=sandy", "sample.grading: 'sandy' is not one of"),
        ("run.threads=0", "run.threads"),
        ("sample.d_min=4mm", "sample.d_min"),
        ("novalue", "expected key=value"),
    ],
)
def test_bad_configuration_names_the_key(override, message):
    with pytest.raises(ConfigError, match=message):
        resolve(overrides=[override])


def test_missing_or_broken_file(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        resolve(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[sample\nwidth = ")
    with pytest.raises(ConfigError, match="not valid TOML"):
        resolve(bad)


def test_round_trip_through_nested_dict():
    c = resolve(overrides=["shear.final_strain=0.05"])
    assert type(c).from_dict(c.to_dict()).values == c.values


def test_sieve_table_grading_sets_the_size_range():
    config_overrides = [
        'sample.grading="curve"',
        'sample.sieve_sizes=["0.8 mm", "1.2 mm", "2 mm"]',
        "sample.percent_passing=[0, 40, 100]",
    ]
    config = resolve(overrides=config_overrides)
    assert config["sample.sieve_sizes"] == pytest.approx([0.8e-3, 1.2e-3, 2.0e-3])
    assert config["sample.percent_passing"] == [0.0, 40.0, 100.0]
    assert (config["sample.d_min"], config["sample.d_max"]) == pytest.approx((0.8e-3, 2.0e-3))
    # a d_min that agrees with the curve may be given too
    same = resolve(overrides=[*config_overrides, 'sample.d_min="0.8 mm"'])
    assert same.values == config.values
    # the resolved configuration round-trips through its nested form (run.h5, TOML)
    assert BiaxialConfig.from_dict(config.to_dict()).values == config.values


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["sample.sieve_sizes=[1e-3, 2e-3]"], "only used with sample.grading = 'curve'"),
        (['sample.grading="curve"'], "at least 2 sieve sizes"),
        (['sample.grading="curve"', "sample.sieve_sizes=[1e-3, 2e-3]", "sample.percent_passing=[0]"],
         "one percentage per size"),
        (['sample.grading="curve"', "sample.sieve_sizes=[2e-3, 1e-3]", "sample.percent_passing=[0, 100]"],
         "sample.sieve_sizes[1]: sizes must strictly increase"),
        (['sample.grading="curve"', "sample.sieve_sizes=[1e-3, 2e-3]", "sample.percent_passing=[0, 90]"],
         "percent_passing[1]: the largest sieve must pass 100%"),
        (['sample.grading="curve"', "sample.sieve_sizes=[1e-3, 2e-3]", "sample.percent_passing=[0, 120]"],
         "sample.percent_passing: 120 is out of range"),
        (['sample.grading="curve"', 'sample.sieve_sizes=["1 mm", "2 kg"]', "sample.percent_passing=[0, 100]"],
         "unknown unit 'kg'"),
        (["shear.snapshot_strains=[]"], "shear.snapshot_strains: must include 0"),
        (['sample.grading="curve"', "sample.sieve_sizes=[1e-3, 2e-3]", "sample.percent_passing=[0, 100]",
          "sample.d_min=0.5e-3"], "sample.d_min: 0.0005 m disagrees with the 'curve' grading"),
        (["shear.snapshot_strains=[0.01, 0.05]"], "shear.snapshot_strains: must include 0"),
    ],
)
def test_bad_sieve_tables_are_refused_before_any_work(overrides, message):
    with pytest.raises(ConfigError, match=re.escape(message)):
        resolve(overrides=overrides)


def test_a_protocol_declares_its_keys_on_the_shared_ones(monkeypatch):
    from grainlab.protocols.config import (
        RUN_FIELDS,
        SCHEMAS,
        SHARED_FIELDS,
        Config,
        ConfigSchema,
        Field,
        check_sample,
    )

    own = {"load.pressure": Field("stress", 1e5, "the final vertical stress", minimum=0.0, exclusive_minimum=True)}
    toy = ConfigSchema("toy", {**SHARED_FIELDS, **own, **RUN_FIELDS}, {"sample.width": 0.03}, check_sample, Config)
    monkeypatch.setitem(SCHEMAS, "toy", toy)
    config = toy.resolve(overrides=["load.pressure=400 kPa", "material.friction=0.5"], quick=True)
    assert config["load.pressure"] == 4e5 and config["material.friction"] == 0.5
    assert config["sample.width"] == 0.03 and config.schema == "toy"
    assert "shear.final_strain" not in config.values  # the biaxial test's own keys are not the toy's
    assert Config.from_dict(config.to_dict(), "toy") == config
    with pytest.raises(ConfigError, match="unknown configuration key 'shear.final_strain'"):
        toy.resolve(overrides=["shear.final_strain=0.05"])
    with pytest.raises(ConfigError, match="load.pressure: -1 is out of range"):
        toy.resolve(overrides=["load.pressure=-1"])
    with pytest.raises(ConfigError, match="sample.d_min: 0.004 m exceeds sample.d_max"):
        toy.resolve(overrides=["sample.d_min=4mm"])  # the shared checks come with the shared keys


def test_the_rolling_resistance_keys_reach_the_grain_and_platen_models() -> None:
    from grainlab import ContactModel
    from grainlab.protocols.specimen import grain_model, platen_model

    # off by default: the paper's law, the engine's defaults
    default = resolve()
    assert (default["material.rolling_friction"], default["material.rolling_stiffness"]) == (0.0, "auto")
    assert grain_model(default) == ContactModel(default["material.normal_stiffness"],
                                                default["material.shear_stiffness"], default["material.friction"])
    config = resolve(overrides=["material.rolling_friction=0.1", "material.rolling_damping=0.3"])
    for model in (grain_model(config), platen_model(config)):
        assert (model.rolling_friction, model.rolling_stiffness, model.rolling_damping_ratio) == (0.1, 0.0, 0.3)
    config = resolve(overrides=["material.rolling_friction=0.1", "material.rolling_stiffness=25"])
    assert grain_model(config).rolling_stiffness == 25.0
