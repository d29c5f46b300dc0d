#!/usr/bin/env bash
# Newton with and without nonlinear elimination on a wet relaxation (issue 23; docs/solvers.md "Nonlinear
# elimination"): a Mikado network of N = q L^2 fibers (q = Q, pl = 0.5, seed SEED), `fibernet wet` at one beta,
# without moduli. One row per method: status, active-set rounds, solver iterations, the last solve's local solves,
# the wet energy, seconds of wet solving and in all.
#   bench/run_wet_elimination.sh                     # L = 4, q = 8 (128 fibers), beta = 1
#   L=10 Q=10 BETA=0.01 bench/run_wet_elimination.sh # 1000 fibers
# Environment: FIBERNET (default build/fibernet), L, Q, SEED (3), BETA, METHODS ("plain eliminate").
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${FIBERNET:-$root/build/fibernet}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$exe" generate --L "${L:-4}" --q "${Q:-8}" --pl 0.5 --seed "${SEED:-3}" -o "$work/w.net" 2>/dev/null
printf "fibers\tbeta\tmethod\tstatus\trounds\tsolver_iterations\tlocal_solves_last\tE_wet\tseconds_wet_solve\tseconds\n"
for method in ${METHODS:-plain eliminate}; do
    flags=()
    [ "$method" = eliminate ] && flags=(--wet-eliminate)  # [wet] newton_eliminate (before 2026-12-04: --eliminate)
    rc=0
    "$exe" wet --network "$work/w.net" --betas "${BETA:-1}" --no-moduli -o "$work/$method" -q "${flags[@]}" \
        > "$work/$method.json" || rc=$?
    /usr/bin/python3 - "$work/$method.json" "$method" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
r = j["runs"][0]
row = [j["network"]["fibers"], r["beta"], sys.argv[2], r["status"], r["events"]["rounds"], r["solver_iterations"],
       r["solver"].get("local_solves", 0), f'{r["energy"]["wet"]["total"]:.10g}', f'{r["seconds"]["wet_solve"]:.1f}',
       f'{j["seconds"]:.1f}']
print("\t".join(str(x) for x in row))
PY
    [ "$rc" = 0 ] || echo "$method: exit $rc" >&2
done
