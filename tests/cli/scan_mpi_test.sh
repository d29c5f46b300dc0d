#!/usr/bin/env bash
# fibernet scan under MPI (src/cli/scan_mpi.cpp): mpirun -n 1, 2 and 3 give the rows of a serial run bit for bit, and
# a scan whose rank is killed mid-run resumes to the same rows. Usage: scan_mpi_test.sh FIBERNET MPIRUN
set -euo pipefail
fibernet=$1
mpirun=$2
t=$(mktemp -d /tmp/fibernet_scan_mpi_XXXXXX)
trap 'rm -rf "$t"' EXIT
mpi=("$mpirun" --oversubscribe)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
grid=(--L 4 --scheme even --prune dangling --vary q=6,8,12 --vary a=10,100 --vary seed=1:3 --job modulus -q)
fail() { echo "scan_mpi_test: FAIL: $*" >&2; exit 1; }

"$fibernet" scan "${grid[@]}" -o "$t/serial" > "$t/serial.json"
for k in 1 2 3; do
  "${mpi[@]}" -n $k "$fibernet" scan "${grid[@]}" -o "$t/mpi$k" > "$t/mpi$k.json" 2> "$t/mpi$k.err" ||
    fail "mpirun -n $k exited $? ($(head -c 400 "$t/mpi$k.err"))"
  cmp -s "$t/serial/samples.csv" "$t/mpi$k/samples.csv" || fail "mpirun -n $k: samples.csv differs from the serial run"
  cmp -s "$t/serial/summary.csv" "$t/mpi$k/summary.csv" || fail "mpirun -n $k: summary.csv differs from the serial run"
  grep -q "\"ranks\": $k" "$t/mpi$k.json" || fail "mpirun -n $k: the summary does not say $k ranks"
  grep -q '"transport": "mpi"' "$t/mpi$k.json" || fail "mpirun -n $k: not run over MPI"
  journals=$(ls "$t/mpi$k/journal" | wc -l)
  [ "$journals" -eq "$k" ] || fail "mpirun -n $k: $journals journals, expected one per rank"
  echo "scan_mpi_test: mpirun -n $k: the serial rows, bit for bit"
done

# Kill a rank once two samples are journaled; mpirun takes the job down; --resume (over MPI again) completes it.
# Slower samples here (about 0.2 s each, 24 of them), so that the kill comes mid-run.
grid=(--L 10 --scheme even --prune dangling --vary q=8,12 --vary seed=1:12 --job modulus -q)
"${mpi[@]}" -n 2 "$fibernet" scan "${grid[@]}" -o "$t/killed" > /dev/null 2> "$t/killed.err" &
launcher=$!
rank1=""
for _ in $(seq 1 1000); do
  n=$( (cat "$t"/killed/journal/*.jsonl 2>/dev/null || true) | wc -l)
  rank1=$(pgrep -n -P "$launcher" -f "scan" || true)  # a rank (a child of mpirun), the newest
  [ "$n" -ge 2 ] && [ -n "$rank1" ] && break
  sleep 0.01
done
[ -n "$rank1" ] || fail "no rank found to kill"
kill -KILL "$rank1" || true
wait "$launcher" && fail "mpirun exited 0 after a rank was killed" || true
kept=$( (cat "$t"/killed/journal/*.jsonl || true) | grep -c '"index"' || true)
[ "$kept" -ge 2 ] || fail "only $kept samples journaled before the kill"
[ "$kept" -lt 24 ] || fail "all 24 samples finished before the kill: nothing tested"
"$fibernet" scan "${grid[@]}" -o "$t/serial_slow" > /dev/null
"${mpi[@]}" -n 2 "$fibernet" scan "${grid[@]}" --resume -o "$t/killed" > "$t/resumed.json" 2> "$t/resumed.err" ||
  fail "the resumed scan exited $? ($(head -c 400 "$t/resumed.err"))"
cmp -s "$t/serial_slow/samples.csv" "$t/killed/samples.csv" || fail "after a killed rank and --resume: samples.csv differs"
echo "scan_mpi_test: a rank killed after $kept samples; --resume gives the serial rows"

# fibernet percolation on the same ranks: the rows (sorted: they arrive as they finish) and the fits of a serial run.
perc=(percolation --pl 1 --L 3,4 --q-min 5 --q-max 7 --q-step 0.5 --samples 10 -q)
"$fibernet" "${perc[@]}" --threads 1 --out "$t/perc_serial.csv" > "$t/perc_serial.json"
"${mpi[@]}" -n 3 "$fibernet" "${perc[@]}" --out "$t/perc_mpi.csv" > "$t/perc_mpi.json" 2> "$t/perc_mpi.err" ||
  fail "percolation under mpirun -n 3 exited $? ($(head -c 400 "$t/perc_mpi.err"))"
rows() { tail -n +2 "$1" | cut -d, -f1-9 | sort; }
[ "$(rows "$t/perc_serial.csv")" = "$(rows "$t/perc_mpi.csv")" ] || fail "percolation: the MPI rows differ from the serial ones"
fits() { python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print(json.dumps([j['per_L'], j['scaling']], sort_keys=True))" "$1"; }
[ "$(fits "$t/perc_serial.json")" = "$(fits "$t/perc_mpi.json")" ] || fail "percolation: the MPI fits differ from the serial ones"
echo "scan_mpi_test: percolation on 3 ranks: the serial rows and fits"
