"""Post-processing of finished runs: results files in, numbers, figures and exports out.

Above :mod:`grainlab.analysis` and :mod:`grainlab.io`, below the report, the
reproduction and the command line (ARCHITECTURE.md).
"""

from grainlab.postprocess.analysis_files import write_analysis
from grainlab.postprocess.band import BandNumbers, BandSearch, band_labels, find_band
from grainlab.postprocess.biaxial import (
    REQUIRED_COLUMNS,
    FabricNumbers,
    MissingColumnError,
    StateNumbers,
    analyse_run,
    fabric_numbers,
)
from grainlab.postprocess.figures import FIGURES, FabricFigures, fabric_figures
from grainlab.postprocess.vtk import VtkExport, export_vtk, snapshot_arrays

__all__ = [
    "FIGURES",
    "REQUIRED_COLUMNS",
    "BandNumbers",
    "BandSearch",
    "FabricFigures",
    "FabricNumbers",
    "MissingColumnError",
    "StateNumbers",
    "VtkExport",
    "analyse_run",
    "band_labels",
    "export_vtk",
    "fabric_figures",
    "fabric_numbers",
    "find_band",
    "snapshot_arrays",
    "write_analysis",
]
