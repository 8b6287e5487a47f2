#!/usr/bin/python3
"""Statistics of silo avalanches from the CSV files of fix clog-detect.

Usage: tools/avalanche_stats.py A.csv [B.csv ...] [--phi 0 0.05 ...] [--labels ...]
                                [--base K] [--skip-first N] [--tail-quantile Q]
                                [--bootstrap B] [--seed S] [--out DIR]

One CSV per case (e.g. one sphere volume fraction phi each). For every case:
  * the number of avalanches n;
  * the mean avalanche size <S>, as mass [kg] and as number of bodies, with
    its 95 % confidence interval from the t-distribution,
    <S> +- t(0.975, n-1) sd / sqrt(n), and from a percentile bootstrap
    (B resamples of the n sizes, fixed seed);
  * <S>/<S0> relative to the base case (the case with phi = 0 when --phi is
    given, else the first; or --base K, 1-based) with the uncertainty
    propagated from the standard errors, sigma_R = R sqrt((se/<S>)^2 + (se0/<S0>)^2)
    (for the base case itself the ratio is 1 with no uncertainty);
  * the complementary cumulative distribution P(S >= s) and an exponential fit
    of its tail: above the threshold s_min (the Q-quantile of the sizes,
    default Q = 0.2) the excesses S - s_min of an exponential distribution are
    exponential with the same characteristic size lambda, whose maximum
    likelihood estimate is their mean; its standard error is lambda/sqrt(k)
    and its exact 95 % interval is [2 k lambda / chi2(0.975, 2k),
    2 k lambda / chi2(0.025, 2k)] for k sizes above s_min.
The table is printed and written to DIR/avalanche_stats.csv together with
DIR/avalanche_ccdf.png (distributions and fits) and DIR/avalanche_mean.png
(<S>/<S0> against phi or the case). Uses numpy, scipy and matplotlib.

The CSV format: '#' comment lines, one header row, one row per avalanche with
at least the columns avalanche, bodies and mass (see doc/tools.md).
"""
import argparse
import csv
import os
import sys

import numpy as np
from scipy import stats

REQUIRED = ("avalanche", "bodies", "mass")


class CsvError(Exception):
    pass


def read_avalanches(path):
    """Dict column -> numpy array of an avalanche CSV; raises CsvError when malformed."""
    try:
        with open(path, newline="") as f:
            lines = [(k + 1, line) for k, line in enumerate(f) if line.strip() and not line.startswith("#")]
    except OSError as e:
        raise CsvError(f"{path}: cannot read: {e.strerror}")
    if not lines:
        raise CsvError(f"{path}: no header row (expected a line starting with 'avalanche,')")
    header = [h.strip() for h in next(csv.reader([lines[0][1]]))]
    missing = [c for c in REQUIRED if c not in header]
    if missing:
        raise CsvError(f"{path}: line {lines[0][0]}: the header lacks the column(s) {', '.join(missing)}")
    rows = []
    for lineno, line in lines[1:]:
        words = next(csv.reader([line]))
        if len(words) != len(header):
            raise CsvError(f"{path}: line {lineno}: {len(words)} fields, the header has {len(header)}")
        try:
            rows.append([float(w) for w in words])
        except ValueError:
            raise CsvError(f"{path}: line {lineno}: a field is not a number: {line.strip()}")
    data = np.array(rows, dtype=float).reshape(-1, len(header))
    out = {h: data[:, k] for k, h in enumerate(header)}
    for c in ("bodies", "mass"):
        if np.any(out[c] < 0) or not np.all(np.isfinite(out[c])):
            raise CsvError(f"{path}: column {c} holds negative or non-finite values")
    return out


def mean_ci_t(x, level=0.95):
    """(mean, standard error, lo, hi) with the t-distribution interval."""
    n = len(x)
    m = float(np.mean(x)) if n else float("nan")
    if n < 2:
        return m, float("nan"), float("nan"), float("nan")
    se = float(np.std(x, ddof=1) / np.sqrt(n))
    h = stats.t.ppf(0.5 + level / 2, n - 1) * se
    return m, se, m - h, m + h


def bootstrap_means(x, rng, nboot=10000):
    """The means of nboot resamples of x (with replacement)."""
    x = np.asarray(x, dtype=float)
    idx = rng.integers(0, len(x), size=(nboot, len(x)))
    return x[idx].mean(axis=1)


def mean_ci_bootstrap(x, rng, nboot=10000, level=0.95):
    """Percentile bootstrap interval of the mean."""
    if len(x) < 2:
        return float("nan"), float("nan")
    means = bootstrap_means(x, rng, nboot)
    lo, hi = np.quantile(means, [0.5 - level / 2, 0.5 + level / 2])
    return float(lo), float(hi)


def exp_tail_fit(x, quantile=0.2, level=0.95):
    """Exponential fit of the tail above the `quantile` of x: (s_min, lambda, se, lo, hi, k)."""
    x = np.sort(np.asarray(x, dtype=float))
    if len(x) < 2:
        return (float("nan"),) * 5 + (0,)
    s_min = float(np.quantile(x, quantile)) if quantile > 0 else 0.0
    tail = x[x > s_min] - s_min if quantile > 0 else x
    k = len(tail)
    if k < 1:
        return s_min, float("nan"), float("nan"), float("nan"), float("nan"), 0
    lam = float(np.mean(tail))
    lo = 2 * k * lam / stats.chi2.ppf(0.5 + level / 2, 2 * k)
    hi = 2 * k * lam / stats.chi2.ppf(0.5 - level / 2, 2 * k)
    return s_min, lam, lam / np.sqrt(k), float(lo), float(hi), k


def ccdf(x):
    """Sorted sizes and P(S >= s) at each of them."""
    s = np.sort(np.asarray(x, dtype=float))
    n = len(s)
    return s, (n - np.arange(n)) / n


def analyse(cases, base, rng, nboot, tail_q):
    """Per-case dicts of the statistics."""
    out = []
    for c in cases:
        r = {"label": c["label"], "phi": c["phi"], "n": len(c["mass"])}
        for what in ("mass", "bodies"):
            x = c[what]
            m, se, lo, hi = mean_ci_t(x)
            blo, bhi = mean_ci_bootstrap(x, rng, nboot)
            r.update({f"mean_{what}": m, f"se_{what}": se, f"ci_t_lo_{what}": lo, f"ci_t_hi_{what}": hi,
                      f"ci_boot_lo_{what}": blo, f"ci_boot_hi_{what}": bhi})
            s_min, lam, lse, llo, lhi, k = exp_tail_fit(x, tail_q)
            r.update({f"tail_min_{what}": s_min, f"lambda_{what}": lam, f"lambda_se_{what}": lse,
                      f"lambda_lo_{what}": llo, f"lambda_hi_{what}": lhi, f"tail_n_{what}": k})
        out.append(r)
    b = out[base]
    for k, r in enumerate(out):
        for what in ("mass", "bodies"):
            m0, se0, m, se = b[f"mean_{what}"], b[f"se_{what}"], r[f"mean_{what}"], r[f"se_{what}"]
            ratio = m / m0 if m0 > 0 else float("nan")
            if k == base:
                err = 0.0
            else:
                err = abs(ratio) * np.sqrt((se / m) ** 2 + (se0 / m0) ** 2) if m > 0 and m0 > 0 else float("nan")
            r[f"ratio_{what}"], r[f"ratio_err_{what}"] = ratio, err
    return out


COLUMNS = ["label", "phi", "n"] + [
    f"{q}_{w}" for w in ("mass", "bodies") for q in (
        "mean", "se", "ci_t_lo", "ci_t_hi", "ci_boot_lo", "ci_boot_hi", "ratio", "ratio_err",
        "tail_min", "lambda", "lambda_se", "lambda_lo", "lambda_hi", "tail_n")]


def write_table(path, results):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in results:
            w.writerow([r[c] if isinstance(r[c], str) else f"{r[c]:.8g}" for c in COLUMNS])


def print_table(results, base_label):
    print(f"{'case':>12} {'phi':>6} {'n':>4} {'<S> [kg]':>11} {'95% CI (t)':>23} {'95% CI (bootstrap)':>23}"
          f" {'<S> bodies':>10} {'<S>/<S0>':>16} {'lambda [kg]':>21}")
    for r in results:
        print(f"{r['label']:>12} {r['phi']:>6.3g} {r['n']:>4d} {r['mean_mass']:>11.4g} "
              f"[{r['ci_t_lo_mass']:>10.4g},{r['ci_t_hi_mass']:>10.4g}] "
              f"[{r['ci_boot_lo_mass']:>10.4g},{r['ci_boot_hi_mass']:>10.4g}] "
              f"{r['mean_bodies']:>10.4g} {r['ratio_mass']:>7.3f} +- {r['ratio_err_mass']:<5.3f} "
              f"{r['lambda_mass']:>10.4g} +- {r['lambda_se_mass']:<8.3g}")
    print(f"(<S0>: case {base_label}; lambda: exponential tail fit of P(S >= s))")


def plot(results, cases, outdir, tail_q):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for c, r in zip(cases, results):
        for ax, what, unit in ((axes[0], "mass", "kg"), (axes[1], "bodies", "bodies")):
            s, p = ccdf(c[what])
            line, = ax.semilogy(s, p, "o", ms=3, label=f"{r['label']} (n = {r['n']})")
            lam, s_min = r[f"lambda_{what}"], r[f"tail_min_{what}"]
            if np.isfinite(lam) and lam > 0:
                ss = np.linspace(s_min, s.max(), 50)
                frac = r[f"tail_n_{what}"] / max(r["n"], 1)
                ax.semilogy(ss, frac * np.exp(-(ss - s_min) / lam), "-", color=line.get_color(), lw=1)
            ax.set_xlabel(f"avalanche size S [{unit}]")
            ax.set_ylabel("P(S >= s)")
    axes[0].ticklabel_format(axis="x", style="sci", scilimits=(-2, 3))
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Avalanche size distributions; lines: exponential tail fits above the {tail_q:g} quantile")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "avalanche_ccdf.png"), dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(5, 4))
    have_phi = all(np.isfinite(r["phi"]) for r in results)
    x = [r["phi"] for r in results] if have_phi else list(range(len(results)))
    ax.errorbar(x, [r["ratio_mass"] for r in results], yerr=[r["ratio_err_mass"] for r in results], fmt="o-",
                capsize=3)
    if not have_phi:
        ax.set_xticks(x)
        ax.set_xticklabels([r["label"] for r in results])
    ax.set_xlabel("sphere volume fraction phi" if have_phi else "case")
    ax.set_ylabel("<S>/<S0> (mass)")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "avalanche_mean.png"), dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv", nargs="+", help="avalanche CSV files, one per case")
    ap.add_argument("--phi", type=float, nargs="+", help="sphere volume fraction of each case")
    ap.add_argument("--labels", nargs="+", help="names of the cases (default: phi or the file name)")
    ap.add_argument("--base", type=int, help="1-based index of the base case (default: phi = 0, else 1)")
    ap.add_argument("--skip-first", type=int, default=0, help="drop the first N avalanches of each case")
    ap.add_argument("--tail-quantile", type=float, default=0.2, help="threshold quantile of the tail fit")
    ap.add_argument("--bootstrap", type=int, default=10000, help="bootstrap resamples")
    ap.add_argument("--seed", type=int, default=12345, help="seed of the bootstrap")
    ap.add_argument("--out", default=".", help="folder for avalanche_stats.csv and the plots")
    ap.add_argument("--no-plots", action="store_true")
    a = ap.parse_args(argv)

    n = len(a.csv)
    if a.phi is not None and len(a.phi) != n:
        sys.exit(f"avalanche_stats.py: {len(a.phi)} values of --phi for {n} files")
    if a.labels is not None and len(a.labels) != n:
        sys.exit(f"avalanche_stats.py: {len(a.labels)} --labels for {n} files")
    if not 0 <= a.tail_quantile < 1:
        sys.exit("avalanche_stats.py: --tail-quantile must lie in [0, 1)")
    cases = []
    for k, path in enumerate(a.csv):
        try:
            d = read_avalanches(path)
        except CsvError as e:
            sys.exit(f"avalanche_stats.py: {e}")
        phi = a.phi[k] if a.phi is not None else float("nan")
        label = a.labels[k] if a.labels else (f"phi={phi:g}" if a.phi is not None else
                                              os.path.splitext(os.path.basename(path))[0])
        mass, bodies = d["mass"][a.skip_first:], d["bodies"][a.skip_first:]
        if len(mass) == 0:
            sys.exit(f"avalanche_stats.py: {path}: no avalanches (after skipping {a.skip_first})")
        cases.append({"label": label, "phi": phi, "mass": mass, "bodies": bodies})
    if a.base is not None:
        if not 1 <= a.base <= n:
            sys.exit(f"avalanche_stats.py: --base must lie in 1..{n}")
        base = a.base - 1
    elif a.phi is not None and 0.0 in a.phi:
        base = a.phi.index(0.0)
    else:
        base = 0
    results = analyse(cases, base, np.random.default_rng(a.seed), a.bootstrap, a.tail_quantile)
    print_table(results, cases[base]["label"])
    os.makedirs(a.out, exist_ok=True)
    write_table(os.path.join(a.out, "avalanche_stats.csv"), results)
    if not a.no_plots:
        plot(results, cases, a.out, a.tail_quantile)
    print(f"wrote {os.path.join(a.out, 'avalanche_stats.csv')}" + ("" if a.no_plots else
          f", {os.path.join(a.out, 'avalanche_ccdf.png')}, {os.path.join(a.out, 'avalanche_mean.png')}"))


if __name__ == "__main__":
    main()
