#!/usr/bin/env python3
"""Pore growth against capillary strength over seeds, from bench/run_wet_pores.sh's output directory.

Reads OUT/seed*/{summary.json,pores.csv} (one `fibernet wet --betas ...` sweep per network seed) and writes
  OUT/runs.csv    one row per seed and beta (beta = "dry": the dry network): status, bridges, bundles (fraction of
                  fibers bundled, largest bundle, partners per bundled segment: 2 x aligned bridges / segments of
                  bundled fibers, how many other fibers' segments a bundled segment lies along; capped: aligned
                  crossings and contacts left without a bridge by --bundle-partners), energies, shear modulus, the
                  pore measures below, and the wet relaxation's seconds (solve + events, moduli and pores excluded);
  OUT/table.md    mean and standard deviation over the seeds per beta (stable runs only; the count says how many);
  OUT/pores.png   the pore measures against beta, one line per seed and the mean (needs matplotlib, Debian
                  python3-matplotlib; without it the tables are still written).
Pore measures (areas in seed units^2; the fiber length is 10 seed units on the seed scheme with 10 segments):
  count, mean area, area-weighted mean area sum(A^2)/sum(A) (the size of the pore that a random point of the open
  area lies in: it is not pulled down by the slivers that zipping leaves between aligned fibers, which the plain mean
  counts as pores), d50 (the equivalent diameter sqrt(4A/pi) that splits the pore area in halves: half of it lies in
  pores at least that wide) and the largest pore's area. From summary.json's pores block (fibernet since issue 22;
  blank for older runs): the fractions of the box in walls (slivers inside bundles), faces with islands and open
  faces, and the cover (pores + those over the box area).
Usage: plot_wet_pores.py OUT
"""
import csv
import glob
import json
import math
import os
import statistics
import sys


def pore_measures(areas):
    areas = sorted(a for a in areas if a > 0)
    total = sum(areas)
    if not areas or total <= 0:
        return {"pores": 0, "mean_area": float("nan"), "weighted_area": float("nan"), "d50": float("nan"),
                "largest_area": float("nan")}
    acc, d50 = 0.0, float("nan")
    for a in reversed(areas):  # largest first: the diameter where the larger pores reach half of the area
        acc += a
        if acc >= 0.5 * total:
            d50 = math.sqrt(4 * a / math.pi)
            break
    return {"pores": len(areas), "mean_area": total / len(areas), "weighted_area": sum(a * a for a in areas) / total,
            "d50": d50, "largest_area": areas[-1]}


def face_classes(p):  # the box's non-pore faces and the cover, as fractions of the box (blank before issue 22)
    if "cover" not in p:
        return {"wall_fraction": "", "island_fraction": "", "open_fraction": "", "cover": ""}
    a = p["box_area"]
    return {"wall_fraction": p["wall_area"] / a, "island_fraction": p["island_area"] / a,
            "open_fraction": p["open_area"] / a, "cover": p["cover"]}


def read_seed(d, study):
    seed = int(os.path.basename(d)[len("seed"):])
    with open(os.path.join(d, "summary.json")) as f:
        summary = json.load(f)
    areas = {}
    with open(os.path.join(d, "pores.csv")) as f:
        for row in csv.DictReader(f):
            if row["state"] == "free_box":
                continue
            key = "dry" if row["state"] == "dry" else float(row["beta"])
            areas.setdefault(key, []).append(float(row["area"]))
    fibers = summary["network"]["fibers"]
    pl = summary.get("parameters", {}).get("pl", study.get("pl", ""))
    seg_per_fiber = summary["model"]["segments"] / fibers

    def partners(b):  # segments of other fibers that a bundled segment lies along, on average (2 per bridge)
        return 2 * b["aligned_bridges"] / (b["bundled_fibers"] * seg_per_fiber) if b["bundled_fibers"] else 0.0

    rows = []
    for i, run in enumerate(summary["runs"]):
        if i == 0:  # the dry network (every beta starts from it)
            rows.append({"seed": seed, "beta": "dry", "status": "dry", "fibers": fibers, "pl": pl, "bridges": "",
                         "bundled_fraction": "", "largest_bundle": "", "bundle_partners": "", "capped": "",
                         "E_capillary": 0.0, "seconds": "",
                         "E_bend": run["energy"]["dry"]["bend"], "G": run["shear_modulus"]["dry"],
                         **pore_measures(areas.get("dry", [])), **face_classes(run["pores"]["dry"])})
        beta = run["beta"]
        rows.append({"seed": seed, "beta": beta, "status": run["status"], "fibers": fibers, "pl": pl,
                     "bridges": run["bridges"]["final"],
                     "bundled_fraction": run["bundles"]["bundled_fibers"] / fibers,
                     "largest_bundle": run["bundles"]["largest"], "bundle_partners": partners(run["bundles"]),
                     "capped": run["events"].get("capped", 0),
                     "seconds": run["seconds"]["wet_solve"] + run["seconds"]["events"],
                     "E_capillary": run["energy"]["wet"]["capillary"],
                     "E_bend": run["energy"]["wet"]["bend"], "G": run["shear_modulus"]["wet"],
                     **pore_measures(areas.get(float(beta), [])), **face_classes(run["pores"]["wet"])})
    return summary.get("complete", False), rows


def main(out):
    rows, incomplete = [], []
    study_path = os.path.join(out, "study.json")  # written by run_wet_pores.sh
    study = json.load(open(study_path)) if os.path.exists(study_path) else {}
    dirs = [d for d in glob.glob(os.path.join(out, "seed*"))
            if os.path.isdir(d) and os.path.basename(d)[4:].isdigit() and os.path.exists(os.path.join(d, "summary.json"))]
    for d in sorted(dirs, key=lambda p: int(os.path.basename(p)[4:])):
        complete, r = read_seed(d, study)
        if not complete:
            incomplete.append(os.path.basename(d))
        rows.extend(r)
    if not rows:
        sys.exit(f"plot_wet_pores.py: no seed*/summary.json under {out}")
    cols = ["seed", "beta", "status", "fibers", "pl", "bridges", "bundled_fraction", "largest_bundle", "bundle_partners",
            "capped", "E_capillary", "seconds",
            "E_bend", "G", "pores", "mean_area", "weighted_area", "d50", "largest_area", "wall_fraction",
            "island_fraction", "open_fraction", "cover"]
    with open(os.path.join(out, "runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.6g}" if isinstance(r[k], float) else r[k]) for k in cols})

    keys = ["dry"] + sorted({r["beta"] for r in rows if r["beta"] != "dry"})
    measures = [("bridges", "bridges", "{:.0f}"), ("bundled_fraction", "bundled fibers", "{:.2f}"),
                ("largest_bundle", "largest bundle", "{:.1f}"), ("bundle_partners", "partners per bundled segment", "{:.2f}"),
                ("capped", "capped (bundle_partners)", "{:.0f}"), ("E_capillary", "E_capillary", "{:.3g}"),
                ("G", "G", "{:.3g}"), ("pores", "pores", "{:.0f}"), ("mean_area", "mean area", "{:.2f}"),
                ("weighted_area", "area-weighted mean area", "{:.1f}"), ("d50", "d50", "{:.2f}"),
                ("largest_area", "largest pore", "{:.0f}"), ("wall_fraction", "walls (box fraction)", "{:.3f}"),
                ("island_fraction", "island faces", "{:.3f}"), ("open_fraction", "open faces", "{:.3f}"),
                ("cover", "cover", "{:.4f}"), ("seconds", "wet solve + events, s", "{:.1f}")]

    def stat(key, m):
        v = [r[m] for r in rows if r["beta"] == key and r["status"] in ("dry", "stable") and r[m] != ""]
        v = [x for x in v if isinstance(x, (int, float)) and math.isfinite(x)]
        if not v:
            return "", 0.0, 0
        mean = statistics.fmean(v)
        return mean, statistics.stdev(v) if len(v) > 1 else 0.0, len(v)

    seeds = sorted({r["seed"] for r in rows})
    extra = f" Extra flags: `{study['extra']}`." if study.get("extra") else ""
    lines = [f"Mean +- standard deviation over {len(seeds)} network seeds ({', '.join(map(str, seeds))}); "
             f"stable runs only (n).{extra}", ""]
    lines.append("| beta | n | " + " | ".join(label for _, label, _ in measures) + " |")
    lines.append("|---" * (len(measures) + 2) + "|")
    for key in keys:
        cells, n = [], 0
        for m, _, fmt in measures:
            mean, sd, k = stat(key, m)
            if k == 0:
                cells.append("")
                continue
            n = max(n, k)
            cells.append(fmt.format(mean) + " +- " + fmt.format(sd))
        lines.append(f"| {key} | {n} | " + " | ".join(cells) + " |")
    unstable = [f"seed {r['seed']} beta {r['beta']}: {r['status']}" for r in rows if r["status"] not in ("dry", "stable")]
    if unstable:
        lines += ["", "Not stable (left out of the means): " + "; ".join(unstable) + "."]
    if incomplete:
        lines += ["", "Incomplete sweeps (interrupted): " + ", ".join(incomplete) + "."]
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot_wet_pores.py: matplotlib not found (Debian: python3-matplotlib); tables written, no picture",
              file=sys.stderr)
        return
    betas = [k for k in keys if k != "dry"]
    positive = [b for b in betas if b > 0]
    xmin = min(positive) / 3 if positive else 1e-3
    x_of = {k: (xmin if k == "dry" or k == 0 else k) for k in keys}  # dry and beta = 0 at the left edge
    panels = [("weighted_area", "area-weighted mean pore area"), ("d50", "d50 (pore diameter, half the area above)"),
              ("pores", "pores"), ("bundled_fraction", "fraction of fibers in bundles")]
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    for ax, (m, title) in zip(axes.flat, panels):
        for s in seeds:
            pts = [(x_of[r["beta"]], r[m]) for r in rows if r["seed"] == s and r["status"] in ("dry", "stable")
                   and r[m] != "" and r["beta"] != "dry"]
            pts.sort()
            if pts:
                ax.plot(*zip(*pts), "o-", color="0.7", lw=0.8, ms=3)
        mean_pts = [(x_of[k], stat(k, m)[0]) for k in betas if stat(k, m)[0] != ""]
        if mean_pts:
            ax.plot(*zip(*mean_pts), "o-", color="C0", lw=2, label="mean over seeds")
        dry = stat("dry", m)
        if dry[0] != "":
            ax.axhline(dry[0], color="C3", ls="--", lw=1, label="dry (mean)")
        ax.set_xscale("log")
        ax.set_xticks([xmin] + positive, ["0"] + [f"{b:g}" for b in positive])
        ax.minorticks_off()
        ax.set_xlabel("beta (bending-energy units per seed unit of bundle length)")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    axes.flat[0].legend()
    fibers = rows[0]["fibers"]
    pl = rows[0].get("pl", "")
    fig.suptitle(f"Wet networks of {fibers} fibers (q = 10{f', pl = {pl}' if pl != '' else ''}): pores against "
                 f"capillary strength, {len(seeds)} seeds")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "pores.png"), dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
