"""Variants of the model (the baseline or the baseline plus one candidate
extension), their predictions, and the bounded robust fit of their free
parameters."""
import itertools
import math

import numpy as np
from scipy.optimize import least_squares

# Robust loss: residuals are in units of the data's uncertainty; beyond
# F_SCALE standard deviations a point's pull grows only linearly (soft_l1).
LOSS = "soft_l1"
F_SCALE = 2.0
# Start points per free parameter for the coarse scan before the local fit.
GRID = {1: 7, 2: 5, 3: 3}


class Variant:
    def __init__(self, name, model, runner, extra_set=None, params=None, mechanism=None, description=""):
        self.name = name
        self.mechanism = mechanism or name
        self.description = description
        self.model = model
        self.runner = runner
        self.set = dict(model.set)
        self.set.update(extra_set or {})
        self.params = list(params or [])

    def settings(self, values, cond_names, cond):
        s = dict(self.set)
        for p, v in zip(self.params, values):
            s[p.var] = float(v)
        for name, c in zip(cond_names, cond):
            s[self.model.conditions[name]] = float(c)
        return s

    def predict(self, values, data, rows):
        """Model value of each row (NaN where the run did not print the observable)."""
        results = self.runner.run_many([self.settings(values, data.conditions, r["cond"]) for r in rows])
        out = []
        for r, res in zip(rows, results):
            out.append(res.get(self.model.key_of(r["observable"]), math.nan))
        return np.array(out)


def normalized_residuals(pred, rows):
    y = np.array([r["value"] for r in rows])
    s = np.array([r["sigma"] for r in rows])
    z = (pred - y) / s
    return np.where(np.isfinite(z), z, 1e3)  # a missing value counts as a gross miss


def default_values(variant):
    return [p.initial if p.initial is not None else p.to_value(0.5) for p in variant.params]


def fit(variant, data, rows, known=None):
    """Fit the variant's free parameters on `rows`. `known` maps parameter
    names to good starting values (the baseline's fit): those are not scanned.
    Returns a dict with the values, their standard errors (Gauss-Newton, in
    parameter units), the chi-square at the optimum and the number of model
    evaluations."""
    known = known or {}
    k = len(variant.params)
    if k == 0:
        z = normalized_residuals(variant.predict([], data, rows), rows)
        return {"values": [], "errors": [], "chi2": float(z @ z), "nfev": 1}
    neval = [0]

    def resid(u):
        neval[0] += 1
        vals = [p.to_value(x) for p, x in zip(variant.params, u)]
        return normalized_residuals(variant.predict(vals, data, rows), rows)

    def robust_cost(z):
        t = (z / F_SCALE) ** 2
        return float(np.sum(2 * (np.sqrt(1 + t) - 1)))

    # Coarse scan of the unit box over the parameters without a known value
    # (the others held at it), plus the declared initial values: the simulated
    # observables can be non-monotonic and kinked in a parameter, so a local
    # optimiser alone may stop in the wrong basin. A choice parameter is tried
    # at every one of its values (crossed with the grid of the continuous ones).
    u_init = np.array([p.to_unit(known.get(p.name, v)) for p, v in zip(variant.params, default_values(variant))])
    scan = [i for i, p in enumerate(variant.params) if p.name not in known]
    scan_c = [i for i in scan if not variant.params[i].discrete]
    scan_d = [i for i in scan if variant.params[i].discrete]
    axes = []
    n = GRID.get(len(scan_c), 1)
    for i in scan:
        p = variant.params[i]
        if p.discrete:
            axes.append(np.linspace(0.0, 1.0, len(p.choices)))
        else:
            axes.append(np.linspace(0.05, 0.95, n) if n > 1 else np.array([u_init[i]]))
    starts = [u_init]
    if n > 1 or scan_d:
        for pt in itertools.product(*axes):
            u = u_init.copy()
            u[scan] = pt
            if not any(np.array_equal(u, s) for s in starts):
                starts.append(u)
    scored = []
    for u in starts:
        z = resid(u)
        scored.append((robust_cost(z), tuple(u), float(z @ z)))
    scored.sort()
    # Profile of each choice parameter: the lowest training chi2 found with
    # each of its values (the evidence for the chosen value over the others).
    profile = {}
    for i in scan_d:
        p = variant.params[i]
        prof = {}
        for _, u, chi2 in scored:
            val = p.to_value(u[i])
            prof[val] = min(prof.get(val, math.inf), chi2)
        profile[p.name] = sorted(prof.items())
    # Local bounded fit of the continuous parameters from the best start point;
    # choice parameters stay at their best value.
    u_best = np.array(scored[0][1])
    cont = [i for i, p in enumerate(variant.params) if not p.discrete]

    def resid_c(uc):
        u = u_best.copy()
        u[cont] = uc
        return resid(u)

    errors = [math.nan] * k
    u = u_best
    if cont:
        best = least_squares(resid_c, u_best[cont], bounds=(0.0, 1.0), loss=LOSS, f_scale=F_SCALE,
                             diff_step=1e-2, x_scale=0.1, xtol=1e-5, ftol=1e-6, gtol=1e-8,
                             max_nfev=15 * (len(cont) + 1))
        u = u_best.copy()
        u[cont] = best.x
        try:
            J = best.jac
            cov_u = np.linalg.pinv(J.T @ J)
            for j, i in enumerate(cont):
                errors[i] = float(math.sqrt(max(cov_u[j, j], 0.0)) * abs(variant.params[i].dvalue_du(u[i])))
        except (np.linalg.LinAlgError, ValueError):
            pass
    z = resid(u)
    values = [p.to_value(x) for p, x in zip(variant.params, u)]
    at_bound = [bool(not p.discrete and (x < 1e-3 or x > 1 - 1e-3)) for p, x in zip(variant.params, u)]
    return {"values": values, "errors": errors, "chi2": float(z @ z), "nfev": neval[0],
            "at_bound": at_bound, "profile": profile}
