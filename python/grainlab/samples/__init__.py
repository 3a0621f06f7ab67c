"""Sample generation: gradings, porosity, random placement, radius expansion, lattices.

Usable on its own (docs/samples.md)::

    from grainlab.samples import expand_to_porosity
    sample = expand_to_porosity()          # the paper's Table 1 sample
    print(sample.summary())
"""

from grainlab.samples.expansion import WALL_NAMES, ExpansionError, Sample, expand_to_porosity
from grainlab.samples.friction_search import (
    FrictionSearch,
    FrictionSearchError,
    FrictionTrial,
    expand_with_friction_search,
)
from grainlab.samples.grading import (
    PAPER_GRADING,
    Grading,
    GradingCurve,
    UniformByMass,
    UniformByNumber,
)
from grainlab.samples.lattice import (
    HEXAGONAL_CONTACT_POROSITY,
    SQUARE_CONTACT_POROSITY,
    Lattice,
    hexagonal_lattice,
    square_lattice,
)
from grainlab.samples.placement import PlacementError, random_placement
from grainlab.samples.porosity import (
    box_area,
    disk_area_in_box,
    grain_overlap_area,
    lens_area,
    measurement_circle_porosity,
    nominal_porosity,
    overlap_corrected_porosity,
    particle_count,
)

__all__ = [
    "HEXAGONAL_CONTACT_POROSITY",
    "PAPER_GRADING",
    "SQUARE_CONTACT_POROSITY",
    "WALL_NAMES",
    "ExpansionError",
    "FrictionSearch",
    "FrictionSearchError",
    "FrictionTrial",
    "Grading",
    "GradingCurve",
    "Lattice",
    "PlacementError",
    "Sample",
    "UniformByMass",
    "UniformByNumber",
    "box_area",
    "disk_area_in_box",
    "expand_to_porosity",
    "expand_with_friction_search",
    "grain_overlap_area",
    "hexagonal_lattice",
    "lens_area",
    "measurement_circle_porosity",
    "nominal_porosity",
    "overlap_corrected_porosity",
    "particle_count",
    "random_placement",
    "square_lattice",
]
