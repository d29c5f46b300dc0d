#!/usr/bin/env python3
"""Stability map from bench_solvers --mode stability (issue 5, part 3), and its wet scenes (issue 6).

    /usr/bin/python3 bench/plot_stability.py [DIR]        (DIR = docs/solvers, holding stability.csv)
    /usr/bin/python3 bench/plot_stability.py --wet [DIR]  (DIR holding stability_wet.csv [+ stability_wet_relax.csv]
                                                           from bench_solvers --mode stability-wet)

Dry: writes DIR/stability.md (one row per network: scheme, q, a, gamma; one column per solver; each cell the outcome
within the budget) and DIR/stability.png (the same as a colour grid).
Wet: writes DIR/stability_wet.md and DIR/stability_wet.png: one row per wet scene (scheme, q, a, beta), one column per
solver plus one for the full active-set relaxation (Newton) if stability_wet_relax.csv is there; a converged run is
told apart by whether its energy is the lowest any solver returned on that scene (to bench_solvers' --best-tol, as a
fraction of the energy drop from the start) or a higher stationary point. Standard library + matplotlib only.
"""
import csv
import sys
from collections import Counter, defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

ORDER = ["newton", "newton+eliminate", "lbfgs-hessian", "ipopt", "lbfgs", "nlopt-lbfgs", "nlopt-var2",
         "nlopt-tnewton", "cg", "fire"]
CODE = {"converged": "ok", "iteration_limit": "budget", "line_search_failed": "LS-fail", "stalled": "stalled",
        "non_finite": "non-finite", "failed": "failed"}
COLOUR = {"converged": 0, "iteration_limit": 1, "stalled": 2, "line_search_failed": 3, "failed": 4, "non_finite": 5}
CMAP = ListedColormap(["#4daf4a", "#ffff99", "#fdb462", "#fb8072", "#e41a1c", "#984ea3"])


def main():
    args = sys.argv[1:]
    if args and args[0] == "--wet":
        return wet(args[1] if len(args) > 1 else "docs/solvers")
    if any(a.startswith("-") for a in args) or len(args) > 1:
        sys.exit("usage: plot_stability.py [--wet] [DIR]")
    d = args[0] if args else "docs/solvers"
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


# ---- Wet scenes (bench_solvers --mode stability-wet) ----
WET_CODE = {"ok": "ok (lowest E)", "ok-higher": "ok (higher E)", "iteration_limit": "budget", "stalled": "stalled",
            "line_search_failed": "LS-fail", "failed": "failed", "non_finite": "non-finite", "cycling": "cycling"}
WET_COLOUR = {"ok": 0, "ok-higher": 1, "iteration_limit": 2, "stalled": 3, "line_search_failed": 4, "failed": 5,
              "non_finite": 6, "cycling": 7}
WET_CMAP = ListedColormap(["#4daf4a", "#80b1d3", "#ffff99", "#fdb462", "#fb8072", "#e41a1c", "#984ea3", "#bebada"])
# The active-set relaxation's outcomes on the same colours: stable = ok, budget or rounds spent = budget.
RELAX_STATE = {"stable": "ok", "cycling": "cycling", "budget": "iteration_limit", "max_rounds": "iteration_limit",
               "failed": "failed"}
RELAX = "active set (newton)"


def wet_state(r):
    """ok / ok-higher for a converged run (lowest energy of the scene or not), else the solver status."""
    if r["status"] == "converged":
        return "ok" if r["at_best"] == "1" else "ok-higher"
    return r["status"]


def distinct_minima(gaps, tol):
    """Number of groups of converged energies (gaps relative to the drop) that lie within tol of each other."""
    gaps = sorted(gaps)
    return sum(1 for i, g in enumerate(gaps) if i == 0 or g - gaps[i - 1] > tol)


def wet(d):
    import os
    rows = defaultdict(dict)
    info = {}
    with open(f"{d}/stability_wet.csv") as f:
        for r in csv.DictReader(f):
            key = (r["scheme"], float(r["q"]), float(r["a"]), float(r["gamma"]), float(r["beta"]))
            rows[key][r["solver"]] = r
            info[key] = r
    relax = {}
    if os.path.exists(f"{d}/stability_wet_relax.csv"):
        with open(f"{d}/stability_wet_relax.csv") as f:
            for r in csv.DictReader(f):
                relax[(r["scheme"], float(r["q"]), float(r["a"]), float(r["gamma"]), float(r["beta"]))] = r
    solvers = [s for s in ORDER if any(s in v for v in rows.values())]
    solvers += sorted({s for v in rows.values() for s in v} - set(solvers))
    keys = sorted(rows, key=lambda k: (k[1], k[2], k[0], k[3], k[4]))
    gammas = {k[3] for k in keys}
    budget = sorted({float(r["budget_s"]) for v in rows.values() for r in v.values()})

    def label(k):
        g = f" γ={k[3]:g}" if len(gammas) > 1 else ""
        return f"{k[0]} q={k[1]:g} a={k[2]:g}{g} β={k[4]:g}"

    def cell(r):
        st, t, gr = wet_state(r), float(r["seconds"]), float(r["grad_rel"])
        gap = float(r["rel_energy_gap"])
        if st in ("ok", "ok-higher"):
            star = "*" if float(r["grad_max"]) > float(r["tol"]) else ""  # Newton at the round-off floor
            extra = f" (g {gr:.0e})" if star else ""
            return f"ok{star} {t:.2g}s{extra}" if st == "ok" else f"ok{star} +{gap:.1e} {t:.2g}s{extra}"
        return f"{CODE.get(st, st)} (g {gr:.0e}, +{gap:.0e})"

    head = ["scheme", "q", "a"] + (["gamma"] if len(gammas) > 1 else []) + ["beta", "DOF", "bridges", "tol",
                                                                           "conv. / minima"]
    cols = solvers + ([RELAX] if relax else [])
    out = ["| " + " | ".join(head + cols) + " |", "|" + "---|" * (len(head) + len(cols))]
    agree = Counter()
    for k in keys:
        i = info[k]
        conv = [float(r["rel_energy_gap"]) for r in rows[k].values() if r["status"] == "converged"]
        nmin = distinct_minima(conv, 1e-6)
        agree[(len(conv) >= 2, nmin)] += 1
        cells = [cell(rows[k][s]) if s in rows[k] else "" for s in solvers]
        if relax:
            x = relax.get(k)
            cells.append("" if x is None else f"{x['outcome']} {x['rounds']}r {float(x['seconds']):.2g}s")
        vals = [k[0], f"{k[1]:g}", f"{k[2]:g}"] + ([f"{k[3]:g}"] if len(gammas) > 1 else []) + [
            f"{k[4]:g}", i["dof"], i["bridges"], f"{float(i['tol']):.1e}", f"{len(conv)} / {nmin}"]
        out.append("| " + " | ".join(vals + cells) + " |")

    states = list(WET_CODE)[:-1]
    summary = ["", "| solver | " + " | ".join(WET_CODE[s] for s in states) +
               " | lowest E of the scene | median energy gap |", "|---|" + "---|" * (len(states) + 2)]
    for s in solvers:
        cnt = Counter(wet_state(rows[k][s]) for k in keys if s in rows[k])
        best = sum(1 for k in keys if s in rows[k] and rows[k][s]["at_best"] == "1")
        gaps = sorted(float(rows[k][s]["rel_energy_gap"]) for k in keys if s in rows[k])
        med = gaps[len(gaps) // 2] if len(gaps) % 2 else 0.5 * (gaps[len(gaps) // 2 - 1] + gaps[len(gaps) // 2])
        summary.append(f"| {s} | " + " | ".join(str(cnt.get(st, 0)) for st in states) + f" | {best} | {med:.2g} |")

    rel = []
    if relax:
        rel = ["", "Full active-set relaxation (relax_wet with Newton, as `fibernet wet`; one wall budget per scene):",
               "", "| scheme | q | a | beta | bridges start -> end | outcome | rounds | Newton it | s | moves | "
               "ruptures | formed | E | lowest fixed-set E |", "|" + "---|" * 14]
        for k in keys:
            x = relax.get(k)
            if x is None:
                continue
            rel.append(f"| {k[0]} | {k[1]:g} | {k[2]:g} | {k[4]:g} | {x['bridges_initial']} -> {x['bridges_final']} | "
                       f"{x['outcome']} | {x['rounds']} | {x['iterations']} | {float(x['seconds']):.2g} | "
                       f"{x['moves']} | {x['ruptures']} | {x['formed']} | {float(x['energy']):.6g} | "
                       f"{float(info[k]['energy_best']):.6g} |")
        oc = Counter(x["outcome"] for x in relax.values())
        rel += ["", "Outcomes: " + ", ".join(f"{v} {n}" for n, v in sorted(oc.items()))]

    with open(f"{d}/stability_wet.md", "w") as f:
        f.write("Wet scenes: every solver minimizes the same wet energy (fixed bridge set: the wet crossings of the dry\n"
                "equilibrium) from the dry equilibrium. Budget: " + ", ".join(f"{b:g}" for b in budget) +
                " s wall per run, on a shared, loaded machine (timings are noisy).\n"
                "Cells: `ok <time>` reached max|g| <= tol at the lowest energy any solver returned on the scene\n"
                "(within 1e-6 of the energy drop E_start - E_best); `ok +<gap>` converged, but to a stationary point\n"
                "whose energy lies <gap> x (E_start - E_best) higher (another local minimum of the capillary\n"
                "landscape); `ok*` Newton converged at its round-off floor above tol; otherwise the status with\n"
                "(g: max|g| / max|g| at the start, +: energy gap as above). `conv. / minima`: solvers converged and\n"
                "how many different energies they reached. Median energy gap: over the solver's runs, 0 = the lowest\n"
                "energy of the scene, 1 = no descent from the start.\n\n")
        f.write("\n".join(out + summary + rel) + "\n")
    print("wrote", f"{d}/stability_wet.md")

    grid, text = [], []
    for k in keys:
        g, t = [], []
        for s in solvers:
            r = rows[k].get(s)
            if r is None:
                g.append(WET_COLOUR["failed"]), t.append("")
                continue
            st = wet_state(r)
            g.append(WET_COLOUR.get(st, WET_COLOUR["failed"]))
            gap = float(r["rel_energy_gap"])
            t.append(f"{float(r['seconds']):.2g}s" if st == "ok" else (f"+{gap:.0e}" if gap > 0 else "best"))
        if relax:
            x = relax.get(k)
            st = RELAX_STATE.get(x["outcome"], "failed") if x else "failed"
            g.append(WET_COLOUR[st]), t.append(f"{x['rounds']}r" if x else "")
        grid.append(g), text.append(t)
    fig, ax = plt.subplots(figsize=(0.95 * len(cols) + 3.4, 0.26 * len(keys) + 1.7))
    ax.imshow(grid, cmap=WET_CMAP, vmin=-0.5, vmax=len(WET_COLOUR) - 0.5, aspect="auto")
    for i, row in enumerate(text):
        for j, s in enumerate(row):
            ax.text(j, i, s, ha="center", va="center", fontsize=5.5)
    if relax:
        ax.axvline(len(solvers) - 0.5, color="k", lw=1.2)
    ax.set_xticks(range(len(cols)))
    ax.set_xticklabels(cols, rotation=40, ha="right", fontsize=8)
    ax.set_yticks(range(len(keys)))
    ax.set_yticklabels([label(k) for k in keys], fontsize=7)
    handles = [plt.Rectangle((0, 0), 1, 1, color=WET_CMAP(v)) for v in range(len(WET_COLOUR))]
    names = list(WET_CODE.values())
    names[-1] = "cycling (active set)"
    ax.legend(handles, names, loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    ax.set_title("Wet scenes: outcome within " + "/".join(f"{b:g}" for b in budget) + " s (fixed bridge set)\n"
                 "text: time if ok at the lowest E, else energy gap / drop" + ("; last column: active-set rounds"
                                                                                if relax else ""), fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{d}/stability_wet.png", dpi=110)
    print("wrote", f"{d}/stability_wet.png")


if __name__ == "__main__":
    main()
