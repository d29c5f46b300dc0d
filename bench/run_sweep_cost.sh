#!/usr/bin/env bash
# Sweep cost (issue 5): factorizations per step and time per step against DOF.
# For each box side L and each pruning, one `fibernet sweep` (simple shear from 0 to GAMMA_MAX, even scheme) and
# `fibernet info` with the same flags for the DOF. Keeps the per-step CSVs in OUT/cost/ and writes OUT/cost.csv,
# one row per (L, pruning), summarizing the strain steps (step >= 1; step 0 is the relaxation of the rest state,
# reported apart as relax0_seconds).
#
#   bench/run_sweep_cost.sh                       # L = 5 10 15 20, unpruned and --prune dangling ends
#   LS="5 10" PRUNES="none" bench/run_sweep_cost.sh
# Environment: FIBERNET (executable, default build/fibernet), OUT (default docs/sweep), LS, PRUNES ("none" and/or
# "dangling,ends"), GAMMA_MAX (0.05), STEP (0.01), MIN_STEP (1e-3), TIME_LIMIT (seconds per sweep, 600),
# SOLVER_FLAGS (extra flags for every sweep, e.g. "--no-eliminate" for plain Newton, the default until 2026-12-04;
# docs/solvers.md "Nonlinear elimination").
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${FIBERNET:-$root/build/fibernet}
out=${OUT:-$root/docs/sweep}
Ls=${LS:-"5 10 15 20"}
prunes=${PRUNES:-"none dangling,ends"}
gamma_max=${GAMMA_MAX:-0.05}
step=${STEP:-0.01}
# A corrector that needs > 30 Newton iterations is retried at half the step down to --min-step; 1e-3 bounds the
# retries per step at 3 (the default 1e-6 would allow 13, each hundreds of iterations at these sizes).
min_step=${MIN_STEP:-1e-3}
limit=${TIME_LIMIT:-600}
py=/usr/bin/python3

mkdir -p "$out/cost"
csv=$out/cost.csv
echo "L,prune,fibers,dof,status,steps,gamma_end,iterations_mean,factorizations_mean,factorizations_median,factorizations_max,seconds_mean,seconds_median,seconds_max,seconds_per_factorization,retries,relax0_seconds,wall_seconds,load_before,load_after" >"$csv"
# Pruning inside the L loop, so both variants of one size run under about the same load.
for L in $Ls; do
    for prune in $prunes; do
        pflags=()
        tag=full
        if [ "$prune" != none ]; then
            pflags=(--prune ${prune//,/ })  # the CLI takes the names as separate words
            tag=${prune//,/_}
        fi
        net=(--L "$L" --q 8 --pl 1 --seed 1 --scheme even --h 1 --a 10 "${pflags[@]}")
        info=$("$exe" info "${net[@]}")
        read -r fibers dof < <(echo "$info" | $py -c 'import json,sys; m=json.load(sys.stdin)["model"]; print(m["fibers"], m["dofs"])')
        rows=$out/cost/shear_L${L}_${tag}.csv
        load0=$(cut -d' ' -f1 /proc/loadavg)
        t0=$(date +%s.%N)
        # Exit 1 (a step below min_step) or 124 (time limit: SIGTERM stops after the step in progress) still leaves
        # the rows written so far; the status column says which.
        rc=0
        res=$(timeout -k 60 "$limit" "$exe" sweep "${net[@]}" --gamma-max "$gamma_max" --step "$step" \
            --min-step "$min_step" ${SOLVER_FLAGS:-} -q -o "$rows") || rc=$?
        [ "$rc" = 0 ] || echo "L = $L, prune $prune: exit $rc: $res" >&2
        t1=$(date +%s.%N)
        load1=$(cut -d' ' -f1 /proc/loadavg)
        rm -f "$rows.ckpt"
        case $rc in 0) status=completed ;; 1) status=failed ;; 124 | 130) status=time_limit ;; *) status=rc$rc ;; esac
        $py - "$rows" "$L" "${prune//,/+}" "$fibers" "$dof" "$status" "$t0" "$t1" "$load0" "$load1" >>"$csv" <<'EOF'
import csv, sys
path, L, prune, fibers, dof, status, t0, t1, load0, load1 = sys.argv[1:]
rows = list(csv.DictReader(open(path)))
steps = [r for r in rows if int(r["step"]) >= 1]
relax0 = next((float(r["seconds"]) for r in rows if int(r["step"]) == 0), float("nan"))
n = len(steps)
col = lambda k: sorted(float(r[k]) for r in steps)
mean = lambda k: sum(col(k)) / n if n else float("nan")
# One hard step (a rearrangement retried down to min_step) can dominate the mean; the median is the typical step.
median = lambda k: (col(k)[(n - 1) // 2] + col(k)[n // 2]) / 2 if n else float("nan")
mx = lambda k: max(col(k), default=float("nan"))
# Time per factorization (= per Newton iteration, with its assembly and line search): the size-dependent cost,
# apart from how many iterations the rearrangements need.
per_fact = sum(col("seconds")) / sum(col("factorizations")) if n and sum(col("factorizations")) else float("nan")
gamma_end = float(rows[-1]["gamma"]) if rows else float("nan")
print(f"{L},{prune},{fibers},{dof},{status},{n},{gamma_end:.6g},{mean('iterations'):.4g},{mean('factorizations'):.4g},"
      f"{median('factorizations'):.4g},{mx('factorizations'):.0f},{mean('seconds'):.4g},{median('seconds'):.4g},"
      f"{mx('seconds'):.4g},{per_fact:.4g},{sum(int(r['retries']) for r in steps)},{relax0:.4g},"
      f"{float(t1) - float(t0):.1f},{load0},{load1}")
EOF
        tail -n 1 "$csv" >&2
    done
done
