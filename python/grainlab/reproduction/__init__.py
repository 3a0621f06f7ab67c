"""``grainlab reproduce``: does the paper's finding hold? (docs/reproduction.md)

The paper's biaxial test (and its packing study) over an ensemble of seeds and
protocol variants (:mod:`.runs`), every claim of the paper measured from the
stored run outputs with the current analysis and judged by a rule fixed in
advance (:mod:`.claims`, :mod:`.verdicts`), the band-resolved fabric over
strain (:mod:`.band_fabric`), and a self-contained ``reproduction.html``.
"""

from grainlab.reproduction.runs import (
    DEFAULT_SEEDS,
    DEFAULT_VARIANTS,
    ReproductionPlan,
    Variant,
    parse_variant,
    run_reproduction,
    snapshot_strains,
)

__all__ = [
    "DEFAULT_SEEDS",
    "DEFAULT_VARIANTS",
    "ReproductionPlan",
    "Variant",
    "parse_variant",
    "run_reproduction",
    "snapshot_strains",
]
