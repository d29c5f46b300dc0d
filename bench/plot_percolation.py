#!/usr/bin/env python3
"""Charts and table for docs/percolation/ from the output of `fibernet percolation` (bench/run_percolation.sh).

Reads P_pl*.csv (P(q) per L) and summary_pl*.json (probit fits per L, finite-size scaling fits) and writes
  percolation_P.png        P_rigid(q) and P_connected(q) per L, one panel per pl, with the probit fits;
  percolation_scaling.png  q_1/2 against L^(-1/nu) with the fitted lines (as seed figure 3.6);
  table.md                 q_c, nu, A per pl, rigidity and connectivity, and q_1/2(L).
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

    # Table.
    def pm(fit, k, nd=3):
        return f"{fit[k]:.{nd}f} ± {fit[k + '_err']:.{nd}f}" if fit else "no fit"

    out = ["Fit q_1/2(L) = q_c + A L^(-1/nu): free nu, and nu held at the known 2D value (rigidity 1.21,",
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
    out += ["", "q_1/2(L) (probit inflection point ± its standard error):", "",
            "| pl | L | samples | rigid q_1/2 | rigid width | connected q_1/2 |", "|---|---|---|---|---|---|"]
    for pl, summary, _ in runs:
        for x in summary["per_L"]:
            out.append(f"| {pl} | {x['L']:g} | {x['samples']} | {pm(x['rigid'], 'q_half')} | "
                       f"{pm(x['rigid'], 'width')} | {pm(x['connected'], 'q_half')} |")
    with open(os.path.join(d, "table.md"), "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/percolation")
