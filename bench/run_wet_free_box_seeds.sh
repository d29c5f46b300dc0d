#!/bin/bash
# The free box (drying shrinkage at zero stress; docs/wet.md, "Free box") over network seeds, on either capillary
# model: one `fibernet wet problems/wet_free.toml --seed S --betas BETAS FLAGS` per seed (90 fibers, L = 3, q = 10,
# pl = 0.5, isotropic box, tolerance 1e-3), its JSON kept as OUT/seedS.json (a seed whose JSON is complete is not run
# again, so an interrupted study continues), then bench/free_box_table.py OUT prints a row per seed and beta and the
# mean and spread per beta (table.md).
#   bench/run_wet_free_box_seeds.sh [FIBERNET=build/fibernet] OUT [SEEDS="2 3 4 5"] [BETAS=0.01,0.02,0.05,0.1] [FLAGS=""]
# FLAGS: e.g. "--wet-model smooth --bundle-partners 2". One thread per run (FIBERNET_THREADS, OPENBLAS_NUM_THREADS).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
FIBERNET=${1:-build/fibernet}; OUT=${2:?output directory}; SEEDS=${3:-"2 3 4 5"}; BETAS=${4:-0.01,0.02,0.05,0.1}
FLAGS=${5:-}
mkdir -p "$OUT"
printf '{"scene": "problems/wet_free.toml", "seeds": "%s", "betas": "%s", "flags": "%s"}\n' "$SEEDS" "$BETAS" "$FLAGS" \
  > "$OUT/study.json"
for s in $SEEDS; do
  j="$OUT/seed$s.json"
  if [ -f "$j" ] && /usr/bin/python3 -c "import json,sys; sys.exit(0 if json.load(open('$j')).get('complete') else 1)" 2>/dev/null; then
    echo "seed $s: done already ($j)" >&2
    continue
  fi
  start=$(date +%s)
  # shellcheck disable=SC2086
  FIBERNET_THREADS=${FIBERNET_THREADS:-1} OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 \
    "$FIBERNET" wet "$root/problems/wet_free.toml" --seed "$s" --betas "$BETAS" $FLAGS -q > "$j.tmp" 2> "$OUT/seed$s.log" || {
      rc=$?
      echo "seed $s: fibernet wet exited $rc (see $OUT/seed$s.log)" >&2
      if [ "$rc" = 130 ]; then exit 130; fi
    }
  mv "$j.tmp" "$j"
  echo "seed $s: $(( $(date +%s) - start )) s" >&2
done
/usr/bin/python3 "$root/bench/free_box_table.py" "$OUT" | tee "$OUT/table.md"
