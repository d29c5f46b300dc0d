#!/bin/bash
# Wet relaxation over network seeds (issue 6): the wet path is sensitive to round-off and events, so one network is
# not a benchmark. Runs build/bench_wet for seeds S0..S (S0=1 unless set in the environment) and prints one line per
# seed plus the totals.
#   [OUT=runs.jsonl] bench/run_wet_seeds.sh BUILD_DIR [N=100] [S=6] [beta=0.01] [scheme=seed] [move_margin=0.1]
#                                            [round_iterations=10] [warm_start=1] [newton_ldl=1] [local_fraction=0.25]
set -euo pipefail
B=${1:?build dir}; N=${2:-100}; S=${3:-6}; S0=${S0:-1}; BETA=${4:-0.01}; SCHEME=${5:-seed}; MARGIN=${6:-0.1}; ROUNDIT=${7:-10}; WARM=${8:-1}; LDL=${9:-1}; LOCAL=${10:-0.25}
for s in $(seq "$S0" "$S"); do
  OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} OPENBLAS_NUM_THREADS=1 "$B/bench_wet" "$N" 10 "$BETA" 1000 500 "$SCHEME" "$s" "$MARGIN" "$ROUNDIT" "$WARM" "$LDL" "$LOCAL"
done | tee "${OUT:-/dev/null}" | /usr/bin/python3 "$(dirname "$0")/summarize_wet_seeds.py"
