#!/usr/bin/env bash
# Reproduces docs/percolation/ (issue 4 part 4): rigidity (d = 0) and connectivity spanning probabilities of
# clamped open Mikado networks for pl = 1.0, 0.9, 0.7, 0.5, 0.4 and L = 8 .. 48 fiber lengths, 40 samples per
# (L, q), densities in steps of 0.25 over a window that holds both transitions; then the fits (q_1/2 per L; q_c,
# nu from the shifts and from the probit widths) and the charts.
# Cost: 29 min wall on the shared 2-core machine (load ~8; 57 CPU-min of per-sample time, mostly network generation).
# Interrupt at will: rerunning continues every CSV where it stopped; on complete CSVs it only refits and redraws
# (3-7 s; the sample CSVs stay byte-identical).
# Usage: bench/run_percolation.sh [path to fibernet, default build/fibernet]
set -euo pipefail
cd "$(dirname "$0")/.."
FN=${1:-build/fibernet}
OUT=docs/percolation
mkdir -p "$OUT"
run() {  # pl q_min q_max
    "$FN" percolation --pl "$1" --L 8,12,16,24,32,48 --q-min "$2" --q-max "$3" --q-step 0.25 --samples 40 \
        --seed 1 --threads 2 --resume --out "$OUT/samples_pl$1.csv" --table "$OUT/P_pl$1.csv" \
        --summary "$OUT/summary_pl$1.json"
}
run 1.0 5.0 8.5
run 0.9 5.5 9.0
run 0.7 6.5 10.5
run 0.5 7.5 12.5
run 0.4 8.5 14.5
# Charts need matplotlib (python3-matplotlib; Debian's python, hence /usr/bin/python3).
/usr/bin/python3 bench/plot_percolation.py "$OUT"
