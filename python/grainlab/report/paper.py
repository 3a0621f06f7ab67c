"""What the paper reports, for the report's "paper beside the run" tables.

Every entry quotes the paper (``shared/paper/``, "Geometrical stability index")
with the place it comes from. Values the paper only shows in a figure are
marked as not stated in the text; nothing is read off a plot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["BIAXIAL_CLAIMS", "STUDY_CLAIMS", "TABLE1", "PaperValue"]


@dataclass(frozen=True)
class PaperValue:
    """One value or statement of the paper."""

    #: Key the report matches the run's value by.
    key: str
    #: What is compared (plain text).
    quantity: str
    #: How the paper states it.
    text: str
    #: Where in the paper.
    where: str
    #: The number, in SI / fractions, when the paper gives one (NaN otherwise).
    value: float = math.nan


#: Table 1 (and Sec. 6) values of the biaxial test, by configuration key (SI units).
TABLE1: dict[str, PaperValue] = {
    v.key: v
    for v in (
        PaperValue("sample.width", "width", "75 mm", "Table 1", 0.075),
        PaperValue("sample.height", "height", "150 mm", "Table 1", 0.150),
        PaperValue("sample.porosity", "initial porosity", "0.12", "Table 1", 0.12),
        PaperValue("sample.d_min", "smallest diameter", "0.5 mm (PSD 0.5-3 mm)", "Table 1", 0.5e-3),
        PaperValue("sample.d_max", "largest diameter", "3 mm (PSD 0.5-3 mm)", "Table 1", 3.0e-3),
        PaperValue("material.normal_stiffness", "Kn", "8.45e7 N/m", "Table 1", 8.45e7),
        PaperValue("material.shear_stiffness", "Ks", "8.45e7 N/m", "Table 1", 8.45e7),
        PaperValue("material.friction", "particle friction", "0.9", "Table 1", 0.9),
        PaperValue("material.platen_friction", "particle-platen friction", "0.0", "Table 1", 0.0),
        PaperValue("material.density", "density", "2e8 kg/m^3 (scaled)", "Table 1", 2.0e8),
        PaperValue("material.local_damping", "damping constant", "0.8", "Table 1", 0.8),
        PaperValue("consolidation.pressure", "consolidation stress", "100 kPa", "Sec. 6", 1.0e5),
        PaperValue("shear.strain_rate", "axial strain rate", "2 %/min", "Table 1", 0.02 / 60.0),
        PaperValue(
            "shear.snapshot_strains", "snapshot strains", "0, 0.5, 0.7, 0.9, 1.5, 10 %", "Figs. 11-12"
        ),
        PaperValue(
            "boundary.kind",
            "lateral boundary",
            "deformable: particles at the edges forming continuous boundaries [26]",
            "Sec. 6",
        ),
    )
}

#: The paper's statements about the default biaxial test (Sec. 6), in report order.
BIAXIAL_CLAIMS: tuple[PaperValue, ...] = (
    PaperValue("porosity", "porosity after generation (nominal)", "0.12", "Table 1", 0.12),
    PaperValue("min_radius", "smallest radius R_min", "0.236 mm", "Table 1", 0.236e-3),
    PaperValue("strain_rate", "axial strain rate", "2 %/min (3.3e-4 1/s)", "Table 1", 0.02 / 60.0),
    PaperValue(
        "density_scaling",
        "density scaling factor I (Eq. 16)",
        "must be below 1e-3 (Table 1 uses p_y = 150 MPa)",
        "Sec. 6, Eq. 16",
        1e-3,
    ),
    PaperValue("a_initial", "contact-normal anisotropy a, isotropic state", "0.0034", "Sec. 6, Fig. 6", 0.0034),
    PaperValue("a_n_initial", "normal-force anisotropy a_n, isotropic state", "0.009", "Sec. 6, Fig. 7", 0.009),
    PaperValue("a_at_0.5", "anisotropy a at 0.5 % axial strain", "around 0.18", "Sec. 6, Fig. 9", 0.18),
    PaperValue("z_initial", "coordination number, start of shearing", "around 3.9", "Sec. 6, Fig. 10", 3.9),
    PaperValue("z_peak", "coordination number at the peak", "around 3.0", "Sec. 6, Fig. 10", 3.0),
    PaperValue(
        "strain_at_peak",
        "axial strain at the peak stress ratio",
        "1.5 % (\"fully developed at 1.5 %, which corresponds to the peak stress ratio\"; "
        "the text also puts the peak at 0.15 % twice)",
        "Sec. 6, Figs. 8, 11",
        0.015,
    ),
    PaperValue("peak_ratio", "peak stress ratio σ₁/σ₃", "not stated in the text (Fig. 8)", "Fig. 8"),
    PaperValue(
        "volumetric",
        "volumetric strain",
        "contraction, then dilation",
        "Fig. 18",
    ),
    PaperValue(
        "band_at_peak", "shear band at the peak", "fully developed at 1.5 % (the peak)", "Sec. 6, Fig. 11"
    ),
    PaperValue(
        "band_inclination",
        "band inclination to the σ₃ direction",
        "not stated (a diagonal band, Fig. 11)",
        "Fig. 11",
    ),
    PaperValue("lambda_in_band", "mean λ inside the band at the peak", "0.34", "Sec. 6, Fig. 13", 0.34),
    PaperValue("lambda_outside", "mean λ outside the band at the peak", "0.31", "Sec. 6, Fig. 13", 0.31),
    PaperValue(
        "lambda_trend",
        "mean λ against axial strain",
        "rises to the peak, then falls to a constant",
        "Sec. 6, Fig. 14",
    ),
)

#: The paper's statements about the packing study (Sec. 7).
STUDY_CLAIMS: tuple[PaperValue, ...] = (
    PaperValue(
        "lambda_vs_z",
        "λ against Z (Fig. 15)",
        "more contacts per particle, more stable (lower λ), hexagonal or irregular",
        "Sec. 7, Fig. 15",
    ),
    PaperValue(
        "hexagonal_lower",
        "hexagonal against irregular",
        "hexagonal packing is more stable (lowest λ) for a given Z",
        "Sec. 7, Fig. 15",
    ),
    PaperValue(
        "lambda_vs_porosity",
        "λ against porosity (Fig. 16)",
        "less well defined; hexagonal more stable at a given porosity",
        "Sec. 7, Fig. 16",
    ),
    PaperValue(
        "lambda_vs_a",
        "λ against anisotropy a (Fig. 17)",
        "linearly related",
        "Sec. 7, Fig. 17",
    ),
)
