#!/usr/bin/env python3
"""Two builds side by side on the rows of bench/run_wet_smooth_elimination.sh (docs/benchmarks.md).

    bench/compare_smooth_rows.py A.tsv B.tsv [label_a label_b]

Groups the rows of each file by (fibers, beta, method) and prints a Markdown table: runs, stable runs, the median and
total of the global factorizations and of the wet-solve seconds, and the median wet energy, for A and for B. Lines
starting with '#' and the header are skipped.
"""
import csv
import statistics
import sys


def load(path):
    groups = {}
    with open(path) as f:
        rows = [line for line in f if line.strip() and not line.startswith("#")]
    for r in csv.DictReader(rows, delimiter="\t"):
        if r["fibers"] == "fibers":
            continue
        key = (int(r["fibers"]), float(r["beta"]), r["method"])
        groups.setdefault(key, []).append(r)
    return groups


def summary(rows):
    fact = [int(r["global_factorizations"]) for r in rows]
    sec = [float(r["seconds_wet_solve"]) for r in rows]
    energy = [float(r["E_wet"]) for r in rows]
    stable = sum(r["status"] == "stable" for r in rows)
    return (f"{stable}/{len(rows)}", f"{statistics.median(fact):g} ({sum(fact)})",
            f"{statistics.median(sec):.1f} ({sum(sec):.1f})", f"{statistics.median(energy):.4g}")


def main():
    if len(sys.argv) not in (3, 5):
        sys.exit(__doc__)
    a, b = load(sys.argv[1]), load(sys.argv[2])
    la, lb = (sys.argv[3], sys.argv[4]) if len(sys.argv) == 5 else ("A", "B")
    print(f"| fibers, beta, method | stable, {la} / {lb} | global factorizations, median (total), {la} / {lb} | "
          f"wet solve s, median (total), {la} / {lb} | median E_wet, {la} / {lb} |")
    print("|---|---|---|---|---|")
    for key in sorted(set(a) | set(b)):
        sa = summary(a[key]) if key in a else ("-",) * 4
        sb = summary(b[key]) if key in b else ("-",) * 4
        cells = " | ".join(f"{x} / {y}" for x, y in zip(sa, sb))
        print(f"| {key[0]}, {key[1]:g}, {key[2]} | {cells} |")


if __name__ == "__main__":
    main()
