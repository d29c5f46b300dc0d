#!/usr/bin/env python3
"""Where Newton's iterations go: reads the per-iteration lines of `fibernet relax ... -v` or `fibernet wet ... -v`
(stderr) and prints the first iteration below each max|g| level, how the steps were taken (full; backtracked by
halving; shortened by the step cap, SolverOptions::max_step, whose alpha is not a power of 2; and of each, how many came
from an LDL^T direction with flipped negative pivots), then every 10th iteration's energy above the last, max|g| and
step.

    build/fibernet relax problems/default.toml --L 80 --gamma 0.01 --prune dangling ends -v \\
        2> l80.err > l80.json
    /usr/bin/python3 bench/newton_history.py l80.err
"""
import math
import re
import sys

LINE = re.compile(r"newton\s+(\d+)\s+E = (\S+)\s+max\|g\| = (\S+)\s+floor (\S+)\s+rung (\d)\S*.*shift (\S+)\s+alpha (\S+)")
FLIPPED = re.compile(r"\(LDL\^T, ([1-9]\d*) negative pivots\)")


def step_kind(alpha):
    if alpha == 1:
        return "full"
    if alpha <= 0:
        return "none"
    k = math.log2(alpha)
    return "halved" if k == int(k) else "capped"


def main(path):
    rows = []
    kinds = {}
    with open(path) as f:
        for line in f:
            m = LINE.match(line)
            if m:
                rows.append((int(m[1]), float(m[2]), float(m[3]), float(m[4]), float(m[7])))
                kind = kinds.setdefault(step_kind(float(m[7])), [0, 0])
                kind[0] += 1
                kind[1] += FLIPPED.search(line) is not None
    if not rows:
        sys.exit("%s: no Newton iteration lines (run fibernet with -v)" % path)
    e_last, floor = rows[-1][1], rows[-1][3]
    print("iterations %d, last E %.12g, floor bound %.2e" % (len(rows), e_last, floor))
    for level in (1e-1, 1e-2, 1e-3, 1e-4, 5 * floor, 2 * floor):
        k = next((r[0] for r in rows if r[2] < level), None)
        print("first max|g| < %.1e: iteration %s" % (level, k))
    for name in ("full", "halved", "capped", "none"):
        n, flipped = kinds.get(name, [0, 0])
        print("steps %s: %d (%d from LDL^T with flipped pivots)" % (name, n, flipped))
    print("it\tE - E_last\tmax|g|\talpha")
    for r in rows[::10]:
        print("%d\t%.3e\t%.2e\t%g" % (r[0], r[1] - e_last, r[2], r[4]))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
