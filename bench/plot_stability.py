#!/usr/bin/env python3
"""Stability map from bench_solvers --mode stability (issue 5, part 3).

    /usr/bin/python3 bench/plot_stability.py [DIR]     (DIR = docs/solvers, holding stability.csv)

Writes DIR/stability.md (one row per network: scheme, q, a, gamma; one column per solver; each cell the outcome
within the budget) and DIR/stability.png (the same as a colour grid). Standard library + matplotlib only.
"""
import csv
import sys
from collections import Counter, defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

ORDER = ["newton", "lbfgs-hessian", "ipopt", "lbfgs", "nlopt-lbfgs", "nlopt-var2", "nlopt-tnewton", "cg", "fire"]
CODE = {"converged": "ok", "iteration_limit": "budget", "line_search_failed": "LS-fail", "stalled": "stalled",
        "non_finite": "non-finite", "failed": "failed"}
COLOUR = {"converged": 0, "iteration_limit": 1, "stalled": 2, "line_search_failed": 3, "failed": 4, "non_finite": 5}
CMAP = ListedColormap(["#4daf4a", "#ffff99", "#fdb462", "#fb8072", "#e41a1c", "#984ea3"])


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "docs/solvers"
    rows = defaultdict(dict)
    info = {}
    with open(f"{d}/stability.csv") as f:
        for r in csv.DictReader(f):
            key = (r["scheme"], float(r["q"]), float(r["a"]), float(r["gamma"]))
            rows[key][r["solver"]] = r
            info[key] = (int(r["dof"]), float(r["tol"]), float(r["budget_s"]))
    solvers = [s for s in ORDER if any(s in v for v in rows.values())]
    keys = sorted(rows)
    out = ["| scheme | q | a | gamma | DOF | tol | " + " | ".join(solvers) + " |",
           "|---|---|---|---|---|---|" + "---|" * len(solvers)]
    for k in keys:
        dof, tol, budget = info[k]
        cells = []
        for s in solvers:
            r = rows[k].get(s)
            if r is None:
                cells.append("")
                continue
            c = CODE.get(r["status"], r["status"])
            if c == "ok" and float(r["grad_max"]) > float(r["tol"]):  # Newton's "converged at the round-off floor"
                cells.append(f"ok* {float(r['seconds']):.2g}s ({float(r['grad_max']):.0e})")
            else:
                cells.append(f"ok {float(r['seconds']):.2g}s" if c == "ok" else f"{c} ({float(r['grad_max']):.0e})")
        out.append(f"| {k[0]} | {k[1]:g} | {k[2]:g} | {k[3]:g} | {dof} | {tol:.1e} | " + " | ".join(cells) + " |")
    summary = ["", "| solver | " + " | ".join(CODE.values()) + " | of which ok* |", "|---|" + "---|" * (len(CODE) + 1)]
    for s in solvers:
        cnt = Counter(rows[k][s]["status"] for k in keys if s in rows[k])
        star = sum(1 for k in keys if s in rows[k] and rows[k][s]["status"] == "converged"
                   and float(rows[k][s]["grad_max"]) > float(rows[k][s]["tol"]))
        summary.append(f"| {s} | " + " | ".join(str(cnt.get(st, 0)) for st in CODE) + f" | {star} |")
    with open(f"{d}/stability.md", "w") as f:
        f.write("Cells: `ok <time>` reached max|g| <= tol; `ok*` the solver (Newton) reported converged above tol, at\n"
                "what it judged the round-off floor of the coordinates (max|g| in brackets); otherwise the status and\n"
                "(in brackets) max|g| at the returned state. Budget: 1 s wall per run.\n\n")
        f.write("\n".join(out + summary) + "\n")
    print("wrote", f"{d}/stability.md")

    grid = [[COLOUR.get(rows[k].get(s, {}).get("status"), 4) for s in solvers] for k in keys]
    fig, ax = plt.subplots(figsize=(1.0 * len(solvers) + 3, 0.22 * len(keys) + 1.5))
    ax.imshow(grid, cmap=CMAP, vmin=-0.5, vmax=5.5, aspect="auto")
    ax.set_xticks(range(len(solvers)))
    ax.set_xticklabels(solvers, rotation=40, ha="right", fontsize=8)
    ax.set_yticks(range(len(keys)))
    ax.set_yticklabels([f"{k[0]} q={k[1]:g} a={k[2]:g} γ={k[3]:g}" for k in keys], fontsize=7)
    handles = [plt.Rectangle((0, 0), 1, 1, color=CMAP(v)) for v in range(6)]
    ax.legend(handles, list(CODE.values()), loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    ax.set_title("Outcome within the budget", fontsize=10)
    fig.tight_layout()
    fig.savefig(f"{d}/stability.png", dpi=110)
    print("wrote", f"{d}/stability.png")


if __name__ == "__main__":
    main()
