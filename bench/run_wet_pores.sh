#!/bin/bash
# Pore growth against capillary strength over network seeds (issue 6, "A sweep over beta shows pore growth"): one
# `fibernet wet` beta sweep per seed on the same kind of network, then bench/plot_wet_pores.py summarizes the pores,
# bundles and moduli per beta (mean and spread over the seeds). A seed whose summary.json is complete is not run
# again, so an interrupted study continues where it stopped.
#   bench/run_wet_pores.sh [FIBERNET=build/fibernet] [OUT=docs/wet/pores_study] [L=10] [SEEDS="1 2 3"]
#                          [BETAS=0,0.003,0.01,0.03,0.1,0.3,1] [PL=0.5] [EXTRA=""]
# EXTRA: more `fibernet wet` flags for every run, e.g. "--bundle-partners 2" (recorded in study.json).
# The network: L x L fiber lengths at q = 10, crosslink probability PL (0.5: the thesis's wet networks), seed scheme,
# all crossings wet.
set -euo pipefail
FIBERNET=${1:-build/fibernet}; OUT=${2:-docs/wet/pores_study}; L=${3:-10}; SEEDS=${4:-"1 2 3"}
BETAS=${5:-0,0.003,0.01,0.03,0.1,0.3,1}; PL=${6:-0.5}; EXTRA=${7:-}
mkdir -p "$OUT"
# The study's parameters, for the summary (plot_wet_pores.py); each seed's summary.json has them too (`parameters`).
printf '{"L": %s, "q": 10, "pl": %s, "seeds": "%s", "betas": "%s", "scheme": "seed", "extra": "%s"}\n' "$L" "$PL" \
  "$SEEDS" "$BETAS" "$EXTRA" \
  > "$OUT/study.json"
for s in $SEEDS; do
  d="$OUT/seed$s"
  if [ -f "$d/summary.json" ] && grep -q '"complete": true' "$d/summary.json"; then
    echo "seed $s: done already ($d)" >&2
    continue
  fi
  echo "seed $s: fibernet wet --L $L --q 10 --pl $PL --seed $s --betas $BETAS $EXTRA -o $d" >&2
  start=$(date +%s)
  OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} \
    "$FIBERNET" wet --L "$L" --q 10 --pl "$PL" --seed "$s" --betas "$BETAS" $EXTRA -o "$d" > /dev/null 2> "$OUT/seed$s.log" || {
      rc=$?
      echo "seed $s: fibernet wet exited $rc (see $OUT/seed$s.log); its summary.json says which betas did not settle" >&2
    }
  echo "seed $s: $(( $(date +%s) - start )) s" >&2
done
/usr/bin/python3 "$(dirname "$0")/plot_wet_pores.py" "$OUT"
