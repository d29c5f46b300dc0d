#!/usr/bin/env bash
# Newton's shift floor at the median diagonal against the mean (docs/solvers.md "Newton's shift floor"): the same
# cases with each executable given, one row per case and executable. Compare a build from before 2026-12-04 (floor at
# 1e-13 mean diag) with one from after (the dry commands floor at 1e-13 median diag):
#   git worktree add /tmp/base 634ec70 && cmake -S /tmp/base -B /tmp/base/build -DCMAKE_BUILD_TYPE=Release \
#     && cmake --build /tmp/base/build -j2 --target fibernet
#   bench/run_shift_floor.sh /tmp/base/build/fibernet build/fibernet
# Cases (CASES, default "seed_relax seed_sweep even20 seed40"; add even80 for the 7-minute L = 80 solve):
#   seed_relax  a floppy seed-scheme network (the soak's case 112: L 3.398, q 10.61, pl 0.472), relaxed at gamma 1e-4
#   seed_sweep  the same network swept to gamma 0.02 (step 0.01)
#   even20      the default scene at L = 20, pruned, gamma 0.01 (even scheme; elimination on)
#   seed40      the same at L = 40 on the seed scheme
#   even80      the default scene at L = 80, pruned, gamma 0.01
# Columns: case, executable, status, iterations (sweep: steps), factorizations, seconds, max|g| (sweep: largest of the
# steps), energy (sweep: sigma_xy at the end).
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 FIBERNET [FIBERNET ...]" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
net=(--L 3.398 --q 10.61 --pl 0.472 --scheme seed --seed 3830921700)
big=("$root/problems/default.toml" --gamma 0.01 --prune dangling ends)
row() {  # case exe json
    /usr/bin/python3 - "$@" <<'PY'
import json, sys
case, exe, path = sys.argv[1:]
j = json.load(open(path))
s = j["solver"]
print("\t".join([case, exe, j["status"], str(s["iterations"]), str(s["factorizations"]),
                 "%.1f" % s["seconds"]["total"], "%.2e" % s["grad_max"], "%.15g" % j["energy"]["total"]]))
PY
}
printf "case\texecutable\tstatus\titerations\tfactorizations\tseconds\tgrad_max\tenergy_or_sigma_xy\n"
for c in ${CASES:-seed_relax seed_sweep even20 seed40}; do
    for exe in "$@"; do
        out="$work/out.json"
        case $c in
            seed_relax) "$exe" relax "${net[@]}" --gamma 0.0001 -q > "$out" || true; row "$c" "$exe" "$out" ;;
            even20) "$exe" relax "${big[@]}" --L 20 -q > "$out" || true; row "$c" "$exe" "$out" ;;
            seed40) "$exe" relax "${big[@]}" --L 40 --scheme seed -q > "$out" || true; row "$c" "$exe" "$out" ;;
            even80) "$exe" relax "${big[@]}" --L 80 -q > "$out" || true; row "$c" "$exe" "$out" ;;
            seed_sweep)
                t0=$(date +%s.%N)
                "$exe" sweep "${net[@]}" --gamma-max 0.02 --step 0.01 -q -o "$work/s.csv" > "$out" || true
                t1=$(date +%s.%N)
                /usr/bin/python3 - "$c" "$exe" "$work/s.csv" "$t0" "$t1" <<'PY'
import csv, sys
case, exe, path, t0, t1 = sys.argv[1:]
r = list(csv.DictReader(open(path)))[1:]
print("\t".join([case, exe, "completed" if r and float(r[-1]["gamma"]) >= 0.02 else "incomplete", str(len(r)),
                 str(sum(int(x["factorizations"]) for x in r)), "%.1f" % (float(t1) - float(t0)),
                 "%.2e" % max(float(x["grad_max"]) for x in r), "%.15g" % float(r[-1]["sigma_xy"])]))
PY
                rm -f "$work"/s.csv* ;;
            *) echo "unknown case $c" >&2; exit 2 ;;
        esac
    done
done
