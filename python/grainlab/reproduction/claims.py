"""Every claim of the paper (Secs. 6-8), what is measured for it on each seed,
and the rule that judges it (:mod:`.verdicts`).

The claims and their tolerances, fixed before any run: docs/reproduction.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from grainlab import paper
from grainlab._html import number
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO
from grainlab.reproduction.measures import END_WINDOW, correlation, relative_slope
from grainlab.reproduction.verdicts import ProportionRule, SideRule, ValueRule

__all__ = ["BIAXIAL_CLAIMS", "RATE_CLAIMS", "STUDY_CLAIMS", "Claim", "band_measure", "evaluate", "single_run_rows"]

Measures = Mapping[str, Any]
Rule = ValueRule | SideRule | ProportionRule


@dataclass(frozen=True)
class Claim:
    """One claim of the paper and how it is checked."""

    id: str
    #: The paper's statement (paraphrased closely; quoted where short).
    statement: str
    #: Where in the paper.
    source: str
    #: The paper's number (fractions, SI), or None when it states no number.
    paper_value: float | None
    #: What is measured on each seed.
    measure: str
    rule: Rule
    extract: Callable[[Measures], float]

    def row(self, per_seed: Sequence[float], seeds: Sequence[int], variant: str) -> dict[str, Any]:
        """The claim's row of ``claims.json``."""
        judgement = self.rule.judge(per_seed)
        return {
            "id": self.id,
            "statement": self.statement,
            "source": self.source,
            "paper_value": self.paper_value,
            "measure": self.measure,
            "mean": judgement.mean,
            "ci95": list(judgement.ci95),
            "n": judgement.n,
            "per_seed": [None if not math.isfinite(v) else v for v in per_seed],
            "seeds": list(seeds),
            "test": self.rule.test,
            "rule": self.rule.to_dict(),
            "p_value": judgement.p_value,
            "verdict": judgement.verdict,
            "reason": judgement.reason,
            "variant": variant,
        }


def evaluate(claims: Sequence[Claim], measures: Sequence[Measures | None], seeds: Sequence[int],
             variant: str) -> list[dict[str, Any]]:
    """One row per claim; a seed without measures (its run failed) gives NaN."""
    return [claim.row([_extracted(claim, m) for m in measures], seeds, variant) for claim in claims]


def _extracted(claim: Claim, measures: Measures | None) -> float:
    """The claim's value in ``measures``; NaN without measures or the numbers it reads."""
    try:
        return float(claim.extract(measures)) if measures is not None else math.nan
    except (KeyError, IndexError, TypeError, ValueError, ZeroDivisionError):
        return math.nan


def _one_run(rule: Rule, value: float) -> str:
    """Whether one run's value lies where the rule wants the ensemble's interval."""
    if not math.isfinite(value):
        return "no value"
    if isinstance(rule, ValueRule):
        inside = rule.low <= value <= rule.high
    elif isinstance(rule, SideRule):
        inside = rule.sign * (value - rule.reference) > 0
    else:
        inside = value == 1.0
    return "as the paper" if inside else "not as the paper"


def single_run_rows(measures: Measures, claims: Sequence[Claim] = ()) -> list[dict[str, Any]]:
    """Each claim on one run: its value and whether it lies where the claim's rule
    wants the ensemble's interval (a tolerance band, a side of a reference, an
    event that happens). One run is not a verdict: ``grainlab reproduce`` is."""
    rows = []
    for claim in claims or BIAXIAL_CLAIMS:
        value = _extracted(claim, measures)
        rows.append({"id": claim.id, "statement": claim.statement, "source": claim.source,
                     "paper_value": claim.paper_value, "measure": claim.measure, "value": value,
                     "rule": claim.rule.to_dict(), "this_run": _one_run(claim.rule, value)})
    return rows


# ----------------------------------------------------------------------------- biaxial helpers
def _snaps(m: Measures) -> list[Mapping[str, Any]]:
    snapshots: list[Mapping[str, Any]] = m["snapshots"]
    return snapshots


def _initial(m: Measures) -> Mapping[str, Any]:
    return _snaps(m)[0]


def _final(m: Measures) -> Mapping[str, Any]:
    return _snaps(m)[-1]


def _peak(m: Measures) -> Mapping[str, Any]:
    return _snaps(m)[m["peak_snapshot"]]


def _at(m: Measures, strain: float, tolerance: float = 0.001) -> Mapping[str, Any]:
    """The snapshot within ``tolerance`` of ``strain`` (KeyError when there is none)."""
    rows = _snaps(m)
    best = min(rows, key=lambda r: abs(number(r[AXIAL_STRAIN]) - strain))
    if abs(number(best[AXIAL_STRAIN]) - strain) > tolerance:
        raise KeyError(f"no snapshot at {strain}")
    return best


def band_measure(row: Mapping[str, Any], key: str) -> float:
    """A band measure of a snapshot: the band's grains (the band accepted at the
    snapshot, or else the first accepted after it, matched by id) against the
    rest; NaN when no band is accepted at or after the snapshot."""
    return number(row.get(key)) if row.get("band_members_known", row.get("band_found")) else math.nan


def _band_share(row: Mapping[str, Any]) -> float:
    """Share of the grains inside the band accepted at this snapshot itself (NaN
    when none is)."""
    if not row.get("band_found"):
        return math.nan
    inside, outside = number(row.get("inside_n_grains")), number(row.get("outside_n_grains"))
    return inside / (inside + outside)


def _series(m: Measures, key: str) -> tuple[np.ndarray, np.ndarray]:
    rows = _snaps(m)
    return (np.array([number(r[AXIAL_STRAIN]) for r in rows]), np.array([number(r.get(key)) for r in rows]))


def _end_slope(m: Measures, key: str) -> float:
    eps, y = _series(m, key)
    start = max(number(_peak(m)[AXIAL_STRAIN]), (1.0 - END_WINDOW) * float(np.nanmax(eps)))
    use = eps >= start - 1e-9
    return relative_slope(eps[use], y[use]) if use.sum() >= 2 else math.nan


def _correlation(m: Measures, a: str, b: str) -> float:
    return correlation(_series(m, a)[1], _series(m, b)[1])


def _strain_of_max(m: Measures, key: str) -> float:
    eps, y = _series(m, key)
    return float(eps[int(np.nanargmax(y))])


def _found(row: Mapping[str, Any]) -> float:
    return 1.0 if row.get("band_found") else 0.0


_EQUAL_N = "Sec. 6, Fig. 13, read at equal contact number"


def _stratum_claim(label: str) -> Claim:
    return Claim(
        f"band_lambda_above_rest_n{label.replace('+', 'plus')}",
        f"band lambda above the rest's among grains with {label} contacts", _EQUAL_N, None,
        f"band minus rest mean lambda of the grains with {label} contacts (as lambda counts them) at the "
        "peak snapshot, paired per seed", SideRule(+1),
        lambda m: band_measure(_peak(m), f"stratum_{label}_difference"))


#: The band against the rest at equal contact number, and what lambda adds to the contact
#: number (grainlab.analysis.band_contacts): the paper's band claim with the contact count held
#: fixed, which tells a new fabric quantity from a proxy of Z and of the rattlers.
_STRATA_CLAIMS: tuple[Claim, ...] = (
    Claim("band_lambda_above_rest_at_equal_contacts", "band lambda above the rest's at equal contact number",
          _EQUAL_N, None, "band minus rest mean lambda within the strata n = 2, 3, 4, >= 5, pooled with "
          "Mantel-Haenszel weights, at the peak snapshot, paired per seed", SideRule(+1),
          lambda m: band_measure(_peak(m), "stratified_lambda_difference")),
    *(_stratum_claim(label) for label in ("2", "3", "4", "5+")),
    Claim("lambda_locates_band_at_equal_contacts", "lambda tells band grains from the rest among grains with "
          "the same number of contacts", _EQUAL_N, None, "ROC AUC of lambda for band membership within the "
          "strata, pooled over band-rest pairs, at the peak snapshot", SideRule(+1, 0.5),
          lambda m: band_measure(_peak(m), "auc_lambda_within_contacts")),
    Claim("contacts_locate_band", "the contact number alone tells band grains from the rest (the reference "
          "of the next claim)", "Sec. 7", None, "out-of-sample ROC AUC of a logistic model of band membership "
          "on the contact-number class (0, 1, 2, 3, 4, >= 5), every grain, at the peak snapshot",
          SideRule(+1, 0.5), lambda m: band_measure(_peak(m), "auc_contacts")),
    Claim("lambda_adds_to_contacts", "lambda adds to the contact number in telling band grains from the rest",
          _EQUAL_N, None, "out-of-sample ROC AUC of the contact-number model with lambda (its own slope per "
          "class n >= 2) minus without, every grain, at the peak snapshot, paired per seed", SideRule(+1),
          lambda m: band_measure(_peak(m), "auc_gain_lambda")),
)

_LAMBDA_BAND = "the library's mean over grains with >= 2 contacts"
_LAMBDA_ALL = "the mean over every grain, 0- and 1-contact grains at lambda = 1"

#: The claims of the biaxial test (Sec. 6, Sec. 7's reading of it, Sec. 8).
BIAXIAL_CLAIMS: tuple[Claim, ...] = (
    Claim("stress_ratio_linear_to_0.5", "the stress ratio rises linearly (\"seems to be linear elastic\") "
          "until 0.5 % axial strain", "Sec. 6, Fig. 8", None,
          "R^2 of a straight line through the stress-ratio records from 0 to 0.5 %",
          SideRule(+1, 0.98), lambda m: m["macro"]["linear_r2"]),
    Claim("peak_near_1.5", "hardening from 0.5 % to the peak stress ratio at 1.5 % axial strain",
          "Sec. 6, Figs. 8, 11", paper.STRAIN_AT_PEAK, "axial strain at the largest stress ratio (fraction)",
          ValueRule(0.010, 0.020), lambda m: m["macro"]["peak_axial_strain"]),
    Claim("softening_after_peak", "after the peak the critical state: a brittle failure, the stress ratio "
          "falls from its peak", "Sec. 6, Fig. 8; Abstract", None,
          "mean stress ratio over the end window minus the peak stress ratio",
          SideRule(-1), lambda m: m["macro"]["residual_stress_ratio"] - m["macro"]["peak_stress_ratio"]),
    Claim("stress_ratio_constant_at_end", "from 1.5 % onward the critical state: the stress ratio is constant",
          "Sec. 6, Fig. 8", None, "relative change of the stress ratio per 1 % axial strain over the end window",
          ValueRule(-0.02, 0.02), lambda m: m["macro"]["residual_relative_slope"]),
    Claim("contraction_first", "the sample contracts first", "Sec. 7, Fig. 18", None,
          "largest volumetric strain (compression positive)", SideRule(+1),
          lambda m: m["macro"]["max_contraction"]),
    Claim("dilation_after", "then dilates", "Sec. 7, Fig. 18", None,
          "volumetric strain at the end of the test (compression positive)", SideRule(-1),
          lambda m: m["macro"]["final_volumetric_strain"]),
    Claim("a_isotropic", "contact-normal anisotropy at the isotropic state a = 0.0034", "Sec. 6, Fig. 6", paper.A_ISOTROPIC,
          "a of the snapshot at 0 % (the library's headline anisotropy)", ValueRule(0.0, 0.0068),
          lambda m: _initial(m)["a"]),
    Claim("a_n_isotropic", "normal-force anisotropy at the isotropic state a_n = 0.009", "Sec. 6, Fig. 7", paper.A_N_ISOTROPIC,
          "a_n of the snapshot at 0 %", ValueRule(0.0, 0.018), lambda m: _initial(m)["a_n"]),
    Claim("a_at_0.5", "the fabric anisotropy increases rapidly to around 0.18 at 0.5 %", "Sec. 6, Fig. 9", paper.A_AT_HALF_PERCENT,
          "a of the snapshot at 0.5 %", ValueRule(0.135, 0.225), lambda m: _at(m, 0.005)["a"]),
    Claim("a_largest_at_peak", "the strain of the largest fabric anisotropy is almost that of the peak "
          "stress ratio", "Sec. 6, Figs. 8, 9", 0.0,
          "strain of the snapshot with the largest a minus the strain of the peak stress ratio",
          ValueRule(-0.005, 0.005), lambda m: _strain_of_max(m, "a") - m["macro"]["peak_axial_strain"]),
    Claim("a_falls_after_peak", "after the peak the fabric anisotropy decreases significantly", "Sec. 6, Fig. 9",
          None, "a at the end minus the largest a", SideRule(-1),
          lambda m: _final(m)["a"] - float(np.nanmax(_series(m, "a")[1]))),
    Claim("a_constant_at_end", "and reaches a constant value (critical state)", "Sec. 6, Fig. 9", None,
          "relative change of a per 1 % axial strain over the end window", ValueRule(-0.02, 0.02),
          lambda m: _end_slope(m, "a")),
    Claim("z_initial", "the coordination number is around 3.9 at 0 %", "Sec. 6, Fig. 10", paper.Z_INITIAL,
          "grain-grain coordination number Z = 2 Nc / Np of the snapshot at 0 %", ValueRule(3.7, 4.1),
          lambda m: _initial(m)["coordination_number"]),
    Claim("z_at_peak", "and around 3.0 at the peak strength", "Sec. 6, Fig. 10", paper.Z_AT_PEAK,
          "Z of the snapshot nearest the peak", ValueRule(2.8, 3.2), lambda m: _peak(m)["coordination_number"]),
    Claim("z_initial_mechanical", "the same, read as the mechanical coordination number (rattlers removed)",
          "Sec. 6, Fig. 10", paper.Z_INITIAL, "mechanical coordination number Z_m (grains with fewer than 2 "
          "contacts removed until none is left) of the snapshot at 0 %", ValueRule(3.7, 4.1),
          lambda m: _initial(m)["mechanical_coordination_number"]),
    Claim("z_at_peak_mechanical", "around 3.0 at the peak, read as the mechanical coordination number",
          "Sec. 6, Fig. 10", paper.Z_AT_PEAK, "Z_m of the snapshot nearest the peak", ValueRule(2.8, 3.2),
          lambda m: _peak(m)["mechanical_coordination_number"]),
    Claim("z_constant_after_peak", "from the peak onward the coordination number is constant", "Sec. 6, Fig. 10",
          0.0, "(Z at the end - Z at the peak) / Z at the peak", ValueRule(-0.05, 0.05),
          lambda m: _final(m)["coordination_number"] / _peak(m)["coordination_number"] - 1.0),
    Claim("band_at_0.5", "a discontinuity (band) is already developing at 0.5 %", "Sec. 6, Figs. 11a, 12b", None,
          "1 when the shear-band detector accepts a band at the 0.5 % snapshot, else 0", ProportionRule(),
          lambda m: _found(_at(m, 0.005))),
    Claim("band_at_peak", "the shear band is fully developed at the peak", "Sec. 6, Fig. 11d", None,
          "1 when the detector accepts a band at the snapshot nearest the peak, else 0", ProportionRule(),
          lambda m: _found(_peak(m))),
    Claim("band_narrows_to_peak", "the zone narrows as the stress ratio increases, to the shear plane at the "
          "peak", "Sec. 6, Figs. 11a-d", None,
          "share of the grains inside the band at the peak minus at 0.5 %, paired per seed (seeds with a band "
          "at both)", SideRule(-1), lambda m: _band_share(_peak(m)) - _band_share(_at(m, 0.005))),
    Claim("band_readings_agree", "the band of the displacement map (Fig. 11) and of lambda > 0.5 (Fig. 12) is the "
          "band of the strain field: the figures show one band", "Sec. 6, Figs. 11-12", None,
          "Jaccard overlap |A & B| / |A | B| of the reading's band grains with the local-strain band's at the "
          "peak snapshot (a band: reading's variant; none for the strain reading itself); most shared: above 0.5",
          SideRule(+1, 0.5), lambda m: number(_peak(m).get("band_overlap_with_strain"))),
    Claim("band_readings_agree_at_end", "the same at the end of the test (10 %)", "Sec. 6, Figs. 11-12", None,
          "the same overlap at the last snapshot", SideRule(+1, 0.5),
          lambda m: number(_final(m).get("band_overlap_with_strain"))),
    Claim("band_lambda_above_rest", "mean lambda in the shear zone at the peak (0.34) above the rest (0.31)",
          "Sec. 6, Fig. 13", 0.03, f"band minus rest at the peak snapshot, paired per seed; {_LAMBDA_BAND}",
          SideRule(+1), lambda m: band_measure(_peak(m), "inside_mean_lambda") - band_measure(_peak(m), "outside_mean_lambda")),
    Claim("band_lambda_above_rest_all", "the same, lambda averaged over every grain", "Sec. 6, Fig. 13", 0.03,
          f"band minus rest at the peak snapshot, paired per seed; {_LAMBDA_ALL}", SideRule(+1),
          lambda m: band_measure(_peak(m), "inside_mean_lambda_all") - band_measure(_peak(m), "outside_mean_lambda_all")),
    Claim("band_lambda_above_rest_at_end", "the same at the end of the test (10 %)", "Sec. 6, Figs. 12, 13", 0.03,
          f"band minus rest at the last snapshot, paired per seed; {_LAMBDA_BAND}", SideRule(+1),
          lambda m: band_measure(_final(m), "inside_mean_lambda") - band_measure(_final(m), "outside_mean_lambda")),
    Claim("band_lambda_above_rest_all_at_end", "the same at the end of the test, every grain", "Sec. 6, Figs. 12, 13",
          0.03, f"band minus rest at the last snapshot, paired per seed; {_LAMBDA_ALL}", SideRule(+1),
          lambda m: band_measure(_final(m), "inside_mean_lambda_all")
          - band_measure(_final(m), "outside_mean_lambda_all")),
    *_STRATA_CLAIMS,
    Claim("band_lambda_0.34", "mean lambda in the shear zone at the peak is 0.34", "Sec. 6", paper.LAMBDA_IN_BAND,
          f"band mean at the peak snapshot; {_LAMBDA_BAND}", ValueRule(0.325, 0.355),
          lambda m: band_measure(_peak(m), "inside_mean_lambda")),
    Claim("rest_lambda_0.31", "mean lambda in the rest of the sample at the peak is 0.31", "Sec. 6", paper.LAMBDA_OUTSIDE_BAND,
          f"rest mean at the peak snapshot; {_LAMBDA_BAND}", ValueRule(0.295, 0.325),
          lambda m: band_measure(_peak(m), "outside_mean_lambda")),
    Claim("band_lambda_0.34_all", "mean lambda in the shear zone at the peak is 0.34 (every grain)", "Sec. 6", paper.LAMBDA_IN_BAND,
          f"band mean at the peak snapshot; {_LAMBDA_ALL}", ValueRule(0.325, 0.355),
          lambda m: band_measure(_peak(m), "inside_mean_lambda_all")),
    Claim("rest_lambda_0.31_all", "mean lambda in the rest at the peak is 0.31 (every grain)", "Sec. 6", paper.LAMBDA_OUTSIDE_BAND,
          f"rest mean at the peak snapshot; {_LAMBDA_ALL}", ValueRule(0.295, 0.325),
          lambda m: band_measure(_peak(m), "outside_mean_lambda_all")),
    Claim("band_mostly_two_contacts", "most grains in the shear band have two contacts at 1.5 % (0- and "
          "1-contact grains filtered out)", "Sec. 6, Fig. 13a", None,
          "share of the band's grains with >= 2 contacts that have exactly 2, at the 1.5 % snapshot",
          SideRule(+1, 0.5), lambda m: band_measure(_at(m, 0.015), "inside_fraction_2_of_load_bearing")),
    Claim("rest_three_or_more", "the rest of the grains have at least three contacts", "Sec. 6, Fig. 13b", None,
          "share of the other grains with >= 2 contacts that have >= 3, at the 1.5 % snapshot",
          SideRule(+1, 0.5), lambda m: band_measure(_at(m, 0.015), "outside_fraction_3_or_more_of_load_bearing")),
    Claim("band_more_two_contact_grains", "two-contact grains are more common in the band than in the rest",
          "Sec. 6, Fig. 13", None, "share of 2-contact grains (of those with >= 2) band minus rest at 1.5 %, "
          "paired per seed", SideRule(+1),
          lambda m: band_measure(_at(m, 0.015), "inside_fraction_2_of_load_bearing")
          - band_measure(_at(m, 0.015), "outside_fraction_2_of_load_bearing")),
    Claim("band_lambda_above_half", "the shear zone is represented by grains with lambda above 0.5",
          "Sec. 6, Fig. 12", 0.5, "share of grains with lambda > 0.5, band minus rest at the peak snapshot, "
          "paired per seed (every grain)", SideRule(+1),
          lambda m: band_measure(_peak(m), "inside_fraction_lambda_above_half")
          - band_measure(_peak(m), "outside_fraction_lambda_above_half")),
    Claim("rest_less_stable", "the remainder of the sample also becomes less stable", "Sec. 6, Fig. 12", None,
          f"rest mean lambda at the peak minus the sample's at 0 %; {_LAMBDA_BAND}", SideRule(+1),
          lambda m: band_measure(_peak(m), "outside_mean_lambda") - _initial(m)["mean_lambda"]),
    Claim("band_rotation_larger", "grains rotate more in the shear band than in the rest (turbulent shear)",
          "Sec. 6 (after Cheung and O'Sullivan; Wu et al.)", None,
          "mean |rotation| since 0 %, band minus rest at the peak snapshot, paired per seed", SideRule(+1),
          lambda m: band_measure(_peak(m), "inside_mean_abs_rotation_rad") - band_measure(_peak(m), "outside_mean_abs_rotation_rad")),
    Claim("band_z_below_rest", "the shear zone coincides with the smallest coordination number",
          "Sec. 7", None, "grain-grain contacts per grain, band minus rest at the peak snapshot, paired per seed",
          SideRule(-1),
          lambda m: band_measure(_peak(m), "inside_coordination_number") - band_measure(_peak(m), "outside_coordination_number")),
    Claim("lambda_locates_band", "lambda at particle level shows the shear band (Fig. 12)", "Sec. 6, Fig. 12; "
          "Sec. 7", None, "ROC AUC of per-grain lambda for band membership at the peak snapshot (every grain)",
          SideRule(+1, 0.6), lambda m: band_measure(_peak(m), "auc_lambda")),
    Claim("lambda_field_locates_band", "the lambda field shows the shear band", "Sec. 6, Fig. 12", None,
          "ROC AUC of lambda averaged over 2 mean diameters for band membership at the peak snapshot",
          SideRule(+1, 0.6), lambda m: band_measure(_peak(m), "auc_lambda_field")),
    Claim("lambda_marks_band_at_0.5", "at 0.5 % lambda already shows a discontinuity surrounded by more "
          "stable grains", "Sec. 6, Fig. 12b", None,
          "ROC AUC of per-grain lambda at the 0.5 % snapshot for the grains of the band found at the peak",
          SideRule(+1, 0.5), lambda m: number(_at(m, 0.005)["auc_lambda_peak_band"])),
    Claim("initial_lambda_random", "the sample starts with randomly distributed stability indices, no "
          "discontinuity", "Sec. 6, Fig. 12a", 0.5,
          "ROC AUC of per-grain lambda at 0 % for the grains of the band found at the peak",
          ValueRule(0.4, 0.6), lambda m: number(_initial(m)["auc_lambda_peak_band"])),
    Claim("initial_lambda_above_zero", "an irregular packing starts with a mean lambda above zero", "Sec. 8", None,
          f"mean lambda at 0 %; {_LAMBDA_BAND}", SideRule(+1), lambda m: _initial(m)["mean_lambda"]),
    Claim("lambda_rises_to_peak", "mean lambda increases up to the peak stress ratio", "Sec. 6, Fig. 14; Sec. 8",
          None, f"mean lambda at the peak snapshot minus at 0 %; {_LAMBDA_BAND}", SideRule(+1),
          lambda m: _peak(m)["mean_lambda"] - _initial(m)["mean_lambda"]),
    Claim("lambda_rises_to_peak_all", "the same, every grain", "Sec. 6, Fig. 14", None,
          f"mean lambda at the peak snapshot minus at 0 %; {_LAMBDA_ALL}", SideRule(+1),
          lambda m: _peak(m)["mean_lambda_all"] - _initial(m)["mean_lambda_all"]),
    Claim("lambda_falls_after_peak", "then reduces", "Sec. 6, Fig. 14; Sec. 8", None,
          f"mean lambda at the end minus at the peak snapshot; {_LAMBDA_BAND}", SideRule(-1),
          lambda m: _final(m)["mean_lambda"] - _peak(m)["mean_lambda"]),
    Claim("lambda_falls_after_peak_all", "the same, every grain", "Sec. 6, Fig. 14", None,
          f"mean lambda at the end minus at the peak snapshot; {_LAMBDA_ALL}", SideRule(-1),
          lambda m: _final(m)["mean_lambda_all"] - _peak(m)["mean_lambda_all"]),
    Claim("lambda_constant_at_end", "to a constant value at the critical state", "Sec. 6, Fig. 14; Sec. 8", None,
          f"relative change of mean lambda per 1 % axial strain over the end window; {_LAMBDA_BAND}",
          ValueRule(-0.02, 0.02), lambda m: _end_slope(m, "mean_lambda")),
    Claim("lambda_tracks_stress_ratio", "the trend of mean lambda agrees with that of the stress ratio",
          "Sec. 6, Figs. 8, 14", None, "Pearson r of mean lambda and the stress ratio over the snapshots",
          SideRule(+1), lambda m: _correlation(m, "mean_lambda", STRESS_RATIO)),
    Claim("lambda_tracks_anisotropy", "and with that of the fabric anisotropy", "Sec. 6, Figs. 9, 14; Sec. 7",
          None, "Pearson r of mean lambda and a over the snapshots", SideRule(+1),
          lambda m: _correlation(m, "mean_lambda", "a")),
    Claim("lambda_tracks_coordination", "mean lambda is related to the coordination number: fewer contacts, "
          "less stable", "Sec. 7, Fig. 15; Sec. 8", None,
          "Pearson r of mean lambda and Z over the snapshots", SideRule(-1),
          lambda m: _correlation(m, "mean_lambda", "coordination_number")),
)


# ----------------------------------------------------------------------------- the packing study
def _fit(s: Measures, name: str, key: str) -> float:
    return number(s[name][key])


#: The claims of the packing study (Sec. 7, Figs. 15-17), one value per seed's 19 packings.
STUDY_CLAIMS: tuple[Claim, ...] = (
    Claim("lambda_falls_with_z_irregular", "more contacts per particle, more stable (lower lambda): "
          "irregular packings", "Sec. 7, Fig. 15", None, "slope of mean lambda against Z over the irregular "
          "packings", SideRule(-1), lambda s: _fit(s, "lambda_vs_z_irregular", "slope")),
    Claim("lambda_falls_with_z_hexagonal", "the same for hexagonal packings", "Sec. 7, Fig. 15", None,
          "slope of mean lambda against Z over the hexagonal packings", SideRule(-1),
          lambda s: _fit(s, "lambda_vs_z_hexagonal", "slope")),
    Claim("hexagonal_more_stable_at_z", "hexagonal packing gives the lowest lambda for a given Z",
          "Sec. 7, Fig. 15", None, "mean over the hexagonal packings inside the irregular packings' Z range of "
          "their lambda minus the irregular fit's at their Z (NaN when none is inside)", SideRule(-1),
          lambda s: s["hexagonal_minus_irregular_at_z"]),
    Claim("hexagonal_more_stable", "hexagonal packings are more stable than irregular ones",
          "Sec. 7, Figs. 15, 16; Sec. 8", None, "mean lambda of the hexagonal packings minus the irregular ones'",
          SideRule(-1), lambda s: s["hexagonal_minus_irregular_mean"]),
    Claim("hexagonal_more_stable_at_porosity", "hexagonal packing is more stable for a given porosity",
          "Sec. 7, Fig. 16", None, "mean over the shared target porosities of hexagonal minus irregular lambda",
          SideRule(-1), lambda s: s["hexagonal_minus_irregular_at_porosity"]),
    Claim("lambda_porosity_less_defined", "the relation of lambda with porosity is less well defined than "
          "with Z", "Sec. 7, Fig. 16", None,
          "R^2 of lambda on porosity minus R^2 of lambda on Z, irregular packings", SideRule(-1),
          lambda s: _fit(s, "lambda_vs_porosity_irregular", "r2") - _fit(s, "lambda_vs_z_irregular", "r2")),
    Claim("lambda_linear_in_a", "the fabric anisotropy is linearly related to mean lambda", "Sec. 7, Fig. 17",
          None, "R^2 of mean lambda on a over all packings", SideRule(+1, 0.8),
          lambda s: _fit(s, "lambda_vs_a_pooled", "r2")),
    Claim("lambda_rises_with_a", "lambda and anisotropy rise together (Figs. 9, 14, 17)", "Sec. 7, Fig. 17",
          None, "slope of mean lambda on a over all packings", SideRule(+1),
          lambda s: _fit(s, "lambda_vs_a_pooled", "slope")),
)


#: Claims on a family of strain rates: ``m`` holds the fastest and slowest rates' measures.
RATE_CLAIMS: tuple[Claim, ...] = (
    Claim("rate_raises_peak", "the bigger the strain rate, the higher the peak stress", "Sec. 7, Fig. 18", None,
          "peak stress ratio at the fastest rate minus at the slowest, paired per seed", SideRule(+1),
          lambda m: m["fast"]["macro"]["peak_stress_ratio"] - m["slow"]["macro"]["peak_stress_ratio"]),
    Claim("rate_raises_residual", "and the higher the residual stress", "Sec. 7, Fig. 18", None,
          "end-window stress ratio at the fastest rate minus at the slowest, paired per seed", SideRule(+1),
          lambda m: m["fast"]["macro"]["residual_stress_ratio"] - m["slow"]["macro"]["residual_stress_ratio"]),
)
