#!/usr/bin/env bash
# OpenBLAS's and CHOLMOD's threads (docs/benchmarks.md, "OpenBLAS's and CHOLMOD's threads"): the commands a user runs,
# with two builds alternated (bench/time_builds.sh), first with the threads a user gets by default, then on one
# thread (FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1, as the benchmarks run).
#   bench/run_library_threads.sh /tmp/base/build/fibernet build/fibernet     # about 25 min on 2 cores
# Environment: REPEATS (per build and case, default 2), ONE_THREAD_ONLY=1 / DEFAULT_ONLY=1 to run half.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -eq 2 ] || { echo "usage: $0 BASE_EXE NEW_EXE" >&2; exit 2; }
base=$(realpath "$1") new=$(realpath "$2")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
"$new" generate --L 3.1623 --q 10 --pl 0.5 --seed 1 -o w100.net 2>/dev/null
"$new" generate --L 4 --q 8 --pl 0.5 --seed 3 -o w128.net 2>/dev/null
"$new" generate --L 4 --q 10 --pl 0.5 --seed 1 -o w160.net 2>/dev/null
p=$root/problems/default.toml
cases=(
    "modulus $p -q"
    "relax $p --L 10 --gamma 0.01 --prune dangling ends -q"
    "relax $p --L 20 --gamma 0.01 --prune dangling ends -q"
    "relax $p --L 40 --gamma 0.01 --prune dangling ends -q"
    "wet --network w160.net --betas 0.1 --no-moduli -q -o OUT"
    "wet --network w100.net --betas 0.01 --wet-model smooth --bundle-partners 2 --wet-schwarz 500 --wet-schwarz-overlap 8 --no-moduli -q -o OUT"
    "wet --network w128.net --betas 1 --wet-model smooth --wet-eliminate --no-moduli -q -o OUT"
)
row() {
    local label=$1 c=$2 out
    # shellcheck disable=SC2086
    out=$("$root/bench/time_builds.sh" "$base" "$new" "${REPEATS:-2}" $c 2>/dev/null | tail -4 | tr '\n' ' ')
    echo "$label | $c | $out"
}
if [ -z "${ONE_THREAD_ONLY:-}" ]; then
    for c in "${cases[@]}"; do row "default threads" "$c"; done
fi
if [ -z "${DEFAULT_ONLY:-}" ]; then
    export FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
    for c in "${cases[@]}"; do row "one thread" "$c"; done
fi
