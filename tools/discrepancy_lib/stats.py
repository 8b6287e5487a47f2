"""Goodness of fit, where the misfit concentrates, held-out errors with
bootstrap uncertainty, information criteria."""
import math

import numpy as np
from scipy import stats as sps

# The baseline fits within the data's uncertainty when its chi-square is not
# rejected at this significance level (chi-square test, dof = N - k).
P_THRESHOLD = 0.01
BOOTSTRAP = 2000


def chi2_summary(z, k):
    n = len(z)
    chi2 = float(np.sum(z ** 2))
    dof = max(n - k, 1)
    return {"n": n, "k": k, "dof": dof, "chi2": chi2, "chi2_red": chi2 / dof,
            "p_value": float(sps.chi2.sf(chi2, dof)),
            "chi2_red_band_99": [float(sps.chi2.ppf(0.005, dof) / dof), float(sps.chi2.ppf(0.995, dof) / dof)]}


def concentration(z, rows, data):
    """Where the misfit sits: per observable, per third of the first condition's
    range, and the points with the largest normalized residuals."""
    total = float(np.sum(z ** 2)) or 1.0
    out = {"by_observable": [], "by_condition_range": [], "worst_points": []}
    for obs in data.observables():
        idx = [i for i, r in enumerate(rows) if r["observable"] == obs]
        if not idx:
            continue
        zz = z[idx]
        out["by_observable"].append({"observable": obs, "n": len(idx), "chi2_per_point": float(np.mean(zz ** 2)),
                                     "share": float(np.sum(zz ** 2) / total),
                                     "mean_residual": float(np.mean(zz))})
    c0 = np.array([r["cond"][0] for r in rows])
    edges = np.quantile(c0, [0, 1 / 3, 2 / 3, 1])
    for a, b in zip(edges[:-1], edges[1:]):
        idx = [i for i in range(len(rows)) if a <= c0[i] <= b and not (b < edges[-1] and c0[i] == b)]
        if not idx:
            continue
        out["by_condition_range"].append({"condition": data.conditions[0], "from": float(a), "to": float(b),
                                          "n": len(idx), "share": float(np.sum(z[idx] ** 2) / total),
                                          "chi2_per_point": float(np.mean(z[idx] ** 2))})
    order = np.argsort(-np.abs(z))[:5]
    for i in order:
        r = rows[i]
        out["worst_points"].append({"observable": r["observable"],
                                    "condition": dict(zip(data.conditions, r["cond"])),
                                    "value": r["value"], "sigma": r["sigma"], "z": float(z[i]),
                                    "share": float(z[i] ** 2 / total)})
    n20 = max(1, int(math.ceil(0.2 * len(z))))
    out["share_of_worst_20pct"] = float(np.sum(np.sort(z ** 2)[::-1][:n20]) / total)
    return out


def rms(z):
    return float(math.sqrt(np.mean(z ** 2)))


def bootstrap_indices(n, seed):
    rng = np.random.default_rng(seed)
    return rng.integers(0, n, size=(BOOTSTRAP, n))


def information_criteria(chi2, k, n):
    """Gaussian likelihood with known uncertainties: -2 ln L = chi2 + const."""
    return {"aic": chi2 + 2 * k, "bic": chi2 + k * math.log(max(n, 1))}


def kfold(n, folds, repeats, seed, strata=None):
    """Repeated, stratified k-fold partitions of n rows: for every repeat (its
    own seeded shuffle) a list of `folds` held-out index lists; each stratum
    (e.g. each observable) is dealt round-robin over the folds after the
    shuffle, so every fold holds all observables where possible and every row
    is held out exactly once per repeat. Folds that would be empty are dropped."""
    strata = strata if strata is not None else [0] * n
    out = []
    for rep in range(repeats):
        rng = np.random.default_rng([seed, rep])
        held = [[] for _ in range(folds)]
        offset = int(rng.integers(folds))
        for s in dict.fromkeys(strata):
            idx = [i for i in range(n) if strata[i] == s]
            for j, i in enumerate(rng.permutation(idx)):
                held[(j + offset) % folds].append(int(i))
            offset = (offset + len(idx)) % folds
        out.append([sorted(h) for h in held if h])
    return out


def bootstrap_gain(loss_num, loss_den, idx):
    """Ratio of the rms of two per-row losses (mean squared out-of-fold
    residuals), sqrt(mean num / mean den), with its paired bootstrap over the
    rows (the same resamples for every model)."""
    point = math.sqrt(np.mean(loss_num) / max(np.mean(loss_den), 1e-300))
    boots = np.sqrt(np.mean(loss_num[idx], axis=1) / np.maximum(np.mean(loss_den[idx], axis=1), 1e-300))
    return {"ratio": point, "ci68": [float(np.percentile(boots, 16)), float(np.percentile(boots, 84))],
            "ci90": [float(np.percentile(boots, 5)), float(np.percentile(boots, 95))],
            "std": float(np.std(boots)), "p_greater_than_1": float(np.mean(boots > 1.0))}
