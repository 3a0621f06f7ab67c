"""The protocols grainlab runs, in one place: their names, their classes and
their configuration schemas. The campaigns (``grainlab study``, ``sweep``,
``reproduce``, Dask) run a protocol by its name from here; a new protocol
registers here, and its schema in :data:`SCHEMAS` (``register_schema`` in its own
package; importing this module imports every protocol, so :data:`SCHEMAS` holds them all).

>>> sorted(PROTOCOLS)
['biaxial', 'brazilian', 'crushing', 'cyclic', 'oedometer', 'simple_shear', 'ucs']
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from grainlab.protocols.biaxial.protocol import BiaxialProtocol
from grainlab.protocols.brazilian.protocol import BrazilianProtocol
from grainlab.protocols.config import SCHEMAS, Config
from grainlab.protocols.crushing.protocol import CrushingProtocol
from grainlab.protocols.cyclic.protocol import CyclicProtocol
from grainlab.protocols.oedometer.protocol import OedometerProtocol
from grainlab.protocols.runner import Protocol, RunResult, run_protocol
from grainlab.protocols.simple_shear.protocol import SimpleShearProtocol
from grainlab.protocols.ucs.protocol import UcsProtocol

__all__ = ["PROTOCOLS", "SCHEMAS", "resolve_config", "run_named"]

#: Protocol name -> its class (the name is also the results file's ``kind``).
PROTOCOLS: dict[str, type[Protocol[Any, Any, Any]]] = {
    BiaxialProtocol.name: BiaxialProtocol,
    OedometerProtocol.name: OedometerProtocol,
    CyclicProtocol.name: CyclicProtocol,
    SimpleShearProtocol.name: SimpleShearProtocol,
    UcsProtocol.name: UcsProtocol,
    BrazilianProtocol.name: BrazilianProtocol,
    CrushingProtocol.name: CrushingProtocol,
}


def _check_name(name: str) -> None:
    if name not in PROTOCOLS or name not in SCHEMAS:
        raise ValueError(f"protocol: unknown protocol {name!r}; known: {', '.join(sorted(PROTOCOLS))}")


def resolve_config(name: str, config_file: str | Path | None = None,
                   overrides: Mapping[str, Any] | Iterable[str] | None = None, *, quick: bool = False) -> Config:
    """The configuration of protocol ``name`` (its schema's ``resolve``)."""
    _check_name(name)
    config: Config = SCHEMAS[name].resolve(config_file, overrides, quick=quick)
    return config


def run_named(name: str, config: Config, out_dir: str | os.PathLike[str], *, resume: bool = False,
              progress: bool = False) -> RunResult:
    """Runs (or resumes) protocol ``name`` with ``config`` into ``out_dir``."""
    _check_name(name)
    result: RunResult = run_protocol(PROTOCOLS[name](config), out_dir, resume=resume, progress=progress)
    return result
