#!/usr/bin/env python3
"""The figures of a strain sweep (fibernet sweep -o sweep.csv): stress against strain with the energy split, and the
differential modulus ds/dgamma against stress (the strain-stiffening plot), as one SVG (or PNG).

    /usr/bin/python3 scripts/plot_sweep.py sweep.csv [-o sweep.svg]

The title comes from the CSV's sidecar (sweep.csv.json: the scene and fibernet's version) when it is there.
Needs python3-matplotlib."""
import argparse
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def column(rows, *names):
    for n in names:  # dsdgamma was called K before fibernet 0.1.0's sidecars; old tables still plot
        if rows and n in rows[0]:
            return [float(r[n]) for r in rows]
    sys.exit(f"plot_sweep: the table has no column {names[0]}")


def title_of(path):
    try:
        with open(path + ".json") as f:
            side = json.load(f)
    except (OSError, ValueError):
        return os.path.basename(path)
    par = side.get("parameters", {})
    words = [f"{k} = {par[k]:g}" if isinstance(par[k], float) else f"{k} = {par[k]}"
             for k in ("L", "q", "pl", "seed") if k in par]
    if "network_file" in par:
        words.append(os.path.basename(par["network_file"]))
    if "scheme" in par:
        words.append(par["scheme"] + " scheme")
    version = side.get("provenance", {}).get("fibernet", {}).get("version", "")
    return ", ".join(words) + (f" (fibernet {version})" if version else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", help="figure file (default: the CSV's name with .svg)")
    a = ap.parse_args()
    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_sweep: {a.csv} has no rows")
    g, s = column(rows, "gamma"), column(rows, "stress_path")
    k = column(rows, "dsdgamma", "K")
    es, eb = column(rows, "stretch"), column(rows, "bend")
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    ax[0].plot(g, s, "o-", ms=3, label="s = (1/A0) dE/dgamma")
    ax[0].set_xlabel("strain gamma")
    ax[0].set_ylabel("stress (bending energy / ls²)")
    ax[0].legend()
    ax[1].plot(g, es, label="stretching")
    ax[1].plot(g, eb, label="bending")
    ax[1].set_xlabel("strain gamma")
    ax[1].set_ylabel("energy (bending units)")
    ax[1].legend()
    pos = [(x, y) for x, y in zip(s, k) if x > 0 and y > 0]
    if pos:
        ax[2].loglog([p[0] for p in pos], [p[1] for p in pos], "o-", ms=3, label="ds/dgamma > 0 steps")
        ax[2].legend()
    ax[2].set_xlabel("stress s")
    ax[2].set_ylabel("differential modulus ds/dgamma")
    fig.suptitle(title_of(a.csv))
    fig.tight_layout()
    out = a.output or os.path.splitext(a.csv)[0] + ".svg"
    fig.savefig(out)
    print(f"plot_sweep: wrote {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
