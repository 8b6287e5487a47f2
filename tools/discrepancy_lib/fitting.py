"""Variants of the model (the baseline or the baseline plus one candidate
extension), their predictions, and the fit of their free parameters: a
space-filling design over the bounds, local bounded robust least squares from
the best few design points, errors from the curvature, and a test of every
parameter for inertness."""
import itertools
import math

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import qmc

# Robust loss: residuals are in units of the data's uncertainty; beyond
# F_SCALE standard deviations a point's pull grows only linearly (soft_l1).
LOSS = "soft_l1"
F_SCALE = 2.0
# Latin hypercube design over the continuous parameters: DESIGN_PER_PARAM
# points per parameter, at least DESIGN_MIN.
DESIGN_PER_PARAM = 5
DESIGN_MIN = 6
# Local fits start from the N_LOCAL best distinct design points.
N_LOCAL = 2
# A later local fit that comes within MERGE (in the unit interval, in every
# continuous parameter, with the same choice values) of an earlier local
# optimum has reached that minimum: it stops there, with the earlier one's
# point and chi2.
MERGE = 0.01
# Step (in the unit interval) of the finite differences of the curvature.
CURV_STEP = 0.02
# A parameter is inert when moving it over its whole range (the others at the
# optimum) changes no prediction by more than INERT_Z uncertainties.
INERT_Z = 0.1


class Variant:
    def __init__(self, name, model, runner, extra_set=None, params=None, mechanism=None, description="",
                 own=None):
        self.name = name
        self.mechanism = mechanism or name
        self.description = description
        self.model = model
        self.runner = runner
        self.set = dict(model.set)
        self.set.update(extra_set or {})
        self.params = list(params or [])
        # names of the parameters the candidate brings (the others are inherited
        # from the baseline)
        self.own = list(own) if own is not None else [p.name for p in self.params]

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


def robust_cost(z):
    t = (np.asarray(z) / F_SCALE) ** 2
    return float(np.sum(2 * (np.sqrt(1 + t) - 1)))


def default_values(variant):
    return [p.initial if p.initial is not None else p.to_value(0.5) for p in variant.params]


def design(variant, seed):
    """Start points in the unit box: the declared initial values, a Latin
    hypercube over the continuous parameters (scrambled, seeded), each crossed
    with every value of the choice parameters."""
    params = variant.params
    cont = [i for i, p in enumerate(params) if not p.discrete]
    disc = [i for i, p in enumerate(params) if p.discrete]
    u_init = np.array([p.to_unit(v) for p, v in zip(params, default_values(variant))])
    cont_pts = [u_init[cont]]
    if cont:
        n = max(DESIGN_MIN, DESIGN_PER_PARAM * len(cont))
        lhs = qmc.LatinHypercube(d=len(cont), seed=seed).random(n)
        cont_pts += list(lhs)
    disc_axes = [np.linspace(0.0, 1.0, len(params[i].choices)) for i in disc]
    starts = []
    for dpt in itertools.product(*disc_axes) if disc else [()]:
        for cpt in cont_pts:
            u = u_init.copy()
            u[cont] = cpt
            u[disc] = dpt
            if not any(np.array_equal(u, s) for s in starts):
                starts.append(u)
    return starts


def _distinct(u, chosen, variant):
    """A start differs from those already chosen: another choice value, or
    more than 0.15 of the range away in a continuous parameter."""
    for c in chosen:
        same_disc = all(abs(u[i] - c[i]) < 1e-9 for i, p in enumerate(variant.params) if p.discrete)
        cont = [i for i, p in enumerate(variant.params) if not p.discrete]
        if same_disc and (not cont or np.max(np.abs(u[cont] - c[cont])) < 0.15):
            return False
    return True


def curvature_errors(resid, u, variant, active):
    """Standard errors (parameter units) from the Gauss-Newton curvature of
    chi2 at u: J^T J with J by central differences of step CURV_STEP in the
    unit interval (one-sided at a bound), over the `active` parameters.
    Returns the errors and the Jacobian (unit space, active columns)."""
    cols = []
    for i in active:
        lo, hi = max(u[i] - CURV_STEP, 0.0), min(u[i] + CURV_STEP, 1.0)
        a, b = u.copy(), u.copy()
        a[i], b[i] = lo, hi
        cols.append((resid(b) - resid(a)) / (hi - lo))
    errors = [math.nan] * len(variant.params)
    if not cols:
        return errors, np.zeros((0, 0))
    J = np.array(cols).T
    cov = np.linalg.pinv(J.T @ J)
    for j, i in enumerate(active):
        errors[i] = float(math.sqrt(max(cov[j, j], 0.0)) * abs(variant.params[i].dvalue_du(u[i])))
    return errors, J


def inert_flags(resid, u, z0, variant, which=None):
    """Which parameters change nothing: each continuous one moved to both ends
    of its range, each choice parameter to every other choice, the others at u.
    `which`: indices of the parameters to test (default all)."""
    flags = []
    for i, p in enumerate(variant.params):
        if which is not None and i not in which:
            continue
        alts = [0.0, 1.0] if not p.discrete else list(np.linspace(0.0, 1.0, len(p.choices)))
        dz = 0.0
        for x in alts:
            if abs(x - u[i]) < 1e-12:
                continue
            w = u.copy()
            w[i] = x
            dz = max(dz, float(np.max(np.abs(resid(w) - z0))))
        flags.append(dz < INERT_Z)
    return flags


def _residual_function(variant, data, rows, neval):
    def resid(u):
        neval[0] += 1
        vals = [p.to_value(x) for p, x in zip(variant.params, u)]
        return normalized_residuals(variant.predict(vals, data, rows), rows)

    return resid


def screen_inert(variant, data, rows, base):
    """A candidate that adds parameters to the baseline (drops none) and whose
    own parameters change nothing at the baseline's optimum `base` (fit() of
    the baseline on the same rows) needs no fit of its own: its optimum is the
    baseline's. Tests the own parameters there (inert_flags, the inherited ones
    at the baseline's values, the own ones at their declared initial values):
    2 to 3 evaluations per own parameter instead of a fit. Returns fit()'s dict
    with the own parameters inert, or None when one of them changes a
    prediction (then the candidate is fitted)."""
    k_base = len(base["u"])
    own = [i for i, p in enumerate(variant.params) if p.name in variant.own]
    if not own or own != list(range(k_base, len(variant.params))):
        return None
    neval = [0]
    resid = _residual_function(variant, data, rows, neval)
    init = default_values(variant)
    u = np.concatenate([base["u"], [variant.params[i].to_unit(init[i]) for i in own]])
    z0 = resid(u)
    if not all(inert_flags(resid, u, z0, variant, which=own)):
        return None
    n_own = len(own)
    return {"values": [p.to_value(x) for p, x in zip(variant.params, u)],
            "errors": list(base["errors"]) + [math.nan] * n_own, "chi2": float(z0 @ z0), "nfev": neval[0],
            "at_bound": list(base["at_bound"]) + [False] * n_own, "inert": list(base["inert"]) + [True] * n_own,
            "profile": dict(base["profile"]), "local_chi2": [], "u": u, "jac": base["jac"],
            "active": list(base["active"])}


class _Joined(Exception):
    """A local fit reached the earlier local optimum number `index`."""

    def __init__(self, index):
        super().__init__(index)
        self.index = index


def fit(variant, data, rows, seed=1):
    """Fit all free parameters of the variant together on `rows`. Returns a
    dict with the values, standard errors (parameter units; NaN for choice and
    inert parameters), the chi-square at the optimum, which parameters are
    inert or at a bound, the profile of each choice parameter, the local fits
    (their chi2: several reaching the same minimum is the check that it is the
    global one), the Jacobian at the optimum and the number of evaluations."""
    k = len(variant.params)
    neval = [0]
    resid = _residual_function(variant, data, rows, neval)

    if k == 0:
        z = resid(np.zeros(0))
        return {"values": [], "errors": [], "chi2": float(z @ z), "nfev": 1, "at_bound": [], "inert": [],
                "profile": {}, "local_chi2": [], "u": np.zeros(0), "jac": np.zeros((len(rows), 0)),
                "active": []}

    scored = []
    for u in design(variant, seed):
        z = resid(u)
        scored.append((robust_cost(z), float(z @ z), u))
    scored.sort(key=lambda t: t[0])
    # Profile of each choice parameter: the lowest training chi2 found with
    # each of its values (the evidence for the chosen value over the others).
    profile = {}
    for i, p in enumerate(variant.params):
        if p.discrete:
            prof = {}
            for _, chi2, u in scored:
                val = p.to_value(u[i])
                prof[val] = min(prof.get(val, math.inf), chi2)
            profile[p.name] = sorted(prof.items())
    cont = [i for i, p in enumerate(variant.params) if not p.discrete]
    starts = []
    for _, _, u in scored:
        if len(starts) >= N_LOCAL:
            break
        if _distinct(u, starts, variant):
            starts.append(u)
    disc = [i for i in range(k) if i not in cont]
    local = []
    for u0 in starts:
        u = u0.copy()
        if cont:
            earlier = [j for j, (_, _, lu) in enumerate(local) if np.allclose(lu[disc], u0[disc])]

            def resid_c(uc, u0=u0, earlier=earlier):
                for j in earlier:
                    if np.max(np.abs(uc - local[j][2][cont])) < MERGE:
                        raise _Joined(j)
                w = u0.copy()
                w[cont] = uc
                return resid(w)

            try:
                r = least_squares(resid_c, u0[cont], bounds=(0.0, 1.0), loss=LOSS, f_scale=F_SCALE,
                                  diff_step=1e-2, x_scale=0.1, xtol=1e-5, ftol=1e-6, gtol=1e-8,
                                  max_nfev=10 * (len(cont) + 1))
                u[cont] = r.x
            except _Joined as joined:
                u = local[joined.index][2].copy()
        z = resid(u)
        local.append((robust_cost(z), float(z @ z), u))
    local.sort(key=lambda t: t[0])
    _, chi2, u = local[0]
    z0 = resid(u)
    inert = inert_flags(resid, u, z0, variant)
    active = [i for i in cont if not inert[i]]
    errors, J = curvature_errors(resid, u, variant, active)
    values = [p.to_value(x) for p, x in zip(variant.params, u)]
    at_bound = [bool(not p.discrete and not inert[i] and (x < 1e-3 or x > 1 - 1e-3))
                for i, (p, x) in enumerate(zip(variant.params, u))]
    return {"values": values, "errors": errors, "chi2": chi2, "nfev": neval[0], "at_bound": at_bound,
            "inert": inert, "profile": profile, "local_chi2": [c for _, c, _ in local], "u": u, "jac": J,
            "active": active}


def refit(variant, data, rows, full, all_rows):
    """Fit on a subset `rows` of the points (a cross-validation fold), starting
    from the fit on all points `full` (fit() on `all_rows`): Gauss-Newton
    steps on the fold's exact residuals with the Jacobian of the full fit
    (restricted to the fold's rows), at most REFIT_NFEV evaluations; choice
    and inert parameters stay at the full fit's values. Returns the values."""
    u_full = full["u"]
    active = full["active"]
    if not active:
        return [p.to_value(x) for p, x in zip(variant.params, u_full)]
    pos = {id(r): k for k, r in enumerate(all_rows)}
    J = full["jac"][[pos[id(r)] for r in rows]]

    def resid_a(ua):
        w = u_full.copy()
        w[active] = ua
        vals = [p.to_value(x) for p, x in zip(variant.params, w)]
        return normalized_residuals(variant.predict(vals, data, rows), rows)

    r = least_squares(resid_a, u_full[active], jac=lambda ua: J, bounds=(0.0, 1.0), loss=LOSS,
                      f_scale=F_SCALE, x_scale=0.1, xtol=1e-4, ftol=1e-5, max_nfev=REFIT_NFEV)
    w = u_full.copy()
    w[active] = r.x
    return [p.to_value(x) for p, x in zip(variant.params, w)]


REFIT_NFEV = 4
