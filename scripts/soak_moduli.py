#!/usr/bin/env python3
"""Soak of the moduli's error estimates (docs/reliability.md, docs/moduli.md "Error estimates").

Random small networks (L 2.5-5, q 4-12, pl 0.3-1, seed and even schemes, gamma 0, 0.01, 0.03) through
`fibernet modulus`, each run three ways: FIBERNET_THREADS=1, =2, and with another CPU's OpenBLAS kernels
(tests/support/other_blas.sh). Counted as failures:
  negative  at the stress-free reference (gamma = 0) G or K below -3 times its error (a stable network's energy is a
            minimum over positions and strain there; at a prestressed state a negative modulus can be physics);
  spread    the two thread counts' runs differ by more than the sum of their errors, or the run on another CPU's
            kernels by more than 3 times it (pairs beyond 1 time are listed as `outside` and counted);
  status    an exit code that disagrees with the run's status.
Reported, not failed: flips, networks where the runs disagree on converging (a seed-scheme CG at its round-off
tolerance accepted on one CPU's kernels and refused on another's: modulus_failed is then the honest answer on one).
Prints `soak_moduli: N passed, M failed`; exit 1 on any failure.
  scripts/soak_moduli.py [--cases 300] [--seed 7] [--fibernet build/fibernet]
"""
import argparse, json, os, random, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(cmd, args, env):
    p = subprocess.run([*cmd, "modulus", *args, "-q"], capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, **env))
    try:
        j = json.loads(p.stdout)
    except ValueError:
        j = None
    return p.returncode, j


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", type=int, default=300)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--fibernet", default=os.path.join(ROOT, "build", "fibernet"))
    o = ap.parse_args()
    if o.cases < 1:
        sys.exit(f"soak_moduli: --cases {o.cases} must be >= 1")
    other = [os.path.join(ROOT, "tests", "support", "other_blas.sh")]
    rng = random.Random(o.seed)
    counts = {"negative": 0, "spread": 0, "status": 0}
    passed = failed = 0
    flips = []
    worst, outside = [0.0], [0]  # largest |difference| / (sum of errors) between two runs, and pairs above 1
    t0 = time.time()
    for i in range(o.cases):
        L, q, pl = round(rng.uniform(2.5, 5), 2), round(rng.uniform(4, 12), 2), round(rng.uniform(0.3, 1), 2)
        seed, gamma, scheme = rng.randrange(1, 10**6), rng.choice([0, 0.01, 0.03]), rng.choice(["seed", "even"])
        args = ["--L", str(L), "--q", str(q), "--pl", str(pl), "--seed", str(seed), "--gamma", str(gamma),
                "--scheme", scheme]
        runs = {"1 thread": run([o.fibernet], args, {"FIBERNET_THREADS": "1"}),
                "2 threads": run([o.fibernet], args, {"FIBERNET_THREADS": "2"}),
                "other kernels": run(["bash", *other, o.fibernet, o.fibernet], args, {})}
        bad = []
        for name, (rc, j) in runs.items():
            ok = j is not None and j["status"] == "converged"
            if j is None or (rc == 0) != ok:
                bad.append(("status", f"{name}: exit {rc}, status {j and j['status']}"))
        conv = [j for rc, j in runs.values() if j is not None and j["status"] == "converged"]
        if 0 < len(conv) < len(runs):  # reported, not a failure of the estimates: see the docstring
            flips.append("fibernet modulus " + " ".join(args) + " | " + ", ".join(
                f"{n} {j and j['status']}" for n, (rc, j) in runs.items()))
        for M in ("G", "K"):
            vals = [(n, j["moduli"][M], j["moduli"][M + "_error"]) for n, (rc, j) in runs.items()
                    if j is not None and j["status"] == "converged"]
            for n, v, e in vals:
                if gamma == 0 and v < -3 * e:
                    bad.append(("negative", f"{n}: {M} = {v:.3g} < -3 * {e:.2g}"))
            for a in range(len(vals)):
                for b in range(a + 1, len(vals)):
                    (na, va, ea), (nb, vb, eb) = vals[a], vals[b]
                    ratio = abs(va - vb) / (ea + eb) if ea + eb > 0 else (0 if va == vb else float("inf"))
                    worst[0] = max(worst[0], ratio)
                    if ratio > 1:
                        outside[0] += 1
                        msg = f"{M}: {na} {va:.10g} +- {ea:.2g} vs {nb} {vb:.10g} +- {eb:.2g} ({ratio:.2f} x)"
                        # Threads must agree within the errors; the kernels of another CPU within 3 times them (the
                        # errors are estimates: docs/moduli.md "Error estimates").
                        if "thread" in na and "thread" in nb or ratio > 3:
                            bad.append(("spread", msg))
                        else:
                            print("outside: fibernet modulus " + " ".join(args) + " | " + msg, flush=True)
        if bad:
            failed += 1
            for kind in {k for k, _ in bad}:
                counts[kind] += 1
            print("fibernet modulus " + " ".join(args) + " | " + "; ".join(m for _, m in bad), flush=True)
        else:
            passed += 1
        el = time.time() - t0
        print(f"\rsoak_moduli: {i + 1}/{o.cases} networks, {failed} failed, {el:.0f} s, ETA "
              f"{el / (i + 1) * (o.cases - i - 1):.0f} s", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    for f in flips:
        print("flip: " + f)
    print("soak_moduli: " + ", ".join(f"{k} {v}" for k, v in counts.items()) + f", flips {len(flips)}")
    print(f"soak_moduli: pairs of runs apart by more than their summed errors: {outside[0]}; "
          f"worst |difference| / (summed errors) {worst[0]:.2f}")
    print(f"soak_moduli: {passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
