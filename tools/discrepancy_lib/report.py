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


RESIDUAL_TICKS = [-1000, -100, -30, -10, -3, -2, -1, 0, 1, 2, 3, 10, 30, 100, 1000]


def _label(name, units):
    return f"{name} [{units[name]}]" if units.get(name) else name


def plots(result, data, model, outdir):
    """One PNG per observable: the data, the baseline, the best candidate
    (named or not) and the other candidates that are not inert; below, the
    residuals of every model on one shared axis (linear within +-3
    uncertainties, logarithmic beyond, so that large and small misfits show
    together)."""
    import textwrap

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.ticker
    import matplotlib.pyplot as plt

    files = []
    xname = model.plot_x if model.plot_x in data.conditions else data.conditions[0]
    xi = data.conditions.index(xname)
    base = result["baseline"]["fit"]
    cause = result["verdict"].get("cause")
    active = [e for e in result["candidates"] if not e["inert"]]
    series = [(base, "baseline", "tab:red", "s", 1.4)]
    colors = ["tab:blue", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:pink", "tab:olive", "tab:cyan"]
    for k, e in enumerate(active):
        if k == 0:
            label = ("with " + e["name"] + (" (named cause)" if cause == e["name"] else " (best, not named)"))
            series.append((e, label, colors[0], "^", 1.4))
        else:
            series.append((e, "with " + e["name"], colors[k % len(colors)], ".", 0.7))
    def other(i):  # the values of the conditions other than the plotted one
        return tuple(c for k, c in enumerate(data.rows[i]["cond"]) if k != xi)

    for obs in data.observables():
        idx = [i for i, r in enumerate(data.rows) if r["observable"] == obs]
        idx.sort(key=lambda i: data.rows[i]["cond"][xi])
        x = np.array([data.rows[i]["cond"][xi] for i in idx])
        y = np.array([data.rows[i]["value"] for i in idx])
        s = np.array([data.rows[i]["sigma"] for i in idx])
        # with more than one condition, a line joins the points that share the
        # other conditions' values (e.g. one line per pour)
        groups = [[k for k, i in enumerate(idx) if other(i) == g] for g in sorted({other(i) for i in idx})]
        fig, (ax, axr) = plt.subplots(2, 1, figsize=(7.0, 6.4), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 1.8]})
        ax.errorbar(x, y, s, fmt="o", color="k", ms=4, capsize=2, label="data", zorder=5)
        for e, label, color, marker, lw in series:
            p = np.array([e["predictions"][i] for i in idx])
            z = np.array([e["residuals"][i] for i in idx])
            for n, g in enumerate(groups):
                ax.plot(x[g], p[g], "-", color=color, marker=marker, ms=4, lw=lw, label=label if n == 0 else None)
                axr.plot(x[g], z[g], marker, color=color, ms=5 if lw > 1 else 4, ls="-" if lw > 1 else ":",
                         lw=0.6, label=label if n == 0 else None)
        axr.axhline(0, color="k", lw=0.8)
        for lvl in (-2, 2):
            axr.axhline(lvl, color="0.6", lw=0.6, ls="--")
        axr.set_yscale("symlog", linthresh=3.0)
        axr.yaxis.set_major_locator(matplotlib.ticker.FixedLocator(RESIDUAL_TICKS))
        axr.yaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        axr.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda t, _: f"{t:g}"))
        if model.log_x:
            ax.set_xscale("log")
        ax.set_ylabel(_label(obs, data.units))
        ax.legend(fontsize=7)
        title = f"{obs}: {model.name}. {result['verdict']['status']}"
        if cause:
            title += f": {cause}"
        ax.set_title(textwrap.fill(title, 80), fontsize=8)
        axr.set_ylabel("(model - data) / unc.", fontsize=8)
        xlabel = _label(xname, data.units)
        if len(groups) > 1:
            xlabel += "; a line per value of " + ", ".join(c for c in data.conditions if c != xname)
        axr.set_xlabel(xlabel)
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
    bf = result["baseline"]["fit"]["params"]
    if bf:
        L.append("Free parameters fitted on all data: " + ", ".join(
            f"{p['name']} = {_num(p['value'])} ± {_num(p['error'], 2)}" for p in bf))
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
        L += ["", f"Remaining misfit of the baseline with {v['cause']} (fit on all points):", "",
              "| observable | points | chi2/point | share of chi2 | mean residual |", "|---|---:|---:|---:|---:|"]
        for o in rm["by_observable"]:
            L.append(f"| {o['observable']} | {o['n']} | {_num(o['chi2_per_point'], 3)} | {100 * o['share']:.0f} % | "
                     f"{_num(o['mean_residual'], 3)} |")
        L += ["", f"| {data.conditions[0]} range | points | chi2/point | share of chi2 |", "|---|---:|---:|---:|"]
        for o in rm["by_condition_range"]:
            L.append(f"| {_num(o['from'])} - {_num(o['to'])} | {o['n']} | {_num(o['chi2_per_point'], 3)} | "
                     f"{100 * o['share']:.0f} % |")
    s = result["settings"]
    cv_how = ("cross-validated by %d-fold, %d repeats" % (s["folds"], s["repeats"])
              if result["cross_validation"]["done"] else "not cross-validated: the baseline fits; ranked by AIC")
    L += ["", "## Candidates (fitted on all %d points; %s)" % (result["data"]["n"], cv_how), "",
          "| rank | model | fitted parameters | cross-validated rms | gain over baseline (68 % CI) | AIC | BIC "
          "| chi2/dof |",
          "|---:|---|---|---:|---:|---:|---:|---:|"]

    def param_text(p):
        if p.get("choices") is not None:
            # a choice parameter: its value and the chi2 of each choice
            prof = p.get("profile_chi2")
            alts = (" (chi2 " + ", ".join(f"{_num(x)}: {_num(c, 3)}" for x, c in prof) + ")" if prof else "")
            return f"{p['name']} = {_num(p['value'])} of {{{', '.join(_num(x) for x in p['choices'])}}}" + alts
        if p.get("inert"):
            return f"{p['name']}: inert (changes nothing)"
        return f"{p['name']} = {_num(p['value'])} ± {_num(p['error'], 2)}" + (" (at bound)" if p.get("at_bound")
                                                                               else "")

    def params_text(e):
        return ", ".join(param_text(p) for p in e["params"]) or "-"

    def cv_text(e):
        if "cv" not in e:
            return "-"
        return f"{_num(e['cv']['rms'], 3)} ({', '.join(_num(x, 3) for x in e['cv']['rms_by_repeat'])})"

    b = result["baseline"]["fit"]
    L.append(f"| - | baseline | {params_text(b)} | {cv_text(b)} | 1 | {_num(b['aic'])} | {_num(b['bic'])} | "
             f"{_num(b['all_chi2']['chi2_red'], 3)} |")
    for k, e in enumerate(result["candidates"], start=1):
        if e["inert"]:
            L.append(f"| - | {e['name']} (inert: excluded) | {params_text(e)} | - | - | - | - | "
                     f"{_num(e['all_chi2']['chi2_red'], 3)} |")
            continue
        gg = e.get("gain")  # none without cross-validation
        gain = f"{_num(gg['ratio'], 3)} ({_num(gg['ci68'][0], 3)}-{_num(gg['ci68'][1], 3)})" if gg else "-"
        L.append(f"| {k} | {e['name']} | {params_text(e)} | {cv_text(e)} | {gain} | {_num(e['aic'])} | "
                 f"{_num(e['bic'])} | {_num(e['all_chi2']['chi2_red'], 3)} |")
    L += ["", "The cross-validated rms is the root mean square of (model - data) / uncertainty over every point, "
          "each predicted by the fit on the other folds (1 for a model that fits within the uncertainty); in "
          "brackets its value in each repeat. The gain is the baseline's over the candidate's, with its paired "
          "bootstrap over the points. AIC, BIC and chi2/dof are those of the fit on all points (k counts the "
          "parameters that are not inert).", ""]
    if pngs:
        L += ["## Plots", ""]
        for p in pngs:
            L += [f"![{p}]({p})", ""]
    L.append(f"{result['runs']} granary runs, {result['wall_time_s']:.0f} s.")
    with open(path, "w") as f:
        f.write("\n".join(L) + "\n")


def write_all(result, data, model, outdir, make_plots=True):
    os.makedirs(outdir, exist_ok=True)
    pngs = plots(result, data, model, outdir) if make_plots else []
    result["plots"] = pngs
    write_json(result, os.path.join(outdir, "report.json"))
    markdown(result, data, model, pngs, os.path.join(outdir, "report.md"))
