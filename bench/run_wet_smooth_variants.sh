#!/usr/bin/env bash
# The smooth model's Newton strategies and partner cap against each other (issue 22; docs/benchmarks.md, "Projected
# Newton and the partner cap"): bench/run_wet_models.sh on the smooth model once per variant and network.
#   bench/run_wet_smooth_variants.sh > rows.tsv
# Environment: FIBERNET, CASES ("L Q SEED BETA" per case, ';'-separated), VARIANTS (flag sets, ';'-separated; an empty
# set is the default LDL^T rung without a cap).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cases=${CASES:-"3.1623 10 1 0.01;3.1623 10 1 0.1;4 8 3 1;5.4772 10 1 0.01"}
variants=${VARIANTS:-" ;--bundle-partners 2;--projected;--projected --bundle-partners 2"}
first=1
IFS=';' read -r -a case_list <<< "$cases"
IFS=';' read -r -a variant_list <<< "$variants"
for c in "${case_list[@]}"; do
    read -r L Q SEED BETA <<< "$c"
    for v in "${variant_list[@]}"; do
        v=$(echo "$v" | xargs)  # trim
        out=$(L=$L Q=$Q SEED=$SEED BETA=$BETA MODELS=smooth SMOOTH_FLAGS="$v" "$root/bench/run_wet_models.sh")
        if [ "$first" = 1 ]; then echo "$out" | head -1; first=0; fi
        echo "$out" | tail -n +2
    done
done
