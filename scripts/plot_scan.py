#!/usr/bin/python3
"""A figure from a scan's summary.csv (fibernet scan, docs/scan.md): the mean of one result column against one axis,
with standard-error bars, one series per value of another axis; each point is labelled with its samples that
succeeded (ok) where some did not.

Usage: /usr/bin/python3 scripts/plot_scan.py DIR/summary.csv --x q --y moduli.G_ratio --series a -o fig.svg
       [--logx] [--logy] [--title TEXT]"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("summary")
    p.add_argument("--x", required=True, help="the axis along x (a column of summary.csv)")
    p.add_argument("--y", required=True, help="the result plotted: its .mean and .sem columns")
    p.add_argument("--series", help="one line per value of this axis")
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--logx", action="store_true")
    p.add_argument("--logy", action="store_true")
    p.add_argument("--title", default="")
    a = p.parse_args()
    rows = list(csv.DictReader(open(a.summary)))
    if not rows:
        sys.exit(f"plot_scan: {a.summary} has no rows")
    for col in [a.x, a.y + ".mean", a.y + ".sem"] + ([a.series] if a.series else []):
        if col not in rows[0]:
            sys.exit(f"plot_scan: {a.summary} has no column '{col}' (columns: {', '.join(rows[0])})")
    groups = {}
    for r in rows:
        groups.setdefault(r[a.series] if a.series else "", []).append(r)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for name, rs in groups.items():
        pts = sorted((float(r[a.x]), float(r[a.y + ".mean"]), float(r[a.y + ".sem"] or 0), int(r["ok"]),
                      int(r["samples"])) for r in rs if r[a.y + ".mean"])
        label = f"{a.series} = {name}" if a.series else a.y
        ax.errorbar([t[0] for t in pts], [t[1] for t in pts], yerr=[t[2] for t in pts], marker="o", ms=4,
                    capsize=3, label=label)
        for x, y, _, ok, n in pts:
            if ok < n:
                ax.annotate(f"{ok}/{n}", (x, y), textcoords="offset points", xytext=(4, -10), fontsize=7)
    if a.logx:
        ax.set_xscale("log")
    if a.logy:
        ax.set_yscale("log")
    ax.set_xlabel(a.x)
    ax.set_ylabel(f"{a.y} (mean ± standard error)")
    ax.set_title(a.title, fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.output)
    print(f"plot_scan: wrote {a.output}")


if __name__ == "__main__":
    main()
