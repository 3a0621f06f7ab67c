"""The contact model's fields are written in four places: the engine's
``ContactModel`` (crates/grainlab-core/src/material.rs), the PyO3 glue's
``set_contact_model`` and ``contact_model`` (crates/grainlab-py), the compiled
module's stub (python/grainlab/_core.pyi) and the Python ``ContactModel``
(python/grainlab/simulation.py). They must name the same fields in the same
order with the same defaults, so that a new field cannot be forgotten in one
of them."""

from __future__ import annotations

import ast
import dataclasses
import inspect
import re
from pathlib import Path

from grainlab import ContactModel, Simulation, _core

ROOT = Path(__file__).resolve().parents[2]
GROUPS = ("group_a", "group_b")
#: Hertz-Mindlin's fields, each a value of its own inside its range
HERTZ_MINDLIN = {"youngs_modulus": 7.0e10, "poisson_ratio": 0.25, "restitution": 0.625}


def rust_fields() -> list[str]:
    """The fields of the engine's ``ContactModel``, in declaration order."""
    source = (ROOT / "crates/grainlab-core/src/material.rs").read_text()
    body = re.search(r"pub struct ContactModel \{(.*?)\n\}", source, re.S)
    assert body is not None
    return re.findall(r"^\s*pub (\w+):", body.group(1), re.M)


def rust_defaults() -> dict[str, object]:
    """What ``ContactModel::linear(kn, ks, mu)`` sets beyond its arguments."""
    source = (ROOT / "crates/grainlab-core/src/material.rs").read_text()
    linear = re.search(r"pub fn linear\((.*?)\) -> Self \{.*?ContactModel \{(.*?)\}", source, re.S)
    assert linear is not None
    arguments = re.findall(r"(\w+): f64", linear.group(1))
    values: dict[str, object] = {}
    laws = {"ContactLaw::Linear": "linear"}
    for name, value in re.findall(r"(\w+): ([^,\s]+),", linear.group(2)):
        if name not in arguments:
            if value in laws:
                values[name] = laws[value]
            else:
                values[name] = value == "true" if value in ("true", "false") else float(value)
    return values


def stub_engine_method(name: str) -> ast.FunctionDef:
    tree = ast.parse((ROOT / "python/grainlab/_core.pyi").read_text())
    engine = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Engine")
    return next(n for n in engine.body if isinstance(n, ast.FunctionDef) and n.name == name)


def stub_typed_dict_fields() -> list[str]:
    tree = ast.parse((ROOT / "python/grainlab/_core.pyi").read_text())
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "_ContactModel")
    return [
        n.target.id
        for n in cls.body
        if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)
    ]


def test_the_four_places_name_the_same_fields_in_the_same_order() -> None:
    fields = rust_fields()
    assert fields[:3] == ["normal_stiffness", "shear_stiffness", "friction"], fields
    # the glue: what set_contact_model takes and what contact_model returns
    glue = list(inspect.signature(_core.Engine.set_contact_model).parameters)[1:]
    assert glue == [*GROUPS, *fields]
    sim = Simulation([[0.0, 0.0]], [1e-3], density=2.0e8, time_step=1e-6)
    assert list(sim._engine.contact_model(0, 0)) == fields
    # the stub: the method's arguments and the TypedDict it returns
    stub = stub_engine_method("set_contact_model")
    assert [a.arg for a in stub.args.args][1:] == [*GROUPS, *fields]
    assert stub_typed_dict_fields() == fields
    # the Python dataclass
    assert [f.name for f in dataclasses.fields(ContactModel)] == fields


def test_the_four_places_give_the_same_defaults() -> None:
    engine = rust_defaults()
    # the fields beyond the stiffnesses and friction have the engine's defaults everywhere
    assert set(engine) == set(rust_fields()[3:]), engine
    python = {f.name: f.default for f in dataclasses.fields(ContactModel)}
    for name, value in engine.items():
        assert python[name] == value and type(python[name]) is type(value), name
    # a default of the glue's signature is the stub's and the dataclass's
    glue = inspect.signature(_core.Engine.set_contact_model).parameters
    stub = stub_engine_method("set_contact_model")
    stub_defaults = {
        a.arg: ast.literal_eval(d)
        for a, d in zip(stub.args.args[-len(stub.args.defaults) :], stub.args.defaults, strict=True)
    }
    glue_defaults = {
        n: p.default for n, p in glue.items() if p.default is not inspect.Parameter.empty
    }
    assert glue_defaults == stub_defaults
    for name, value in glue_defaults.items():
        assert engine[name] == value == python[name], name


def test_every_field_goes_to_the_engine_and_comes_back() -> None:
    # each field a value of its own, none a default, so that two fields swapped in
    # one place show
    fields = rust_fields()
    values: dict[str, object] = {}
    for k, f in enumerate(dataclasses.fields(ContactModel)):
        if f.name == "law":  # a name, not a number: the law that is not the default
            values[f.name] = "hertz_mindlin"
        elif f.name in HERTZ_MINDLIN:  # values in its ranges, each its own
            values[f.name] = HERTZ_MINDLIN[f.name]
        elif f.name.endswith("damping_ratio") and f.name != "rolling_damping_ratio":
            values[f.name] = 0.0  # Hertz-Mindlin is damped by its restitution
        else:
            values[f.name] = (not f.default) if isinstance(f.default, bool) else 1.0e6 * (k + 1) + 0.125 * k
    assert list(values) == fields
    model = ContactModel(**values)  # type: ignore[arg-type]
    sim = Simulation([[0.0, 0.0]], [1e-3], density=2.0e8, time_step=1e-6)
    sim.set_contact_model(2, 5, model)
    assert sim.contact_model(5, 2) == model
    assert sim._engine.contact_model(2, 5) == values
