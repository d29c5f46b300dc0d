#!/usr/bin/env bash
# Do two builds give the same results? Runs relax (plain, with elimination, --ldl, every other solver), modulus and a
# wet run on small scenes with each executable and compares their JSON (timings, paths and provenance removed) and
# the wet state file byte for byte. For a change that must not move any result (a refactoring; docs/solvers.md,
# "One loop, one registry, one linear-solver interface").
#   git worktree add /tmp/base HEAD~1 && cmake -S /tmp/base -B /tmp/base/build -DCMAKE_BUILD_TYPE=Release \
#     && cmake --build /tmp/base/build -j2 --target fibernet
#   bench/compare_builds.sh /tmp/base/build/fibernet build/fibernet      # about 3 min on 2 cores
# Prints "same" or "DIFF" with the differing lines per output; exit 1 if any differs.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -eq 2 ] || { echo "usage: $0 BASE_EXE NEW_EXE" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
strip() { /usr/bin/python3 "$root/bench/strip_timings.py"; }
run_all() {
    local exe=$1 out=$2 s
    mkdir -p "$out"
    cd "$root" || exit 2
    # Elimination is the default since 2026-12-04; an executable from before that has no --no-eliminate and runs plain.
    local plain=(--no-eliminate) elim=()
    "$exe" relax --help | grep -q -- --no-eliminate || plain=() elim=(--eliminate)
    "$exe" relax problems/default.toml --L 10 --gamma 0.01 --prune dangling ends "${plain[@]}" -q | strip > "$out/relax_plain.json"
    "$exe" relax problems/default.toml --L 10 --gamma 0.01 --prune dangling ends "${elim[@]}" -q | strip > "$out/relax_eliminate.json"
    "$exe" relax problems/default.toml --L 10 --gamma 0.05 --ldl -q 2>/dev/null | strip > "$out/relax_ldl.json"
    "$exe" modulus problems/default.toml --L 8 -q | strip > "$out/modulus.json"
    for s in lbfgs lbfgs-hessian cg fire nlopt-lbfgs ipopt; do
        "$exe" relax problems/default.toml --L 6 --gamma 0.01 --solver "$s" --max-iter 20000 -q | strip > "$out/relax_$s.json"
    done
    "$exe" generate --L 3 --q 8 --pl 0.5 --seed 3 -o "$work/w.net" 2>/dev/null
    "$exe" wet --network "$work/w.net" --betas 0.5 -o "$out/wet" -q 2>/dev/null | strip | grep -v '"/' > "$out/wet.json"
    cp "$out/wet/state_0.txt" "$out/wet_state_0.txt"
}
run_all "$(realpath "$1")" "$work/base"
run_all "$(realpath "$2")" "$work/new"
rc=0
for f in "$work"/base/*.json "$work"/base/*.txt; do
    b=$(basename "$f")
    if cmp -s "$f" "$work/new/$b"; then echo "same $b"; else echo "DIFF $b"; diff "$f" "$work/new/$b" | head -6; rc=1; fi
done
exit $rc
