"""The unconfined compression test (UCS) of a cemented sample: the side walls
removed, the top platen down at a constant strain rate to the peak and past it
(docs/cemented.md, "The unconfined compression test")."""

from grainlab.protocols.ucs.config import UCS_FIELDS, UCS_SCHEMA, UcsConfig
from grainlab.protocols.ucs.outputs import UcsResult, elastic_fit
from grainlab.protocols.ucs.protocol import UcsProtocol, run_ucs
from grainlab.protocols.ucs.state import UcsRun

__all__ = ["UCS_FIELDS", "UCS_SCHEMA", "UcsConfig", "UcsProtocol", "UcsResult", "UcsRun", "elastic_fit", "run_ucs"]
