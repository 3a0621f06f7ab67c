"""The cyclic biaxial test's configuration: the biaxial test's keys but the
monotonic loading's end and snapshots (``shear.final_strain``,
``shear.snapshot_strains``), and its own (``cyclic.*``)."""

from __future__ import annotations

from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any, ClassVar

from grainlab.protocols.biaxial.config import BIAXIAL_FIELDS, BiaxialConfig, check_boundary
from grainlab.protocols.config import (
    POSITIVE,
    ConfigError,
    Section,
    SectionOf,
    check_sample,
    key,
    register_test,
)

__all__ = ["CYCLIC_FIELDS", "CYCLIC_SCHEMA", "CyclicConfig", "CyclicSection"]

@dataclass(frozen=True)
class CyclicSection(Section):
    """The cyclic test's own keys: the cycles and their control."""

    prefix: ClassVar[str] = "cyclic"
    strain_amplitude: float = key(
        "strain", 0.005, "axial strain amplitude: each cycle goes 0 -> +amplitude -> -amplitude -> 0 "
        "(compression positive); at most 5 %", minimum=0.0, maximum=0.05, exclusive_minimum=True,
    )
    cycles: int = key("integer", 5, "number of cycles", minimum=1, maximum=1000)
    control: str = key(
        "choice", "strain",
        "strain: the platens turn at +/- cyclic.strain_amplitude; stress: they turn where the deviator "
        "q = sigma_1 - sigma_3' reaches +/- cyclic.stress_amplitude",
        choices=("strain", "stress"),
    )
    stress_amplitude: float | str = key(
        "stress", "auto", "deviator amplitude A_q of a stress-controlled test: each cycle goes q = 0 -> +A_q -> "
        "-A_q -> 0; below sigma_0 (extension to -A_q needs sigma_1 = sigma_3 - A_q > 0)",
        **POSITIVE, allow_auto=True,
    )
    strain_limit: float = key(
        "strain", 0.05, "a stress-controlled test ends when the axial strain reaches +/- this (the sample has "
        "failed: the cycles it completed are its cycles to failure)", minimum=0.0, maximum=0.2,
        exclusive_minimum=True,
    )


CYCLIC_FIELDS = CyclicSection.keys()


@dataclass(frozen=True)
class CyclicConfig(BiaxialConfig):
    """The cyclic test's configuration: the biaxial test's sections and its cycles."""

    cyclic = SectionOf(CyclicSection)

_MONOTONIC_ONLY = ("shear.final_strain", "shear.snapshot_strains")


def _check(values: dict[str, Any], given: AbstractSet[str]) -> None:
    check_sample(values, given)
    check_boundary(values, given)
    if values["cyclic.control"] == "stress":
        _check_stress_control(values, given)
        return
    if values["cyclic.stress_amplitude"] != "auto":
        raise ConfigError("cyclic.stress_amplitude: only used with cyclic.control = 'stress'")
    amplitude, interval = values["cyclic.strain_amplitude"], values["shear.record_interval"]
    if amplitude < 4 * interval:
        raise ConfigError(
            f"cyclic.strain_amplitude: {amplitude:g} is less than four record intervals "
            f"(shear.record_interval {interval:g}): a cycle's loops would have too few points; "
            "raise it or record more often"
        )


def _check_stress_control(values: dict[str, Any], given: AbstractSet[str]) -> None:
    amplitude, sigma_0 = values["cyclic.stress_amplitude"], values["consolidation.pressure"]
    # (a saved configuration holds every key: only a value other than the default is refused)
    if "cyclic.strain_amplitude" in given and values["cyclic.strain_amplitude"] != CYCLIC_FIELDS[
            "cyclic.strain_amplitude"].default:
        raise ConfigError("cyclic.strain_amplitude: a stress-controlled test turns at cyclic.stress_amplitude; "
                          "its strain bound is cyclic.strain_limit")
    if amplitude == "auto":
        raise ConfigError("cyclic.stress_amplitude: give the deviator amplitude of a stress-controlled test, "
                          "e.g. --set 'cyclic.stress_amplitude=50 kPa'")
    if amplitude >= sigma_0:
        raise ConfigError(
            f"cyclic.stress_amplitude: {amplitude / 1e3:g} kPa reaches beyond the sample: extension to q = -A_q "
            f"needs sigma_1 = sigma_3 - A_q > 0 with sigma_3 = consolidation.pressure = {sigma_0 / 1e3:g} kPa"
        )


#: The cyclic test's configuration schema (registered as ``"cyclic"``).
CYCLIC_SCHEMA = register_test(
    "cyclic", {**{k: f for k, f in BIAXIAL_FIELDS.items() if k not in _MONOTONIC_ONLY}, **CYCLIC_FIELDS}, _check,
    CyclicConfig)
