#!/usr/bin/env bash
# Where a clean build's time goes (docs/benchmarks.md, "Build time"): configures a fresh build directory with this
# script as the compiler launcher, builds (all, or TARGET) with -j JOBS, and prints the wall time, the compiler's
# seconds per target and the slowest sources.
#   bench/compile_times.sh /tmp/ct            (a full build; about 10 min on 2 cores)
#   TARGET=catch_main bench/compile_times.sh /tmp/ct
# Environment: JOBS (default nproc), TARGET (default all), TOP (slowest sources listed, default 20). As a launcher
# (first argument --launch) it runs the compiler and appends "seconds object" to $FIBERNET_COMPILE_LOG.
set -euo pipefail
if [ "${1:-}" = --launch ]; then
    shift
    t0=$(date +%s.%N)
    rc=0
    "$@" || rc=$?
    t1=$(date +%s.%N)
    out=""
    prev=""
    for a in "$@"; do [ "$prev" = -o ] && out=$a; prev=$a; done
    echo "$(echo "$t1 - $t0" | bc) $out" >> "$FIBERNET_COMPILE_LOG"
    exit $rc
fi
[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR (a directory that does not exist yet)" >&2; exit 2; }
dir=$1
[ ! -e "$dir" ] || { echo "$0: $dir exists; give a new directory (the build must start clean)" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
self=$root/bench/compile_times.sh
export FIBERNET_COMPILE_LOG=$dir/compile_times.txt
mkdir -p "$dir"
cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER_LAUNCHER="$self;--launch" >/dev/null
t0=$(date +%s.%N)
cmake --build "$dir" -j"${JOBS:-$(nproc)}" ${TARGET:+--target "$TARGET"} >/dev/null
t1=$(date +%s.%N)
printf "wall %.1f s with -j%s\n" "$(echo "$t1 - $t0" | bc)" "${JOBS:-$(nproc)}"
awk '{s += $1} END {printf "compiler %.1f s in all, per target:\n", s}' "$FIBERNET_COMPILE_LOG"
awk '{split($2, p, "/"); t[p[2]] += $1} END {for (k in t) printf "  %7.1f s  %s\n", t[k], k}' "$FIBERNET_COMPILE_LOG" |
    sort -rn
echo "slowest sources:"
sort -rn "$FIBERNET_COMPILE_LOG" | head -n "${TOP:-20}" | awk '{printf "  %7.1f s  %s\n", $1, $2}'
