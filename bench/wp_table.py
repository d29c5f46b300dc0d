#!/usr/bin/env python3
"""The work-precision tables of docs/solvers.md from bench_solvers --mode wp's runs.csv and trace.csv: each run's
final state (status, seconds, max|g|), then the Newton variants' time to max|g| <= 1e-6 and 1e-10. Solvers absent
from runs.csv are left out (a run of only the Newton variants gives their columns alone).

    /usr/bin/python3 bench/wp_table.py docs/solvers
"""
import csv, collections, sys
d = sys.argv[1]
runs = list(csv.DictReader(open(d + '/runs.csv')))
order = ["newton", "newton+eliminate", "newton+eliminate+median", "lbfgs-hessian", "ipopt", "lbfgs", "nlopt-lbfgs", "nlopt-var2", "nlopt-tnewton", "cg", "fire"]
code = {"converged": "**conv**", "iteration_limit": "budget", "failed": "failed", "line_search_failed": "LS-fail", "stalled": "stalled", "non_finite": "non-finite"}
present = {r['solver'] for r in runs}
order = [s for s in order if s in present]
newtons = [s for s in order if s.startswith("newton")]
cases = []
by = collections.defaultdict(dict)
for r in runs:
    if r['case'] not in cases: cases.append(r['case'])
    by[r['case']][r['solver']] = r
print("| network | DOF | " + " | ".join(order) + " |")
print("|---|---|" + "---|" * len(order))
for c in cases:
    cells = []
    for s in order:
        r = by[c].get(s)
        cells.append("-" if r is None else "%s %.2g s, %.0e" % (code.get(r['status'], r['status']), float(r['seconds']), float(r['grad_max'])))
    print("| %s | %s | %s |" % (c.replace('_g0.05', ''), next(iter(by[c].values()))['dof'], " | ".join(cells)))
# time to 1e-6 and 1e-10 (or the floor) for the Newton variants
tr = list(csv.DictReader(open(d + '/trace.csv')))
print()
print("| network | " + " | ".join("%s to %s" % (s, lev) for lev in ("1e-6", "1e-10") for s in newtons) + " |")
print("|---|" + "---|" * (2 * len(newtons)))
for c in cases:
    cells = []
    for lev in (1e-6, 1e-10):
        for s in newtons:
            ts = [float(t['t']) for t in tr if t['case'] == c and t['solver'] == s and float(t['grad_min']) <= lev]
            cells.append("%.2g s" % min(ts) if ts else "-")
    print("| %s | %s |" % (c.replace('_g0.05', ''), " | ".join(cells)))
