#!/usr/bin/env python3
"""Charts of a strain sweep CSV (fibernet sweep): stress against strain, and the differential modulus K against
stress (the strain-stiffening plot). Usage: bench/plot_sweep.py sweep.csv out_prefix  (writes PREFIX_stress.png,
PREFIX_stiffening.png). Needs python3-matplotlib (apt-get install python3-matplotlib)."""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    g = [float(r["gamma"]) for r in rows]
    s = [float(r["stress_path"]) for r in rows]
    K = [float(r["K"]) for r in rows]
    eb = [float(r["bend"]) for r in rows]
    es = [float(r["stretch"]) for r in rows]
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    ax[0].plot(g, s, "o-", ms=3)
    ax[0].set_xlabel("strain gamma")
    ax[0].set_ylabel("stress (seed units)")
    ax[1].plot(g, es, label="stretching")
    ax[1].plot(g, eb, label="bending")
    ax[1].set_xlabel("strain gamma")
    ax[1].set_ylabel("energy")
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(sys.argv[2] + "_stress.png", dpi=120)
    fig, ax = plt.subplots(figsize=(4.5, 3.6))
    pos = [(a, b) for a, b in zip(s, K) if a > 0 and b > 0]
    if pos:
        ax.loglog([p[0] for p in pos], [p[1] for p in pos], "o-", ms=3)
    ax.set_xlabel("stress")
    ax.set_ylabel("differential modulus K = d stress / d gamma")
    fig.tight_layout()
    fig.savefig(sys.argv[2] + "_stiffening.png", dpi=120)


if __name__ == "__main__":
    main()
