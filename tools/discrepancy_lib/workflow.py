"""The discrepancy workflow, step by step (doc/discrepancy.md):
1. run the baseline at every measured condition, residuals, chi-square, where
   the misfit concentrates;
2. split the data (seeded) into a training and a held-out part;
3. fit the baseline's and every candidate's free parameters on the training part;
4. held-out error of each with bootstrap uncertainty, AIC/BIC on the training fit;
5. rank, name the cause with its margin over the runner-up, report the gain."""
import time

import numpy as np

from . import stats
from .fitting import Variant, fit, normalized_residuals


def _variant_for(cand, model, runner):
    params = [p for p in model.params if p.name not in cand.drop] + cand.params
    return Variant(cand.name, model, runner, extra_set=cand.set, params=params, mechanism=cand.mechanism,
                   description=cand.description)


def _log(opts, msg):
    if not opts.get("quiet"):
        print(msg, flush=True)


def run(data, model, candidates, runner, opts):
    t0 = time.time()
    rows = data.rows
    n = len(rows)
    result = {"data": {"source": data.source, "n": n, "conditions": data.conditions,
                       "observables": data.observables()},
              "model": {"name": model.name, "script": model.script, "set": model.set,
                        "params": [p.to_json() for p in model.params]},
              "settings": {"seed": opts["seed"], "holdout": opts["holdout"], "p_threshold": stats.P_THRESHOLD,
                           "bootstrap": stats.BOOTSTRAP}}

    # 1. Baseline against all data.
    base = Variant("baseline", model, runner, params=model.params, mechanism="baseline")
    _log(opts, f"baseline: {n} points, {len(model.params)} free parameter(s)")
    fit_all = fit(base, data, rows)
    pred_base_all = base.predict(fit_all["values"], data, rows)
    z_all = normalized_residuals(pred_base_all, rows)
    gof = stats.chi2_summary(z_all, len(model.params))
    significant = gof["p_value"] < stats.P_THRESHOLD
    result["baseline"] = {"fit_all": {"values": dict(zip([p.name for p in model.params], fit_all["values"])),
                                      "errors": dict(zip([p.name for p in model.params], fit_all["errors"]))},
                          "goodness_of_fit": gof, "significant_discrepancy": bool(significant),
                          "concentration": stats.concentration(z_all, rows, data),
                          "predictions": pred_base_all.tolist(), "residuals": z_all.tolist()}
    _log(opts, "baseline: chi2/dof = %.3g (dof %d), p = %.3g" % (gof["chi2_red"], gof["dof"], gof["p_value"]))

    # 2. Train / held-out split, stratified by observable.
    train, held = stats.split(n, opts["holdout"], opts["seed"], [r["observable"] for r in rows])
    result["split"] = {"train": train, "heldout": held}
    rows_tr = [rows[i] for i in train]
    boot_idx = stats.bootstrap_indices(len(held), opts["seed"] + 1)

    # 3-4. Fit every variant on the training part, evaluate on the held-out part.
    variants = [base] + [_variant_for(c, model, runner) for c in candidates]
    entries, boots = [], []
    known = {}
    for v in variants:
        t1 = time.time()
        f = fit(v, data, rows_tr, known)
        if v is base:  # candidates start from the baseline's training fit
            known = {p.name: x for p, x in zip(v.params, f["values"])}
        pred_all = v.predict(f["values"], data, rows)
        z = normalized_residuals(pred_all, rows)
        z_ho = z[held]
        ho, b = stats.heldout_summary(z_ho, boot_idx)
        ic = stats.information_criteria(f["chi2"], len(v.params), len(rows_tr))
        per_obs = {}
        for obs in data.observables():
            ii = [k for k, i in enumerate(held) if rows[i]["observable"] == obs]
            if ii:
                per_obs[obs] = stats.rms(z_ho[ii])
        e = {"name": v.name, "mechanism": v.mechanism, "description": v.description, "set": v.set,
             "params": [dict(p.to_json(), value=val, error=err, at_bound=ab,
                             **({"profile_chi2": [[x, c] for x, c in f["profile"][p.name]]}
                                if p.name in f.get("profile", {}) else {}))
                        for p, val, err, ab in zip(v.params, f["values"], f["errors"],
                                                   f.get("at_bound", [False] * len(v.params)))],
             "train_chi2": f["chi2"], "train_n": len(rows_tr), "k": len(v.params), **ic,
             "heldout": ho, "heldout_by_observable": per_obs,
             "all_chi2": stats.chi2_summary(z, len(v.params)),
             "predictions": pred_all.tolist(), "residuals": z.tolist(), "evaluations": f["nfev"]}
        entries.append(e)
        boots.append(b)
        _log(opts, "%-40s held-out rms %.3g +- %.2g, AIC %.4g  (%d evaluations, %.1f s)" % (
            v.name, ho["rms"], ho["rms_std"], ic["aic"], f["nfev"], time.time() - t1))

    base_e, base_b = entries[0], boots[0]
    cands = list(range(1, len(entries)))
    # 5. Rank by held-out error, AIC breaking ties.
    cands.sort(key=lambda i: (entries[i]["heldout"]["rms"], entries[i]["aic"]))
    for i in cands:
        entries[i]["gain"] = stats.ratio_summary(base_b, boots[i], base_e["heldout"]["rms"] /
                                                 max(entries[i]["heldout"]["rms"], 1e-300))
        entries[i]["delta_aic_vs_baseline"] = base_e["aic"] - entries[i]["aic"]
    result["candidates"] = [entries[i] for i in cands]
    result["baseline"]["heldout_fit"] = base_e
    best = entries[cands[0]] if cands else None
    verdict = {}
    if best is not None and len(cands) > 1:
        ru = entries[cands[1]]
        verdict["runner_up"] = ru["name"]
        verdict["margin"] = {
            "delta_aic": ru["aic"] - best["aic"], "delta_bic": ru["bic"] - best["bic"],
            "heldout_ratio": stats.ratio_summary(boots[cands[1]], boots[cands[0]],
                                                 ru["heldout"]["rms"] / max(best["heldout"]["rms"], 1e-300))}
    if not significant:
        verdict["status"] = "no significant discrepancy"
        verdict["statement"] = ("No significant discrepancy: the baseline fits within the data's uncertainty "
                                "(chi2/dof = %.3g with %d degrees of freedom, p = %.3g >= %g)."
                                % (gof["chi2_red"], gof["dof"], gof["p_value"], stats.P_THRESHOLD))
        verdict["cause"] = None
    elif best is None:
        verdict["status"] = "discrepancy, no candidates"
        verdict["cause"] = None
        verdict["statement"] = "The baseline misses the data, and no candidate extension was given."
    elif best["gain"]["p_greater_than_1"] >= 0.95 and best["delta_aic_vs_baseline"] > 0:
        verdict["status"] = "cause named"
        verdict["cause"] = best["name"]
        verdict["mechanism"] = best["mechanism"]
        m = verdict.get("margin")
        strength = "only candidate"
        if m:
            p = m["heldout_ratio"]["p_greater_than_1"]
            if m["delta_aic"] >= 6 and p >= 0.9:
                strength = "decisive"
            elif m["delta_aic"] >= 2 and p >= 0.8:
                strength = "clear"
            elif m["delta_aic"] < 0 and p >= 0.8:
                strength = ("mixed: the held-out error favours it, the training AIC favours the runner-up "
                            "(a sign that the runner-up over-fits the training points)")
            else:
                strength = "weak: the runner-up is not excluded"
        verdict["strength"] = strength
        g = best["gain"]
        verdict["statement"] = (
            "The most likely cause is '%s': held-out error (rms of residual/uncertainty) %.3g against the "
            "baseline's %.3g, a gain of %.3g (68%% bootstrap interval %.3g-%.3g)." % (
                best["name"], best["heldout"]["rms"], base_e["heldout"]["rms"], g["ratio"], g["ci68"][0],
                g["ci68"][1]))
        if m:
            verdict["statement"] += (" Margin over the runner-up '%s': delta AIC %.3g, held-out error ratio %.3g "
                                     "(better in %.0f%% of bootstrap resamples); evidence %s." % (
                                         verdict["runner_up"], m["delta_aic"], m["heldout_ratio"]["ratio"],
                                         100 * m["heldout_ratio"]["p_greater_than_1"], strength))
        # Does the extended model fit within the uncertainty, and if not, where
        # does what is left concentrate?
        z_best = np.array(best["residuals"])
        rest = stats.chi2_summary(z_best, best["k"])
        verdict["extended_fit"] = rest
        verdict["remaining_misfit"] = stats.concentration(z_best, rows, data)
        if rest["p_value"] < stats.P_THRESHOLD:
            worst = verdict["remaining_misfit"]["worst_points"][0]
            verdict["statement"] += (" The extended model still misses the data beyond its uncertainty "
                                     "(chi2/dof = %.3g on all points); the largest remaining residual is %s at %s "
                                     "(%+.1f uncertainties)." % (
                                         rest["chi2_red"], worst["observable"],
                                         ", ".join(f"{k} = {v:.4g}" for k, v in worst["condition"].items()),
                                         worst["z"]))
        else:
            verdict["statement"] += (" The extended model fits within the data's uncertainty "
                                     "(chi2/dof = %.3g on all points, p = %.3g)." % (rest["chi2_red"],
                                                                                    rest["p_value"]))
    else:
        verdict["status"] = "discrepancy not explained"
        verdict["cause"] = None
        verdict["statement"] = ("The baseline misses the data (p = %.3g), but no candidate lowers the held-out "
                                "error significantly (best: '%s', gain %.3g, better in %.0f%% of resamples)." % (
                                    gof["p_value"], best["name"], best["gain"]["ratio"],
                                    100 * best["gain"]["p_greater_than_1"]))
    result["verdict"] = verdict
    result["runs"] = runner.nruns
    result["wall_time_s"] = time.time() - t0
    return result
