r"""The band against the rest at equal contact number: is lambda more than a contact count?

:class:`BandContacts`: strata, pooled differences, AUCs and the cross-fitted
models: docs/analysis.md, "The band against the rest".

Example
-------
>>> import numpy as np
>>> lam = np.array([0.4, 0.3, 0.1, 0.2, 0.5, 0.1, 0.2, 0.6])
>>> n = np.array([2, 2, 2, 2, 3, 3, 3, 3])
>>> band = np.array([True, True, False, False, True, False, False, True])
>>> bc = BandContacts().compute(lam, n, band)
>>> round(bc.strata["2"]["difference"], 12), round(bc.strata["3"]["difference"], 12)
(0.2, 0.4)
>>> bc.auc_within
1.0
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis.band_fabric import roc_auc

__all__ = ["STRATA", "BandContacts"]

#: The contact-number strata: label, smallest n, largest n (None: no bound).
STRATA: tuple[tuple[str, int, int | None], ...] = (("2", 2, 2), ("3", 3, 3), ("4", 4, 4), ("5+", 5, None))
#: Contact-number classes of the logistic models: 0, 1, 2, 3, 4, >= 5.
_CLASSES = 6
#: Ridge penalty of the logistic fits (per coefficient, on the mean log-likelihood).
_RIDGE = 1e-4
#: Seed of the two-fold split (fixed: the same grains always give the same AUCs).
SPLIT_SEED = 20261203


def _stratum(counts: NDArray[np.int64], low: int, high: int | None) -> NDArray[np.bool_]:
    inside: NDArray[np.bool_] = counts >= low
    if high is not None:
        inside &= counts <= high
    return inside


def _design(lam: NDArray[np.float64], counts: NDArray[np.int64], with_lambda: bool) -> NDArray[np.float64]:
    """Columns: one indicator per contact class, then (with lambda) lambda times the
    indicator of each class n >= 2."""
    cls = np.minimum(counts, _CLASSES - 1)
    onehot: NDArray[np.float64] = (cls[:, None] == np.arange(_CLASSES)[None, :]).astype(np.float64)
    if not with_lambda:
        return onehot
    slopes = onehot[:, 2:] * np.where(np.isfinite(lam), lam, 0.0)[:, None]
    design: NDArray[np.float64] = np.hstack([onehot, slopes])
    return design


def _fit_logistic(x: NDArray[np.float64], y: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Coefficients of a logistic model of ``y`` on the columns of ``x`` (mean
    log-likelihood with a ridge penalty, L-BFGS-B with the exact gradient)."""
    target = y.astype(np.float64)
    m = max(1, x.shape[0])

    def loss(w: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        z = x @ w
        # log(1 + e^z) - y z, evaluated stably
        value = float(np.sum(np.logaddexp(0.0, z) - target * z)) / m + _RIDGE * float(w @ w)
        p = 0.5 * (1.0 + np.tanh(0.5 * z))
        grad = x.T @ (p - target) / m + 2.0 * _RIDGE * w
        return value, grad

    result = minimize(loss, np.zeros(x.shape[1]), jac=True, method="L-BFGS-B")
    return np.asarray(result.x, dtype=np.float64)


def cross_fitted_scores(x: NDArray[np.float64], y: NDArray[np.bool_], seed: int = SPLIT_SEED) -> NDArray[np.float64]:
    """(N,) linear scores of a logistic model of ``y`` on ``x``, each half of the rows
    (a random split, fixed ``seed``) scored by the model fitted on the other half."""
    n = x.shape[0]
    fold = np.zeros(n, dtype=bool)
    fold[np.random.default_rng(seed).permutation(n)[: n // 2]] = True
    scores = np.full(n, np.nan)
    for held in (fold, ~fold):
        train = ~held
        if train.sum() == 0 or held.sum() == 0:
            continue
        scores[held] = x[held] @ _fit_logistic(x[train], y[train])
    return scores


class BandContacts(Compute):
    """The band against the rest at equal contact number (docs/analysis.md).
    """

    def compute(self, stability_index: ArrayLike, n_contacts: ArrayLike, members: ArrayLike) -> BandContacts:
        """Measure the grains given (one entry per grain): their lambda (1 for 0/1
        contacts), their contacts as lambda counts them, and band membership."""
        lam = np.asarray(stability_index, dtype=np.float64)
        counts = np.asarray(n_contacts, dtype=np.int64)
        band = np.asarray(members, dtype=bool)
        n = lam.shape[0]
        for name, a in (("n_contacts", counts), ("members", band)):
            if a.shape != (n,):
                raise ValueError(f"{name}: expected {n} entries (one per grain), got shape {a.shape}")
        if np.any(counts < 0):
            raise ValueError("n_contacts: counts must be >= 0")
        strata: dict[str, dict[str, float]] = {}
        weight_sum = weighted = pairs = pair_auc = 0.0
        for label, low, high in STRATA:
            s = _stratum(counts, low, high) & np.isfinite(lam)
            n_in, n_out = int((s & band).sum()), int((s & ~band).sum())
            mean_in = float(lam[s & band].mean()) if n_in else math.nan
            mean_out = float(lam[s & ~band].mean()) if n_out else math.nan
            auc = roc_auc(lam[s], band[s]) if n_in and n_out else math.nan
            strata[label] = {"n_inside": n_in, "n_outside": n_out, "mean_inside": mean_in,
                             "mean_outside": mean_out, "difference": mean_in - mean_out, "auc_lambda": auc}
            if n_in and n_out:
                w = n_in * n_out / (n_in + n_out)
                weight_sum += w
                weighted += w * (mean_in - mean_out)
                pairs += n_in * n_out
                pair_auc += n_in * n_out * auc
        auc_contacts = auc_both = math.nan
        if band.any() and (~band).any():
            ok = np.isfinite(lam) | (counts < 2)
            auc_contacts = roc_auc(cross_fitted_scores(_design(lam[ok], counts[ok], False), band[ok]), band[ok])
            auc_both = roc_auc(cross_fitted_scores(_design(lam[ok], counts[ok], True), band[ok]), band[ok])
        self._store(
            strata=strata,
            stratified_difference=weighted / weight_sum if weight_sum else math.nan,
            auc_within=pair_auc / pairs if pairs else math.nan,
            auc_contacts=auc_contacts,
            auc_contacts_lambda=auc_both,
        )
        return self

    strata = Computed[dict[str, dict[str, float]]](
        "Per stratum label ('2', '3', '4', '5+'): n_inside, n_outside, mean_inside, "
        "mean_outside, difference (band minus rest mean lambda) and auc_lambda (lambda's ROC "
        "AUC for band membership within the stratum); NaN where a group is empty."
    )
    stratified_difference = Computed[float](
        "Band minus rest mean lambda at equal contact number (Mantel-Haenszel weights)."
    )
    auc_within = Computed[float](
        "lambda's ROC AUC for band membership among grains of equal contact number."
    )
    auc_contacts = Computed[float]("Out-of-sample ROC AUC of the contact number alone.")
    auc_contacts_lambda = Computed[float](
        "Out-of-sample ROC AUC of the contact number and lambda together."
    )

    @property
    def auc_gain(self) -> float:
        """What lambda adds: ``auc_contacts_lambda - auc_contacts``."""
        return self.auc_contacts_lambda - self.auc_contacts

    def summary(self) -> dict[str, Any]:
        """Every number, JSON-ready: ``stratum_<label>_<key>`` and the pooled values."""
        out: dict[str, Any] = {}
        for label, numbers in self.strata.items():
            for key, value in numbers.items():
                out[f"stratum_{label}_{key}"] = value
        out["stratified_lambda_difference"] = self.stratified_difference
        out["auc_lambda_within_contacts"] = self.auc_within
        out["auc_contacts"] = self.auc_contacts
        out["auc_contacts_lambda"] = self.auc_contacts_lambda
        out["auc_gain_lambda"] = self.auc_gain
        return out

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Mean lambda inside and outside the band per stratum (bars); returns the axes."""
        from grainlab import plot

        return plot.band_strata(self.strata, ax=ax, **kwargs)
