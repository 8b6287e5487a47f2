"""The discrepancy workflow, step by step (doc/discrepancy.md):
1. fit the baseline's free parameters on all data (several starts), residuals,
   chi-square, where the misfit concentrates;
2. fit every candidate's free parameters (its own and the baseline's it keeps)
   together on all data; flag parameters that change nothing (inert);
3. repeated stratified k-fold cross-validation of the baseline and every
   candidate that is not inert: out-of-fold residuals of every point;
4. AIC/BIC of the fits on all data;
5. rank, name the cause only when it wins on cross-validated error and on AIC,
   with its stability over folds and repeats and its margin over the runner-up."""
import time

import numpy as np

from . import stats
from .fitting import INERT_Z, Variant, fit, normalized_residuals, refit, screen_inert


def _variant_for(cand, model, runner):
    params = [p for p in model.params if p.name not in cand.drop] + cand.params
    return Variant(cand.name, model, runner, extra_set=cand.set, params=params, mechanism=cand.mechanism,
                   description=cand.description, own=[p.name for p in cand.params])


def _log(opts, msg):
    if not opts.get("quiet"):
        print(msg, flush=True)


def _fit_entry(v, data, rows, opts, base_f=None):
    """Fit a variant on all points; its entry of the report. A candidate whose
    own parameters are inert at the baseline's optimum `base_f` is not fitted
    (fitting.screen_inert)."""
    t1 = time.time()
    f = screen_inert(v, data, rows, base_f) if base_f is not None else None
    if f is None:
        f = fit(v, data, rows, opts["seed"])
    pred = v.predict(f["values"], data, rows)
    z = normalized_residuals(pred, rows)
    # Inert parameters change nothing, so they are not counted as fitted.
    k = sum(1 for x in f["inert"] if not x)
    ic = stats.information_criteria(f["chi2"], k, len(rows))
    own_inert = [x for p, x in zip(v.params, f["inert"]) if p.name in v.own]
    e = {"name": v.name, "mechanism": v.mechanism, "description": v.description, "set": v.set,
         "params": [dict(p.to_json(), value=val, error=err, at_bound=ab, inert=bool(ine), own=p.name in v.own,
                         **({"profile_chi2": [[x, c] for x, c in f["profile"][p.name]]}
                            if p.name in f["profile"] else {}))
                    for p, val, err, ab, ine in zip(v.params, f["values"], f["errors"], f["at_bound"],
                                                    f["inert"])],
         "chi2": f["chi2"], "n": len(rows), "k": k, **ic,
         "inert": bool(own_inert) and all(own_inert),
         "local_fits_chi2": f["local_chi2"],
         "all_chi2": stats.chi2_summary(z, k),
         "predictions": pred.tolist(), "residuals": z.tolist(), "evaluations": f["nfev"]}
    _log(opts, "%-40s chi2/dof %.3g, AIC %.4g%s  (%d evaluations, %d granary runs so far, %.1f s)" % (
        v.name, e["all_chi2"]["chi2_red"], ic["aic"], ", inert" if e["inert"] else "", f["nfev"],
        v.runner.nruns, time.time() - t1))
    return e, f


def _cross_validate(v, f, data, rows, partitions):
    """Out-of-fold normalized residuals Z[repeat, row] and the rms of every
    fold, refitting the variant on the other folds."""
    Z = np.zeros((len(partitions), len(rows)))
    fold_rms = []
    for r, folds in enumerate(partitions):
        fr = []
        for held in folds:
            hs = set(held)
            rows_tr = [rows[i] for i in range(len(rows)) if i not in hs]
            vals = refit(v, data, rows_tr, f, rows)
            rows_ho = [rows[i] for i in held]
            z = normalized_residuals(v.predict(vals, data, rows_ho), rows_ho)
            Z[r, held] = z
            fr.append(stats.rms(z))
        fold_rms.append(fr)
    return Z, fold_rms


def run(data, model, candidates, runner, opts):
    t0 = time.time()
    rows = data.rows
    n = len(rows)
    result = {"data": {"source": data.source, "n": n, "conditions": data.conditions,
                       "observables": data.observables(), "units": getattr(data, "units", {})},
              "model": {"name": model.name, "script": model.script, "set": model.set,
                        "params": [p.to_json() for p in model.params]},
              "settings": {"seed": opts["seed"], "folds": opts["folds"], "repeats": opts["repeats"],
                           "cv": opts.get("cv", "always"),
                           "p_threshold": stats.P_THRESHOLD, "bootstrap": stats.BOOTSTRAP,
                           "stability_required": STABILITY}}

    # 1. Baseline against all data.
    base = Variant("baseline", model, runner, params=model.params, mechanism="baseline")
    _log(opts, f"baseline: {n} points, {len(model.params)} free parameter(s)")
    base_e, base_f = _fit_entry(base, data, rows, opts)
    z_all = np.array(base_e["residuals"])
    gof = stats.chi2_summary(z_all, base_e["k"])
    significant = gof["p_value"] < stats.P_THRESHOLD
    result["baseline"] = {"fit": base_e, "goodness_of_fit": gof, "significant_discrepancy": bool(significant),
                          "concentration": stats.concentration(z_all, rows, data)}
    _log(opts, "baseline: chi2/dof = %.3g (dof %d), p = %.3g" % (gof["chi2_red"], gof["dof"], gof["p_value"]))

    # 2. Every candidate fitted on all data, all its parameters together.
    variants = [_variant_for(c, model, runner) for c in candidates]
    fitted = [_fit_entry(v, data, rows, opts, base_f) for v in variants]

    # 3. Repeated k-fold cross-validation of the baseline and the candidates
    # that are not inert. With opts["cv"] == "if-significant" only when the
    # baseline misses the data (otherwise the verdict is 'no significant
    # discrepancy' whatever the held-out errors; the candidates are then
    # ranked by AIC alone).
    do_cv = bool(significant) or opts.get("cv", "always") == "always"
    partitions = stats.kfold(n, opts["folds"], opts["repeats"], opts["seed"], [r["observable"] for r in rows])
    result["cross_validation"] = {"partitions": partitions, "done": do_cv}
    boot_idx = stats.bootstrap_indices(n, opts["seed"] + 1)
    losses = {}
    for v, (e, f) in [(base, (base_e, base_f))] + list(zip(variants, fitted)):
        if e["inert"] or not do_cv:
            continue
        t1 = time.time()
        Z, fold_rms = _cross_validate(v, f, data, rows, partitions)
        losses[v.name] = np.mean(Z ** 2, axis=0)
        per_obs = {}
        for obs in data.observables():
            ii = [i for i, r in enumerate(rows) if r["observable"] == obs]
            per_obs[obs] = float(np.sqrt(np.mean(Z[:, ii] ** 2)))
        e["cv"] = {"rms": float(np.sqrt(np.mean(Z ** 2))),
                   "rms_by_repeat": [float(np.sqrt(np.mean(zr ** 2))) for zr in Z],
                   "rms_by_fold": fold_rms, "rms_by_observable": per_obs,
                   "residuals_out_of_fold": Z.tolist()}
        _log(opts, "%-40s cross-validated rms %.3g  (%d granary runs so far, %.1f s)" % (
            v.name, e["cv"]["rms"], v.runner.nruns, time.time() - t1))

    entries = [e for e, _ in fitted]
    active = [e for e in entries if not e["inert"]]
    # 4-5. Rank by cross-validated error (AIC breaks ties); inert candidates last.
    active.sort(key=lambda e: (e["cv"]["rms"], e["aic"]) if do_cv else e["aic"])
    for e in active if do_cv else []:
        e["gain"] = stats.bootstrap_gain(losses["baseline"], losses[e["name"]], boot_idx)
        e["delta_aic_vs_baseline"] = base_e["aic"] - e["aic"]
        e["delta_bic_vs_baseline"] = base_e["bic"] - e["bic"]
    result["candidates"] = active + [e for e in entries if e["inert"]]
    result["inert_candidates"] = [e["name"] for e in entries if e["inert"]]
    verdict = _verdict(result, active, base_e, gof, significant, losses, boot_idx, rows, data)
    result["verdict"] = verdict
    result["runs"] = runner.nruns
    result["wall_time_s"] = time.time() - t0
    return result


# A cause is named only when it is the cross-validation winner in more than
# this fraction of the repeats (besides the other conditions of _verdict).
STABILITY = 0.5


def _stability(best, models):
    """Fraction of repeats and of folds in which `best` has the lowest
    out-of-fold error among `models` (the baseline and the active candidates)."""
    reps = len(best["cv"]["rms_by_repeat"])
    won_r = sum(1 for r in range(reps)
                if all(best["cv"]["rms_by_repeat"][r] <= m["cv"]["rms_by_repeat"][r] for m in models))
    nf, won_f = 0, 0
    for r in range(reps):
        for j, x in enumerate(best["cv"]["rms_by_fold"][r]):
            nf += 1
            won_f += all(x <= m["cv"]["rms_by_fold"][r][j] for m in models)
    return {"repeats_won": won_r, "repeats": reps, "folds_won": won_f, "folds": nf,
            "fraction_repeats": won_r / max(reps, 1), "fraction_folds": won_f / max(nf, 1)}


def _verdict(result, active, base_e, gof, significant, losses, boot_idx, rows, data):
    verdict = {"cause": None}
    inert = result["inert_candidates"]
    inert_note = (" Inert (their parameters change no prediction by %.2g uncertainties; excluded from the "
                  "ranking): %s." % (INERT_Z, ", ".join(f"'{x}'" for x in inert))) if inert else ""
    best = active[0] if active else None
    cv_done = result["cross_validation"]["done"]
    if best is not None:
        models = [base_e] + active
        verdict["best"] = best["name"]
        if cv_done:
            verdict["stability"] = _stability(best, models)
        aic_best = min(active, key=lambda e: e["aic"])
        verdict["aic_best"] = aic_best["name"]
    if best is not None and len(active) > 1 and cv_done:
        ru = active[1]
        verdict["runner_up"] = ru["name"]
        verdict["margin"] = {"delta_aic": ru["aic"] - best["aic"], "delta_bic": ru["bic"] - best["bic"],
                             "cv_ratio": stats.bootstrap_gain(losses[ru["name"]], losses[best["name"]],
                                                              boot_idx)}
    if not significant:
        verdict["status"] = "no significant discrepancy"
        verdict["statement"] = ("No significant discrepancy: the baseline fits within the data's uncertainty "
                                "(chi2/dof = %.3g with %d degrees of freedom, p = %.3g >= %g)."
                                % (gof["chi2_red"], gof["dof"], gof["p_value"], stats.P_THRESHOLD))
        if not cv_done:
            verdict["statement"] += " Not cross-validated; the candidates are ranked by AIC."
        verdict["statement"] += inert_note
        return verdict
    if best is None:
        verdict["status"] = "discrepancy, no candidates"
        verdict["statement"] = ("The baseline misses the data, and no candidate extension that changes the "
                                "predictions was given." + inert_note)
        return verdict
    g = best["gain"]
    st = verdict["stability"]
    stab_text = ("it has the lowest out-of-fold error in %d of %d repeats and %d of %d folds" % (
        st["repeats_won"], st["repeats"], st["folds_won"], st["folds"]))
    reasons = []
    if g["p_greater_than_1"] < 0.95:
        reasons.append("its gain over the baseline is not significant (better in %.0f%% of bootstrap resamples, "
                       "95%% needed)" % (100 * g["p_greater_than_1"]))
    if aic_best is not best:
        reasons.append("AIC favours '%s' (%.4g against %.4g)" % (aic_best["name"], aic_best["aic"], best["aic"]))
    if best["aic"] >= base_e["aic"]:
        reasons.append("its AIC (%.4g) is not below the baseline's (%.4g)" % (best["aic"], base_e["aic"]))
    if st["fraction_repeats"] <= STABILITY:
        reasons.append("the win is not stable (%s)" % stab_text)
    cv_text = ("cross-validated error (rms of residual/uncertainty, %d-fold, %d repeats) %.3g against the "
               "baseline's %.3g, a gain of %.3g (68%% bootstrap interval %.3g-%.3g)" % (
                   len(result["cross_validation"]["partitions"][0]), st["repeats"], best["cv"]["rms"],
                   base_e["cv"]["rms"], g["ratio"], g["ci68"][0], g["ci68"][1]))
    if reasons:
        verdict["status"] = "discrepancy not explained"
        verdict["statement"] = ("The baseline misses the data (p = %.3g), but no cause is named: the best "
                                "candidate by held-out error is '%s' (%s), but %s." % (
                                    gof["p_value"], best["name"], cv_text, "; ".join(reasons)))
        verdict["statement"] += inert_note
        return verdict
    verdict["status"] = "cause named"
    verdict["cause"] = best["name"]
    verdict["mechanism"] = best["mechanism"]
    m = verdict.get("margin")
    strength = "only candidate"
    if m:
        p = m["cv_ratio"]["p_greater_than_1"]
        if m["delta_aic"] >= 6 and p >= 0.9 and st["fraction_repeats"] == 1:
            strength = "decisive"
        elif m["delta_aic"] >= 2 and p >= 0.8:
            strength = "clear"
        else:
            strength = "weak: the runner-up is not excluded"
    verdict["strength"] = strength
    verdict["statement"] = ("The most likely cause is '%s': %s; it also has the lowest AIC (%.4g, baseline "
                            "%.4g); %s." % (best["name"], cv_text, best["aic"], base_e["aic"], stab_text))
    if m:
        verdict["statement"] += (" Margin over the runner-up '%s': delta AIC %.3g, delta BIC %.3g, "
                                 "cross-validated error ratio %.3g (better in %.0f%% of bootstrap resamples); "
                                 "evidence %s." % (verdict["runner_up"], m["delta_aic"], m["delta_bic"],
                                                   m["cv_ratio"]["ratio"], 100 * m["cv_ratio"]["p_greater_than_1"],
                                                   strength))
    # Does the extended model fit within the uncertainty, and if not, where
    # does what is left concentrate?
    z_best = np.array(best["residuals"])
    rest = stats.chi2_summary(z_best, best["k"])
    verdict["extended_fit"] = rest
    verdict["remaining_misfit"] = stats.concentration(z_best, rows, data)
    if rest["p_value"] < stats.P_THRESHOLD:
        worst = verdict["remaining_misfit"]["worst_points"][0]
        verdict["statement"] += (" The extended model still misses the data beyond its uncertainty "
                                 "(chi2/dof = %.3g); the largest remaining residual is %s at %s "
                                 "(%+.1f uncertainties)." % (
                                     rest["chi2_red"], worst["observable"],
                                     ", ".join(f"{k} = {v:.4g}" for k, v in worst["condition"].items()),
                                     worst["z"]))
    else:
        verdict["statement"] += (" The extended model fits within the data's uncertainty "
                                 "(chi2/dof = %.3g, p = %.3g)." % (rest["chi2_red"], rest["p_value"]))
    verdict["statement"] += inert_note
    return verdict
