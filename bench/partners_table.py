#!/usr/bin/env python3
"""The partner cap over seeds, models side by side: one markdown table from bench/run_wet_partners.sh's outputs.

Reads DIR/<network>_cap<N>/runs.csv (bench/plot_wet_pores.py) for each model directory given, and prints per network,
beta and cap one row per model with the mean +- standard deviation over the seeds that every model finished (status
stable in each of them; n counts them; a seed unstable in one model is left out of all, so the rows compare the same
networks): bridges (event model) or non-zero pairs (smooth model), partners per bundled segment, fibers bundled,
largest bundle, E_capillary, G (linear), d50, area-weighted mean pore area, and the wet relaxation's seconds.
Usage: partners_table.py NAME=DIR [NAME=DIR ...] [--caps "0 2 6"] [--networks "pl0.5 pl0.2"]
"""
import csv
import math
import os
import statistics
import sys

COLUMNS = [("bridges", "bridges / pairs", "{:.0f}"), ("bundle_partners", "partners per bundled segment", "{:.2f}"),
           ("bundled_fraction", "bundled fibers", "{:.2f}"), ("largest_bundle", "largest bundle", "{:.0f}"),
           ("E_capillary", "E_capillary", "{:.4g}"), ("G", "G", "{:.3g}"), ("d50", "d50", "{:.2f}"),
           ("weighted_area", "area-weighted mean area", "{:.1f}"), ("seconds", "wet solve s", "{:.0f}")]


def read(path):
    rows = {}
    if not os.path.exists(path):
        return rows
    with open(path) as f:
        for r in csv.DictReader(f):
            rows[(r["seed"], r["beta"])] = r
    return rows


def cell(rows, key, fmt):
    xs = []
    for r in rows:
        try:
            x = float(r[key])
        except (KeyError, ValueError):
            continue
        if math.isfinite(x):
            xs.append(x)
    if not xs:
        return ""
    sd = statistics.stdev(xs) if len(xs) > 1 else 0.0
    return (fmt + " +- " + fmt).format(statistics.mean(xs), sd)


def main(argv):
    models, caps, networks = [], "0 2 6".split(), "pl0.5 pl0.2".split()
    it = iter(argv)
    for a in it:
        if a == "--caps":
            caps = next(it).split()
        elif a == "--networks":
            networks = next(it).split()
        elif "=" in a:
            models.append(tuple(a.split("=", 1)))
        else:
            sys.exit(__doc__)
    if not models:
        sys.exit(__doc__)
    print("| network | beta | cap | model | n | " + " | ".join(c[1] for c in COLUMNS) + " |")
    print("|---|---|---:|---|---:|" + "---|" * len(COLUMNS))
    for net in networks:
        for cap in caps:
            data = [(name, read(f"{d}/{net}_cap{cap}/runs.csv")) for name, d in models]
            if not all(rows for _, rows in data):
                continue
            betas = []
            for _, beta in data[0][1]:
                if beta not in betas and beta != "dry":
                    betas.append(beta)
            for beta in betas:
                seeds = sorted({s for s, b in data[0][1] if b == beta}, key=int)
                both = [s for s in seeds if all(rows.get((s, beta), {}).get("status") == "stable" for _, rows in data)]
                for name, rows in data:
                    sel = [rows[(s, beta)] for s in both]
                    print(f"| {net} | {beta} | {cap} | {name} | {len(sel)} of {len(seeds)} | " +
                          " | ".join(cell(sel, k, fmt) for k, _, fmt in COLUMNS) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
