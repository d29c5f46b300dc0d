#!/usr/bin/env bash
# What an interrupt costs a smooth-model wet relaxation that checkpoints (docs/wet.md, "Checkpoints and
# --start-state"): one network relaxed three ways, on one thread each, one after the other:
#   uninterrupted;
#   interrupted by SIGTERM after SECONDS (checkpoints every CHECKPOINT seconds; SIGTERM, since a background job
#   ignores SIGINT);
#   continued from that run's last checkpoint with --start-state.
# One row per way: status, Newton iterations (global factorizations), E_wet, max|g| of the whole energy, seconds of
# wet solving; for the interrupted run, the checkpoint's iterations and energy. The continued run's total is the
# checkpoint's iterations plus its own.
#   bench/run_wet_checkpoint.sh [SECONDS] > rows.tsv
# Environment: FIBERNET (default build/fibernet), NETWORK (generate flags, default 1000 fibers: "--L 10 --q 10 --pl 0.5
# --seed 1"), BETA (0.01), FLAGS (default "--bundle-partners 2 --wet-eliminate"), CHECKPOINT (seconds between
# checkpoints, default 10).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${FIBERNET:-$root/build/fibernet}
secs=${1:-60}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
# shellcheck disable=SC2086
"$exe" generate ${NETWORK:---L 10 --q 10 --pl 0.5 --seed 1} -o "$work/w.net" >/dev/null 2>&1
run=("$exe" wet --network "$work/w.net" --betas "${BETA:-0.01}" --wet-model smooth --no-moduli -q)
# shellcheck disable=SC2206
flags=(${FLAGS:---bundle-partners 2 --wet-eliminate})
row() {  # NAME JSON [CHECKPOINT_JSON]
    /usr/bin/python3 - "$@" <<'PY'
import json, sys
name, path = sys.argv[1], sys.argv[2]
j = json.load(open(path))
r = j["runs"][0] if j.get("runs") else None
ck = json.load(open(sys.argv[3])) if len(sys.argv) > 3 else None
cells = [name]
if r:
    s = r["smooth"]
    cells += [r["status"], s["factorizations"], f'{r["energy"]["wet"]["total"]:.10g}', f'{s["grad_max"]:.1e}',
              f'{r["seconds"]["wet_solve"]:.1f}']
else:
    cells += ["interrupted", "-", "-", "-", "-"]
cells += [ck["iterations"], f'{ck["energy"]:.10g}'] if ck else ["-", "-"]
print("\t".join(str(c) for c in cells))
PY
}
printf "run\tstatus\tglobal_factorizations\tE_wet\tmax_g\tseconds_wet_solve\tcheckpoint_iterations\tcheckpoint_E\n"
"${run[@]}" "${flags[@]}" -o "$work/a" > "$work/a.json"
row uninterrupted "$work/a.json"
rc=0
timeout --preserve-status --signal=TERM "$secs" "${run[@]}" "${flags[@]}" --checkpoint-seconds "${CHECKPOINT:-10}" -o "$work/b" \
    > "$work/b.json" 2> "$work/b.err" || rc=$?
[ -f "$work/b/checkpoint_0.json" ] || { echo "no checkpoint after $secs s (exit $rc)" >&2; cat "$work/b.err" >&2; exit 1; }
row "interrupted at ${secs} s (exit $rc)" "$work/b.json" "$work/b/checkpoint_0.json"
"${run[@]}" "${flags[@]}" --start-state "$work/b/checkpoint_0.txt" -o "$work/c" > "$work/c.json"
row continued "$work/c.json"
