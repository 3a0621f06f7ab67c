"""Configuration of the protocols: defaults from the paper's Table 1, TOML
files, ``key=value`` overrides, units at the edge, validation before any work.

Typed sections of keys (:class:`Section`, :func:`key`), the shared ones and each
test's :class:`ConfigSchema`: docs/protocols.md, "Configuration"; units:
docs/conventions.md, "Units". A bad key or value raises :class:`ConfigError` (a
``ValueError``) naming the key and the allowed values."""

from __future__ import annotations

import dataclasses
import math
import re
import tomllib
from collections.abc import Callable, Iterable, Mapping
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Generic, TypedDict, TypeVar

from grainlab import paper
from grainlab._mapping import flatten_keys
from grainlab.io._table import FileFormatError
from grainlab.io.shape_file import read_shape_template
from grainlab.shapes import SHAPES, ShapeTemplate, shape_template
from grainlab.simulation import DEFAULT_TIME_STEP_SAFETY


class ConfigError(ValueError):
    """A configuration key or value is not allowed."""


_UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "cm": 1e-2},
    "stress": {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9},
    "strain_rate": {"1/s": 1.0, "/s": 1.0, "%/s": 1e-2, "%/min": 1e-2 / 60.0, "1/min": 1.0 / 60.0},
    "strain": {"": 1.0, "%": 1e-2},
    "stiffness": {"N/m": 1.0, "kN/m": 1e3, "MN/m": 1e6},
    "density": {"kg/m^3": 1.0, "kg/m3": 1.0},
    "number": {"": 1.0},
    "time": {"s": 1.0, "min": 60.0, "h": 3600.0},
    "angle": {"rad": 1.0, "deg": math.pi / 180.0},
}


@dataclass(frozen=True)
class Field:
    """One configuration key: its kind (units), default, allowed range and help."""

    kind: str
    default: Any
    help: str
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: bool = False
    exclusive_maximum: bool = False
    choices: tuple[str, ...] = ()
    allow_auto: bool = False

    def describe_range(self) -> str:
        if self.kind == "text":
            return "a text" + (" (" + ", ".join(self.choices) + ", or a file)" if self.choices else "")
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        lo = "(" if self.exclusive_minimum else "["
        hi = ")" if self.exclusive_maximum else "]"
        lo_v = "-inf" if self.minimum is None else f"{self.minimum:g}"
        hi_v = "inf" if self.maximum is None else f"{self.maximum:g}"
        units = ", ".join(u for u in _UNITS.get(self.kind, {}) if u) if self.kind in _UNITS else ""
        text = f"a number in {lo}{lo_v}, {hi_v}{hi}"
        if units:
            text += f" (SI, or a string with a unit: {units})"
        if self.allow_auto:
            text += ' or "auto"'
        return text


class Range(TypedDict, total=False):
    """Range keywords of :class:`Field` shared by many keys."""

    minimum: float
    exclusive_minimum: bool


#: The range of a positive key (``**POSITIVE`` in a :func:`key`).
POSITIVE: Range = {"minimum": 0.0, "exclusive_minimum": True}

def key(kind: str, default: Any, help: str, **limits: Any) -> Any:
    """One key of a :class:`Section`: a dataclass field with ``default`` whose metadata
    holds the key's :class:`Field` (its kind, range and help)."""
    spec = Field(kind, default, help, **limits)
    if isinstance(default, list):
        return dataclasses.field(default_factory=lambda: list(default), metadata={"key": spec})
    return dataclasses.field(default=default, metadata={"key": spec})


@dataclass(frozen=True)
class Section:
    """A typed section of a configuration: a frozen dataclass whose fields (each a
    :func:`key`) are the keys ``prefix.field``."""

    prefix: ClassVar[str]

    @classmethod
    def keys(cls) -> dict[str, Field]:
        """The section's keys, in order: ``prefix.field`` -> :class:`Field`."""
        return {f"{cls.prefix}.{f.name}": f.metadata["key"] for f in dataclasses.fields(cls)}


@dataclass(frozen=True)
class SampleSection(Section):
    """The sample: its size, porosity, grading and seed."""

    prefix: ClassVar[str] = "sample"
    width: float = key("length", paper.WIDTH_M, "sample width (Table 1: 75 mm)", **POSITIVE)
    height: float = key("length", paper.HEIGHT_M, "sample height (Table 1: 150 mm)", **POSITIVE)
    porosity: float = key(
        "strain", paper.POROSITY, "target nominal porosity of the radius expansion (Table 1: 0.12)",
        minimum=0.0, maximum=1.0, exclusive_minimum=True, exclusive_maximum=True,
    )
    d_min: float = key("length", paper.D_MIN_M, "smallest grain diameter (Table 1: 0.5 mm)", **POSITIVE)
    d_max: float = key("length", paper.D_MAX_M, "largest grain diameter (Table 1: 3 mm)", **POSITIVE)
    grading: str = key(
        "choice", "paper",
        "grain size distribution; 'curve' takes sample.sieve_sizes and sample.percent_passing",
        choices=("paper", "uniform_by_number", "uniform_by_mass", "curve"),
    )
    sieve_sizes: list[float] = key(
        "length_list", [],
        "sieve sizes of a 'curve' grading, smallest first (they set d_min and d_max)",
    )
    percent_passing: list[float] = key(
        "percent_list", [],
        "percent passing by mass at each sieve size of a 'curve' grading (0 first, 100 last)",
    )
    seed: int = key("integer", 1, "random seed of the sample", minimum=0)
    shape: str = key(
        "text", "disk",
        "grain shape (docs/bodies.md, 'Shapes'): rigid clumps of disks, the grading giving each grain's "
        "circumscribed diameter; a file lists a template's pebbles (x, y, r per line)",
        choices=SHAPES,
    )
    shape_parameter: float = key(
        "number", 0.0, "CEGEO's eta = 1 - inscribed / circumscribed radius of dimers, trimers and rods (0: disks)",
        minimum=0.0, maximum=1.0, exclusive_maximum=True,
    )
    rod_pebbles: int = key("integer", 3, "pebbles of a rod (sample.shape = rod)", minimum=2)
    generation_friction: float = key("number", 0.0, "particle friction during radius expansion", minimum=0.0)
    max_generation_stress: float = key(
        "stress", 5.0e6, "stress bound of the radius expansion", **POSITIVE
    )


@dataclass(frozen=True)
class MaterialSection(Section):
    """The grains' material and contact law (Table 1)."""

    prefix: ClassVar[str] = "material"
    normal_stiffness: float = key("stiffness", paper.NORMAL_STIFFNESS_N_PER_M, "contact kn (Table 1)", **POSITIVE)
    shear_stiffness: float = key("stiffness", paper.SHEAR_STIFFNESS_N_PER_M, "contact ks (Table 1)", **POSITIVE)
    friction: float = key("number", paper.FRICTION, "particle friction (Table 1: 0.9)", minimum=0.0)
    platen_friction: float = key("number", paper.PLATEN_FRICTION, "particle-platen friction (Table 1: 0)", minimum=0.0)
    rolling_friction: float = key(
        "number", 0.0, "rolling friction mu_r between grains and at the platens (0: none, the paper's law)", minimum=0.0
    )
    rolling_stiffness: float | str = key(
        "number", "auto", "rolling stiffness k_r in N m/rad (auto: 2.25 kn mu_r^2 R*^2)",
        **POSITIVE, allow_auto=True,
    )
    rolling_damping: float = key(
        "number", 0.0, "rolling dashpot, fraction of critical 2 sqrt(I_r k_r), below the cap", minimum=0.0
    )
    contact_damping: float = key(
        "number", 0.0, "normal and shear contact dashpots between grains, fraction of critical "
        "(0: none, the paper's law)", minimum=0.0
    )
    contact_law: str = key(
        "choice", "linear",
        "contact law between grains and at the platens: 'linear' (kn, ks: the paper's) or "
        "'hertz_mindlin' (material.youngs_modulus, poisson_ratio, restitution)",
        choices=("linear", "hertz_mindlin"),
    )
    youngs_modulus: float = key(
        "stress", 70.0e9, "Young's modulus E of the grains, read by hertz_mindlin (quartz: about 70 GPa)",
        **POSITIVE,
    )
    poisson_ratio: float = key(
        "number", 0.25, "Poisson ratio of the grains, read by hertz_mindlin",
        minimum=-1.0, maximum=0.5, exclusive_minimum=True, exclusive_maximum=True,
    )
    restitution: float = key(
        "number", 0.5, "normal coefficient of restitution of hertz_mindlin's dashpot (1: elastic)",
        minimum=0.0, maximum=1.0, exclusive_minimum=True,
    )
    density: float = key("density", paper.DENSITY_KG_PER_M3, "scaled particle density (Table 1: 2e8 kg/m^3)", **POSITIVE)
    limiting_contact_pressure: float = key(
        "stress", paper.LIMITING_CONTACT_PRESSURE_PA, "p_y of the density scaling factor, paper Eq. 16 (Table 1: 150 MPa)", **POSITIVE
    )
    local_damping: float = key(
        "number", paper.LOCAL_DAMPING, "local damping alpha (Table 1: 0.8)", minimum=0.0, maximum=1.0, exclusive_maximum=True
    )


@dataclass(frozen=True)
class ConsolidationSection(Section):
    """The isotropic consolidation to sigma_0."""

    prefix: ClassVar[str] = "consolidation"
    pressure: float = key("stress", paper.CONSOLIDATION_PRESSURE_PA, "isotropic consolidation stress sigma_0 = sigma_3", **POSITIVE)
    friction: float = key(
        "number", 0.0,
        "grain friction while consolidating (the generation's; Table 1 friction acts from the membrane on)",
        minimum=0.0,
    )
    tolerance: float = key("strain", 0.01, "wall stresses within this fraction of sigma_0", **POSITIVE)
    unbalanced_force_ratio: float = key(
        "number", 1.0e-3, "equilibrium: mean unbalanced force ratio below this", **POSITIVE
    )
    max_steps: int = key("integer", 2_000_000, "give up consolidating after this many steps", minimum=1)


@dataclass(frozen=True)
class CementSection(Section):
    """Cement bonds made at the end of the consolidation (docs/cemented.md, "Cemented samples")."""

    prefix: ClassVar[str] = "cement"
    bonds: str = key(
        "choice", "none",
        "'parallel': the grains' pairs are cemented with parallel bonds at the end of the consolidation "
        "(Potyondy and Cundall); 'none': no cement",
        choices=("none", "parallel"),
    )
    gap: float = key("length", 0.0, "pairs whose surfaces are at most this far apart are cemented (0: touching)",
                     minimum=0.0)
    radius_multiplier: float = key("number", 1.0, "lambda_b: bond radius over the smaller grain's", **POSITIVE)
    normal_stiffness: float | str = key(
        "number", "auto", "kn_bar of the bonds in Pa/m (auto: material.normal_stiffness over each bond's area)",
        **POSITIVE, allow_auto=True,
    )
    shear_stiffness: float | str = key(
        "number", "auto", "ks_bar of the bonds in Pa/m (auto: material.shear_stiffness over each bond's area)",
        **POSITIVE, allow_auto=True,
    )
    tensile_strength: float = key("stress", 0.0, "sigma_c: mean tensile strength of the bonds (required)",
                                  minimum=0.0)
    cohesion: float = key("stress", 0.0, "c: mean cohesion of the bonds (required)", minimum=0.0)
    friction_angle: float = key("number", 0.0, "phi_b in degrees: tau_c = c - sigma tan(phi_b)", minimum=0.0,
                                maximum=90.0, exclusive_maximum=True)
    strength_scatter: float = key(
        "number", 0.0, "coefficient of variation of both strengths over the bonds (0: every bond the mean)",
        minimum=0.0,
    )
    strength_distribution: str = key(
        "choice", "normal", "law of the strengths' scatter, seeded by sample.seed", choices=("normal", "weibull")
    )


@dataclass(frozen=True)
class RunSection(Section):
    """How a run executes (the runner's keys, in every test's configuration)."""

    prefix: ClassVar[str] = "run"
    threads: int | str = key("integer", "auto", "engine threads (auto: all cores)", minimum=1, allow_auto=True)
    time_step_safety: float = key(
        "number", DEFAULT_TIME_STEP_SAFETY, "time step = this x the critical time step (0.8, as PFC)", minimum=0.0,
        maximum=1.0,
        exclusive_minimum=True,
    )
    checkpoint_interval: float = key("time", 30.0, "wall-clock time between checkpoints", **POSITIVE)


@dataclass(frozen=True)
class PlatenSection(Section):
    """The loading keys of a test of a cemented sample pressed by its top platen (the
    unconfined compression and Brazilian tests, ``grainlab.protocols.platens``), under
    the test's own prefix; the strain is the top platen's travel over the sample's height
    (the disc's diameter D in the Brazilian test)."""

    prefix: ClassVar[str] = ""
    strain_rate: float = key("strain_rate", "1 %/min", "the top platen's speed over the sample's height where "
                             "the strains start (the disc's diameter D in the Brazilian test)", **POSITIVE)
    final_strain: float = key("strain", 0.02, "the loading ends at this strain (the top platen's travel over that "
                              "height)", minimum=0.0, maximum=0.5, exclusive_minimum=True)
    residual_fraction: float = key(
        "number", 0.5, "the loading ends once the stress after the peak falls below this fraction of the peak",
        minimum=0.0, maximum=1.0, exclusive_maximum=True,
    )
    records: int = key("integer", 200, "records over final_strain (one every final_strain / records)", minimum=1)


def check_cemented_sample(v: dict[str, Any], given: AbstractSet[str], test: str, strength: str) -> None:
    """A platen test's checks: :func:`check_sample`'s, after the one-line refusal of an
    uncemented sample, which has no ``strength`` to measure."""
    if v["cement.bonds"] == "none":
        raise ConfigError(f"{test}: an uncemented sample has no {strength}; give cement.bonds=parallel and its "
                          f"strengths")
    check_sample(v, given)


#: The keys of every test that makes a sample and consolidates it: the sample, its
#: material (Table 1) and the consolidation.
SHARED_FIELDS: dict[str, Field] = {
    **SampleSection.keys(), **MaterialSection.keys(), **ConsolidationSection.keys(), **CementSection.keys()
}
#: How a run executes (the runner's keys, in every test's configuration).
RUN_FIELDS: dict[str, Field] = RunSection.keys()
#: A square sample by default (a test's own keys): Table 1's width, 75 mm, on both sides.
SQUARE: dict[str, Field] = {"sample.height": dataclasses.replace(
    SHARED_FIELDS["sample.height"], default=SHARED_FIELDS["sample.width"].default,
    help="sample height (a square sample: Table 1's width, 75 mm)")}

#: Item kind and range of each list kind.
_LIST_ITEMS: dict[str, tuple[str, Field]] = {
    "strain_list": ("strains", Field("strain", 0.0, "", minimum=0.0, maximum=0.5)),
    "shear_strain_list": ("shear strains", Field("strain", 0.0, "", minimum=0.0, maximum=100.0)),
    "length_list": ("lengths", Field("length", 0.0, "", **POSITIVE)),
    "percent_list": ("percentages", Field("number", 0.0, "", minimum=0.0, maximum=100.0)),
    "stress_list": ("stresses", Field("stress", 0.0, "", **POSITIVE)),
}

#: Overrides of ``--quick``: a small sample of a few hundred disks, for demos and CI.
QUICK: dict[str, Any] = {"sample.width": 0.03, "sample.height": 0.06}

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S*)\s*$")


def _parse_quantity(key: str, field: Field, value: Any) -> float:
    if isinstance(value, bool):
        raise ConfigError(f"{key}: expected {field.describe_range()}, got {value!r}")
    if isinstance(value, int | float):
        return float(value)
    if isinstance(value, str):
        match = _QUANTITY.match(value)
        if match:
            number, unit = float(match.group(1)), match.group(2)
            units = _UNITS.get(field.kind, {"": 1.0})
            if unit in units:
                return number * units[unit]
            allowed = ", ".join(repr(u) for u in units if u) or "none"
            raise ConfigError(f"{key}: unknown unit {unit!r} in {value!r}; allowed units: {allowed}")
    raise ConfigError(f"{key}: expected {field.describe_range()}, got {value!r}")


def _check_range(key: str, field: Field, number: float) -> float:
    if not math.isfinite(number):
        raise ConfigError(f"{key}: expected {field.describe_range()}, got {number!r}")
    low_bad = field.minimum is not None and (
        number <= field.minimum if field.exclusive_minimum else number < field.minimum
    )
    high_bad = field.maximum is not None and (
        number >= field.maximum if field.exclusive_maximum else number > field.maximum
    )
    if low_bad or high_bad:
        raise ConfigError(f"{key}: {number:g} is out of range; expected {field.describe_range()}")
    return number


def coerce_field(fields: Mapping[str, Field], key: str, value: Any) -> Any:
    """Converts ``value`` for ``key`` of ``fields`` to SI and checks its range."""
    if key not in fields:
        close = [k for k in fields if k.split(".")[-1] == key.split(".")[-1]]
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ConfigError(f"unknown configuration key {key!r}{hint}; known keys: {', '.join(sorted(fields))}")
    field = fields[key]
    if field.allow_auto and value == "auto":
        return "auto"
    if field.kind == "text":
        if not isinstance(value, str) or not value.strip():
            raise ConfigError(f"{key}: expected {field.describe_range()}, got {value!r}")
        return value.strip()
    if field.kind == "choice":
        if value not in field.choices:
            raise ConfigError(f"{key}: {value!r} is not {field.describe_range()}")
        return value
    if field.kind == "integer":
        if isinstance(value, bool) or not (
            isinstance(value, int) or (isinstance(value, str) and value.strip().lstrip("+").isdigit())
        ):
            raise ConfigError(f"{key}: expected an integer >= {field.minimum:g}, got {value!r}")
        return int(_check_range(key, field, float(int(value))))
    if field.kind in _LIST_ITEMS:
        what, item = _LIST_ITEMS[field.kind]
        items = value
        if isinstance(value, str):
            items = [v for v in value.strip("[]").split(",") if v.strip()]
        if not isinstance(items, list | tuple):
            raise ConfigError(f"{key}: expected a list of {what}, got {value!r}")
        numbers = [_check_range(key, item, _parse_quantity(key, item, v)) for v in items]
        # snapshot strains are a set of times; sieve data keep their given order
        return sorted(numbers) if field.kind in ("strain_list", "shear_strain_list") else numbers
    return _check_range(key, field, _parse_quantity(key, field, value))


def parse_override(text: str) -> tuple[str, Any]:
    if "=" not in text:
        raise ConfigError(f"--set {text!r}: expected key=value, e.g. shear.final_strain=5%")
    key, raw = (part.strip() for part in text.split("=", 1))
    try:
        value: Any = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw  # a bare string such as 100kPa or auto
    return key, value


S = TypeVar("S", bound=Section)


class SectionOf(Generic[S]):
    """A :class:`Config` attribute: the configuration's section ``kind``, read once."""

    def __init__(self, kind: type[S]) -> None:
        self.kind = kind

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, config: Config | None, owner: type | None = None) -> S:
        if config is None:
            raise AttributeError(f"{self.name}: a configuration's section, read on the configuration")
        if self.name not in config.__dict__:
            config.__dict__[self.name] = config.section(self.kind)
        found: S = config.__dict__[self.name]
        return found


@dataclass(frozen=True)
class Config:
    """A resolved, validated configuration: ``values`` maps every key of its schema
    (``schema``, a name of :data:`SCHEMAS`) to SI values. Each section reads typed as
    an attribute (``config.sample.width``; a test's subclass adds its own sections),
    each key by its name (``config["sample.width"]``)."""

    values: dict[str, Any]
    schema: str = "biaxial"

    def __getitem__(self, key: str) -> Any:
        return self.values[key]

    def section(self, kind: type[S]) -> S:
        """The section ``kind`` of this configuration (a key its schema leaves out, as the
        cyclic test leaves out the monotonic loading's end, keeps the section's default)."""
        names = (f.name for f in dataclasses.fields(kind))
        return kind(**{name: self.values[k] for name in names if (k := f"{kind.prefix}.{name}") in self.values})

    sample = SectionOf(SampleSection)
    material = SectionOf(MaterialSection)
    consolidation = SectionOf(ConsolidationSection)
    cement = SectionOf(CementSection)
    run = SectionOf(RunSection)

    def to_dict(self) -> dict[str, Any]:
        """Nested ``{section: {name: value}}``, as written to ``run.h5`` and TOML."""
        nested: dict[str, dict[str, Any]] = {}
        for key, value in self.values.items():
            section, name = key.split(".", 1)
            nested.setdefault(section, {})[name] = value
        return nested

    @classmethod
    def from_dict(cls, nested: Mapping[str, Any], schema: str = "biaxial") -> Config:
        """A stored configuration resolved again (keys added since take their defaults)."""
        if schema not in SCHEMAS:
            raise ConfigError(f"no configuration schema {schema!r} (import grainlab.protocols.registry); "
                              f"known: {', '.join(sorted(SCHEMAS))}")
        config: Config = SCHEMAS[schema].resolve(overrides=flatten_keys(nested))
        return config




C = TypeVar("C", bound=Config)


@dataclass(frozen=True)
class ConfigSchema(Generic[C]):
    """The configuration keys of one protocol: its fields (usually :data:`SHARED_FIELDS`,
    its own sections' and :data:`RUN_FIELDS`), the overrides of ``--quick``, the checks
    that span several keys (``check(values, given_keys)``, raising :class:`ConfigError`)
    and the :class:`Config` subclass it resolves to (its sections typed)."""

    name: str
    fields: Mapping[str, Field]
    quick: Mapping[str, Any]
    check: Callable[[dict[str, Any], AbstractSet[str]], None]
    config_type: type[C]

    def coerce(self, key: str, value: Any) -> Any:
        return coerce_field(self.fields, key, value)

    def resolve(
        self,
        config_file: str | Path | None = None,
        overrides: Mapping[str, Any] | Iterable[str] | None = None,
        *,
        quick: bool = False,
    ) -> C:
        """Defaults, then ``--quick``, then the TOML file, then overrides (a mapping,
        or ``key=value`` strings), all validated before anything runs."""
        values = {key: field.default for key, field in self.fields.items()}
        layers: list[dict[str, Any]] = []
        if quick:
            layers.append(dict(self.quick))
        if config_file is not None:
            path = Path(config_file)
            file_layer = flatten_keys(_read_toml(path))
            for key, value in file_layer.items():  # checked even where an override replaces it
                try:
                    self.coerce(key, value)
                except ConfigError as error:
                    raise ConfigError(f"{path}: {error}") from None
            layers.append(file_layer)
        if overrides is not None:
            if isinstance(overrides, Mapping):
                layers.append(dict(overrides))
            else:
                layers.append(dict(parse_override(text) for text in overrides))
        for layer in layers:
            for key, value in layer.items():
                values[key] = value
        resolved = {key: self.coerce(key, value) for key, value in values.items()}
        self.check(resolved, {key for layer in layers for key in layer})
        return self.config_type(resolved, self.name)


def _read_toml(path: Path) -> dict[str, Any]:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{path}: configuration file not found") from None
    except IsADirectoryError:
        raise ConfigError(f"{path}: is a folder, not a configuration file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ConfigError(f"{path}: cannot be read as a TOML configuration file ({error})") from None
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(f"{path}: not valid TOML ({error})") from None


def _grading_curve(v: dict[str, Any], given: AbstractSet[str]) -> None:
    """Checks a 'curve' grading's sieve data and takes d_min and d_max from it
    (a d_min or d_max given as well must agree with the curve's ends)."""
    sizes, passing = v["sample.sieve_sizes"], v["sample.percent_passing"]
    if v["sample.grading"] != "curve":
        if sizes or passing:
            raise ConfigError(
                "sample.sieve_sizes/sample.percent_passing: only used with sample.grading = 'curve', "
                f"got sample.grading = {v['sample.grading']!r}"
            )
        return
    from grainlab.samples import GradingCurve  # the samples package checks the curve itself

    if len(sizes) < 2 or len(passing) != len(sizes):
        raise ConfigError(
            "sample.sieve_sizes/sample.percent_passing: a 'curve' grading needs at least 2 sieve sizes "
            f"and one percentage per size, got {len(sizes)} sizes and {len(passing)} percentages"
        )
    try:
        GradingCurve(sizes, passing)
    except ValueError as error:
        raise ConfigError("sample." + str(error).replace("sieve_sizes_m", "sieve_sizes", 1)) from None
    for key, end in (("sample.d_min", sizes[0]), ("sample.d_max", sizes[-1])):
        if key in given and not math.isclose(v[key], end, rel_tol=1e-9):
            raise ConfigError(
                f"{key}: {v[key]:g} m disagrees with the 'curve' grading, whose sieve sizes run from "
                f"{sizes[0]:g} to {sizes[-1]:g} m; leave {key} out (the curve sets it)"
            )
    v["sample.d_min"], v["sample.d_max"] = sizes[0], sizes[-1]


def grain_shape(v: Mapping[str, Any]) -> ShapeTemplate | None:
    """The grains' clump template of ``sample.shape`` (None for disks, and for any
    shape at eta 0), or a :class:`ConfigError` saying what is wrong."""
    shape, eta = v["sample.shape"], v["sample.shape_parameter"]
    if v["sample.rod_pebbles"] != SHARED_FIELDS["sample.rod_pebbles"].default and shape != "rod":
        raise ConfigError(f"sample.rod_pebbles: only a rod takes it, got sample.shape = {shape!r}")
    if shape == "disk" and eta > 0.0:
        raise ConfigError(f"sample.shape_parameter: a disk has eta 0, got {eta:g} (choose dimer, trimer or rod)")
    if shape in SHAPES:
        try:
            template = shape_template(shape, eta, n_pebbles=v["sample.rod_pebbles"] if shape == "rod" else None)
        except ValueError as error:
            raise ConfigError(f"sample.{error}") from None
    elif eta > 0.0:
        raise ConfigError(f"sample.shape_parameter: the template file {shape!r} gives its own eta; leave it out")
    else:
        try:
            template = read_shape_template(shape)
        except FileFormatError as error:
            reason = str(error) if Path(shape).is_file() else "no such file"
            raise ConfigError(f"sample.shape: {shape!r} is not {', '.join(SHAPES)} or a template file ({reason})") from None
    return template if template.n_pebbles > 1 else None


def _check_cement(v: Mapping[str, Any], given: AbstractSet[str]) -> None:
    """Cement keys set without cement (a stored configuration's defaults pass), strengths
    missing, automatic stiffnesses without a linear law."""
    if v["cement.bonds"] == "none":
        defaults = CementSection.keys()
        stray = sorted(k for k in given if k in defaults and k != "cement.bonds" and v[k] != defaults[k].default)
        if stray:
            raise ConfigError(f"{stray[0]}: given, but cement.bonds is 'none' (give cement.bonds=parallel)")
        return
    check_bonds(v)


def check_bonds(v: Mapping[str, Any]) -> None:
    """The bonds' strengths missing, automatic stiffnesses without a linear law."""
    for name in ("cement.tensile_strength", "cement.cohesion"):
        if not v[name] > 0:
            raise ConfigError(f"{name}: cemented grains need a strength > 0 (e.g. {name}=\"1 MPa\")")
    auto = [k for k in ("cement.normal_stiffness", "cement.shear_stiffness") if v[k] == "auto"]
    if auto and v["material.contact_law"] != "linear":
        raise ConfigError(f"{auto[0]}: 'auto' follows the linear law's stiffness; with "
                          f"{v['material.contact_law']} give it in Pa/m")


def check_sample(v: dict[str, Any], given: AbstractSet[str] = frozenset()) -> None:
    """The checks of :data:`SHARED_FIELDS` that span several keys (the grading, the
    grains' shape, the sample's size against its grains, Hertz-Mindlin without
    contact dashpots); a 'curve' grading sets ``sample.d_min/d_max``."""
    _grading_curve(v, given)
    grain_shape(v)
    _check_cement(v, given)
    if v["material.contact_law"] == "hertz_mindlin" and v["material.contact_damping"] > 0:
        raise ConfigError(
            "material.contact_damping: hertz_mindlin is damped by material.restitution, "
            "not by contact dashpots (give 0)"
        )
    if v["sample.d_min"] > v["sample.d_max"]:
        raise ConfigError(
            f"sample.d_min: {v['sample.d_min']:g} m exceeds sample.d_max {v['sample.d_max']:g} m"
        )
    if 10 * v["sample.d_max"] > min(v["sample.width"], v["sample.height"]):
        raise ConfigError(
            f"sample.width/height: the sample must be at least 10 largest diameters wide "
            f"({10 * v['sample.d_max']:g} m), got {v['sample.width']:g} x {v['sample.height']:g} m"
        )


#: The configuration schemas of the protocols, by name (a protocol registers its own
#: with :func:`register_schema`; :mod:`grainlab.protocols.registry` imports every protocol).
SCHEMAS: dict[str, ConfigSchema[Any]] = {}


def register_test(name: str, own: Mapping[str, Field], check: Callable[[dict[str, Any], AbstractSet[str]], None],
                  config_type: type[C], quick: Mapping[str, Any] = QUICK) -> ConfigSchema[C]:
    """Registers the schema of a test that makes a sample: :data:`SHARED_FIELDS`, its
    ``own`` keys (one of the shared ones given again takes its place) and
    :data:`RUN_FIELDS`; returns it."""
    return register_schema(ConfigSchema(name, {**SHARED_FIELDS, **own, **RUN_FIELDS}, quick, check, config_type))


def register_schema(schema: ConfigSchema[C]) -> ConfigSchema[C]:
    """Adds ``schema`` to :data:`SCHEMAS` under its name (a protocol's own module does,
    when it is imported); returns it."""
    known = SCHEMAS.setdefault(schema.name, schema)
    if known is not schema:
        raise ValueError(f"protocol configuration {schema.name!r} is registered already")
    return schema
