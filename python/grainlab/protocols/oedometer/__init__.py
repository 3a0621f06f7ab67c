"""The oedometer (K0) test: confined compression between fixed side walls,
loading and unloading to given vertical stresses (docs/protocols.md)."""

from grainlab.protocols.oedometer.config import OEDOMETER_FIELDS, OEDOMETER_SCHEMA
from grainlab.protocols.oedometer.outputs import K0_FROM_STRESS_RATIO, OedometerResult, k0_loading
from grainlab.protocols.oedometer.protocol import OedometerProtocol, load_path, run_oedometer
from grainlab.protocols.oedometer.state import OedometerRun

__all__ = ["K0_FROM_STRESS_RATIO", "OEDOMETER_FIELDS", "OEDOMETER_SCHEMA", "OedometerProtocol", "OedometerResult",
           "OedometerRun", "k0_loading", "load_path", "run_oedometer"]
