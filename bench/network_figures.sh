#!/usr/bin/env bash
# Issue 2 figures: model sizes for both schemes at L=10, q=8, pl=1, and generation time for 1e5 and 1e6 fibers.
# Usage: bench/network_figures.sh [build-dir]   (prints a Markdown table)
set -euo pipefail
exe=${1:-build}/fibernet
echo "| scheme | fibers | crosslinks | nodes | DOF | segments | hinges | shortest segment | longest |"
echo "|---|---|---|---|---|---|---|---|---|"
for scheme in seed even; do
  "$exe" info --L 10 --q 8 --pl 1 --seed 1 --scheme "$scheme" | python3 -c "
import json,sys; j=json.load(sys.stdin); m=j['model']; n=j['network']
print(f\"| $scheme | {n['fibers']} | {n['crosslinks']} | {m['nodes']} | {m['dofs']} | {m['segments']} | {m['hinges']} | {m['shortest_segment']:.3g} | {m['longest_segment']:.3g} |\")"
done
echo
echo "| fibers (q=8) | generation seconds (best of 3) | crossings per fiber (2q/pi = 5.093) |"
echo "|---|---|---|"
for N in 100000 1000000; do
  L=$(python3 -c "print(($N/8)**0.5)")
  best=1e9; cpf=0
  for s in 1 2 3; do
    line=$("$exe" generate --L "$L" --q 8 --pl 1 --seed "$s" -o /dev/null 2>&1 >/dev/null | tail -1)
    t=$(python3 -c "import json,sys; print(json.loads(sys.argv[1])['generation_seconds'])" "$line")
    cpf=$(python3 -c "import json,sys; print(json.loads(sys.argv[1])['crossings_per_fiber'])" "$line")
    best=$(python3 -c "print(round(min($best, $t), 3))")
  done
  echo "| $N | $best | $cpf |"
done
