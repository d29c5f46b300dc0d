#!/usr/bin/python3
"""Newton against FIRE and L-BFGS at ~1e5 DOF (issue 5, part 1): running minimum of max|g| against wall time,
from bench_solvers --mode ratio. Usage: /usr/bin/python3 bench/plot_ratio.py docs/solvers"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

d = sys.argv[1] if len(sys.argv) > 1 else "docs/solvers"
runs = list(csv.DictReader(open(f"{d}/ratio.csv")))
trace = list(csv.DictReader(open(f"{d}/ratio_trace.csv")))
for case in sorted({r["case"] for r in runs}):
    rs = [r for r in runs if r["case"] == case]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for r in rs:
        pts = [t for t in trace if t["case"] == case and t["solver"] == r["solver"]]
        # FIRE and L-BFGS stop at the target, so the last point of each is where it got (or the budget).
        ax.step([float(p["t"]) for p in pts], [float(p["grad_min"]) for p in pts], where="post",
                label=f"{r['solver']} ({r['status']}, {float(r['seconds']):.0f} s)")
    target = float(rs[0]["target"])
    ax.axhline(target, color="gray", ls="--", lw=0.8)
    ax.text(1e-2, target * 1.5, f"max|g| = {target:g}", color="gray", fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("running min of max|g|")
    r0 = rs[0]
    ax.set_title(f"{case}, {r0['dof']} DOF (prune {r0['prune']})", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{d}/ratio_{case}.png", dpi=110)
    print(f"{d}/ratio_{case}.png")
