#!/usr/bin/env bash
# The exact comparison of pebble-game rigidity with the elastic Hessian (issue 4 part 3, docs/rigidity.md) from the
# command line: 5 x 40 open networks of about 40 fibers across q and pl; prints one summary line per run.
# Usage: bench/compare_elastic.sh [path to fibernet, default build/fibernet]
set -euo pipefail
cd "$(dirname "$0")/.."
FN=${1:-build/fibernet}
for spec in "4 0.6 3.16" "5 0.7 2.83" "6 0.8 2.58" "7 0.9 2.39" "8 1.0 2.24"; do
    set -- $spec
    { "$FN" compare --open --q "$1" --pl "$2" --L "$3" --seed 1 --samples 40 -q | /usr/bin/python3 -c "
import json, sys
j = json.load(sys.stdin); g = j['gaps']
print(f\"q=$1 pl=$2 L=$3: {j['agree']}/{j['networks']} agree; zero eigenvalues <= {g['largest_zero_eigenvalue']:.2e}, \"
      f\"non-zero >= {g['smallest_nonzero_eigenvalue']:.2e}; |G| (d=3) <= {g['largest_abs_G_with_d_3']:.2e}, \"
      f\"G (d<3) >= {g['smallest_G_with_d_below_3'] or float('nan'):.2e}; {j['seconds']:.1f} s\")
for r in j['disagreements']: print('  disagreement:', json.dumps(r))"; } || true  # compare exits 1 on a disagreement
done
