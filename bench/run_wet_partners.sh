#!/bin/bash
# The bundle-partner cap (excluded volume, `fibernet wet --bundle-partners N`, docs/wet.md "Bundle partners") on
# networks where 2D stacking matters: one bench/run_wet_pores.sh study per cap, the same networks and betas, into
# OUT/<name>_cap<N> (table.md, runs.csv per cap; interrupted studies continue where they stopped).
#   bench/run_wet_partners.sh [FIBERNET=build/fibernet] [OUT=docs/wet/partners] [CAPS="0 2 6"]
# Networks (default: L = 6 fiber lengths, q = 10, about 360 fibers): pl = 0.2 seed 5 at beta = 0.05 (the floppy network
# of bench/run_wet_robustness.sh that collapses into stacks) and pl = 0.5 seeds 1-2 at beta = 0.3 and 1 (strong
# capillarity, most fibers bundled).
# Environment, for the same study at other sizes, seeds or models (docs/wet.md, "The partner cap over 16 seeds"):
#   L (default 6), SEEDS_02 (default "5"), SEEDS_05 (default "1 2"); either seed list empty: that network is skipped;
#   EXTRA: more `fibernet wet` flags for every run, e.g. "--wet-model smooth --wet-eliminate".
set -euo pipefail
FIBERNET=${1:-build/fibernet}; OUT=${2:-docs/wet/partners}; CAPS=${3:-"0 2 6"}
L=${L:-6}; SEEDS_02=${SEEDS_02-5}; SEEDS_05=${SEEDS_05-1 2}; EXTRA=${EXTRA:-}
here=$(dirname "$0")
for cap in $CAPS; do
  [ -z "$SEEDS_02" ] || "$here/run_wet_pores.sh" "$FIBERNET" "$OUT/pl0.2_cap$cap" "$L" "$SEEDS_02" 0.05 0.2 \
      "--bundle-partners $cap${EXTRA:+ $EXTRA}"
  [ -z "$SEEDS_05" ] || "$here/run_wet_pores.sh" "$FIBERNET" "$OUT/pl0.5_cap$cap" "$L" "$SEEDS_05" 0.3,1 0.5 \
      "--bundle-partners $cap${EXTRA:+ $EXTRA}"
done
