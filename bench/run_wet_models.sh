#!/usr/bin/env bash
# The event model against the smooth model (issue 22; docs/wet.md "The smooth model", docs/benchmarks.md): a Mikado
# network of N = q L^2 fibers (pl = 0.5), `fibernet wet` at one beta without moduli, once per model. One row per
# model: status, rounds, solver iterations, final bridges (smooth: non-zero segment pairs), the wet energy and its
# capillary part, the smooth model's list and pattern builds and final max|g|, seconds of wet solving and in all.
#   bench/run_wet_models.sh                          # L = 4, q = 8 (128 fibers), seed 3, beta = 1
#   L=3.16 Q=10 SEED=1 BETA=0.01 bench/run_wet_models.sh   # 100 fibers
#   SMOOTH_FLAGS="--projected --bundle-partners 2" MODELS=smooth bench/run_wet_models.sh   # projected Newton, cap 2
# Environment: FIBERNET (default build/fibernet), L, Q, SEED, BETA, MODELS ("events smooth"), FLAGS (extra flags),
# SMOOTH_FLAGS (extra flags of the smooth model only, shown in the model column). The smooth rows end with the solver's
# time split (assembly, factorization, line search; seconds summed over the rounds).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${FIBERNET:-$root/build/fibernet}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$exe" generate --L "${L:-4}" --q "${Q:-8}" --pl 0.5 --seed "${SEED:-3}" -o "$work/w.net" >/dev/null 2>&1
printf "fibers\tbeta\tmodel\tstatus\trounds\tsolver_iterations\tbridges\tE_wet\tE_capillary\tlist_builds\tpattern_builds\tmax_g\tseconds_wet_solve\tseconds\tassembly\tfactorization\tline_search\n"
for model in ${MODELS:-events smooth}; do
    rc=0
    extra=""
    label=$model
    if [ "$model" = smooth ] && [ -n "${SMOOTH_FLAGS:-}" ]; then extra=$SMOOTH_FLAGS; label="smooth $SMOOTH_FLAGS"; fi
    # shellcheck disable=SC2086
    "$exe" wet --network "$work/w.net" --betas "${BETA:-1}" --no-moduli --wet-model "$model" -o "$work/$model" -q \
        ${FLAGS:-} $extra > "$work/$model.json" || rc=$?
    /usr/bin/python3 - "$work/$model.json" "$label" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
r = j["runs"][0]
s = r.get("smooth") or {}
row = [j["network"]["fibers"], r["beta"], sys.argv[2], r["status"], r["events"]["rounds"], r["solver_iterations"],
       r["bridges"]["final"], f'{r["energy"]["wet"]["total"]:.6g}', f'{r["energy"]["wet"]["capillary"]:.6g}',
       s.get("list_builds", "-"), s.get("pattern_builds", "-"),
       f'{s["grad_max"]:.1e}' if "grad_max" in s else f'{r["solver"]["grad_max"]:.1e}',
       f'{r["seconds"]["wet_solve"]:.1f}', f'{j["seconds"]:.1f}']
t = s.get("seconds_solver") or {}
row += [f'{t[k]:.1f}' if k in t else "-" for k in ("assembly", "factorization", "line_search")]
print("\t".join(str(x) for x in row))
PY
    [ "$rc" = 0 ] || echo "$model: exit $rc" >&2
done
