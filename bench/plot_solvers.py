#!/usr/bin/env python3
"""Work-precision charts from bench_solvers' CSV (issue 5, part 2).

    /usr/bin/python3 bench/plot_solvers.py [DIR]      (DIR = docs/solvers, holding trace.csv and runs.csv)

Writes DIR/wp_<scheme>_a<a>.png: for each network size (columns), the running minimum of max|g| (top) and of the
relative energy error (E - E_best)/|E_best| (bottom) against wall time, one line per solver; a marker at the end
of each line shows how the solver stopped (o converged, x any failure or budget).
Needs only matplotlib (Debian: python3-matplotlib) and the standard library.
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ORDER = ["newton", "newton+eliminate", "lbfgs-hessian", "ipopt", "lbfgs", "nlopt-lbfgs", "nlopt-var2",
         "nlopt-tnewton", "cg", "fire"]
STYLE = {
    "newton": ("k", "-"), "newton+eliminate": ("k", "--"), "lbfgs-hessian": ("tab:blue", "-"),
    "ipopt": ("tab:purple", "-"),
    "lbfgs": ("tab:orange", "-"), "nlopt-lbfgs": ("tab:orange", "--"), "nlopt-var2": ("tab:brown", "--"),
    "nlopt-tnewton": ("tab:pink", "--"), "cg": ("tab:green", "-"), "fire": ("tab:red", "-"),
}
FLOOR = 1e-17  # energy errors below this (or exactly 0) are drawn here


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "docs/solvers"
    traces = defaultdict(list)  # (case, solver) -> [(t, gmin, err)]
    meta = {}
    with open(f"{d}/trace.csv") as f:
        for r in csv.DictReader(f):
            traces[(r["case"], r["solver"])].append(
                (float(r["t"]), float(r["grad_min"]), max(float(r["rel_energy_err"]), FLOOR)))
            meta[r["case"]] = (r["scheme"], float(r["a"]), float(r["L"]), int(r["dof"]))
    status = {}
    with open(f"{d}/runs.csv") as f:
        for r in csv.DictReader(f):
            status[(r["case"], r["solver"])] = r["status"]
            tol = float(r["tol"])
    groups = defaultdict(list)
    for case, (scheme, a, L, dof) in meta.items():
        groups[(scheme, a)].append((L, dof, case))
    for (scheme, a), cases in sorted(groups.items()):
        cases.sort()
        fig, axes = plt.subplots(2, len(cases), figsize=(4.2 * len(cases), 7), squeeze=False, sharex="col")
        for col, (L, dof, case) in enumerate(cases):
            for solver in ORDER:
                pts = traces.get((case, solver))
                if not pts:
                    continue
                t = [p[0] for p in pts]
                c, ls = STYLE.get(solver, ("gray", ":"))
                ok = status.get((case, solver)) == "converged"
                for row, k in ((0, 1), (1, 2)):
                    ax = axes[row][col]
                    y = [p[k] for p in pts]
                    ax.step(t, y, where="post", color=c, ls=ls, lw=1.3, label=solver if col == 0 and row == 0 else None)
                    ax.plot(t[-1], y[-1], marker="o" if ok else "x", color=c, ms=6, mfc="none" if ok else c)
            axes[0][col].axhline(tol, color="gray", lw=0.8, ls=":")
            axes[0][col].set_title(f"{scheme} scheme, a = {a:g}, L = {L:g} ({dof} DOF)", fontsize=10)
            axes[1][col].set_xlabel("wall time [s]")
            for row in (0, 1):
                axes[row][col].set_xscale("log")
                axes[row][col].set_yscale("log")
                axes[row][col].grid(True, which="major", alpha=0.3)
        axes[0][0].set_ylabel("running min of max|g|")
        axes[1][0].set_ylabel("running min of (E - E_best) / |E_best|")
        fig.legend(loc="lower center", ncol=(len(ORDER) + 1) // 2, fontsize=9, frameon=False)
        fig.suptitle(f"Work-precision, simple shear gamma = 0.05 (o: converged, x: stopped otherwise; dotted: tol)",
                     fontsize=11)
        fig.tight_layout(rect=(0, 0.04, 1, 0.97))
        out = f"{d}/wp_{scheme}_a{a:g}.png"
        fig.savefig(out, dpi=110)
        plt.close(fig)
        print("wrote", out)


if __name__ == "__main__":
    main()
