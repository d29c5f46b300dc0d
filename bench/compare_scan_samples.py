#!/usr/bin/env python3
"""Two scans of the same grid side by side (docs/solvers.md "Nonlinear elimination"): per sample, both statuses, a
numeric column of each (e.g. stress.xy) and its relative difference, and the solver's counts; then the largest
difference and the totals.

    fibernet scan problems/default.toml --job relax --gamma 0.01 --prune dangling ends \\
        --vary L=6,10 --vary seed=1:6 -q -o runs/elim
    fibernet scan problems/default.toml --job relax --gamma 0.01 --prune dangling ends --no-eliminate \\
        --vary L=6,10 --vary seed=1:6 -q -o runs/plain
    /usr/bin/python3 bench/compare_scan_samples.py runs/elim runs/plain [--column stress.xy]
"""
import argparse
import csv
import os
import sys


def rows(scan_dir):
    path = os.path.join(scan_dir, "samples.csv")
    try:
        with open(path, newline="") as f:
            return {r["index"]: r for r in csv.DictReader(f)}
    except OSError as e:
        sys.exit("%s: %s" % (path, e.strerror))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", help="scan directory A")
    ap.add_argument("b", help="scan directory B (the reference of the relative difference)")
    ap.add_argument("--column", default="stress.xy", help="numeric column to compare (default stress.xy)")
    args = ap.parse_args()
    A, B = rows(args.a), rows(args.b)
    common = sorted(set(A) & set(B), key=int)
    if not common:
        sys.exit("no sample index in both scans")
    counts = ["solver.factorizations", "solver.iterations", "solver.local_solves"]
    header = list(A[common[0]])
    axes = header[1:header.index("status")] if "status" in header else []  # the grid's keys: index, axes, status, ...
    print("\t".join(["index"] + axes + ["status_a", "status_b", args.column + "_a", "rel_diff"] +
                    [c + "_a" for c in counts] + [c + "_b" for c in counts]))
    worst, tot_a, tot_b = 0.0, [0] * len(counts), [0] * len(counts)
    for i in common:
        a, b = A[i], B[i]
        try:
            va, vb = float(a[args.column]), float(b[args.column])
        except (KeyError, ValueError):
            sys.exit("sample %s: no number in column %s" % (i, args.column))
        rel = abs(va - vb) / abs(vb) if vb != 0 else abs(va - vb)
        worst = max(worst, rel)
        ca = [int(float(a.get(c) or 0)) for c in counts]
        cb = [int(float(b.get(c) or 0)) for c in counts]
        tot_a = [x + y for x, y in zip(tot_a, ca)]
        tot_b = [x + y for x, y in zip(tot_b, cb)]
        print("\t".join([i] + [a[k] for k in axes] + [a["status"], b["status"], "%.12g" % va, "%.1e" % rel] +
                        [str(x) for x in ca + cb]))
    print("samples %d, largest relative difference of %s: %.1e" % (len(common), args.column, worst))
    print("totals A: " + ", ".join("%s %d" % (c, t) for c, t in zip(counts, tot_a)))
    print("totals B: " + ", ".join("%s %d" % (c, t) for c, t in zip(counts, tot_b)))


if __name__ == "__main__":
    main()
