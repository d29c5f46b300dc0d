#!/usr/bin/env bash
# Where a fibernet run spends its time: samples the command's first SECONDS (or all of it, if it ends sooner) with
# `perf record` (software clock, DWARF call graphs, so inlined and LTO'd frames still get their callers) and prints the
# functions with the largest inclusive share ("children": the function and what it calls), then the largest self
# shares. For a run too long to profile whole (a 1e4-fiber wet relaxation), the first minutes; for a later phase, attach
# with `perf record -e cpu-clock -F 199 --call-graph dwarf,16384 -p PID -- sleep 60` and `perf report` as below.
#   bench/profile.sh 60 build/fibernet wet --network w.net --betas 0.01 --wet-model smooth --bundle-partners 2 \
#       --wet-eliminate --no-moduli -q -o out
# Environment: TOP (rows per table, default 30), RATE (samples per second, default 199). Needs perf (linux-perf) and
# kernel.perf_event_paranoid <= 2 or root. One thread (FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1) unless set.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 SECONDS COMMAND [ARGS...]" >&2; exit 2; }
secs=$1
shift
command -v perf >/dev/null || { echo "$0: perf not found (apt-get install linux-perf)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export FIBERNET_THREADS=${FIBERNET_THREADS:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
timeout --signal=INT "$secs" perf record -q -e cpu-clock -F "${RATE:-199}" --call-graph dwarf,16384 \
    -o "$work/perf.data" -- "$@" >/dev/null 2>"$work/run.err" || true
report() {  # --children | --no-children; head closing the pipe early is no error (pipefail)
    perf report -i "$work/perf.data" "$1" --sort symbol -g none 2>/dev/null | grep -v '^#' | grep '%' |
        sed 's/  */ /g' | grep -v '0xffffffffffffffff' | cut -c1-150 | head -n "${TOP:-30}" || true
}
echo "inclusive (children, self) per function:"
report --children
echo
echo "self per function:"
report --no-children
