#!/usr/bin/env python3
"""Where Newton's iterations go: reads the per-iteration lines of `fibernet relax ... -v` (stderr) and prints the
first iteration below each max|g| level, then every 10th iteration's energy above the last, max|g| and step.

    build/fibernet relax problems/default.toml --L 80 --gamma 0.01 --prune dangling ends -v \\
        2> l80.err > l80.json
    /usr/bin/python3 bench/newton_history.py l80.err
"""
import re
import sys

LINE = re.compile(r"newton\s+(\d+)\s+E = (\S+)\s+max\|g\| = (\S+)\s+floor (\S+)\s+rung (\d)\S*.*shift (\S+)\s+alpha (\S+)")


def main(path):
    rows = []
    with open(path) as f:
        for line in f:
            m = LINE.match(line)
            if m:
                rows.append((int(m[1]), float(m[2]), float(m[3]), float(m[4]), float(m[7])))
    if not rows:
        sys.exit("%s: no Newton iteration lines (run fibernet with -v)" % path)
    e_last, floor = rows[-1][1], rows[-1][3]
    print("iterations %d, last E %.12g, floor bound %.2e" % (len(rows), e_last, floor))
    for level in (1e-1, 1e-2, 1e-3, 1e-4, 5 * floor, 2 * floor):
        k = next((r[0] for r in rows if r[2] < level), None)
        print("first max|g| < %.1e: iteration %s" % (level, k))
    print("it\tE - E_last\tmax|g|\talpha")
    for r in rows[::10]:
        print("%d\t%.3e\t%.2e\t%g" % (r[0], r[1] - e_last, r[2], r[4]))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
