#!/usr/bin/env python3
"""The stability map's summary table of docs/solvers.md from bench_solvers --mode stability's stability.csv: per
solver, how many networks ended in each status, and how many of the converged ones Newton accepted at its round-off
floor above tol (ok*).

    /usr/bin/python3 bench/stability_table.py docs/solvers
"""
import collections
import csv
import sys

ORDER = ["newton", "newton+eliminate", "newton+eliminate+median", "lbfgs-hessian", "ipopt", "lbfgs", "nlopt-lbfgs", "nlopt-var2",
         "nlopt-tnewton", "cg", "fire"]
COLS = [("converged", "ok"), ("iteration_limit", "budget"), ("line_search_failed", "LS-fail"), ("stalled", "stalled"),
        ("non_finite", "non-finite"), ("failed", "failed")]


def main(d):
    count = collections.defaultdict(collections.Counter)
    floor = collections.Counter()
    for r in csv.DictReader(open(d + "/stability.csv")):
        count[r["solver"]][r["status"]] += 1
        if r["status"] == "converged" and "round-off floor" in r["message"]:
            floor[r["solver"]] += 1
    print("| solver | " + " | ".join(c for _, c in COLS) + " | of which ok* |")
    print("|---|" + "---|" * (len(COLS) + 1))
    for s in [s for s in ORDER if s in count] + sorted(set(count) - set(ORDER)):
        print("| %s | %s | %d |" % (s, " | ".join(str(count[s][k]) for k, _ in COLS), floor[s]))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/solvers")
