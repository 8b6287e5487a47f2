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


def heldout_summary(z, idx):
    """RMS of the normalized held-out residuals and its bootstrap spread."""
    boots = np.sqrt(np.mean(z[idx] ** 2, axis=1))
    return {"rms": rms(z), "rms_std": float(np.std(boots)),
            "rms_ci68": [float(np.percentile(boots, 16)), float(np.percentile(boots, 84))]}, boots


def ratio_summary(b_num, b_den, point):
    r = b_num / np.maximum(b_den, 1e-300)
    return {"ratio": point, "ci68": [float(np.percentile(r, 16)), float(np.percentile(r, 84))],
            "ci90": [float(np.percentile(r, 5)), float(np.percentile(r, 95))],
            "std": float(np.std(r)), "p_greater_than_1": float(np.mean(r > 1.0))}


def information_criteria(chi2, k, n):
    """Gaussian likelihood with known uncertainties: -2 ln L = chi2 + const."""
    return {"aic": chi2 + 2 * k, "bic": chi2 + k * math.log(max(n, 1))}


def split(n, fraction, seed, strata=None):
    """Seeded train/held-out split of n rows; with strata, each stratum (e.g.
    each observable) is split on its own so all are represented on both sides."""
    rng = np.random.default_rng(seed)
    strata = strata if strata is not None else [0] * n
    held = []
    for s in dict.fromkeys(strata):
        idx = [i for i in range(n) if strata[i] == s]
        m = int(round(fraction * len(idx)))
        if len(idx) >= 3:
            m = min(max(m, 1), len(idx) - 2)
        else:
            m = 0
        held += list(rng.choice(idx, size=m, replace=False))
    held = sorted(int(i) for i in held)
    train = [i for i in range(n) if i not in set(held)]
    return train, held
