#!/bin/bash
# The active-set loop across the parameter space (issue 6: "terminates on every test network and reports what it
# did"), beyond the tests' small networks: 9 wet relaxations of about 360 fibers (L = 6 or 5 fiber lengths) over
# density q, crosslink probability pl, beta and both discretizations, one after another, moduli off. Prints one line
# per run: status, rounds (local), bridges initial -> final, bundles (largest; aligned bridges per segment of a
# bundled fiber: how many other fibers' segments each lies along), solver iterations, seconds.
#   bench/run_wet_robustness.sh [FIBERNET=build/fibernet] [OUT=/tmp/wet_robustness] [EXTRA=""]
# EXTRA: more `fibernet wet` flags for every run, e.g. "--bundle-partners 2".
set -euo pipefail
FIBERNET=${1:-build/fibernet}; OUT=${2:-/tmp/wet_robustness}; EXTRA=${3:-}
mkdir -p "$OUT"
#      L q  pl  beta scheme seed
for cfg in "6 10 0.5 0.1 seed 1" "6 10 0.5 1 seed 2" "6 6 0.5 0.01 seed 3" "6 20 0.5 0.01 seed 4" \
           "6 10 0.2 0.05 seed 5" "6 10 1.0 0.05 seed 6" "6 10 0.5 0.05 even 7" "5 15 0.5 0.3 even 8" \
           "6 10 0.0 0.02 seed 9"; do
  set -- $cfg
  name="L$1_q$2_pl$3_b$4_$5_s$6"
  start=$(date +%s.%N)
  rc=0
  OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} \
    "$FIBERNET" wet --L "$1" --q "$2" --pl "$3" --beta "$4" --scheme "$5" --seed "$6" --no-moduli -q $EXTRA \
    > "$OUT/$name.json" 2> "$OUT/$name.err" || rc=$?
  secs=$(echo "$(date +%s.%N) - $start" | bc)
  /usr/bin/python3 - "$OUT/$name.json" "$name" "$rc" "$secs" <<'PY'
import json, sys
path, name, rc, secs = sys.argv[1:]
try:
    d = json.load(open(path))
except Exception as e:
    print(f"{name}: exit {rc}, no JSON ({e})")
    sys.exit(0)
for r in d["runs"]:
    ev = r["events"]
    print(f"{name}: exit {rc}, {r['status']}, {ev['rounds']} rounds ({ev['local_rounds']} local, "
          f"{ev['cycles_broken']} cycles broken), bridges {r['bridges']['initial']} -> {r['bridges']['final']}, "
          f"largest bundle {r['bundles']['largest']} of {d['network']['fibers']} fibers, "
          f"{r['bundles']['bundled_fibers']} bundled with {r['bundles']['aligned_bridges']} aligned bridges "
          f"({2 * r['bundles']['aligned_bridges'] / max(1, r['bundles']['bundled_fibers'] * d['model']['segments'] / d['network']['fibers']):.1f} per bundled segment), "
          f"{r['solver_iterations']} solver iterations, {float(secs):.1f} s")
PY
done
