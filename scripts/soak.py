#!/usr/bin/env python3
"""Soak test: many random small networks through `fibernet modulus`, `fibernet sweep` and `fibernet wet`.

One case is one random network (L uniform in (2, 5], q in [4, 12], pl in [0.3, 1], scheme seed|even, periodic or
--open, a random seed), run through every command of --commands (default modulus,sweep,wet), one process at a time;
--every wet=K runs a command only on every K-th case, --flags CMD=FLAGS adds flags to a command (e.g.
modulus=--no-eliminate), --round-robin runs case i through one command only (command
i mod the number of commands). Commands:

  modulus  fibernet modulus NET -q [--gamma 0.01 on one case in five]
  sweep    fibernet sweep NET --gamma-max 0.02 --step 0.01 -q -o DIR/s.csv
  wet      fibernet wet NET --betas 0,0.1 -o DIR/wet   (progress on stderr is watched: no line for --stall seconds is
           a "stall", a run still printing at --wet-timeout a "timeout")

Checks (a failure category each):
  crash (signal), timeout / stall, internal_error (exit 3 or "internal error"), unexpected_exit (not 0/1/2),
  exit2_unnamed (a rejection whose message names nothing); rejections (exit 2) of a valid network are recorded as
  "rejected" (not failures) with their message;
  bad_json, nonfinite_output (NaN/inf in stdout JSON or in a CSV, apart from the documented NaN of wet's G columns on a
  row that is not ok), unexpected_null (a null where the run says it succeeded), status_mismatch (exit 0 iff status
  converged / completed / complete with every beta stable; exit 1 iff not), bad_csv (sweep: header, one row per step
  numbered 0.., gamma rising inside [0, 0.02] and ending there when completed, rows == JSON rows; wet: one sweep.csv row
  per beta, summary.json == stdout), missing_output;
  negative_modulus: modulus converged at the stress-free reference (gamma = 0) but G < -3 G_error or K < -3 K_error
  (a failure unless --allow-negative-modulus).

Passing outcomes are "ok" (exit 0) and "not_converged" (exit 1 with a matching status). Failing runs are saved under
--out DIR/<command>-<category>-<case>/ (cmd.sh, stdout, stderr, outputs), at most --keep per category. Summary: a
table per command and category, then `soak: N passed, M failed` (cases: a case fails if any of its runs failed).
Exit status 1 if any case failed. Case i uses random.Random("<seed>:i"): deterministic, independent of --cases.
"""
import argparse
import json
import math
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

from fibernet_runs import child_env, child_limits, parse_json

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_SEED = 20261201
COMMANDS = ["modulus", "sweep", "wet"]
SWEEP_HEADER = ("step,gamma,sigma_xx,sigma_xy,sigma_yy,stress_path,dsdgamma,dsdgamma_affine,energy,stretch,bend,iterations,"
                "factorizations,retries,grad_max,seconds")
GAMMA_MAX = 0.02
BETAS = [0.0, 0.1]
NONFINITE = re.compile(r"(?<![A-Za-z_])[-+]?(nan|inf|infinity)(?![A-Za-z_])", re.I)




class Result:
    pass


def run(argv, cwd, timeout, stall=None):
    """Runs argv; kills it at `timeout` s, or when stderr has been silent for `stall` s (if given)."""
    r = Result()
    t0 = time.monotonic()
    p = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         env=child_env(), preexec_fn=lambda: child_limits(4))
    out, err = [], []
    last = [time.monotonic()]

    def pump(stream, sink, mark):
        for chunk in iter(lambda: stream.read1(65536) if hasattr(stream, "read1") else stream.read(65536), b""):
            sink.append(chunk)
            if mark:
                last[0] = time.monotonic()
    th = [threading.Thread(target=pump, args=(p.stdout, out, False), daemon=True),
          threading.Thread(target=pump, args=(p.stderr, err, True), daemon=True)]
    for t in th:
        t.start()
    r.timed_out = r.stalled = False
    while p.poll() is None:
        now = time.monotonic()
        if now - t0 > timeout:
            r.timed_out = True
        elif stall and now - last[0] > stall:
            r.stalled = True
        if r.timed_out or r.stalled:
            p.kill()  # only the process we started, by its pid
            break
        time.sleep(0.05)
    p.wait()
    for t in th:
        t.join(5)
    r.rc = p.returncode
    r.out, r.err = b"".join(out), b"".join(err)
    r.seconds = time.monotonic() - t0
    return r



def num(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


# ------------------------------------------------------------------------------------------------------------------


def network_flags(rng):
    L = round(rng.uniform(2, 5), 3)
    if L <= 2:
        L = 2.001
    flags = ["--L", repr(L), "--q", repr(round(rng.uniform(4, 12), 2)), "--pl", repr(round(rng.uniform(0.3, 1), 3)),
             "--scheme", rng.choice(["seed", "even"]), "--seed", str(rng.randrange(1, 2 ** 32))]
    if rng.random() < 0.3:
        flags.append("--open")
    return flags


def argv_for(cmd, net, rng, d):
    if cmd == "modulus":
        return ["modulus"] + net + ["-q"] + (["--gamma", "0.01"] if rng.random() < 0.2 else [])
    if cmd == "sweep":
        return ["sweep"] + net + ["--gamma-max", repr(GAMMA_MAX), "--step", "0.01", "-q", "-o", os.path.join(d, "s.csv")]
    return ["wet"] + net + ["--betas", ",".join(repr(b) for b in BETAS), "-o", os.path.join(d, "wet")]


def check_common(r, cmd):
    if r.stalled:
        return [("stall", "no progress on stderr for the stall time (%.0f s in all)" % r.seconds)], None
    if r.timed_out:
        return [("timeout", "still running after %.0f s" % r.seconds)], None
    if r.rc < 0:
        return [("crash", "signal %d (%s)" % (-r.rc, signal.Signals(-r.rc).name))], None
    if r.rc == 3 or b"internal error" in r.err:
        return [("internal_error", "exit %d: %s" % (r.rc, r.err.decode(errors="replace").strip()[-300:]))], None
    if r.rc == 2:
        msg = r.err.decode(errors="replace").strip()
        if not re.search(r"--[a-zA-Z]|command line|\[[a-z]+\]", msg):
            return [("exit2_unnamed", "exit 2: " + msg[-200:])], None
        return [], "rejected"
    if r.rc not in (0, 1):
        return [("unexpected_exit", "exit %d: %s" % (r.rc, r.err.decode(errors="replace").strip()[-200:]))], None
    return [], None


def stdout_json(r):
    """The run's JSON on stdout and the failures reading it shows: (None, [bad_json]) if it does not parse."""
    j, err, bad = parse_json(r.out)
    if err:
        return None, [("bad_json", err)]
    return j, [("nonfinite_output", "stdout JSON has %s" % bad)] if bad else []


def check_modulus(r, d, allow_negative):
    j, f = stdout_json(r)
    if j is None:
        return f
    st = j.get("status")
    if (r.rc == 0) != (st == "converged"):
        f.append(("status_mismatch", "exit %d with status %r" % (r.rc, st)))
    if st == "converged":
        m = j.get("moduli") or {}
        nulls = [k for k in ("G", "K", "G_error", "K_error", "G_affine", "K_affine") if not num(m.get(k))]
        s = j.get("stress") or {}
        nulls += ["stress." + k for k in ("xx", "xy", "yy") if not num(s.get(k))]
        nulls += ["energy." + k for k in ("total", "stretch", "bend") if not num((j.get("energy") or {}).get(k))]
        if nulls:
            f.append(("unexpected_null", "converged, but not a finite number: %s" % nulls))
        # Only at the stress-free reference must a stable network's moduli be >= 0; at a prestressed state a
        # negative differential modulus can be physics (docs/moduli.md "Error estimates").
        for k in ("G", "K") if j.get("gamma") == 0 else ():
            if num(m.get(k)) and num(m.get(k + "_error")) and m[k] < -3 * m[k + "_error"]:
                f.append(("negative_modulus", "%s = %.6g < -3 %s_error = %.3g" % (k, m[k], k, -3 * m[k + "_error"])))
    elif r.rc == 1:
        m = j.get("moduli")
        if isinstance(m, dict) and st != "modulus_failed":
            f.append(("status_mismatch", "status %r but moduli reported" % st))
    return f


def check_sweep(r, d):
    j, f = stdout_json(r)
    if j is None:
        return f
    st = j.get("status")
    if st != {0: "completed", 1: "failed"}.get(r.rc):
        f.append(("status_mismatch", "exit %d with status %r" % (r.rc, st)))
    if st == "failed" and not j.get("message"):
        f.append(("status_mismatch", "failed without a message"))
    p = os.path.join(d, "s.csv")
    if j.get("rows") == 0:  # failed before its first row: no files at all (docs/sweep.md)
        left = [n for n in ("s.csv", "s.csv.ckpt") if os.path.exists(os.path.join(d, n))]
        if left or j.get("output") is not None or j.get("checkpoint") is not None:
            f.append(("partial_output", "no rows, yet %s left and output %r" % (left, j.get("output"))))
        return f
    if not os.path.exists(p):
        return f + [("missing_output", "s.csv not written")]
    lines = open(p, encoding="utf-8", errors="replace").read().splitlines()
    if not lines or lines[0] != SWEEP_HEADER:
        f.append(("bad_csv", "header %r" % (lines[0][:60] if lines else "")))
    rows = lines[1:]
    if j.get("rows") != len(rows):
        f.append(("bad_csv", "JSON rows %r, CSV rows %d" % (j.get("rows"), len(rows))))
    steps, gammas = [], []
    for l in rows:
        if NONFINITE.search(l):
            f.append(("nonfinite_output", "s.csv row %r" % l[:100]))
        try:
            v = [float(x) for x in l.split(",")]
        except ValueError:
            f.append(("bad_csv", "row %r" % l[:100]))
            continue
        if len(v) != 16:
            f.append(("bad_csv", "row with %d fields" % len(v)))
            continue
        steps.append(v[0]), gammas.append(v[1])
    if steps != [float(k) for k in range(len(steps))]:
        f.append(("bad_csv", "steps %s, not 0, 1, ..." % steps[:8]))
    if any(not (-1e-15 <= g <= GAMMA_MAX + 1e-12) for g in gammas) or any(b <= a for a, b in zip(gammas, gammas[1:])):
        f.append(("bad_csv", "gammas %s" % gammas[:8]))
    if st == "completed" and (not gammas or abs(gammas[-1] - GAMMA_MAX) > 1e-9):
        f.append(("bad_csv", "completed, last gamma %s" % gammas[-1:]))
    if rows and not os.path.exists(p + ".ckpt"):  # a sweep that fails at t = 0 has nothing to checkpoint
        f.append(("missing_output", "s.csv.ckpt not written"))
    return f


def check_wet(r, d):
    j, f = stdout_json(r)
    if j is None:
        return f
    runs = j.get("runs") or []
    stable = [x.get("status") == "stable" for x in runs]
    good = bool(j.get("complete")) and len(runs) == len(BETAS) and all(stable)
    if (r.rc == 0) != good:
        f.append(("status_mismatch", "exit %d, complete %r, statuses %r" % (r.rc, j.get("complete"),
                                                                            [x.get("status") for x in runs])))
    if not j.get("complete") or len(runs) != len(BETAS):
        f.append(("status_mismatch", "complete %r with %d of %d runs" % (j.get("complete"), len(runs), len(BETAS))))
    for x in runs:
        e = x.get("energy") or {}
        nulls = ["energy.%s.%s" % (s, k) for s in ("dry", "wet") for k in ("total", "stretch", "bend", "capillary")
                 if not num((e.get(s) or {}).get(k))]
        if x.get("status") == "stable":
            sm = x.get("shear_modulus") or {}
            nulls += ["shear_modulus." + k for k in ("dry", "wet") if not num(sm.get(k))]
        if nulls:
            f.append(("unexpected_null", "beta %r (%s): %s" % (x.get("beta"), x.get("status"), nulls)))
    w = os.path.join(d, "wet")
    for name in ("summary.json", "sweep.csv", "pores.csv", "network.svg", "pores.svg"):
        if not os.path.exists(os.path.join(w, name)):
            f.append(("missing_output", "wet/%s not written" % name))
    try:
        with open(os.path.join(w, "summary.json"), "rb") as fh:
            sj, serr, sbad = parse_json(fh.read())
        if serr or sj != j:
            f.append(("bad_csv", "summary.json differs from stdout (%s)" % (serr or "content")))
    except OSError:
        pass
    try:
        lines = open(os.path.join(w, "sweep.csv"), encoding="utf-8", errors="replace").read().splitlines()
        head = lines[0].split(",")
        if len(lines) - 1 != len(runs):
            f.append(("bad_csv", "sweep.csv has %d rows for %d runs" % (len(lines) - 1, len(runs))))
        for l in lines[1:]:
            v = l.split(",")
            for name, x in zip(head, v):
                if NONFINITE.fullmatch(x.strip()) and not (name.startswith("G_") and v[1] != "ok"):
                    f.append(("nonfinite_output", "sweep.csv %s = %s on a row with status %s" % (name, x, v[1])))
        pores = open(os.path.join(w, "pores.csv"), encoding="utf-8", errors="replace").read()
        if NONFINITE.search(pores):
            f.append(("nonfinite_output", "pores.csv has %r" % NONFINITE.search(pores).group(0)))
    except (OSError, IndexError):
        pass
    return f


def shell_quote(a):
    return a if re.fullmatch(r"[A-Za-z0-9_./=,:+-]+", a) else "'" + a.replace("'", "'\\''") + "'"


def save_repro(outdir, case, cmd, category, detail, argv, r, d):
    dst = os.path.join(outdir, "%s-%s-%04d" % (cmd, category, case))
    if os.path.exists(dst):
        shutil.rmtree(dst)
    shutil.copytree(d, dst)
    a = [x.replace(d + os.sep, "") for x in argv]
    with open(os.path.join(dst, "cmd.sh"), "w") as f:
        f.write("#!/bin/sh\n# soak case %d, %s: %s\n# %s\ncd \"$(dirname \"$0\")\" && ${FIBERNET:-fibernet} %s\necho \"exit $?\"\n"
                % (case, cmd, category, detail.replace("\n", " ")[:400], " ".join(shell_quote(x) for x in a)))
    os.chmod(os.path.join(dst, "cmd.sh"), 0o755)
    with open(os.path.join(dst, "stdout"), "wb") as f:
        f.write(r.out[:500000])
    with open(os.path.join(dst, "stderr"), "wb") as f:
        f.write(r.err[-200000:])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=DEFAULT_SEED, help="master seed (default %(default)s)")
    ap.add_argument("--cases", type=int, default=1000, help="random networks (default %(default)s)")
    ap.add_argument("--fibernet", default=os.path.join(REPO, "build", "fibernet"),
                    help="the fibernet executable (default: build/fibernet of the repository)")
    ap.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "fibernet-soak-failures"),
                    help="directory for failing reproducers (default %(default)s)")
    ap.add_argument("--commands", default=",".join(COMMANDS), help="comma-separated subset of modulus,sweep,wet")
    ap.add_argument("--flags", action="append", default=[], metavar="CMD=FLAGS",
                    help="extra flags for a command, e.g. modulus=--no-eliminate (space-separated; repeatable)")
    ap.add_argument("--round-robin", action="store_true", help="case i runs only command i mod len(commands)")
    ap.add_argument("--every", action="append", default=[], metavar="CMD=K",
                    help="run CMD only on every K-th case (e.g. wet=3); repeatable")
    ap.add_argument("--timeout", type=float, default=60, help="seconds per modulus/sweep run (default %(default)s)")
    ap.add_argument("--wet-timeout", type=float, default=120, help="seconds per wet run (default %(default)s)")
    ap.add_argument("--stall", type=float, default=30,
                    help="wet: seconds without a progress line on stderr that count as a hang (default %(default)s)")
    ap.add_argument("--time-budget", type=float, default=0, help="stop starting cases after this many seconds (0: none)")
    ap.add_argument("--start", type=int, default=0, help="first case index (default 0)")
    ap.add_argument("--keep", type=int, default=5, help="reproducers kept per (command, category) (default %(default)s)")
    ap.add_argument("--allow-negative-modulus", action="store_true",
                    help="count negative_modulus but do not fail on it (another issue)")
    ap.add_argument("-v", "--verbose", action="store_true", help="print every failure as it happens")
    a = ap.parse_args()
    cmds = [c.strip() for c in a.commands.split(",") if c.strip()]
    for c in cmds:
        if c not in COMMANDS:
            ap.error("unknown command %r in --commands" % c)
    every = {}
    for e in a.every:
        m = re.fullmatch(r"(\w+)=(\d+)", e)
        if not m or m.group(1) not in COMMANDS or int(m.group(2)) < 1:
            ap.error("--every %r: expected CMD=K with K >= 1" % e)
        every[m.group(1)] = int(m.group(2))
    extra = {}
    for e in a.flags:
        cmd, _, flags = e.partition("=")
        if cmd not in COMMANDS or not flags.strip():
            ap.error("--flags %r: expected CMD=FLAGS with CMD one of %s" % (e, ",".join(COMMANDS)))
        extra.setdefault(cmd, []).extend(flags.split())
    fib = os.path.abspath(a.fibernet)
    if not os.access(fib, os.X_OK):
        ap.error("--fibernet %s is not an executable" % fib)
    outdir = os.path.abspath(a.out)
    work = tempfile.mkdtemp(prefix="fibernet-soak-")
    counts, kept, first = {}, {}, {}
    seconds = {c: 0.0 for c in COMMANDS}
    runs = {c: 0 for c in COMMANDS}
    passed = failed = 0
    t0 = time.monotonic()
    last = 0
    tty = sys.stderr.isatty()
    done = 0
    try:
        for i in range(a.start, a.start + a.cases):
            if a.time_budget and time.monotonic() - t0 > a.time_budget:
                break
            rng = random.Random("%d:%d" % (a.seed, i))
            net = network_flags(rng)
            todo = [cmds[i % len(cmds)]] if a.round_robin else [c for c in cmds if i % every.get(c, 1) == 0]
            case_failed = False
            for cmd in todo:
                d = os.path.join(work, "case")
                if os.path.exists(d):
                    shutil.rmtree(d)
                os.makedirs(d)
                argv = argv_for(cmd, net, rng, d) + extra.get(cmd, [])
                if cmd == "wet":
                    r = run([fib] + argv, d, a.wet_timeout, a.stall)
                else:
                    r = run([fib] + argv, d, a.timeout)
                seconds[cmd] += r.seconds
                runs[cmd] += 1
                fails, verdict = check_common(r, cmd)
                if not fails and verdict is None:
                    fails = {"modulus": lambda: check_modulus(r, d, a.allow_negative_modulus),
                             "sweep": lambda: check_sweep(r, d), "wet": lambda: check_wet(r, d)}[cmd]()
                    verdict = "ok" if r.rc == 0 else "not_converged"
                if verdict == "rejected":
                    first.setdefault((cmd, "rejected"), (i, r.err.decode(errors="replace").strip()[-200:],
                                                         " ".join(argv)))
                real = [x for x in fails if not (x[0] == "negative_modulus" and a.allow_negative_modulus)]
                if fails:
                    seen = set()
                    for cat, detail in fails:
                        if cat in seen:
                            continue
                        seen.add(cat)
                        counts[(cmd, cat)] = counts.get((cmd, cat), 0) + 1
                        first.setdefault((cmd, cat), (i, detail, " ".join(argv).replace(d + os.sep, "")))
                        if kept.get((cmd, cat), 0) < a.keep:
                            kept[(cmd, cat)] = kept.get((cmd, cat), 0) + 1
                            save_repro(outdir, i, cmd, cat, detail, argv, r, d)
                        if a.verbose:
                            sys.stderr.write("\nFAIL #%d %s %s: %s | %s\n" % (
                                i, cmd, cat, detail, " ".join(argv).replace(d + os.sep, "")))
                if not real:
                    counts[(cmd, verdict or "ok")] = counts.get((cmd, verdict or "ok"), 0) + 1
                case_failed = case_failed or bool(real)
            done += 1
            if case_failed:
                failed += 1
            else:
                passed += 1
            now = time.monotonic()
            if (tty and now - last > 0.5) or (not tty and now - last > 30):
                last = now
                sys.stderr.write("%ssoak: case %d (%d done) passed %d failed %d, %.0f s%s" % (
                    "\r" if tty else "", i, done, passed, failed, now - t0, "   " if tty else "\n"))
                sys.stderr.flush()
        if tty:
            sys.stderr.write("\n")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    cats = ["ok", "not_converged", "rejected"] + sorted({c for (_, c) in counts} - {"ok", "not_converged", "rejected"})
    print("%-9s%7s" % ("command", "runs") + "".join("%*s" % (max(len(c) + 2, 8), c) for c in cats) + "   seconds")
    for c in COMMANDS:
        if runs[c]:
            print("%-9s%7d" % (c, runs[c]) + "".join("%*d" % (max(len(k) + 2, 8), counts.get((c, k), 0)) for k in cats)
                  + "   %7.0f" % seconds[c])
    if first:
        print("first case of each category other than ok/not_converged (reproducers under %s):" % outdir)
        for (c, cat), (i, detail, argv) in sorted(first.items()):
            print("  %s/%s: case %d: %s\n      fibernet %s" % (c, cat, i, detail[:200], argv))
    if any(k[1] == "negative_modulus" for k in counts):
        print("note: negative_modulus (G or K below -3 x its error at the stress-free reference): %s" %
              ("not counted as failed (--allow-negative-modulus)" if a.allow_negative_modulus else "counted as failed"))
    print("elapsed %.0f s, seed %d, %d cases (%s%s)" % (time.monotonic() - t0, a.seed, done, ",".join(cmds),
                                                       ", round robin" if a.round_robin else
                                                       "".join(", %s every %d" % kv for kv in every.items())))
    print("soak: %d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
