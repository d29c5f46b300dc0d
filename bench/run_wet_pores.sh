#!/bin/bash
# Pore growth against capillary strength over network seeds (issue 6, "A sweep over beta shows pore growth"): one
# `fibernet wet` beta sweep per seed on the same kind of network, then bench/plot_wet_pores.py summarizes the pores,
# bundles and moduli per beta (mean and spread over the seeds). A seed whose summary.json is complete and records this
# study's parameters (the `command` it was run with) is not run again, so an interrupted study continues where it
# stopped; an unfinished seed is run again from its start. A complete seed run with other parameters (betas, PL, L,
# EXTRA), or any other seed*/ directory with other parameters (the summary would mix it in), is refused before
# anything is run or written (exit 2): give another OUT, or remove that directory.
#   bench/run_wet_pores.sh [FIBERNET=build/fibernet] [OUT=docs/wet/pores_study] [L=10] [SEEDS="1 2 3"]
#                          [BETAS=0,0.003,0.01,0.03,0.1,0.3,1] [PL=0.5] [EXTRA=""]
# EXTRA: more `fibernet wet` flags for every run, e.g. "--bundle-partners 2" (recorded in study.json).
# The network: L x L fiber lengths at q = 10, crosslink probability PL (0.5: the thesis's wet networks), seed scheme,
# all crossings wet.
set -euo pipefail
FIBERNET=${1:-build/fibernet}; OUT=${2:-docs/wet/pores_study}; L=${3:-10}; SEEDS=${4:-"1 2 3"}
BETAS=${5:-0,0.003,0.01,0.03,0.1,0.3,1}; PL=${6:-0.5}; EXTRA=${7:-}

# The arguments of seed $1's run, in ARGS (EXTRA split into words, as it always was).
run_args() {
  # shellcheck disable=SC2206
  ARGS=(wet --L "$L" --q 10 --pl "$PL" --seed "$1" --betas "$BETAS" $EXTRA -o "$OUT/seed$1")
}

# Compares seed directory $1's summary.json with ARGS: prints "complete|incomplete same|differs", then the
# differences. The recorded command line decides (it holds EXTRA too); L, pl, seed and the betas are named when they
# differ. -o (the directory is the one looked at) and -q/-v (progress only) are left out of the comparison. A summary
# of an older fibernet records no command line: it matches when the values it records are this study's and EXTRA is
# at most --bundle-partners N, the one EXTRA flag it records.
compare() {
  /usr/bin/python3 - "$1/summary.json" "${ARGS[@]}" <<'PY'
import json, sys
path, args = sys.argv[1], sys.argv[2:]
def norm(a):
    out, skip = [], False
    for t in a:
        if skip:
            skip = False
        elif t in ("-o", "--out-dir"):
            skip = True
        elif t.startswith("--out-dir=") or t in ("-q", "--quiet", "-v", "--verbose"):
            pass
        else:
            out.append(t)
    return out
try:
    j = json.load(open(path))
except (OSError, ValueError) as e:
    print("incomplete differs", f"summary.json cannot be read ({e})")
    sys.exit(0)
state = "complete" if j.get("complete") is True else "incomplete"
diffs = []
new = norm(args)  # wet --L L --q 10 --pl PL --seed S --betas BETAS EXTRA...
cmd, wet, p = j.get("command"), j.get("wet", {}), j.get("parameters", {})
if isinstance(cmd, list) and len(cmd) >= 2:
    if norm(cmd[1:]) != new:
        diffs.append("recorded `" + " ".join(norm(cmd[1:])) + "`, this study `" + " ".join(new) + "`")
    recorded_betas = wet.get("betas")
else:
    extra = new[11:]
    if extra[:1] == ["--bundle-partners"] and len(extra) == 2:
        extra = ["--bundle-partners=" + extra[1]]
    if len(extra) > 1 or (extra and not extra[0].startswith("--bundle-partners=")):
        diffs.append("it was written by an older fibernet, which does not record EXTRA `" + " ".join(new[11:]) + "`")
    elif extra and str(wet.get("bundle_partners", 0)) != extra[0].split("=", 1)[1]:
        diffs.append(f"bundle_partners = {wet.get('bundle_partners', 0)} (this study: {extra[0].split('=', 1)[1]})")
    for k, v in (("q", 10.0), ("scheme", "seed")):
        if p.get(k) != v:
            diffs.append(f"{k} = {p.get(k)} (this study: {v})")
    for k, v in (("crossings", "all"), ("law", "cos2"), ("free_box", False)):
        if wet.get(k) != v:
            diffs.append(f"{k} = {wet.get(k)} (this study: {v})")
    recorded_betas = [r.get("beta") for r in j.get("runs", [])]
try:  # names the main differences; a value that is not a number here is fibernet's to refuse
    want = {"L": float(args[args.index("--L") + 1]), "pl": float(args[args.index("--pl") + 1]),
            "seed": int(args[args.index("--seed") + 1])}
    for k, v in want.items():
        if p.get(k) != v:
            diffs.append(f"{k} = {p.get(k)} (this study: {v})")
    betas = [float(b) for b in args[args.index("--betas") + 1].split(",")]
    older_unfinished = not isinstance(cmd, list) and state == "incomplete"  # its runs: the betas finished
    if recorded_betas != (betas[:len(recorded_betas)] if older_unfinished else betas):
        diffs.append(f"betas = {recorded_betas} (this study: {betas})")
except ValueError:
    pass
print(state, "differs" if diffs else "same", "; ".join(diffs))
PY
}

# Before anything runs or is written: every seed directory the summary would read must be this study's.
bad=0
others=$(ls -d "$OUT"/seed*/ 2>/dev/null | sed -n 's|.*/seed\([0-9][0-9]*\)/$|\1|p' || true)
for s in $(printf '%s\n' $SEEDS $others | sort -un); do
  d="$OUT/seed$s"
  [ -f "$d/summary.json" ] || continue
  run_args "$s"
  read -r state same why < <(compare "$d")
  if [ "$same" = differs ]; then
    if [[ " $SEEDS " == *" $s "* ]] && [ "$state" = incomplete ]; then
      echo "seed $s: an unfinished run with other parameters in $d is started over ($why)" >&2
    else
      echo "run_wet_pores.sh: $d holds a$([ "$state" = complete ] && echo " complete" || echo "n unfinished") run" \
        "with other parameters than this study's: $why; give another OUT, or remove $d" >&2
      bad=1
    fi
  fi
done
[ "$bad" = 0 ] || exit 2

mkdir -p "$OUT"
# The study's parameters, for the summary (plot_wet_pores.py); each seed's summary.json has them too (`parameters`).
printf '{"L": %s, "q": 10, "pl": %s, "seeds": "%s", "betas": "%s", "scheme": "seed", "extra": "%s"}\n' "$L" "$PL" \
  "$SEEDS" "$BETAS" "$EXTRA" \
  > "$OUT/study.json"
for s in $SEEDS; do
  d="$OUT/seed$s"
  run_args "$s"
  if [ -f "$d/summary.json" ] && [ "$(compare "$d" | cut -d' ' -f1-2)" = "complete same" ]; then
    echo "seed $s: done already ($d)" >&2
    continue
  fi
  echo "seed $s: $FIBERNET ${ARGS[*]}" >&2
  start=$(date +%s)
  OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} \
    "$FIBERNET" "${ARGS[@]}" > /dev/null 2> "$OUT/seed$s.log" || {
      rc=$?
      echo "seed $s: fibernet wet exited $rc (see $OUT/seed$s.log); its summary.json says which betas did not settle" >&2
      if [ "$rc" = 130 ]; then exit 130; fi  # interrupted: the finished betas are kept; run the study again to go on
    }
  echo "seed $s: $(( $(date +%s) - start )) s" >&2
done
/usr/bin/python3 "$(dirname "$0")/plot_wet_pores.py" "$OUT"
