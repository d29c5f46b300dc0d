#!/usr/bin/env bash
# Newton with and without nonlinear elimination on the smooth wet model (issues 22 and 23; docs/wet.md "Nonlinear
# elimination on the smooth model", docs/benchmarks.md): per case a Mikado network of N = q L^2 fibers (pl = 0.5),
# `fibernet wet --wet-model smooth --bundle-partners 2` at one beta without moduli, on one thread, once plain and once
# with --wet-eliminate (and with the Schwarz sweep, --wet-schwarz, when METHODS names it). One row per run: status, global factorizations (the solver's iterations: one factorization
# each), local solves and their iterations, neighbour-list builds, the wet energy and its capillary part, max|g| of the
# whole energy at the end, and seconds of wet solving.
#   bench/run_wet_smooth_elimination.sh > rows.tsv
# Environment: FIBERNET (default build/fibernet), CASES ("L Q SEED BETA" per case, ';'-separated; default 100, 300 and
# 1000 fibers at beta = 0.01 and the 128-fiber beta = 1 example), METHODS ("plain eliminate", or any of plain, eliminate,
# schwarz), SCHWARZ (the Schwarz sweep's block size, default 500 coordinates), FLAGS (extra flags of
# every run, e.g. "--wet-eliminate-hops 4"), KEEP (a directory: each run's JSON and its -v progress log are kept there as
# N-BETA-METHOD.json and .log, for the time split in the JSON's smooth.seconds_solver and a long run's progress).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${FIBERNET:-$root/build/fibernet}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cases=${CASES:-"3.1623 10 1 0.01;5.4772 10 1 0.01;10 10 1 0.01;4 8 3 1"}
export FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
printf "fibers\tbeta\tmethod\tstatus\tglobal_factorizations\tlocal_solves\tlocal_iterations\tlist_builds\tE_wet\tE_capillary\tmax_g\tseconds_wet_solve\n"
IFS=';' read -r -a case_list <<< "$cases"
for c in "${case_list[@]}"; do
    read -r L Q SEED BETA <<< "$c"
    "$exe" generate --L "$L" --q "$Q" --pl 0.5 --seed "$SEED" -o "$work/w.net" >/dev/null 2>&1
    for method in ${METHODS:-plain eliminate}; do
        flags=()
        [ "$method" = eliminate ] && flags=(--wet-eliminate)
        [ "$method" = schwarz ] && flags=(--wet-schwarz "${SCHWARZ:-500}")
        rc=0
        log=/dev/stderr  # errors stay visible; -q keeps progress off
        talk=-q
        if [ -n "${KEEP:-}" ]; then
            mkdir -p "$KEEP"
            tag=$(/usr/bin/python3 -c "print(round($Q * $L * $L))")-$BETA-$method
            log=$KEEP/$tag.log
            talk=-v
        fi
        # shellcheck disable=SC2086
        "$exe" wet --network "$work/w.net" --betas "$BETA" --no-moduli --wet-model smooth --bundle-partners 2 \
            -o "$work/$method" $talk ${FLAGS:-} "${flags[@]}" > "$work/$method.json" 2> "$log" || rc=$?
        if [ -n "${KEEP:-}" ]; then cp "$work/$method.json" "$KEEP/$tag.json"; fi
        /usr/bin/python3 - "$work/$method.json" "$method" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
r = j["runs"][0]
s = r["smooth"]
row = [j["network"]["fibers"], r["beta"], sys.argv[2], r["status"], s["factorizations"], s["local_solves"],
       s["local_iterations"], s["list_builds"], f'{r["energy"]["wet"]["total"]:.6g}',
       f'{r["energy"]["wet"]["capillary"]:.6g}', f'{s["grad_max"]:.1e}', f'{r["seconds"]["wet_solve"]:.1f}']
print("\t".join(str(x) for x in row))
PY
        [ "$rc" = 0 ] || echo "$method, $c: exit $rc" >&2
    done
done
