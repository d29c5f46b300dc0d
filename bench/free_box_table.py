#!/usr/bin/env python3
"""The free box over seeds, from bench/run_wet_free_box_seeds.sh's output directory (OUT/seed*.json, one
`fibernet wet ... --free-box` JSON per network seed). Prints markdown: a row per seed and beta (whether the free box
converged, s, the areal shrinkage 1 - det F / det F0, outer iterations, trial relaxations, relaxed-response solves,
the residual at the fixed box and at the end in units of sigma_c, the stiffness eigenvalue(s) per unit area, the
capillary energy and the linear shear modulus at the fixed box and at the free box, and the free box's seconds),
then per beta the mean and standard deviation over the converged seeds and how many converged.
Usage: free_box_table.py OUT
"""
import glob
import json
import math
import os
import re
import statistics
import sys

NAN = float("nan")


def num(x):
    return NAN if x is None else float(x)


def mean_sd(xs):
    xs = [x for x in xs if math.isfinite(x)]
    if not xs:
        return "-"
    sd = statistics.stdev(xs) if len(xs) > 1 else 0.0
    return f"{statistics.mean(xs):.4g} +- {sd:.2g}"


def main(out):
    rows = []
    for path in sorted(glob.glob(os.path.join(out, "seed*.json")),
                       key=lambda p: int(re.search(r"seed(\d+)\.json$", p).group(1))):
        seed = int(re.search(r"seed(\d+)\.json$", path).group(1))
        try:
            j = json.load(open(path))
        except (OSError, ValueError) as e:
            print(f"<!-- {path}: not read ({e}) -->")
            continue
        for r in j.get("runs", []):
            f = r.get("free_box") or {}
            if not f:
                continue
            ev = f.get("stiffness_eigenvalues") or []
            rows.append({
                "seed": seed, "beta": r["beta"], "status": r.get("status"), "converged": bool(f.get("converged")),
                "s": num(f.get("s")), "shrinkage": num(f.get("areal_shrinkage")),
                "iterations": f.get("iterations"), "relaxations": f.get("relaxations"),
                "stiffness_solves": f.get("stiffness_solves"),
                "res0": num(f.get("residual_fixed_box")), "res": num(f.get("residual")),
                "K": min(ev) if ev else NAN,
                "E0": num(r["energy"]["wet"]["capillary"]), "E1": num(f["energy"]["capillary"]),
                "G0": num(r["shear_modulus"]["wet"]), "G1": num(f.get("shear_modulus")),
                "seconds": num(f.get("seconds")), "message": f.get("message", ""),
            })
    print("| seed | beta | free box | s | areal shrinkage | iterations | relaxations | response solves | residual fixed -> free | "
          "stiffness (min) | E_capillary fixed -> free | G fixed -> free | seconds | message |")
    print("|---:|---:|---|---:|---:|---:|---:|---:|---|---:|---|---|---:|---|")
    for r in rows:
        print(f"| {r['seed']} | {r['beta']} | {'converged' if r['converged'] else 'NOT converged'} | {r['s']:.5f} | "
              f"{r['shrinkage']:.4f} | {r['iterations']} | {r['relaxations']} | {r['stiffness_solves']} | "
              f"{r['res0']:.3g} -> {r['res']:.2g} | {r['K']:.4g} | {r['E0']:.4g} -> {r['E1']:.4g} | "
              f"{r['G0']:.3g} -> {r['G1']:.3g} | {r['seconds']:.1f} | {r['message'][:70]} |")
    print()
    print("Per beta, mean +- standard deviation over the seeds whose free box converged (n of all):")
    print()
    print("| beta | n | areal shrinkage | iterations | E_capillary fixed | E_capillary free | G fixed | G free | seconds |")
    print("|---:|---|---|---|---|---|---|---|---|")
    for beta in sorted({r["beta"] for r in rows}):
        all_b = [r for r in rows if r["beta"] == beta]
        ok = [r for r in all_b if r["converged"]]
        print(f"| {beta} | {len(ok)} of {len(all_b)} | {mean_sd([r['shrinkage'] for r in ok])} | "
              f"{mean_sd([float(r['iterations']) for r in ok])} | {mean_sd([r['E0'] for r in ok])} | "
              f"{mean_sd([r['E1'] for r in ok])} | {mean_sd([r['G0'] for r in ok])} | {mean_sd([r['G1'] for r in ok])} | "
              f"{mean_sd([r['seconds'] for r in ok])} |")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
