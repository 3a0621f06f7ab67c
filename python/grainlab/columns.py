"""The time-series columns the protocols record, in one place: each column's
name, unit and meaning (:class:`Column`), and the columns of each test
(:class:`Columns`: :data:`BIAXIAL`, :data:`OEDOMETER`, :data:`CYCLIC`,
:data:`SIMPLE_SHEAR`, :data:`UCS`, :data:`BRAZILIAN`, :data:`CRUSHING`).

A :class:`Column` *is* its name (a ``str``), so ``timeseries[AXIAL_STRAIN]``
reads the column from a results file, a CSV or a record, while
``AXIAL_STRAIN.unit`` and ``AXIAL_STRAIN.meaning`` say what it holds. The
protocols record with these names, and postprocess, the report, the viewer
and the reproduction read with them; ``docs/file-formats.md``'s table of the
columns is made from this module (``python -m grainlab.columns
docs/file-formats.md`` writes it; ``tests/test_columns.py`` keeps it so).

>>> AXIAL_STRAIN, AXIAL_STRAIN.unit
('axial_strain', '1')
>>> BIAXIAL.units()[AXIAL_STRESS_PA]
'Pa'
"""

from __future__ import annotations

import re
import sys
from collections.abc import Iterator
from pathlib import Path

__all__ = [
    "AGGLOMERATE",
    "CHARACTERISTIC_STRESS_PA",
    "CRUSHING",
    "DIAMETER_M",
    "FRAGMENTS",
    "LARGEST_FRAGMENT",
    "MAJOR_FRAGMENTS",
    "AGGLOMERATE_PLATEN_DISPLACEMENT_M",
    "PLATEN_FORCE_N",
    "AXIAL_STRAIN",
    "AXIAL_STRESS_PA",
    "BIAXIAL",
    "BRAZILIAN",
    "COORDINATION_NUMBER",
    "CYCLE",
    "CYCLIC",
    "Column",
    "Columns",
    "FABRIC",
    "FRICTION_COEFFICIENT",
    "HORIZONTAL_STRESS_PA",
    "INERTIAL_NUMBER",
    "LATERAL_STRAIN",
    "LATERAL_STRESS_RATIO",
    "OEDOMETER",
    "NORMAL_STRESS_PA",
    "OVERCONSOLIDATION_RATIO",
    "PLATEN_DISPLACEMENT_M",
    "PLATEN_FORCE_N_PER_M",
    "SHEAR_STRAIN",
    "SHEAR_STRESS_PA",
    "SIMPLE_SHEAR",
    "STRAIN_PATH",
    "STRESS_RATIO",
    "TENSILE_STRESS_PA",
    "UCS",
    "VERTICAL_STRESS_PA",
    "VOLUMETRIC_STRAIN",
    "WIDTH_M",
]


class Column(str):
    """One time-series column: the string is its name; ``unit`` is its unit (``"1"``
    for strains, ratios and counts) and ``meaning`` what it holds, in a line."""

    unit: str
    meaning: str

    def __new__(cls, name: str, unit: str, meaning: str) -> Column:
        column = super().__new__(cls, name)
        column.unit = unit
        column.meaning = meaning
        return column

    def __reduce__(self) -> tuple[type[Column], tuple[str, str, str]]:
        return (Column, (str(self), self.unit, self.meaning))


class Columns:
    """The columns one test records, in the order a file lists them."""

    def __init__(self, kind: str, *groups: tuple[Column, ...]) -> None:
        self.kind = kind
        self.columns: tuple[Column, ...] = tuple(c for group in groups for c in group)
        names = [str(c) for c in self.columns]
        if len(set(names)) != len(names):
            raise ValueError(f"{kind}: a column is listed twice in {names}")
        self._by_name = dict(zip(names, self.columns, strict=True))

    def __iter__(self) -> Iterator[Column]:
        return iter(self.columns)

    def __len__(self) -> int:
        return len(self.columns)

    def __contains__(self, name: object) -> bool:
        return name in self._by_name

    def __getitem__(self, name: str) -> Column:
        return self._by_name[name]

    def units(self) -> dict[str, str]:
        """Column name -> unit, as a results file stores them."""
        return {str(c): c.unit for c in self.columns}

    def markdown_table(self) -> str:
        """The columns as a Markdown table (name, unit, meaning)."""
        rows = ["| column | unit | meaning |", "| --- | --- | --- |"]
        rows += [f"| `{c}` | {c.unit} | {c.meaning} |" for c in self.columns]
        return "\n".join(rows)


# ---- every test's ------------------------------------------------------------------
STEP = Column("step", "1", "engine step count (int64)")
TIME_S = Column("time_s", "s", "simulated time")
AXIAL_STRAIN = Column("axial_strain", "1", "axial strain eps_1 = (H0 - H) / H0, compression positive")
VOLUMETRIC_STRAIN = Column("volumetric_strain", "1", "volumetric strain (A0 - A) / A0, compression positive")
AXIAL_STRESS_PA = Column("axial_stress_pa", "Pa", "axial stress sigma_1 on the platens")
AREA_M2 = Column("area_m2", "m^2", "sample area")
HEIGHT_M = Column("height_m", "m", "sample height between the platens")
LOVE_WEBER = (
    Column("love_weber_xx_pa", "Pa", "Love-Weber stress of the grains, xx"),
    Column("love_weber_yy_pa", "Pa", "Love-Weber stress of the grains, yy"),
    Column("love_weber_xy_pa", "Pa", "Love-Weber stress of the grains, xy"),
)
COORDINATION_NUMBER = Column("coordination_number", "1", "Z = 2 x grain-grain contacts / grains")
UNBALANCED_FORCE_RATIO = Column("unbalanced_force_ratio", "1", "mean unbalanced force over mean contact force")
#: The engine's energy ledger (J per m of thickness; docs/contact-law.md, "Energy bookkeeping").
ENERGY = (
    Column("kinetic_energy_j", "J", "kinetic energy of the particles"),
    Column("elastic_energy_j", "J", "energy stored in the contact and bond springs"),
    Column("friction_dissipated_j", "J", "dissipated by frictional slip since step 0"),
    Column("damping_dissipated_j", "J", "dissipated by local damping since step 0"),
    Column("boundary_work_j", "J", "work of the follower loads (the membrane's pressure) since step 0"),
    Column("wall_work_j", "J", "work of the walls on the particles since step 0"),
)
#: The fabric of every record (grainlab.analysis.fabric_summary, in its order, but its Z: a
#: record's own counts grain-grain contacts only).
FABRIC = (
    Column("mechanical_coordination_number", "1", "Z of the grains with >= 2 contacts (rattlers out)"),
    Column("mean_stability_index", "1", "mean lambda of the grains with >= 2 contacts (paper Sec. 5)"),
    Column("mean_stability_index_all", "1", "mean lambda of every grain (0 and 1 contact at lambda = 1)"),
    Column("anisotropy", "1", "contact-normal anisotropy a (exact estimate, paper Eq. 7)"),
    Column("anisotropy_direction_rad", "rad", "principal direction of the contact normals"),
    Column("anisotropy_binned", "1", "contact-normal anisotropy, Eq. 7 on 18 bins"),
    Column("anisotropy_fourier", "1", "the exact estimate under its earlier name"),
    Column("force_anisotropy", "1", "normal-force anisotropy a_n (exact estimate, Eq. 8)"),
    Column("force_anisotropy_binned", "1", "normal-force anisotropy, Eq. 8 on 18 bins"),
)
#: What every test records after its own columns: the stress, Z, the energy ledger and the fabric.
EVERY_TEST = (*LOVE_WEBER, COORDINATION_NUMBER, UNBALANCED_FORCE_RATIO, *ENERGY, *FABRIC)

# ---- the biaxial test's ------------------------------------------------------------
CONFINING_PRESSURE_PA = Column("confining_pressure_pa", "Pa", "confining pressure sigma_3 applied")
CONFINING_STRESS_FELT_PA = Column("confining_stress_felt_pa", "Pa", "lateral stress the grains feel")
STRESS_RATIO = Column("stress_ratio", "1", "principal stress ratio sigma_1 / sigma_3")
STRESS_RATIO_MOBILISED = Column("stress_ratio_mobilised", "1", "(sigma_1 - sigma_3) / (sigma_1 + sigma_3)")

#: The biaxial test's records (grainlab.protocols.biaxial.records).
BIAXIAL = Columns(
    "biaxial",
    (STEP, TIME_S, AXIAL_STRAIN, AXIAL_STRESS_PA, CONFINING_PRESSURE_PA, CONFINING_STRESS_FELT_PA,
     STRESS_RATIO, STRESS_RATIO_MOBILISED, VOLUMETRIC_STRAIN, AREA_M2, HEIGHT_M),
    EVERY_TEST,
)

# ---- the oedometer's ---------------------------------------------------------------
VERTICAL_STRESS_PA = Column("vertical_stress_pa", "Pa", "vertical stress sigma_v on the platens")
HORIZONTAL_STRESS_PA = Column("horizontal_stress_pa", "Pa", "horizontal stress sigma_h on the fixed side walls")
LATERAL_STRESS_RATIO = Column("lateral_stress_ratio", "1", "K = sigma_h / sigma_v (K0 on first loading)")
TARGET_VERTICAL_STRESS_PA = Column("target_vertical_stress_pa", "Pa", "the load step's vertical stress")
MAX_VERTICAL_STRESS_PA = Column("max_vertical_stress_pa", "Pa", "largest vertical stress reached so far")
OVERCONSOLIDATION_RATIO = Column("overconsolidation_ratio", "1", "OCR = max sigma_v so far / sigma_v")
POROSITY = Column("porosity", "1", "porosity of the grains in the box")
VOID_RATIO = Column("void_ratio", "1", "void ratio e = n / (1 - n)")

#: The oedometer's records, one per load step at equilibrium (grainlab.protocols.oedometer).
OEDOMETER = Columns(
    "oedometer",
    (STEP, TIME_S, TARGET_VERTICAL_STRESS_PA, VERTICAL_STRESS_PA, HORIZONTAL_STRESS_PA, LATERAL_STRESS_RATIO,
     MAX_VERTICAL_STRESS_PA, OVERCONSOLIDATION_RATIO, AXIAL_STRAIN, VOLUMETRIC_STRAIN, POROSITY, VOID_RATIO,
     HEIGHT_M, AREA_M2),
    EVERY_TEST,
)

# ---- the cyclic biaxial test's ------------------------------------------------------
STRAIN_PATH = Column("strain_path", "1", "axial strain travelled since the start of cycling, whatever its direction")
CYCLE = Column("cycle", "1", "cycles done: strain_path / (4 x amplitude)")

#: The cyclic biaxial test's records (grainlab.protocols.cyclic): the biaxial test's and the path.
CYCLIC = Columns("cyclic", BIAXIAL.columns, (STRAIN_PATH, CYCLE))

# ---- the periodic simple-shear test's ------------------------------------------------
SHEAR_STRAIN = Column("shear_strain", "1", "shear strain gamma, the imposed shear rate integrated over time")
SHEAR_STRESS_PA = Column("shear_stress_pa", "Pa", "shear stress tau = -sigma_xy of the cell (contacts and kinetic)")
NORMAL_STRESS_PA = Column("normal_stress_pa", "Pa", "normal stress sigma_n = sigma_yy of the cell")
LATERAL_NORMAL_STRESS_PA = Column("lateral_stress_pa", "Pa", "sigma_xx of the cell")
FRICTION_COEFFICIENT = Column("friction_coefficient", "1", "effective friction mu = tau / sigma_n")
INERTIAL_NUMBER = Column("inertial_number", "1", "I = gamma_dot d / sqrt(sigma_n / rho), d the mean diameter")
CELL_TILT = Column("cell_tilt", "1", "the cell's tilt along x over its width, within [-1/2, 1/2] (remapped)")
KINETIC_STRESS_RATIO = Column("kinetic_stress_share", "1", "kinetic part of sigma_yy over sigma_yy")
RB_STRESS_RATIO = Column("rb_stress_ratio", "1", "q/p = (s1 - s2) / (s1 + s2) of the contact stress")
RB_PREDICTED = Column("rb_predicted_stress_ratio", "1", "Rothenburg-Bathurst: (a + a_n + a_t) projected, / 2")
RB_RESIDUAL = Column("rb_residual", "1", "rb_stress_ratio - rb_predicted_stress_ratio")

#: The periodic simple-shear test's records (grainlab.protocols.simple_shear).
SIMPLE_SHEAR = Columns(
    "simple_shear",
    (STEP, TIME_S, SHEAR_STRAIN, SHEAR_STRESS_PA, NORMAL_STRESS_PA, LATERAL_NORMAL_STRESS_PA, FRICTION_COEFFICIENT,
     INERTIAL_NUMBER, VOLUMETRIC_STRAIN, POROSITY, VOID_RATIO, AREA_M2, HEIGHT_M, CELL_TILT, KINETIC_STRESS_RATIO),
    EVERY_TEST,
    (RB_STRESS_RATIO, RB_PREDICTED, RB_RESIDUAL),
)

# ---- a cemented sample's, after its test's own -------------------------------------------
CEMENT_BONDS_BROKEN = Column("cement_bonds_broken", "1", "cement bonds broken since the end of the consolidation")

# ---- the unconfined compression test's ----------------------------------------------
LATERAL_STRAIN = Column("lateral_strain", "1", "lateral strain (W - W0) / W0 of the grains' width over the middle "
                        "half of the height, extension positive")
WIDTH_M = Column("width_m", "m", "the grains' width over the middle half of the height, max(x + r) - min(x - r)")
UCS_AXIAL_STRESS_PA = Column("axial_stress_pa", "Pa", "axial stress on the top platen over the sample's width")

#: The unconfined compression test's records (grainlab.protocols.ucs): a cemented sample's always.
UCS = Columns(
    "ucs",
    (STEP, TIME_S, AXIAL_STRAIN, UCS_AXIAL_STRESS_PA, LATERAL_STRAIN, WIDTH_M, HEIGHT_M, UNBALANCED_FORCE_RATIO),
    ENERGY,
    (CEMENT_BONDS_BROKEN,),
)

# ---- the Brazilian test's -----------------------------------------------------------
DISC_STRAIN = Column("axial_strain", "1", "the platens' displacement over the disc's diameter, delta / D")
PLATEN_DISPLACEMENT_M = Column("platen_displacement_m", "m", "delta = D - the distance between the platens, "
                               "the top platen's travel since the loading's start")
PLATEN_FORCE_N_PER_M = Column("platen_force_n_per_m", "N/m", "F, the mean of the two platens' normal forces (per m "
                              "of thickness), compression positive")
TENSILE_STRESS_PA = Column("tensile_stress_pa", "Pa", "the indirect tensile stress 2 F / (pi D t) at the disc's "
                           "centre, t = 1 m")

#: The Brazilian test's records (grainlab.protocols.brazilian): a cemented disc's always.
BRAZILIAN = Columns(
    "brazilian",
    (STEP, TIME_S, DISC_STRAIN, PLATEN_DISPLACEMENT_M, PLATEN_FORCE_N_PER_M, TENSILE_STRESS_PA,
     UNBALANCED_FORCE_RATIO),
    ENERGY,
    (CEMENT_BONDS_BROKEN,),
)

# ---- the crushing test's ----------------------------------------------------------
AGGLOMERATE = Column("agglomerate", "1", "the agglomerate crushed (0 .. crushing.agglomerates - 1)")
DIAMETER_M = Column("diameter_m", "m", "the agglomerate's diameter d")
AGGLOMERATE_PLATEN_DISPLACEMENT_M = Column("platen_displacement_m", "m", "the top platen's displacement "
                                           "since the agglomerate's start, down positive")
PLATEN_FORCE_N = Column("platen_force_n", "N", "force of the agglomerate on the top platen, N per m of thickness")
CHARACTERISTIC_STRESS_PA = Column("characteristic_stress_pa", "Pa", "F / (d t), the platen force over the "
                                  "diameter and the thickness t = 1 m")
FRAGMENTS = Column("fragments", "1", "the agglomerate's fragments: connected components of its intact bonds")
MAJOR_FRAGMENTS = Column("major_fragments", "1", "the fragments holding at least 0.1 of the agglomerate's solid area")
LARGEST_FRAGMENT = Column("largest_fragment_fraction", "1", "the largest fragment's share of the agglomerate's "
                          "solid area")

#: The crushing test's records (grainlab.protocols.crushing): every agglomerate's, one after the other.
CRUSHING = Columns(
    "crushing",
    (AGGLOMERATE, STEP, Column("time_s", "s", "simulated time since the agglomerate's start"), DIAMETER_M,
     Column("axial_strain", "1", "the platen's displacement over d, compression positive"),
     AGGLOMERATE_PLATEN_DISPLACEMENT_M,
     PLATEN_FORCE_N, CHARACTERISTIC_STRESS_PA,
     Column("cement_bonds_broken", "1", "the agglomerate's bonds broken since its start"), FRAGMENTS,
     MAJOR_FRAGMENTS, LARGEST_FRAGMENT, UNBALANCED_FORCE_RATIO),
    ENERGY,
)

#: Every test's columns, by the results file's ``kind``.

#: The column a cemented sample (``cement.bonds`` not ``none``) adds to the biaxial and
#: cyclic tests' records (docs/cemented.md).
CEMENTED = Columns("cemented", (CEMENT_BONDS_BROKEN,))

BY_KIND: dict[str, Columns] = {BIAXIAL.kind: BIAXIAL, OEDOMETER.kind: OEDOMETER, CYCLIC.kind: CYCLIC,
                               SIMPLE_SHEAR.kind: SIMPLE_SHEAR, CEMENTED.kind: CEMENTED, UCS.kind: UCS,
                               BRAZILIAN.kind: BRAZILIAN, CRUSHING.kind: CRUSHING}


_BLOCK = re.compile(
    r"(<!-- generated from python/grainlab/columns.py: (\w+) -->\n)(.*?)(<!-- end of generated block -->)", re.S
)


def update_markdown(text: str) -> str:
    """``text`` with each block ``<!-- generated from python/grainlab/columns.py: KIND -->``
    ... ``<!-- end of generated block -->`` made again from :data:`BY_KIND`'s table of KIND."""

    def table(match: re.Match[str]) -> str:
        kind = match.group(2)
        if kind not in BY_KIND:
            raise ValueError(f"a generated block names the test {kind!r}; known: {', '.join(sorted(BY_KIND))}")
        return match.group(1) + BY_KIND[kind].markdown_table() + "\n" + match.group(4)

    return _BLOCK.sub(table, text)


if __name__ == "__main__":  # python -m grainlab.columns docs/file-formats.md
    for name in sys.argv[1:]:
        page = Path(name)
        page.write_text(update_markdown(page.read_text(encoding="utf-8")), encoding="utf-8")
