#!/bin/bash
# Runs bench_modulus for the issue-3 table (docs/benchmarks.md): L = 10, 20, 40 (and 80 if asked), both schemes,
# one process per network so that peak memory is per network. Usage: bench/run_modulus_bench.sh BUILD_DIR [L...]
# Environment: GAMMA (default 0.01; 0 skips the strained solve), PRUNE (none | ends | dangling,ends; default none),
# SCHEMES (default "even seed").
set -euo pipefail
build=${1:-build}
shift || true
Ls=${*:-10 20 40}
printf "prune\tL\tscheme\tfibers\tdofs\tt_assembly\tt_analyze\tt_factor\tt_modulus\tratio\tnewton_s\tnewton_it\tnewton_fact\tgrad_max\tstatus\tpeak_MiB\tG\tG_ratio\n"
for L in $Ls; do
  for scheme in ${SCHEMES:-even seed}; do
    printf "%s\t" "${PRUNE:-none}"
    "$build/bench_modulus" "$L" "$scheme" "${GAMMA:-0.01}" "${PRUNE:-none}" 2>/dev/null
  done
done
