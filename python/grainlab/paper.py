"""What the paper states, in one place: Table 1, the values of its figures and its claims.

The paper is "Geometrical stability index" (the biaxial test of Sec. 6 and
the packing study of Sec. 7). Every number here is the paper's, in SI units
or fractions, with the place it comes from; values the paper only shows in a
figure are marked as not stated in the text, and nothing is read off a plot.
The configuration defaults (:mod:`grainlab.protocols.config`), the engine's
Table 1 constants (:mod:`grainlab.simulation`), the sample generation's
(:mod:`grainlab.samples.expansion`), the report's "paper beside the run"
tables (:mod:`grainlab.report.biaxial`, :mod:`grainlab.report.study`) and the
reproduction's claims (:mod:`grainlab.reproduction.claims`) take their
numbers from here.

This module imports nothing from grainlab (the bottom layer, ARCHITECTURE.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "A_AT_HALF_PERCENT",
    "A_ISOTROPIC",
    "A_N_ISOTROPIC",
    "BIAXIAL_CLAIMS",
    "CONSOLIDATION_PRESSURE_PA",
    "DENSITY_KG_PER_M3",
    "DENSITY_SCALING_LIMIT",
    "D_MAX_M",
    "D_MIN_M",
    "FRICTION",
    "HEIGHT_M",
    "LAMBDA_IN_BAND",
    "LAMBDA_OUTSIDE_BAND",
    "LIMITING_CONTACT_PRESSURE_PA",
    "LOCAL_DAMPING",
    "MIN_RADIUS_M",
    "NORMAL_STIFFNESS_N_PER_M",
    "PLATEN_FRICTION",
    "POROSITY",
    "SHEAR_STIFFNESS_N_PER_M",
    "SNAPSHOT_STRAINS",
    "STRAIN_AT_PEAK",
    "STRAIN_RATE_PER_S",
    "STUDY_CLAIMS",
    "TABLE1",
    "WIDTH_M",
    "Z_AT_PEAK",
    "Z_INITIAL",
    "PaperValue",
]

# ---- Table 1: the biaxial test ------------------------------------------------
#: Sample width and height (Table 1: 75 mm x 150 mm).
WIDTH_M = 0.075
HEIGHT_M = 0.150
#: Initial (nominal) porosity after generation (Table 1).
POROSITY = 0.12
#: Particle size distribution, 0.5-3 mm diameters (Table 1).
D_MIN_M = 0.5e-3
D_MAX_M = 3.0e-3
#: Smallest radius R_min (Table 1: 0.236 mm).
MIN_RADIUS_M = 0.236e-3
#: Contact normal and shear stiffness (Table 1: 8.45e7 N/m).
NORMAL_STIFFNESS_N_PER_M = 8.45e7
SHEAR_STIFFNESS_N_PER_M = 8.45e7
#: Particle-particle and particle-platen friction coefficients (Table 1).
FRICTION = 0.9
PLATEN_FRICTION = 0.0
#: Scaled particle density (Table 1: 2e8 kg/m^3).
DENSITY_KG_PER_M3 = 2.0e8
#: Local damping constant alpha (Table 1).
LOCAL_DAMPING = 0.8
#: Limiting contact pressure p_y of the density scaling (Table 1: 150 MPa).
LIMITING_CONTACT_PRESSURE_PA = 150.0e6
#: Isotropic consolidation stress sigma_0 = sigma_3 (Sec. 6: 100 kPa).
CONSOLIDATION_PRESSURE_PA = 1.0e5
#: Axial strain rate (Table 1: 2 %/min).
STRAIN_RATE_PER_S = 0.02 / 60.0
#: Axial strains of the snapshots shown (Figs. 11-12: 0, 0.5, 0.7, 0.9, 1.5 and 10 %).
SNAPSHOT_STRAINS = (0.0, 0.005, 0.007, 0.009, 0.015, 0.10)
#: Upper bound of the density scaling factor I (Sec. 6, Eq. 16).
DENSITY_SCALING_LIMIT = 1.0e-3

# ---- Sec. 6: the values of the figures and the text -----------------------------
#: Anisotropies of the isotropic state: contact normals a (Fig. 6), normal forces a_n (Fig. 7).
A_ISOTROPIC = 0.0034
A_N_ISOTROPIC = 0.009
#: Contact-normal anisotropy at 0.5 % axial strain ("around 0.18", Fig. 9).
A_AT_HALF_PERCENT = 0.18
#: Coordination number at the start of shearing and at the peak ("around 3.9", "around 3.0", Fig. 10).
Z_INITIAL = 3.9
Z_AT_PEAK = 3.0
#: Axial strain of the peak stress ratio, where the band is fully developed (Figs. 8, 11: 1.5 %).
STRAIN_AT_PEAK = 0.015
#: Mean lambda inside the shear band and in the rest of the sample at the peak (Fig. 13).
LAMBDA_IN_BAND = 0.34
LAMBDA_OUTSIDE_BAND = 0.31


@dataclass(frozen=True)
class PaperValue:
    """One value or statement of the paper."""

    #: Key a run's value is matched by (a configuration key for :data:`TABLE1`).
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
        PaperValue("sample.width", "width", "75 mm", "Table 1", WIDTH_M),
        PaperValue("sample.height", "height", "150 mm", "Table 1", HEIGHT_M),
        PaperValue("sample.porosity", "initial porosity", "0.12", "Table 1", POROSITY),
        PaperValue("sample.d_min", "smallest diameter", "0.5 mm (PSD 0.5-3 mm)", "Table 1", D_MIN_M),
        PaperValue("sample.d_max", "largest diameter", "3 mm (PSD 0.5-3 mm)", "Table 1", D_MAX_M),
        PaperValue("material.normal_stiffness", "Kn", "8.45e7 N/m", "Table 1", NORMAL_STIFFNESS_N_PER_M),
        PaperValue("material.shear_stiffness", "Ks", "8.45e7 N/m", "Table 1", SHEAR_STIFFNESS_N_PER_M),
        PaperValue("material.friction", "particle friction", "0.9", "Table 1", FRICTION),
        PaperValue("material.platen_friction", "particle-platen friction", "0.0", "Table 1", PLATEN_FRICTION),
        PaperValue("material.density", "density", "2e8 kg/m^3 (scaled)", "Table 1", DENSITY_KG_PER_M3),
        PaperValue("material.local_damping", "damping constant", "0.8", "Table 1", LOCAL_DAMPING),
        PaperValue("consolidation.pressure", "consolidation stress", "100 kPa", "Sec. 6", CONSOLIDATION_PRESSURE_PA),
        PaperValue("shear.strain_rate", "axial strain rate", "2 %/min", "Table 1", STRAIN_RATE_PER_S),
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
    PaperValue("porosity", "porosity after generation (nominal)", "0.12", "Table 1", POROSITY),
    PaperValue("min_radius", "smallest radius R_min", "0.236 mm", "Table 1", MIN_RADIUS_M),
    PaperValue("strain_rate", "axial strain rate", "2 %/min (3.3e-4 1/s)", "Table 1", STRAIN_RATE_PER_S),
    PaperValue(
        "density_scaling",
        "density scaling factor I (Eq. 16)",
        "must be below 1e-3 (Table 1 uses p_y = 150 MPa)",
        "Sec. 6, Eq. 16",
        DENSITY_SCALING_LIMIT,
    ),
    PaperValue("a_initial", "contact-normal anisotropy a, isotropic state", "0.0034", "Sec. 6, Fig. 6", A_ISOTROPIC),
    PaperValue(
        "a_n_initial", "normal-force anisotropy a_n, isotropic state", "0.009", "Sec. 6, Fig. 7", A_N_ISOTROPIC
    ),
    PaperValue("a_at_0.5", "anisotropy a at 0.5 % axial strain", "around 0.18", "Sec. 6, Fig. 9", A_AT_HALF_PERCENT),
    PaperValue("z_initial", "coordination number, start of shearing", "around 3.9", "Sec. 6, Fig. 10", Z_INITIAL),
    PaperValue("z_peak", "coordination number at the peak", "around 3.0", "Sec. 6, Fig. 10", Z_AT_PEAK),
    PaperValue(
        "strain_at_peak",
        "axial strain at the peak stress ratio",
        "1.5 % (\"fully developed at 1.5 %, which corresponds to the peak stress ratio\"; "
        "the text also puts the peak at 0.15 % twice)",
        "Sec. 6, Figs. 8, 11",
        STRAIN_AT_PEAK,
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
    PaperValue("lambda_in_band", "mean λ inside the band at the peak", "0.34", "Sec. 6, Fig. 13", LAMBDA_IN_BAND),
    PaperValue(
        "lambda_outside", "mean λ outside the band at the peak", "0.31", "Sec. 6, Fig. 13", LAMBDA_OUTSIDE_BAND
    ),
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
