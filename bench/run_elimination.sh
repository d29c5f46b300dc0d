#!/usr/bin/env bash
# Nonlinear elimination against plain Newton (issue 23; docs/solvers.md "Nonlinear elimination"): the default scene's
# network grown to L (q = 8, pl = 1, seed SEED, even scheme), dangling fibers and end arms pruned, simple shear
# gamma = 0.01 from the affine start, Newton to tol 1e-10 (or its round-off floor), with elimination (the default since
# 2026-12-04) and without it (--no-eliminate).
# One row per (L, method): global iterations and factorizations, the local solves' counts, seconds, max|g| and the
# stress, so the two equilibria can be compared.
#   bench/run_elimination.sh                # L = 10 20 40
#   LS="80" METHODS="eliminate" bench/run_elimination.sh
# Environment: FIBERNET (default build/fibernet), LS, METHODS ("plain eliminate"), SEED (1), GAMMA (0.01).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${FIBERNET:-$root/build/fibernet}
printf "L\tseed\tmethod\tdofs\tstatus\titerations\tfactorizations\tlocal_solves\tlocal_iterations\tseconds\tgrad_max\tsigma_xy\tload\n"
for L in ${LS:-10 20 40}; do
    for method in ${METHODS:-plain eliminate}; do
        flags=()
        [ "$method" = plain ] && flags=(--no-eliminate)
        load=$(cut -d' ' -f1 /proc/loadavg)
        rc=0
        json=$("$exe" relax "$root/problems/default.toml" --L "$L" --seed "${SEED:-1}" --gamma "${GAMMA:-0.01}" \
            --prune dangling ends "${flags[@]}" -q) || rc=$?
        JSON=$json /usr/bin/python3 - "$L" "${SEED:-1}" "$method" "$load" <<'PY'
import json, os, sys
L, seed, method, load = sys.argv[1:]
j = json.loads(os.environ["JSON"])
s = j["solver"]
xy = j["stress"]["xy"] if j.get("stress") else float("nan")
row = [L, seed, method, j["model"]["dofs"], j["status"], s["iterations"], s["factorizations"], s["local_solves"],
       s["local_iterations"], f'{s["seconds"]["total"]:.3f}', f'{s["grad_max"]:.2e}', f"{xy:.12g}", load]
print("\t".join(str(x) for x in row))
PY
        [ "$rc" = 0 ] || echo "L = $L $method: exit $rc" >&2
    done
done
