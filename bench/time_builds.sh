#!/usr/bin/env bash
# Wall time of one fibernet command with two builds, alternated (base, new, base, new, ...) so that the machine's
# drift hits both alike; for a change that must keep every result and only cut time (docs/benchmarks.md).
#   bench/time_builds.sh /tmp/base/build/fibernet build/fibernet 3 wet --network w.net --betas 0.01 \
#       --wet-model smooth --bundle-partners 2 --no-moduli -q -o OUT
# An argument OUT is replaced by a fresh directory per run. Prints each run's seconds, then per build the median and
# the ratio base/new of the medians, and whether the runs' stdout (with timings, paths and provenance removed, as
# bench/compare_builds.sh does) is the same between the runs of each build and between the builds. Threads as a user gets them unless the environment sets
# FIBERNET_THREADS, OPENBLAS_NUM_THREADS or OMP_NUM_THREADS.
set -euo pipefail
[ $# -ge 4 ] || { echo "usage: $0 BASE_EXE NEW_EXE REPEATS COMMAND [ARGS...]" >&2; exit 2; }
base=$1 new=$2 repeats=$3
shift 3
[[ $repeats =~ ^[1-9][0-9]*$ ]] || { echo "$0: REPEATS = '$repeats': expected a positive integer" >&2; exit 2; }
for exe in "$base" "$new"; do [ -x "$exe" ] || { echo "$0: not an executable: $exe" >&2; exit 2; }; done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
strip_py=$(cd "$(dirname "$0")" && pwd)/strip_timings.py
strip() { /usr/bin/python3 "$strip_py"; }
for ((r = 1; r <= repeats; ++r)); do
    for b in base new; do
        exe=$base
        [ $b = new ] && exe=$new
        args=()
        for a in "$@"; do [ "$a" = OUT ] && a="$work/out_${b}_$r"; args+=("$a"); done
        t0=$(date +%s.%N)
        "$exe" "${args[@]}" > "$work/stdout_${b}_$r" 2> "$work/stderr_${b}_$r" ||
            echo "$b run $r: exit $? (stderr: $work/stderr_${b}_$r)" >&2
        t1=$(date +%s.%N)
        echo "$b $r $(echo "$t1 - $t0" | bc)" | tee -a "$work/times"
        strip < "$work/stdout_${b}_$r" | grep -v "$work" > "$work/clean_${b}_$r" || true
    done
done
/usr/bin/python3 - "$work" "$repeats" <<'PY'
import statistics, sys, filecmp
work, n = sys.argv[1], int(sys.argv[2])
t = {"base": [], "new": []}
for line in open(work + "/times"):
    b, _, s = line.split()
    t[b].append(float(s))
mb, mn = statistics.median(t["base"]), statistics.median(t["new"])
print(f"median base {mb:.2f} s, new {mn:.2f} s, base/new {mb / mn:.2f}")
def same(a, b):
    return filecmp.cmp(f"{work}/clean_{a}", f"{work}/clean_{b}", shallow=False)
for b in ("base", "new"):
    print(f"{b}: results " + ("the same in every run" if all(same(f"{b}_1", f"{b}_{r}") for r in range(2, n + 1))
                             else "DIFFER between its runs (not deterministic)"))
print("base and new: " + ("the same results" if same("base_1", "new_1") else "DIFFERENT results (first runs)"))
PY
