#!/usr/bin/env python3
"""Charts and table for docs/percolation/ from the output of `fibernet percolation` (bench/run_percolation.sh).

Reads P_pl*.csv (P(q) per L) and summary_pl*.json (probit fits per L, finite-size scaling fits) and writes
  percolation_P.png        P_rigid(q) and P_connected(q) per L, one panel per pl, with the probit fits;
  percolation_scaling.png  q_1/2 against L^(-1/nu) with nu held at the known 2D values, fitted lines;
  percolation_width.png    probit width against L (log-log) with the fits width = c L^(-1/nu);
  percolation_scaling_width_nu.png  q_1/2 against L^(-1/nu) with nu from the widths, per pl (as seed figure 3.6);
  table.md                 nu from the widths, q_c with that nu; q_c, nu, A of the free and fixed-nu fits per pl,
                           rigidity and connectivity; q_1/2(L) and widths.
Needs matplotlib (Debian: python3-matplotlib). Usage: plot_percolation.py docs/percolation
"""
import csv
import glob
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def phi(x):
    return 0.5 * math.erfc(-x / math.sqrt(2))


def main(d):
    runs = []
    for path in sorted(glob.glob(os.path.join(d, "summary_pl*.json")), reverse=True):
        pl = os.path.basename(path)[len("summary_pl"):-len(".json")]
        with open(path) as f:
            summary = json.load(f)
        rows = list(csv.DictReader(open(os.path.join(d, f"P_pl{pl}.csv"))))
        runs.append((pl, summary, rows))
    if not runs:
        sys.exit(f"no summary_pl*.json in {d}")

    # P(q) curves.
    fig, axes = plt.subplots(1, len(runs), figsize=(4 * len(runs), 3.6), sharey=True)
    axes = axes if len(runs) > 1 else [axes]
    for ax, (pl, summary, rows) in zip(axes, runs):
        Ls = sorted({float(r["L"]) for r in rows})
        cmap = plt.get_cmap("viridis")
        for k, L in enumerate(Ls):
            c = cmap(k / max(1, len(Ls) - 1))
            pts = sorted((float(r["q"]), float(r["P_rigid"]), float(r["P_connected"])) for r in rows if float(r["L"]) == L)
            q = [p[0] for p in pts]
            ax.plot(q, [p[1] for p in pts], "o", ms=3, color=c, label=f"L={L:g}")
            ax.plot(q, [p[2] for p in pts], "s", ms=2.5, mfc="none", color=c)
            fit = next(x for x in summary["per_L"] if x["L"] == L)
            qq = [q[0] + (q[-1] - q[0]) * i / 200 for i in range(201)]
            for key, ls in (("rigid", "-"), ("connected", "--")):
                if fit[key]:
                    ax.plot(qq, [phi((x - fit[key]["q_half"]) / fit[key]["width"]) for x in qq], ls, lw=0.8, color=c)
        ax.set_title(f"pl = {pl}")
        ax.set_xlabel("density q")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("spanning probability P(q)")
    axes[-1].legend(fontsize=7, title="filled/solid: rigid (d=0)\nopen/dashed: connected", title_fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "percolation_P.png"), dpi=110)

    # Finite-size scaling, as seed figure 3.6. A free nu is not determined by these sizes (see table.md), so the
    # x axis uses the known exponents: nu = 1.21 for rigidity (Jacobs & Thorpe 1995), 4/3 for connectivity.
    fixed = {"rigid": ("rigid_nu_1.21", 1.21), "connected": ("connected_nu_4/3", 4 / 3)}
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key in zip(axes, ("rigid", "connected")):
        name, nu = fixed[key]
        for pl, summary, _ in runs:
            fit = summary["scaling"].get(name)
            pts = [(x["L"], x[key]["q_half"], x[key]["q_half_err"]) for x in summary["per_L"] if x[key]]
            if not pts:
                continue
            xs = [L ** (-1 / nu) for L, _, _ in pts]
            line = ax.errorbar(xs, [p[1] for p in pts], yerr=[p[2] for p in pts], fmt="o", ms=3, capsize=2,
                               label=f"pl={pl}" + (f": q_c={fit['q_c']:.2f}±{fit['q_c_err']:.2f}" if fit else ""))
            if fit:
                xx = [0, max(xs) * 1.05]
                ax.plot(xx, [fit["q_c"] + fit["A"] * x for x in xx], "-", lw=0.8, color=line[0].get_color())
        ax.set_xlabel(f"L^(-1/nu), nu = {nu:.3g}")
        ax.set_ylabel("inflection point q_1/2(L)")
        ax.set_title("rigidity percolation (d = 0)" if key == "rigid" else "connectivity percolation")
        ax.set_xlim(left=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "percolation_scaling.png"), dpi=110)

    def ok(fit):
        return bool(fit) and "no_fit" not in fit

    # Widths against L, log-log, with width = c L^(-1/nu).
    kinds = (("rigid", "rigidity percolation (d = 0)", 1.21), ("connected", "connectivity percolation", 4 / 3))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, (key, title, nu_known) in zip(axes, kinds):
        allL, allw = [], []
        for pl, summary, _ in runs:
            fit = summary["scaling"].get(key + "_width")
            pts = [(x["L"], x[key]["width"], x[key]["width_err"]) for x in summary["per_L"] if x[key]]
            if not pts:
                continue
            allL += [p[0] for p in pts]
            allw += [p[1] for p in pts]
            label = f"pl={pl}: nu={fit['nu']:.2f}±{fit['nu_err']:.2f}" if ok(fit) else f"pl={pl}: no fit"
            line = ax.errorbar([p[0] for p in pts], [p[1] for p in pts], yerr=[p[2] for p in pts], fmt="o", ms=3,
                               capsize=2, label=label)
            if ok(fit):
                LL = [min(p[0] for p in pts) * 0.9, max(p[0] for p in pts) * 1.1]
                ax.plot(LL, [fit["c"] * x ** (-fit["inv_nu"]) for x in LL], "-", lw=0.8, color=line[0].get_color())
        if allL:  # the known exponent's slope, below the data (its height is arbitrary)
            Lm = math.exp(sum(map(math.log, allL)) / len(allL))
            wm = 0.6 * math.exp(sum(map(math.log, allw)) / len(allw))
            LL = [min(allL) * 0.9, max(allL) * 1.1]
            ax.plot(LL, [wm * (x / Lm) ** (-1 / nu_known) for x in LL], "k--", lw=0.8,
                    label=f"slope -1/{nu_known:.3g} (known 2D nu)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("box size L (fiber lengths)")
        ax.set_ylabel("probit width of P(q)")
        ax.set_title(title)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "percolation_width.png"), dpi=110)

    # q_1/2 against L^(-1/nu) with nu from the widths (each pl its own nu), as seed figure 3.6.
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, (key, title, _) in zip(axes, kinds):
        for pl, summary, _ in runs:
            fit = summary["scaling"].get(key + "_nu_from_width")
            pts = [(x["L"], x[key]["q_half"], x[key]["q_half_err"]) for x in summary["per_L"] if x[key]]
            if not pts or not fit:
                continue
            inv_nu = 1 / fit["nu"]
            xs = [L ** (-inv_nu) for L, _, _ in pts]
            line = ax.errorbar(xs, [p[1] for p in pts], yerr=[p[2] for p in pts], fmt="o", ms=3, capsize=2,
                               label=f"pl={pl}: nu={fit['nu']:.2f}, q_c={fit['q_c']:.2f}±{fit['q_c_err']:.2f}")
            xx = [0, max(xs) * 1.05]
            ax.plot(xx, [fit["q_c"] + fit["A"] * x for x in xx], "-", lw=0.8, color=line[0].get_color())
        ax.set_xlabel("L^(-1/nu), nu from the widths (per pl)")
        ax.set_ylabel("inflection point q_1/2(L)")
        ax.set_title(title)
        ax.set_xlim(left=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "percolation_scaling_width_nu.png"), dpi=110)

    # Table.
    def pm(fit, k, nd=3):
        return f"{fit[k]:.{nd}f} ± {fit[k + '_err']:.{nd}f}" if ok(fit) else "no fit"

    def chi(fit):
        return f"{fit['chi2']:.1f} / {fit['dof']}" if ok(fit) else "-"

    out = ["nu from the probit widths, width(L) = c L^(-1/nu) (weighted least squares of log width against log L;",
           "sizes with a failed probit fit skipped; error of nu by the delta method from that of 1/nu, both scaled by",
           "sqrt(chi2/dof) when chi2/dof > 1), and q_1/2(L) = q_c + A L^(-1/nu) with nu held there. q_c error =",
           "stat (fixed-nu fit) and nu part (half the q_c spread between refits at 1/nu ± its error) in quadrature.",
           "Checks: nu from the widths without the smallest size (L = 8: corrections to scaling) and without the",
           "largest fitted size (its width rests on the fewest densities inside the transition).", "",
           "| pl | kind | sizes | 1/nu | nu (widths) | chi2 / dof | nu, without smallest L | nu, without largest L "
           "| q_c (nu from widths) | stat, nu part | A | chi2 / dof |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    pooled = {}
    for pl, summary, _ in runs:
        for key in ("rigid", "connected"):
            w = summary["scaling"].get(key + "_width")
            w2 = summary["scaling"].get(key + "_width_without_smallest_L")
            w3 = summary["scaling"].get(key + "_width_without_largest_L")
            g = summary["scaling"].get(key + "_nu_from_width")
            if ok(w):
                pooled.setdefault(key, []).append((w["inv_nu"], w["inv_nu_err"]))
            out.append(f"| {pl} | {key} | {w['points'] if w else 0} | {pm(w, 'inv_nu')} | {pm(w, 'nu', 2)} | "
                       f"{chi(w)} | {pm(w2, 'nu', 2)} | {pm(w3, 'nu', 2)} | {pm(g, 'q_c')} | "
                       + (f"{g['q_c_err_stat']:.3f}, {g['q_c_err_nu']:.3f}" if g else "-")
                       + f" | {pm(g, 'A', 2)} | {chi(g)} |")
    # Universality: one nu for all pl. The weighted mean of 1/nu over pl, and the chi2 of the pl values about it.
    out += ["", "Weighted mean of 1/nu over the pl values (one exponent for all pl if the transition is universal;",
            "chi2 of the pl values about the mean):", "",
            "| kind | pl values | 1/nu | nu | chi2 / dof | known 2D nu |", "|---|---|---|---|---|---|"]
    for key, _, nu_known in kinds:
        v = pooled.get(key, [])
        if not v:
            continue
        wsum = sum(1 / e ** 2 for _, e in v)
        mean = sum(x / e ** 2 for x, e in v) / wsum
        err = wsum ** -0.5
        c2 = sum(((x - mean) / e) ** 2 for x, e in v)
        out.append(f"| {key} | {len(v)} | {mean:.3f} ± {err:.3f} | {1 / mean:.2f} ± {err / mean ** 2:.2f} | "
                   f"{c2:.1f} / {len(v) - 1} | {nu_known:.3g} |")

    out += ["", "Fit q_1/2(L) = q_c + A L^(-1/nu): free nu, and nu held at the known 2D value (rigidity 1.21,",
            "Jacobs & Thorpe 1995; connectivity 4/3). 'no fit': the best nu lies on the edge of the scan (0.33..20).", "",
           "| pl | kind | q_c (free nu) | nu | A | chi2 / dof | q_c (nu fixed) | A (nu fixed) | chi2 / dof |",
           "|---|---|---|---|---|---|---|---|---|"]
    for pl, summary, _ in runs:
        for key in ("rigid", "connected"):
            f = summary["scaling"][key]
            g = summary["scaling"][fixed[key][0]]
            out.append(f"| {pl} | {key} | {pm(f, 'q_c')} | {pm(f, 'nu', 2)} | {pm(f, 'A', 2)} | "
                       + (f"{f['chi2']:.1f} / {f['dof']}" if f else "-") + f" | {pm(g, 'q_c')} | {pm(g, 'A', 2)} | "
                       + (f"{g['chi2']:.1f} / {g['dof']}" if g else "-") + " |")
    out += ["", "q_1/2(L) and width (probit inflection point and width ± their standard errors):", "",
            "| pl | L | samples | rigid q_1/2 | rigid width | connected q_1/2 | connected width |",
            "|---|---|---|---|---|---|---|"]
    for pl, summary, _ in runs:
        for x in summary["per_L"]:
            out.append(f"| {pl} | {x['L']:g} | {x['samples']} | {pm(x['rigid'], 'q_half')} | "
                       f"{pm(x['rigid'], 'width')} | {pm(x['connected'], 'q_half')} | "
                       f"{pm(x['connected'], 'width')} |")
    with open(os.path.join(d, "table.md"), "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/percolation")
