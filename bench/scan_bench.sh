#!/usr/bin/env bash
# fibernet scan's own costs (docs/benchmarks.md, "Ensembles"): parallel efficiency of mpirun -n 2 against -n 1 on a
# grid of moduli (samples of 0.01 to 2 s), and the fraction of wall time not spent in samples (scheduling, scene
# files, journals, tables) at 10^4 tiny samples (pebble-game rigidity of L = 2 boxes, about 1 ms each).
# Usage: bench/scan_bench.sh [build/fibernet]   (prints one JSON line per run)
set -euo pipefail
fibernet=${1:-build/fibernet}
t=$(mktemp -d /tmp/fibernet_scan_bench_XXXXXX)
trap 'rm -rf "$t"' EXIT
mpi=(mpirun --oversubscribe)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
report() {  # name, directory's run JSON
  python3 -c "import json,sys; j=json.load(open(sys.argv[2]))['run']; print(json.dumps({'run': sys.argv[1], **{k: j[k] for k in ('ranks','samples_run','wall_seconds','sample_seconds','fraction_not_in_samples')}}))" "$1" "$2"
}
moduli=(scan problems/scan_G_q.toml --job modulus --vary a=10,100 --vary q=7,10,14,20,28,40 --vary seed=1:4 -q)
for k in 1 2; do
  "${mpi[@]}" -n $k "$fibernet" "${moduli[@]}" -o "$t/moduli$k" > "$t/moduli$k.json" 2> /dev/null || [ $? -eq 1 ]  # 1: some samples failed
  report "moduli 48 samples, mpirun -n $k" "$t/moduli$k.json"
done
cmp -s "$t/moduli1/samples.csv" "$t/moduli2/samples.csv" && echo '{"check": "moduli rows identical for -n 1 and -n 2"}'
tiny=(scan --L 2 --open --job rigidity --vary seed=1:10000 -q)
"$fibernet" "${tiny[@]}" -o "$t/tiny_serial" > "$t/tiny_serial.json"
report "rigidity 10^4 tiny samples, serial" "$t/tiny_serial.json"
"${mpi[@]}" -n 2 "$fibernet" "${tiny[@]}" -o "$t/tiny2" > "$t/tiny2.json"
report "rigidity 10^4 tiny samples, mpirun -n 2" "$t/tiny2.json"
