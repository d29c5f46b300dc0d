#!/bin/bash
# Runs bench_modulus for the issue-3 table (docs/benchmarks.md): L = 10, 20, 40 (and 80 if asked), both schemes,
# one process per network so that peak memory is per network. Usage: bench/run_modulus_bench.sh BUILD_DIR [L...]
set -euo pipefail
build=${1:-build}
shift || true
Ls=${*:-10 20 40}
printf "L\tscheme\tfibers\tdofs\tt_assembly\tt_analyze\tt_factor\tt_modulus\tratio\tnewton_s\tnewton_it\tnewton_fact\tgrad_max\tstatus\tpeak_MiB\tG\tG_ratio\n"
for L in $Ls; do
  for scheme in even seed; do
    "$build/bench_modulus" "$L" "$scheme" "${GAMMA:-0.01}" 2>/dev/null
  done
done
