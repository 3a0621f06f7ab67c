"""Post-processing of finished runs: results files in, numbers, figures and exports out.

This layer sits above :mod:`grainlab.analysis` (the measures, pure: snapshots
and arrays in, numbers out) and :mod:`grainlab.io` (reading ``run.h5``,
writing files), and below the report, the reproduction and the command line,
which present what it computes (the layer rule is in ARCHITECTURE.md).

- :mod:`.biaxial`: a biaxial run's states (initial, peak, final), their
  fabric and shear bands (:func:`fabric_numbers`, :func:`analyse_run`);
- :mod:`.band`: finding and accepting the shear band between two snapshots
  (:func:`find_band`, :func:`band_labels`);
- :mod:`.figures`: the paper's Figs. 6, 7, 9, 11-14 as files
  (:func:`fabric_figures`), drawn by :mod:`grainlab.plot.biaxial`;
- :mod:`.vtk`: the ParaView export of a run (:func:`export_vtk`);
- :mod:`.analysis_files`: the files of ``grainlab analyze`` (:func:`write_analysis`).
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
