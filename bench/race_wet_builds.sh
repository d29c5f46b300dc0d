#!/usr/bin/env bash
# Two builds side by side on one smooth-model wet relaxation, for a change that must keep the path and only cut the
# time of a run too long to finish twice (docs/benchmarks.md): both run at once, one core each, one thread, for
# SECONDS of wall time; the progress lines (`newton: it N  E ...  t T s`) give the seconds at which each reached the
# iterations both reached. Prints per build its last common iteration and the seconds it took there, and whether the
# energies of the common iterations agree in every digit printed (the same path).
#   git worktree add /tmp/base HEAD~1 && cmake -S /tmp/base -B /tmp/base/build -DCMAKE_BUILD_TYPE=Release \
#     && cmake --build /tmp/base/build -j2 --target fibernet
#   bench/race_wet_builds.sh /tmp/base/build/fibernet build/fibernet 600
# Environment: NETWORK (generate flags; default the 1e4-fiber network of issue 22's table: --L 31.623 --q 10 --pl 0.5
# --seed 1), BETA (0.01), FLAGS (wet flags; default --wet-model smooth --bundle-partners 2 --wet-eliminate).
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 BASE_EXE NEW_EXE SECONDS" >&2; exit 2; }
base=$1 new=$2 secs=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# shellcheck disable=SC2086
"$new" generate ${NETWORK:---L 31.623 --q 10 --pl 0.5 --seed 1} -o "$work/w.net" >/dev/null 2>&1 ||
    { echo "$0: generate failed: ${NETWORK:-}" >&2; exit 2; }
export FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
for b in base new; do
    exe=$base
    [ $b = new ] && exe=$new
    # shellcheck disable=SC2086
    timeout "$secs" "$exe" wet --network "$work/w.net" --betas "${BETA:-0.01}" --no-moduli \
        ${FLAGS:---wet-model smooth --bundle-partners 2 --wet-eliminate} -o "$work/out_$b" >/dev/null 2>"$work/$b.log" &
done
wait || true
/usr/bin/python3 - "$work/base.log" "$work/new.log" <<'PY'
import re, sys
runs = []
for path in sys.argv[1:]:
    it = {}
    for line in open(path):
        m = re.match(r"newton: it (\d+)\s+E (\S+)\s+max\|g\| \S+\s+t (\S+)s", line)
        if m:
            it[int(m.group(1))] = (m.group(2), float(m.group(3)))
    runs.append(it)
common = sorted(set(runs[0]) & set(runs[1]))
if not common:
    sys.exit("no common iteration in the progress lines: run longer")
last = common[-1]
same = all(runs[0][k][0] == runs[1][k][0] for k in common)
print("build\tlast_common_iteration\tseconds_there\tlast_iteration")
for name, it in zip(("base", "new"), runs):
    print(f"{name}\t{last}\t{it[last][1]:.1f}\t{max(it)}")
print(f"ratio base/new at iteration {last}: {runs[0][last][1] / runs[1][last][1]:.2f}; "
      f"same path: {'yes' if same else 'NO'} ({len(common)} common progress lines)")
PY
