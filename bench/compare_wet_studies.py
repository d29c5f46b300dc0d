#!/usr/bin/env python3
"""Two pore studies side by side (bench/run_wet_pores.sh outputs, e.g. the event model and the smooth model on the
same networks): reads each study's runs.csv (bench/plot_wet_pores.py) and prints a markdown table per beta with the
mean +- standard deviation over the stable runs of each study: capillary energy, bridges (event model) or non-zero
pairs (smooth model), fraction of fibers bundled, largest bundle, pore count, d50, area-weighted mean pore area,
walls + island faces (box fractions), cover and the linear shear modulus G; n counts the stable runs.
Only seeds present in both studies are compared.
Usage: compare_wet_studies.py NAME_A DIR_A NAME_B DIR_B
"""
import csv
import math
import statistics
import sys

COLUMNS = [("E_capillary", "E_capillary", "{:.4g}"), ("bridges", "bridges / pairs", "{:.0f}"),
           ("bundled_fraction", "bundled fibers", "{:.2f}"), ("largest_bundle", "largest bundle", "{:.1f}"),
           ("pores", "pores", "{:.0f}"), ("d50", "d50", "{:.2f}"), ("weighted_area", "area-weighted mean area", "{:.1f}"),
           ("walls_islands", "walls + island faces", "{:.3f}"), ("cover", "cover", "{:.4f}"), ("G", "G", "{:.3g}")]


def read(path):
    rows = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            rows[(r["seed"], r["beta"])] = r
    return rows


def value(r, key):
    try:
        if key == "walls_islands":
            return float(r["wall_fraction"]) + float(r["island_fraction"])
        return float(r[key])
    except (KeyError, ValueError):
        return math.nan


def cell(rows, key, fmt):
    xs = [value(r, key) for r in rows]
    xs = [x for x in xs if math.isfinite(x)]
    if not xs:
        return ""
    sd = statistics.stdev(xs) if len(xs) > 1 else 0.0
    return (fmt + " +- " + fmt).format(statistics.mean(xs), sd)


def main(name_a, dir_a, name_b, dir_b):
    a, b = read(dir_a + "/runs.csv"), read(dir_b + "/runs.csv")
    seeds = sorted({s for s, _ in a} & {s for s, _ in b}, key=int)
    betas = []
    for s, beta in a:
        if beta not in betas:
            betas.append(beta)
    print(f"Seeds in both studies: {len(seeds)} ({', '.join(seeds)}); mean +- standard deviation over stable runs.")
    print()
    print("| beta | model | n | " + " | ".join(c[1] for c in COLUMNS) + " |")
    print("|---|---|---:|" + "---|" * len(COLUMNS))
    for beta in betas:
        for name, rows in ((name_a, a), (name_b, b)):
            sel = [rows[(s, beta)] for s in seeds if (s, beta) in rows]
            ok = [r for r in sel if r["status"] in ("stable", "dry")]
            print(f"| {beta} | {name} | {len(ok)} of {len(sel)} | " +
                  " | ".join(cell(ok, key, fmt) for key, _, fmt in COLUMNS) + " |")


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    main(*sys.argv[1:])
