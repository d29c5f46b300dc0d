#!/usr/bin/env bash
# The smooth wet model's pair term with cheaper jets (docs/benchmarks.md, "The pair term's jets: values first, packed
# Hessians"): the per-pair cost (bench_capillary_pair at the test length 0.1 and at the networks' mean segment 0.8),
# then wet relaxations with two builds alternated. The uncapped model's path depends on round-off (docs/wet.md), so
# each run's global and local iteration counts and energy are printed beside its time: compare time per iteration
# where the paths differ.
#   bench/run_pair_jets.sh /tmp/base/build build        # build directories (fibernet and bench_capillary_pair)
# Environment: REPEATS (per build and case, default 2). One thread (FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1
# OMP_NUM_THREADS=1), as the benchmarks run.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -eq 2 ] || { echo "usage: $0 BASE_BUILD_DIR NEW_BUILD_DIR" >&2; exit 2; }
base=$(realpath "$1") new=$(realpath "$2")
for d in "$base" "$new"; do
    for exe in fibernet bench_capillary_pair; do
        [ -x "$d/$exe" ] || { echo "$0: not an executable: $d/$exe" >&2; exit 2; }
    done
done
export FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "## bench_capillary_pair 20000 7 1 LENGTH (us per pair, best of 7)"
for l in 0.1 0.8; do
    for b in base new; do
        d=$base
        [ $b = new ] && d=$new
        echo "length $l, $b: $("$d/bench_capillary_pair" 20000 7 1 $l | awk '{printf "%s %s  ", $1, $2}')"
    done
done
cd "$work"
"$new/fibernet" generate --L 3.1623 --q 10 --pl 0.5 --seed 1 -o w100.net 2>/dev/null
"$new/fibernet" generate --L 4 --q 8 --pl 0.5 --seed 3 -o w128.net 2>/dev/null
"$new/fibernet" generate --L 4 --q 10 --pl 0.5 --seed 1 -o w160.net 2>/dev/null
"$new/fibernet" generate --L 5.4772 --q 10 --pl 0.5 --seed 1 -o w300.net 2>/dev/null
cases=(
    "wet --network w128.net --betas 1 --wet-model smooth --wet-eliminate --no-moduli -q -o OUT"
    "wet --network w160.net --betas 0.1 --wet-model smooth --bundle-partners 2 --no-moduli -q -o OUT"
    "wet --network w100.net --betas 0.01 --wet-model smooth --bundle-partners 2 --wet-schwarz 500 --wet-schwarz-overlap 8 --no-moduli -q -o OUT"
    "wet --network w300.net --betas 0.01 --wet-model smooth --bundle-partners 2 --wet-eliminate --no-moduli -q -o OUT"
    "wet --network w160.net --betas 0.1 --no-moduli -q -o OUT"
)
echo
echo "## wet relaxations: seconds, global iterations, local iterations, E_wet (per run)"
n=0
for c in "${cases[@]}"; do
    n=$((n + 1))
    echo "case $n: fibernet $c"
    for ((r = 1; r <= ${REPEATS:-2}; ++r)); do
        for b in base new; do
            d=$base
            [ $b = new ] && d=$new
            out="$work/out_${n}_${b}_$r"
            # shellcheck disable=SC2086
            args=${c//OUT/$out}
            t0=$(date +%s.%N)
            # shellcheck disable=SC2086
            "$d/fibernet" $args > /dev/null 2> "$work/err" || echo "  $b run $r: exit $? ($(tail -1 "$work/err"))"
            t1=$(date +%s.%N)
            /usr/bin/python3 - "$out/summary.json" "$b" "$(echo "$t1 - $t0" | bc)" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["runs"][0]
s = r.get("smooth") or {}
it = s.get("factorizations", r.get("solver_iterations"))
print(f"  {sys.argv[2]:4s} {float(sys.argv[3]):8.2f} s  global {it}  local {s.get('local_iterations', 0)}  "
      f"E_wet {r['energy']['wet']['total']:.10g}")
PY
        done
    done
done
