"""Writing the result: report.json, report.md and one PNG per observable."""
import json
import math
import os

import numpy as np


def _num(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return f"{x:.{digits}g}"


def write_json(result, path):
    def clean(o):
        if isinstance(o, float) and not math.isfinite(o):
            return None
        if isinstance(o, dict):
            return {k: clean(v) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [clean(v) for v in o]
        if isinstance(o, np.generic):
            return clean(o.item())
        return o

    with open(path, "w") as f:
        json.dump(clean(result), f, indent=1)


def plots(result, data, model, outdir, best):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    xname = model.plot_x if model.plot_x in data.conditions else data.conditions[0]
    xi = data.conditions.index(xname)
    held = set(result["split"]["heldout"])
    base = result["baseline"]["heldout_fit"]
    for obs in data.observables():
        idx = [i for i, r in enumerate(data.rows) if r["observable"] == obs]
        idx.sort(key=lambda i: data.rows[i]["cond"][xi])
        x = np.array([data.rows[i]["cond"][xi] for i in idx])
        y = np.array([data.rows[i]["value"] for i in idx])
        s = np.array([data.rows[i]["sigma"] for i in idx])
        fig, (ax, axr) = plt.subplots(2, 1, figsize=(6.4, 5.6), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 1.4]})
        tr = np.array([i not in held for i in idx])
        ax.errorbar(x[tr], y[tr], s[tr], fmt="o", color="k", ms=4, capsize=2, label="data (training)")
        if (~tr).any():
            ax.errorbar(x[~tr], y[~tr], s[~tr], fmt="o", mfc="white", color="k", ms=5, capsize=2,
                        label="data (held out)")
        series = [(base, "baseline", "tab:red", "s")]
        if best is not None:
            series.append((best, "with " + best["name"], "tab:blue", "^"))
        for e, label, color, marker in series:
            p = np.array([e["predictions"][i] for i in idx])
            z = np.array([e["residuals"][i] for i in idx])
            ax.plot(x, p, "-", color=color, marker=marker, ms=4, lw=1.2, label=label)
            axr.plot(x, z, marker, color=color, ms=4, ls="none", label=label)
        axr.axhline(0, color="k", lw=0.8)
        for lvl in (-2, 2):
            axr.axhline(lvl, color="0.6", lw=0.6, ls="--")
        if model.log_x:
            ax.set_xscale("log")
        ax.set_ylabel(obs)
        ax.legend(fontsize=8)
        ax.set_title(f"{obs}: {model.name}", fontsize=9)
        axr.set_ylabel("(model - data) / unc.", fontsize=8)
        axr.set_xlabel(xname)
        fig.tight_layout()
        name = f"{obs}.png"
        fig.savefig(os.path.join(outdir, name), dpi=90)
        plt.close(fig)
        files.append(name)
    return files


def markdown(result, data, model, pngs, path):
    g = result["baseline"]["goodness_of_fit"]
    v = result["verdict"]
    L = [f"# Discrepancy report: {model.name}", ""]
    L.append(f"Data: `{os.path.basename(data.source)}`, {result['data']['n']} points, observables "
             f"{', '.join(result['data']['observables'])}, conditions {', '.join(data.conditions)}.")
    L.append("")
    L += ["## Verdict", "", f"**{v['status']}.** {v['statement']}", ""]
    L += ["## Baseline against all data", ""]
    bf = result["baseline"]["fit_all"]["values"]
    if bf:
        L.append("Free parameters fitted on all data: " + ", ".join(
            f"{k} = {_num(x)} ± {_num(result['baseline']['fit_all']['errors'][k], 2)}" for k, x in bf.items()))
        L.append("")
    L.append("chi2 = %s for %d degrees of freedom, chi2/dof = %s (99%% band for a correct model: %s-%s), "
             "p = %s; threshold p < %g for a significant discrepancy." % (
                 _num(g["chi2"]), g["dof"], _num(g["chi2_red"]), _num(g["chi2_red_band_99"][0], 3),
                 _num(g["chi2_red_band_99"][1], 3), _num(g["p_value"], 3), result["settings"]["p_threshold"]))
    L.append("")
    c = result["baseline"]["concentration"]
    L += ["Where the misfit concentrates:", "", "| observable | points | chi2/point | share of chi2 | mean residual |",
          "|---|---:|---:|---:|---:|"]
    for o in c["by_observable"]:
        L.append(f"| {o['observable']} | {o['n']} | {_num(o['chi2_per_point'], 3)} | {100 * o['share']:.0f} % | "
                 f"{_num(o['mean_residual'], 3)} |")
    L += ["", f"| {data.conditions[0]} range | points | chi2/point | share of chi2 |", "|---|---:|---:|---:|"]
    for o in c["by_condition_range"]:
        L.append(f"| {_num(o['from'])} - {_num(o['to'])} | {o['n']} | {_num(o['chi2_per_point'], 3)} | "
                 f"{100 * o['share']:.0f} % |")
    L += ["", "Largest residuals (in units of the uncertainty):", ""]
    for w in c["worst_points"]:
        cond = ", ".join(f"{k} = {_num(x)}" for k, x in w["condition"].items())
        L.append(f"* {w['observable']} at {cond}: measured {_num(w['value'])} ± {_num(w['sigma'], 2)}, "
                 f"residual {w['z']:+.2f} ({100 * w['share']:.0f} % of chi2)")
    L.append(f"* the worst 20 % of the points carry {100 * c['share_of_worst_20pct']:.0f} % of chi2")
    rm = v.get("remaining_misfit")
    if rm:
        L += ["", f"Remaining misfit of the baseline with {v['cause']} (training fit, all points):", "",
              "| observable | points | chi2/point | share of chi2 | mean residual |", "|---|---:|---:|---:|---:|"]
        for o in rm["by_observable"]:
            L.append(f"| {o['observable']} | {o['n']} | {_num(o['chi2_per_point'], 3)} | {100 * o['share']:.0f} % | "
                     f"{_num(o['mean_residual'], 3)} |")
        L += ["", f"| {data.conditions[0]} range | points | chi2/point | share of chi2 |", "|---|---:|---:|---:|"]
        for o in rm["by_condition_range"]:
            L.append(f"| {_num(o['from'])} - {_num(o['to'])} | {o['n']} | {_num(o['chi2_per_point'], 3)} | "
                     f"{100 * o['share']:.0f} % |")
    L += ["", "## Candidates (fitted on %d training points, ranked on %d held-out points)" % (
        len(result["split"]["train"]), len(result["split"]["heldout"])), "",
          "| rank | model | fitted parameters | held-out rms | gain over baseline (68 % CI) | AIC | BIC "
          "| chi2/dof, all points |",
          "|---:|---|---|---:|---:|---:|---:|---:|"]

    def param_text(p):
        if p.get("choices") is not None:
            # a choice parameter: its value and the training chi2 of each choice
            prof = p.get("profile_chi2")
            alts = (" (training chi2 " + ", ".join(f"{_num(x)}: {_num(c, 3)}" for x, c in prof) + ")"
                    if prof else "")
            return f"{p['name']} = {_num(p['value'])} of {{{', '.join(_num(x) for x in p['choices'])}}}" + alts
        return f"{p['name']} = {_num(p['value'])} ± {_num(p['error'], 2)}" + (" (at bound)" if p.get("at_bound")
                                                                               else "")

    def params_text(e):
        return ", ".join(param_text(p) for p in e["params"]) or "-"

    b = result["baseline"]["heldout_fit"]
    L.append(f"| - | baseline | {params_text(b)} | {_num(b['heldout']['rms'], 3)} ± "
             f"{_num(b['heldout']['rms_std'], 2)} | 1 | {_num(b['aic'])} | {_num(b['bic'])} | "
             f"{_num(b['all_chi2']['chi2_red'], 3)} |")
    for k, e in enumerate(result["candidates"], start=1):
        gg = e["gain"]
        L.append(f"| {k} | {e['name']} | {params_text(e)} | {_num(e['heldout']['rms'], 3)} ± "
                 f"{_num(e['heldout']['rms_std'], 2)} | {_num(gg['ratio'], 3)} ({_num(gg['ci68'][0], 3)}-"
                 f"{_num(gg['ci68'][1], 3)}) | {_num(e['aic'])} | {_num(e['bic'])} | {_num(e['all_chi2']['chi2_red'], 3)} |")
    L += ["", "Held-out rms is the root mean square of (model - data) / uncertainty over the held-out points "
          "(1 for a model that fits within the uncertainty); its ± is the bootstrap standard deviation. "
          "AIC and BIC are those of the training fit; the last column uses the training fit on all points.", ""]
    if pngs:
        L += ["## Plots", ""]
        for p in pngs:
            L += [f"![{p}]({p})", ""]
    L.append(f"{result['runs']} granary runs, {result['wall_time_s']:.0f} s.")
    with open(path, "w") as f:
        f.write("\n".join(L) + "\n")


def write_all(result, data, model, outdir, make_plots=True):
    os.makedirs(outdir, exist_ok=True)
    best = result["candidates"][0] if result["candidates"] and result["verdict"].get("cause") else None
    pngs = plots(result, data, model, outdir, best) if make_plots else []
    result["plots"] = pngs
    write_json(result, os.path.join(outdir, "report.json"))
    markdown(result, data, model, pngs, os.path.join(outdir, "report.md"))
