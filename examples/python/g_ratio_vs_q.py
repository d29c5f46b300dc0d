#!/usr/bin/env python3
"""G / G_affine against density q, averaged over seeds: the classic Mikado stiffening curve (seed ch. 3).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/g_ratio_vs_q.py [-o g_ratio_vs_q.svg] [--L 5]

Each point is the mean over the seeds with its standard error; a seed whose modulus failed is left out and counted.
"""
import argparse
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fibernet as fn  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--L", type=float, default=5)
    ap.add_argument("--qs", default="6,8,10,14,20,28")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("-o", "--output", default="g_ratio_vs_q.svg")
    args = ap.parse_args()
    qs = [float(q) for q in args.qs.split(",")]
    mean, sem, failed = [], [], 0
    for q in qs:
        ratios = []
        for seed in range(1, args.seeds + 1):
            r = fn.modulus(L=args.L, q=q, seed=seed, scheme="even", prune=["dangling"])
            if r["moduli"]["G"] is None:  # not converged: the result says so, no number is given
                failed += 1
                continue
            ratios.append(r["moduli"]["G_ratio"])
        ratios = np.array(ratios)
        mean.append(ratios.mean() if len(ratios) else np.nan)
        sem.append(ratios.std(ddof=1) / np.sqrt(len(ratios)) if len(ratios) > 1 else np.nan)
        print(f"q = {q:g}: G/G_affine = {mean[-1]:.4g} +- {sem[-1]:.2g} ({len(ratios)} seeds)", file=sys.stderr)
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.errorbar(qs, mean, yerr=sem, marker="o", capsize=3, label=f"L = {args.L:g}, {args.seeds} seeds")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("density q = N lf² / A")
    ax.set_ylabel("G / G_affine")
    ax.set_title(f"Mikado networks, pl = 1, even scheme (fibernet {fn.__version__})")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output)
    print(f"wrote {args.output}; {failed} failed moduli left out", file=sys.stderr)


if __name__ == "__main__":
    main()
