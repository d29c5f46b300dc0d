#!/usr/bin/env python3
"""Tables of the smooth wet model's stability map (bench_smooth_map's stability_smooth.csv; docs/solvers.md, "Wet
scenes on the smooth model"): one row per scene with a cell per solver, then one row per solver with its counts.

Cells: `ok <t6> / <t10>`: max|g| of the whole energy reached 1e-6 after t6 s and 1e-10 after t10 s, at the lowest
energy any solver returned on the scene (within --best-tol of the energy drop); `(floor, g ...)`: Newton stopped at
its round-off floor above 1e-10 (converged, docs/moduli.md "Round-off floor"); `ok +<gap> ...`: converged, to another
minimum whose energy lies <gap> x (E_start - E_best) higher; otherwise `budget (g <max|g|>, +<gap>)`, with the time to
1e-6 if it got there.

    /usr/bin/python3 bench/smooth_map_table.py docs/solvers/stability_smooth > docs/solvers/stability_smooth/stability_smooth.md
"""
import collections
import csv
import math
import statistics
import sys


def seconds(x):
    v = float(x)
    return None if math.isnan(v) else v


def cell(r):
    t6, t10 = seconds(r["t_grad_1e-6"]), seconds(r["t_grad_1e-10"])
    gap = float(r["rel_energy_gap"])
    times = "%.2g s / %s" % (t6, "%.2g s" % t10 if t10 is not None else "-") if t6 is not None else ""
    if r["converged"] == "1":
        floor = " (floor, g %.0e)" % float(r["grad_max"]) if t10 is None else ""
        return ("ok " if r["at_best"] == "1" else "ok +%.1e " % gap) + times + floor
    head = "budget (g %.0e, +%.1e)" % (float(r["grad_max"]), gap)
    return head + (" 1e-6 at %.2g s" % t6 if t6 is not None else "")


def main(d):
    rows = list(csv.DictReader(open(d + "/stability_smooth.csv")))
    solvers = list(dict.fromkeys(r["solver"] for r in rows))
    scenes = collections.OrderedDict()
    for r in rows:
        scenes.setdefault(r["case"], {})[r["solver"]] = r
    budget = rows[0]["budget_s"] if rows else "?"
    print("Smooth wet model (`--bundle-partners %s`), every solver through `relax_smooth_wet` from the rest state, tol"
          % (rows[0]["partners"] if rows else "?"))
    print("1e-10 on the whole energy, %s s wall per run. Cells: see bench/smooth_map_table.py.\n" % budget)
    print("| scheme | q | a | beta | DOF | " + " | ".join(solvers) + " |")
    print("|---|---|---|---|---|" + "---|" * len(solvers))
    for case, by in scenes.items():
        r0 = next(iter(by.values()))
        print("| %s | %s | %s | %s | %s | %s |" % (r0["scheme"], r0["q"], r0["a"], r0["beta"], r0["dof"],
                                                   " | ".join(cell(by[s]) if s in by else "" for s in solvers)))
    print("\n| solver | converged | converged at the lowest energy | reached 1e-6 | median time to 1e-6 (where reached) |")
    print("|---|---|---|---|---|")
    for s in solvers:
        mine = [r for r in rows if r["solver"] == s]
        t6 = [seconds(r["t_grad_1e-6"]) for r in mine if seconds(r["t_grad_1e-6"]) is not None]
        print("| %s | %d / %d | %d | %d | %s |" % (
            s, sum(r["converged"] == "1" for r in mine), len(mine), sum(r["converged"] == "1" and r["at_best"] == "1" for r in mine), len(t6),
            "%.2g s" % statistics.median(t6) if t6 else "-"))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: smooth_map_table.py DIR (holding stability_smooth.csv)")
    main(sys.argv[1])
