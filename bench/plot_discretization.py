#!/usr/bin/env python3
"""Discretization accuracy against cost from bench_solvers --mode discretization (issue 5, part 2).

    /usr/bin/python3 bench/plot_discretization.py [DIR]     (DIR = docs/solvers, holding discretization.csv)

Writes DIR/discretization.png: the relative error of the rest-state shear modulus G (against the finest even
discretization) against nodes per fiber (left) and against the time to discretize and compute G (right),
seed scheme against even scheme, one line per aspect ratio a. The reference point itself (error 0) is left out;
points where linear_moduli reported ok = false are marked with a black x.
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "docs/solvers"
    series = defaultdict(list)
    with open(f"{d}/discretization.csv") as f:
        for r in csv.DictReader(f):
            err = float(r["rel_err"])
            if err <= 0:
                continue
            label = (r["scheme"], float(r["a"]))
            knob = f"n_seg={r['n_seg']}" if r["scheme"] == "seed" else f"h={float(r['h']):g}"
            series[label].append((float(r["nodes_per_fiber"]), float(r["seconds_discretize"]) +
                                  float(r["seconds_modulus"]), err, knob, r["moduli_ok"] == "1"))
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    colours = {"seed": "tab:red", "even": "tab:blue"}
    styles = {10.0: "-", 100.0: "--", 1.0: ":", 1000.0: "-."}
    for (scheme, a), pts in sorted(series.items()):
        pts.sort()
        for ax, k in ((axes[0], 0), (axes[1], 1)):
            ax.plot([p[k] for p in pts], [p[2] for p in pts], marker="o", color=colours[scheme],
                    ls=styles.get(a, "-"), label=f"{scheme}, a = {a:g}")
            bad = [p for p in pts if not p[4]]
            if bad:  # linear_moduli reported ok = false (refinement not converged): drawn as a black x
                ax.plot([p[k] for p in bad], [p[2] for p in bad], "kx", ms=9, ls="none",
                        label="moduli ok = false" if k == 0 and scheme == "seed" and a == 10.0 else None)
        if a == 10.0:
            for p in pts:
                axes[0].annotate(p[3], (p[0], p[2]), fontsize=6, xytext=(3, 3), textcoords="offset points")
    for ax, xl in ((axes[0], "nodes per fiber"), (axes[1], "seconds (discretize + G, one factorization)")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xl)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("|G - G_ref| / G_ref")
    axes[0].legend(fontsize=8)
    fig.suptitle("Rest-state shear modulus G against discretization (reference: even scheme, finest h)", fontsize=10)
    fig.tight_layout()
    fig.savefig(f"{d}/discretization.png", dpi=110)
    print("wrote", f"{d}/discretization.png")


if __name__ == "__main__":
    main()
