#!/usr/bin/env python3
"""Mutation fuzzing of every input format the fibernet CLI reads.

Formats (--formats, comma-separated; default all):

  network     network files (`fibernet generate` output) through --network of info, modulus, export, relax,
              rigidity, wet, sweep and generate
  scene       scene TOML files (problems/*.toml and small generated ones, also ones naming a network file and a
              law file) as the positional scene of info, modulus, export, relax, rigidity, wet and sweep
  law         tabulated capillary law files (docs/formats.md) through `fibernet wet --law FILE` (with and without -o)
  sweep_ckpt  sweep checkpoints and their CSV (docs/sweep.md) through `fibernet sweep ... --resume`; the resumed CSV is
              checked: header kept, no row lost, steps contiguous from the first, gamma inside [0, gamma_max] and
              rising, a completed sweep ends at gamma_max, JSON rows == CSV rows
  percolation percolation sample CSVs through `fibernet percolation --resume`; the result is checked: header kept, no
              duplicate (L, q, sample), every sample present, d/rigid/connected consistent, P in [0, 1]
  model       model files (`fibernet export` / `relax -o`) through `fibernet export --model FILE` (--format vtp and
              lammps), and fed to every other reader slot as a wrong file, as in `foreign`
  foreign     every seed file (and empty, binary, UTF-16, BOM, directory, /dev/null inputs) in every reader slot: the
              positional scene (a non-scene file there must get a message that says so), --network, --law, a sweep
              checkpoint, a percolation CSV
  paths       valid inputs and outputs under odd file names (invalid UTF-8, a newline, a leading '-', ...)
  points      lists of points (`fibernet scan --points FILE`, docs/scan.md) for a scan of pebble games; a scan that
              runs must give one samples.csv row per point

Each case gets a fresh directory with its input files, runs one fibernet command (timeout, 1 process at a time,
OMP/OpenBLAS/FIBERNET threads = 1, address space limited) and is classified:

  ok        exit 0 or 1 with valid output (JSON parses, no NaN/inf, status agrees with the exit code, checks above)
  rejected  exit 2, a message on stderr naming a file / flag / key, and no file created, changed or removed
  failures  crash (signal), timeout, internal_error (exit 3 or "internal error"), exit2_partial_output,
            exit2_unnamed, nonfinite_output, bad_json, status_mismatch, unexpected_exit, missing_output,
            scene_arg_not_explained, and the format checks (resume_*, perc_*)

Failing cases are saved under --out DIR/<format>-<category>-<case>/ (input files, cmd.sh, stdout, stderr,
meta.json), at most --keep per (format, category). Summary: a table per format and category, then the line
`fuzz: N passed, M failed`. Exit status 1 if any case failed.

Case generation is deterministic: case i of format F uses random.Random("<seed>:F:i"), so selecting formats or
changing --cases keeps the other cases the same.
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import random

from fibernet_runs import child_env, child_limits, parse_json, sanitized

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FORMATS = ["network", "scene", "law", "sweep_ckpt", "percolation", "model", "foreign", "paths", "points"]
DEFAULT_SEED = 20261201
TINY = ["--L", "2.5", "--q", "4"]

SWEEP_HEADER = (b"step,gamma,sigma_xx,sigma_xy,sigma_yy,stress_path,dsdgamma,dsdgamma_affine,energy,stretch,bend,iterations,"
                b"factorizations,retries,grad_max,seconds")
PERC_HEADER = b"pl,L,q,sample,seed,fibers,d,rigid_spanning,connected_spanning,seconds"
PERC_ARGS = ["--pl", "1", "--L", "3", "--q-min", "5", "--q-max", "6", "--q-step", "0.5", "--samples", "2",
             "--threads", "1", "--seed", "1"]
PERC_GRID = {("3", q, s) for q in ("5", "5.5", "6") for s in (0, 1)}
SWEEP_PARTIAL = ["sweep"] + TINY + ["--gamma-max", "0.06", "--step", "0.01", "--max-step", "0.01", "-q"]
SWEEP_DONE = ["sweep"] + TINY + ["--gamma-max", "0.03", "--step", "0.01", "--max-step", "0.01", "-q"]

NONFINITE = re.compile(rb"(?<![A-Za-z_])[-+]?(nan|inf|infinity)(?![A-Za-z_])", re.I)

# ----------------------------------------------------------------------------------------------------------------
# mutations (bytes -> bytes); each returns (new bytes, description)

ODD_NUMBERS = ["0", "-0", "-1", "1", "2", "3", "0.5", "1e308", "-1e308", "1e309", "-1e309", "nan", "NaN", "-nan",
               "inf", "-inf", "Infinity", "1e-320", "4.9e-324", "-1e-320", "1e-12", "-0.001", "1e15",
               "9223372036854775807", "9223372036854775808", "-9223372036854775809", "18446744073709551616",
               "2147483647", "2147483648", "4294967296", "100000000", "1000000000", "99999999999999999999999", "",
               "1e", "1e+", "0x10", "0x1p3", "1.", ".5", "+1", "--1", "0.0.1", "1,5", "1_000", "\u0661", "1 2"]
INVALID_UTF8 = [b"\xff", b"\xc3", b"\xed\xa0\x80", b"\xc0\xaf", b"\xfe\xff", b"\x80", b"\xf4\x90\x80\x80", b"\xe2\x82",
                b"\x00"]
INSERT_LINES = [b"\n", b"   \n", b"#\n", b"# a comment\n", b"\t# tab comment\n", b"\r\n", b"\x0c\n", b" \t \n",
                b"#\xff\n", b"x\n", b"1 2\n", b"[network]\n", b"= 1\n"]
TOML_VALUES = ['"x"', '""', 'true', 'false', '[]', '["dangling"]', '{}', '{ a = 1 }', '1979-05-27', '07:32:00',
               '"seed"', '"even"', '"shear"', '"newton"', '"lbfgs"', '"fraction"', '"free"', 'nan', '+nan', 'inf',
               '-inf', '0x10', '0o7', '0b11', '1_0', '9223372036854775807', '9223372036854775808', '-1', '0', '-0.0',
               '1e308', '1e-320', '1e400', '"\\uD800"', '"\\u0000"', '"net_p.txt"', '"law3.txt"', '"/nonexistent"',
               '"."', '"../x"', '2.5', '100000', '1e9', '0.0001']
TOML_KEYS = ["L", "q", "pl", "seed", "periodic", "file", "scheme", "n_seg", "h", "a", "fiber_length", "prune", "strain",
             "gamma", "name", "tol", "max_iter", "beta", "law", "crossings", "fraction", "free_box", "free_box_shape",
             "free_box_tol", "max_rounds", "round_iterations", "newton_ldl", "local_fraction", "local_threshold",
             "local_hops", "bundle_partners", "bogus"]
NUM_RE = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _lines(b):
    return b.splitlines(keepends=True)


def m_byte_flip(rng, b, kind):
    if not b:
        return b"\xff", "byte flip on empty -> \\xff"
    b = bytearray(b)
    i = rng.randrange(len(b))
    if rng.random() < 0.5:
        b[i] ^= 1 << rng.randrange(8)
    else:
        b[i] = rng.randrange(256)
    return bytes(b), "byte flip at %d" % i


def m_invalid_utf8(rng, b, kind):
    bad = rng.choice(INVALID_UTF8)
    r = rng.random()
    lines = _lines(b)
    if r < 0.35 or not lines:  # a comment line (readers skip comments: the bytes reach whatever copies the text)
        i = rng.randrange(len(lines) + 1)
        lines.insert(i, b"# " + bad + b" comment\n")
        return b"".join(lines), "comment line with %r inserted at line %d" % (bad, i + 1)
    if r < 0.55:  # after a row, as a trailing comment
        i = rng.randrange(len(lines))
        lines[i] = lines[i].rstrip(b"\r\n") + b"  # " + bad + b"\n"
        return b"".join(lines), "trailing comment with %r on line %d" % (bad, i + 1)
    i = rng.randrange(len(b) + 1)
    return b[:i] + bad + b[i:], "%r inserted at byte %d" % (bad, i)


def m_truncate(rng, b, kind):
    if rng.random() < 0.5:
        i = rng.randrange(len(b) + 1)
        return b[:i], "truncated at byte %d of %d" % (i, len(b))
    lines = _lines(b)
    i = rng.randrange(len(lines) + 1)
    return b"".join(lines[:i]), "truncated to %d of %d lines" % (i, len(lines))


def m_line_op(rng, b, kind):
    lines = _lines(b)
    if not lines:
        return b"\n", "line op on empty"
    op = rng.choice(["delete", "duplicate", "swap", "move"])
    i = rng.randrange(len(lines))
    if not lines[i].endswith(b"\n"):
        lines[i] += b"\n"
    if op == "delete":
        del lines[i]
        return b"".join(lines), "line %d deleted" % (i + 1)
    if op == "duplicate":
        lines.insert(i, lines[i])
        return b"".join(lines), "line %d duplicated" % (i + 1)
    j = rng.randrange(len(lines))
    if not lines[j].endswith(b"\n"):
        lines[j] += b"\n"
    if op == "swap":
        lines[i], lines[j] = lines[j], lines[i]
        return b"".join(lines), "lines %d and %d swapped" % (i + 1, j + 1)
    line = lines.pop(i)
    lines.insert(j, line)
    return b"".join(lines), "line %d moved to %d" % (i + 1, j + 1)


def _number_spans(b, head_lines=None):
    spans = []
    off = 0
    for n, line in enumerate(_lines(b)):
        if head_lines is None or n < head_lines:
            for m in NUM_RE.finditer(line):
                spans.append((off + m.start(), off + m.end()))
        off += len(line)
    return spans


def m_number(rng, b, kind):
    # headers and counts matter most: half the time only numbers of the first lines
    head = {"network": 5, "sweep_ckpt": 9, "model": 10}.get(kind)
    spans = _number_spans(b, head if head and rng.random() < 0.5 else None) or _number_spans(b)
    if not spans:
        return m_byte_flip(rng, b, kind)
    s, e = rng.choice(spans)
    v = rng.choice(ODD_NUMBERS).encode()
    return b[:s] + v + b[e:], "number %r at byte %d -> %r" % (b[s:e], s, v)


def m_keyword(rng, b, kind):
    lines = _lines(b)
    cands = [i for i, l in enumerate(lines) if re.match(rb"\s*[A-Za-z_\[]", l)]
    if not cands:
        return m_byte_flip(rng, b, kind)
    i = rng.choice(cands)
    m = re.match(rb"(\s*)([A-Za-z_\[\]\-.]+)", lines[i])
    word = m.group(2)
    words = sorted({re.match(rb"\s*([A-Za-z_\[\]\-.]+)", lines[k]).group(1) for k in cands})
    op = rng.choice(["upper", "drop", "append", "other", "random", "empty"])
    if op == "upper":
        new = word.upper() if word != word.upper() else word.lower()
    elif op == "drop":
        new = word[:-1]
    elif op == "append":
        new = word + rng.choice([b"s", b"_", b"2", b"\xff"])
    elif op == "other":
        new = rng.choice(words)
    elif op == "random":
        new = rng.choice([b"box", b"fibers", b"crossings", b"breakpoints", b"meta", b"rows", b"step", b"t", b"q",
                          b"next_step", b"dofs", b"completed", b"parameters", b"[wet]", b"[network]", b"bogus",
                          b"fibernet-network", b"fibernet-model", b"fibernet-sweep-checkpoint"])
    else:
        new = b""
    lines[i] = m.group(1) + new + lines[i][m.end():]
    return b"".join(lines), "keyword %r on line %d -> %r" % (word, i + 1, new)


def m_insert_line(rng, b, kind):
    lines = _lines(b)
    i = rng.randrange(len(lines) + 1)
    if i > 0 and not lines[i - 1].endswith(b"\n"):
        lines[i - 1] += b"\n"
    ins = rng.choice(INSERT_LINES)
    lines.insert(i, ins)
    return b"".join(lines), "line %r inserted at %d" % (ins, i + 1)


def m_whitespace(rng, b, kind):
    op = rng.choice(["crlf", "cr", "tabs", "no_final_newline", "trailing_spaces", "leading_spaces", "bom",
                     "double_newlines"])
    if op == "crlf":
        return b.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n"), "CRLF line ends"
    if op == "cr":
        return b.replace(b"\n", b"\r"), "CR line ends"
    if op == "tabs":
        return b.replace(b" ", b"\t"), "spaces -> tabs"
    if op == "no_final_newline":
        return b.rstrip(b"\n"), "no final newline"
    if op == "trailing_spaces":
        return b.replace(b"\n", b"  \n"), "trailing spaces"
    if op == "leading_spaces":
        return b"".join(b"  " + l for l in _lines(b)), "leading spaces"
    if op == "bom":
        return b"\xef\xbb\xbf" + b, "UTF-8 BOM"
    return b.replace(b"\n", b"\n\n"), "blank line after every line"


def m_token(rng, b, kind):
    lines = _lines(b)
    cands = [i for i, l in enumerate(lines) if l.strip()]
    if not cands:
        return m_byte_flip(rng, b, kind)
    i = rng.choice(cands)
    end = b"\n" if lines[i].endswith(b"\n") else b""
    sep = b"," if kind == "percolation" or (b"," in lines[i] and b" " not in lines[i].strip()) else b" "
    toks = lines[i].rstrip(b"\r\n").split(sep)
    op = rng.choice(["delete", "duplicate", "extra", "replace"])
    k = rng.randrange(len(toks))
    if op == "delete" and len(toks) > 1:
        del toks[k]
    elif op == "duplicate":
        toks.insert(k, toks[k])
    elif op == "extra":
        toks.append(rng.choice([b"1", b"x", b"#", b"0", b"nan"]))
    else:
        toks[k] = rng.choice(ODD_NUMBERS).encode()
    lines[i] = sep.join(toks) + end
    return b"".join(lines), "token %s at line %d field %d" % (op, i + 1, k + 1)


def m_toml(rng, b, kind):
    lines = _lines(b)
    kv = [i for i, l in enumerate(lines) if re.match(rb"\s*[A-Za-z_]+\s*=", l)]
    op = rng.choice(["value", "value", "key", "dup_table", "new_key", "drop_table_header", "inline"])
    if op == "value" and kv:
        i = rng.choice(kv)
        m = re.match(rb"(\s*[A-Za-z_]+\s*=\s*)(.*?)(\s*(#.*)?)(\r?\n)?$", lines[i], re.S)
        new = rng.choice(TOML_VALUES).encode()
        lines[i] = m.group(1) + new + b"\n"
        return b"".join(lines), "value on line %d -> %r" % (i + 1, new)
    if op == "key" and kv:
        i = rng.choice(kv)
        m = re.match(rb"(\s*)([A-Za-z_]+)", lines[i])
        new = rng.choice(TOML_KEYS).encode()
        lines[i] = m.group(1) + new + lines[i][m.end():]
        return b"".join(lines), "key on line %d -> %r" % (i + 1, new)
    if op == "new_key":
        tables = [i for i, l in enumerate(lines) if l.strip().startswith(b"[")]
        i = rng.choice(tables) + 1 if tables else 0
        line = ("%s = %s\n" % (rng.choice(TOML_KEYS), rng.choice(TOML_VALUES))).encode()
        lines.insert(i, line)
        return b"".join(lines), "line %r inserted at %d" % (line, i + 1)
    if op == "dup_table":
        t = rng.choice([b"[network]", b"[model]", b"[load]", b"[solver]", b"[wet]", b"[bogus]", b"[[network]]",
                        b"[network.sub]"])
        return b + b"\n" + t + b"\n", "table %r appended" % t
    if op == "drop_table_header":
        tables = [i for i, l in enumerate(lines) if l.strip().startswith(b"[")]
        if tables:
            i = rng.choice(tables)
            del lines[i]
            return b"".join(lines), "table header on line %d deleted" % (i + 1)
    if op == "inline":
        return b"x = { a = 1, b = [1, \"2\"] }\n" + b, "inline table prepended"
    return m_number(rng, b, kind)


def m_ckpt_params(rng, b, kind):
    lines = _lines(b)
    for i, l in enumerate(lines):
        if l.startswith(b"parameters "):
            try:
                j = json.loads(l[len(b"parameters "):])
            except ValueError:
                break
            key = rng.choice(sorted(j) + ["bogus"])
            op = rng.choice(["delete", "value", "value"])
            if op == "delete" and key in j:
                del j[key]
                desc = "parameters: %s deleted" % key
            else:
                v = rng.choice([0, -1, 1e308, None, "x", True, [], {}, 0.06, 0.03, 2.5, 4.0, "shear"])
                j[key] = v
                desc = "parameters: %s -> %r" % (key, v)
            lines[i] = b"parameters " + json.dumps(j, separators=(",", ":"), sort_keys=True).encode() + b"\n"
            return b"".join(lines), desc
    return m_number(rng, b, kind)


def m_ckpt_header(rng, b, kind):
    """The known-bad values of the issue report, on the checkpoint's header fields."""
    key = rng.choice([b"rows", b"step", b"t", b"next_step", b"dofs", b"completed"])
    val = rng.choice([b"0", b"-0", b"-1", b"-5", b"1", b"2", b"3", b"5", b"1000", b"-0.001", b"0.001", b"1e-320",
                      b"1e308", b"nan", b"inf", b"0.5", b"-0.03", b"0.06", b"0.07", b"2147483648", b"1.5", b""])
    out, n = re.subn(rb"(?m)^" + key + rb" [^\n]*$", key + b" " + val, b, count=1)
    if not n:
        return m_number(rng, b, kind)
    return out, "checkpoint %s -> %r" % (key.decode(), val)


def m_csv_field(rng, b, kind):
    lines = _lines(b)
    data = [i for i in range(1, len(lines)) if lines[i].strip()]
    if not data:
        return m_number(rng, b, kind)
    i = rng.choice(data)
    end = b"\n" if lines[i].endswith(b"\n") else b""
    f = lines[i].rstrip(b"\r\n").split(b",")
    k = rng.randrange(len(f))
    new = rng.choice(ODD_NUMBERS + ["7", "-3", "4", "5.25", "4.0", "3.0", "1.0000000001", "0.999999999999"]).encode()
    f[k] = new
    lines[i] = b",".join(f) + end
    return b"".join(lines), "CSV line %d field %d -> %r" % (i + 1, k + 1, new)


GENERIC = [(m_byte_flip, 2), (m_invalid_utf8, 2), (m_truncate, 2), (m_line_op, 3), (m_number, 5), (m_keyword, 2),
           (m_insert_line, 2), (m_whitespace, 1), (m_token, 2)]
EXTRA = {"scene": [(m_toml, 6)], "sweep_ckpt": [(m_ckpt_header, 5), (m_ckpt_params, 1)],
         "sweep_csv": [(m_csv_field, 4)],
         "percolation": [(m_csv_field, 6)], "points": [(m_csv_field, 6)]}


def mutate(rng, b, kind, n=None):
    ops = GENERIC + EXTRA.get(kind, [])
    total = sum(w for _, w in ops)
    descs = []
    for _ in range(n if n is not None else rng.choice([1, 1, 1, 2, 2, 3])):
        r = rng.uniform(0, total)
        for f, w in ops:
            r -= w
            if r <= 0:
                break
        b, d = f(rng, b, kind)
        descs.append(d)
    return b, descs


# ----------------------------------------------------------------------------------------------------------------
# running




class Result:
    pass


# True when the fibernet under test is built with AddressSanitizer (set in main): no address-space limit, a cap per
# allocation instead, and a longer timeout (fibernet_runs.child_limits).
ASAN = False
# ASan and UBSan at -O1 (scripts/sanitize.sh) run fibernet a few times slower than the Release build.
ASAN_SLOWDOWN = 4


def run(argv, cwd, timeout):
    asan = ASAN
    if asan:
        timeout *= ASAN_SLOWDOWN
    r = Result()
    t0 = time.monotonic()
    p = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         env=child_env(3, asan), preexec_fn=lambda: child_limits(3, 256, asan))
    r.timed_out = False
    try:
        r.out, r.err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        r.timed_out = True
        p.kill()  # only the process we started, by its pid
        r.out, r.err = p.communicate()
    r.rc = p.returncode
    r.seconds = time.monotonic() - t0
    return r


def snapshot(d):
    snap = {}
    for root, dirs, files in os.walk(d):
        for n in dirs:
            snap[os.path.relpath(os.path.join(root, n), d)] = "dir"
        for n in files:
            p = os.path.join(root, n)
            try:
                with open(p, "rb") as f:
                    snap[os.path.relpath(p, d)] = f.read()
            except OSError:
                snap[os.path.relpath(p, d)] = "unreadable"
    return snap


def snap_diff(a, b):
    """Files created, changed or removed between two snapshots (names as str or bytes)."""
    out = []
    for k in sorted(set(a) | set(b), key=lambda x: os.fsencode(x)):
        if a.get(k) != b.get(k):
            out.append(("created " if k not in a else "removed " if k not in b else "changed ") + repr(k))
    return out



def csv_rows(b):
    return [l.split(b",") for l in b.splitlines()]


def nonfinite_in(b):
    m = NONFINITE.search(b)
    return m.group(0) if m else None


# ----------------------------------------------------------------------------------------------------------------
# checks shared by fuzz cases


class Case:
    def __init__(self, fmt, index, argv, files, descs, command, checks=None, expect_scene_msg=False, outputs=()):
        self.fmt, self.index, self.argv, self.files, self.descs = fmt, index, argv, files, descs
        self.command = command          # subcommand name, for exit-code expectations
        self.checks = checks or []      # extra checks: f(case, result, before, after, dir) -> [(category, detail)]
        self.expect_scene_msg = expect_scene_msg
        self.outputs = outputs          # output paths (relative) that exit 0 must produce
        self.skip_nonfinite = set()     # outputs that are also (mutated) inputs: their own check looks at them


EXPECTED_RC = {"info": {0, 2}, "export": {0, 2}, "generate": {0, 2}, "rigidity": {0, 2}, "percolation": {0, 2},
               "modulus": {0, 1, 2}, "relax": {0, 1, 2}, "sweep": {0, 1, 2}, "wet": {0, 1, 2}, "compare": {0, 1, 2},
               "scan": {0, 1, 2}}
JSON_STDOUT = {"info", "modulus", "relax", "sweep", "wet", "rigidity", "percolation", "compare", "scan"}


def names_something(err, case):
    if re.search(rb"--[a-zA-Z]", err) or b"command line" in err or re.search(rb"\[[a-z]+\]", err):
        return True
    for name in case.files:
        bn = os.path.basename(os.fsencode(name))
        if bn and bn in err:
            return True
    for a in case.argv[1:]:
        a = os.fsencode(a)
        if len(a) > 2 and a in err:
            return True
    return False


def wet_csv_problems(b, moduli):
    """NaN is documented in the G columns of a row whose status is not ok (and without moduli)."""
    rows = csv_rows(b)
    if not rows:
        return ["empty sweep.csv"]
    head = rows[0]
    probs = []
    for r in rows[1:]:
        for name, v in zip(head, r):
            if NONFINITE.fullmatch(v.strip()):
                allowed = name.startswith(b"G_") and (not moduli or (len(r) > 1 and r[1] != b"ok"))
                if not allowed:
                    probs.append("%s = %s (status %s)" % (name.decode(), v.decode(), r[1].decode() if len(r) > 1 else "?"))
    return probs


def generic_checks(case, r, before, after, d):
    """Returns (category or None for pass, 'ok'/'rejected', detail)."""
    err, out = r.err, r.out
    fails = []
    if r.timed_out:
        return [("timeout", "no exit within the timeout (%.0f s)" % r.seconds)], None
    if r.rc < 0:
        return [("crash", "signal %d (%s)" % (-r.rc, signal.Signals(-r.rc).name if -r.rc in signal.valid_signals() else "?"))], None
    if r.rc == 3 or b"internal error" in err:
        return [("internal_error", "exit %d: %s" % (r.rc, err.decode(errors="replace").strip()[-300:]))], None
    if r.rc not in EXPECTED_RC.get(case.command, {0, 1, 2}):
        return [("unexpected_exit", "exit %d for %s: %s" % (r.rc, case.command, err.decode(errors="replace").strip()[-200:]))], None
    diff = snap_diff(before, after)
    if r.rc == 2:
        if diff:
            fails.append(("exit2_partial_output", "exit 2 but " + ", ".join(diff[:5])))
        if not err.strip():
            fails.append(("exit2_unnamed", "exit 2 with an empty stderr"))
        elif not names_something(err, case):
            fails.append(("exit2_unnamed", "message names no file, flag or key: " + err.decode(errors="replace").strip()[:200]))
        if case.expect_scene_msg and not re.search(rb"scene|--network|--law", err, re.I):
            fails.append(("scene_arg_not_explained", "a non-scene file as the scene: " + err.decode(errors="replace").strip()[:200]))
        return fails, "rejected"
    # exit 0 or 1
    j = None
    json_to_file = ((case.command in ("rigidity", "compare") and "--out" in case.argv) or
                    (case.command == "percolation" and "--summary" in case.argv))
    if case.command in JSON_STDOUT and not json_to_file:
        j, jerr, bad = parse_json(out)
        if jerr:
            fails.append(("bad_json", "stdout is not JSON: " + jerr))
        elif bad:
            fails.append(("nonfinite_output", "stdout JSON has %s" % bad))
    if case.command == "generate" and "-o" not in case.argv:
        if nonfinite_in(out):
            fails.append(("nonfinite_output", "network on stdout has %r" % nonfinite_in(out)))
    # new or changed text outputs must be finite (SVG skipped; wet sweep.csv has documented NaN columns)
    moduli = "--no-moduli" not in case.argv
    for name, v in after.items():
        if not isinstance(v, bytes) or before.get(name) == v:
            continue
        n = os.fsdecode(name)
        if n.endswith(".svg") or n in case.skip_nonfinite:
            continue
        if n.endswith("sweep.csv") and os.path.dirname(n):
            for p in wet_csv_problems(v, moduli):
                fails.append(("nonfinite_output", "%s: %s" % (n, p)))
            continue
        bad = nonfinite_in(v)
        if bad and not n.endswith(".json"):
            fails.append(("nonfinite_output", "%s contains %r" % (n, bad)))
        if n.endswith(".json"):
            jj, jerr, badc = parse_json(v)
            if jerr:
                fails.append(("bad_json", "%s: %s" % (n, jerr)))
            elif badc:
                fails.append(("nonfinite_output", "%s has %s" % (n, badc)))
    if r.rc == 0:
        for o in case.outputs:
            if not os.path.exists(os.path.join(d, o)):
                fails.append(("missing_output", "exit 0 but %r was not written" % o))
    if isinstance(j, dict):
        fails += status_checks(case, r, j, d)
    return fails, "ok"


def status_checks(case, r, j, d):
    f = []
    c = case.command
    st = j.get("status")
    if c in ("modulus", "relax"):
        if (r.rc == 0) != (st == "converged"):
            f.append(("status_mismatch", "exit %d with status %r" % (r.rc, st)))
        if c == "modulus" and st == "converged":
            m = j.get("moduli") or {}
            for k in ("G", "K", "G_error", "K_error"):
                if not isinstance(m.get(k), (int, float)):
                    f.append(("status_mismatch", "converged but moduli.%s = %r" % (k, m.get(k))))
    elif c == "sweep":
        want = {0: "completed", 1: "failed"}.get(r.rc)
        if st != want:
            f.append(("status_mismatch", "exit %d with status %r" % (r.rc, st)))
    elif c == "wet":
        runs = j.get("runs") or []
        good = bool(j.get("complete")) and all(x.get("status") == "stable" for x in runs)
        if (r.rc == 0) != good:
            f.append(("status_mismatch", "exit %d, complete %r, run statuses %r" % (
                r.rc, j.get("complete"), [x.get("status") for x in runs])))
        if "--no-moduli" not in case.argv:  # docs/wet.md: the moduli are NaN (null) only for an unstable relaxation
            for x in runs:
                sm = x.get("shear_modulus") or {}
                nulls = [k for k in ("dry", "wet") if not isinstance(sm.get(k), (int, float))]
                if x.get("status") == "stable" and nulls:
                    f.append(("unexpected_null", "beta %r stable but shear_modulus %s null" % (x.get("beta"), nulls)))
    return f


# ----------------------------------------------------------------------------------------------------------------
# format-specific checks


def parse_float(x):
    try:
        return float(x)
    except ValueError:
        return None


def sweep_resume_check(base_csv, gmax, csv_mutated):
    """The resumed CSV: header kept, every row of the base CSV kept (when the CSV itself was not mutated), steps
    contiguous from the base's first, gamma rising inside [0, gamma_max], a completed sweep ending at gamma_max, JSON
    rows == CSV rows. When the test mutated the CSV itself, every finding is filed as resume_keeps_bad_csv (the resume
    does not validate the CSV it appends to)."""
    def check(case, r, before, after, d):
        if not r.timed_out and r.rc not in (0, 1):
            return []
        f = []
        csv = after.get("s.csv")
        if not isinstance(csv, bytes):
            return [("resume_csv_lost", "s.csv missing after exit %d" % r.rc)]
        lines = csv.splitlines()
        if not lines or lines[0] != SWEEP_HEADER:
            f.append(("resume_header_lost", "first line of s.csv is %r" % (lines[0][:60] if lines else b"")))
        data = lines[1:]
        steps, gammas = [], []
        for l in data:
            fl = l.split(b",")
            vals = [parse_float(x.decode(errors="replace")) for x in fl]
            if len(fl) != 16 or any(v is None for v in vals):
                f.append(("resume_bad_row", "row %r" % l[:80]))
                continue
            if any(v != v or v in (float("inf"), float("-inf")) for v in vals):
                f.append(("nonfinite_output", "s.csv row %r" % l[:80]))
            steps.append(vals[0])
            gammas.append(vals[1])
        base_rows = base_csv.splitlines()[1:]
        if steps:
            if steps[0] != float(base_rows[0].split(b",")[0]):
                f.append(("resume_steps_bad", "first step %g (was %s)" % (steps[0], base_rows[0].split(b",")[0].decode())))
            jumps = [(a, b) for a, b in zip(steps, steps[1:]) if b != a + 1]
            if jumps:
                f.append(("resume_steps_bad", "steps not contiguous: %s" % jumps[:3]))
            lo, hi = min(0.0, gmax), max(0.0, gmax)
            out = [g for g in gammas if not (lo - 1e-12 <= g <= hi + 1e-12)]
            if out:
                f.append(("resume_gamma_out_of_range", "gamma %s outside [%g, %g]" % (out[:3], lo, hi)))
            if any(not (b > a) for a, b in zip(gammas, gammas[1:])):
                f.append(("resume_gamma_not_monotone", "gammas %s" % gammas[:8]))
        j, _, _ = parse_json(r.out)
        if isinstance(j, dict):
            if j.get("status") == "completed" and (not gammas or abs(gammas[-1] - gmax) > 1e-9):
                f.append(("resume_incomplete", "status completed but last gamma %s != %g" % (gammas[-1:] or None, gmax)))
            if j.get("rows") != len(data):
                f.append(("resume_rows_mismatch", "JSON rows %r, CSV data rows %d" % (j.get("rows"), len(data))))
        if not csv_mutated and data[:len(base_rows)] != base_rows:
            f.append(("resume_rows_dropped", "CSV had %d data rows, the resumed CSV keeps %d of them (%d rows now)" % (
                len(base_rows), sum(1 for a, b in zip(data, base_rows) if a == b), len(data))))
        if csv_mutated:
            f = [("resume_keeps_bad_csv", "%s: %s" % (c, x)) for c, x in f]
        return f
    return check


DECIMAL = re.compile(rb"[0-9+\-.eE]+")
INTEGER = re.compile(rb"-?[0-9]+")      # std::from_chars: no '+'
UNSIGNED = re.compile(rb"[0-9]+")


def strict_perc_row(line):
    """A row as `fibernet percolation --resume` reads it (src/cli/cmd_percolation.cpp, parse_row): 10 comma-separated
    fields, decimals in [0-9+-.eE] parsed whole, integers in range of their type (int; the seed uint64). None for a
    line that is no such row: fibernet leaves it out and runs its sample again."""
    f = line.split(b",")
    if len(f) != 10:
        return None
    vals = []
    for k, tok in enumerate(f):
        if k in (0, 1, 2, 9):
            if not DECIMAL.fullmatch(tok):
                return None
            try:
                vals.append(float(tok))
            except ValueError:
                return None
        else:
            if not (UNSIGNED if k == 4 else INTEGER).fullmatch(tok):
                return None
            v = int(tok)
            lo, hi = (0, 2 ** 64) if k == 4 else (-2 ** 31, 2 ** 31)
            if not lo <= v < hi:
                return None
            vals.append(v)
    return vals


def perc_check(case, r, before, after, d):
    if r.timed_out or r.rc != 0:
        return []
    f = []
    csv = after.get("p.csv")
    if not isinstance(csv, bytes):
        return [("perc_csv_lost", "p.csv missing")]
    lines = csv.splitlines()
    if not lines or lines[0] != PERC_HEADER:
        f.append(("perc_header_lost", "first line %r" % (lines[0][:70] if lines else b"")))
    keys, bad, parsed = {}, [], 0
    for l in lines[1:]:
        v = strict_perc_row(l)
        if v is None:
            continue
        pl, L, q, sample, seed, fibers, dd, rig, con, sec = v
        parsed += 1
        key = ("%.10g" % L, "%.10g" % q, sample)
        keys[key] = keys.get(key, 0) + 1
        if not (dd in (0, 1, 2, 3) and rig in (0, 1) and con in (0, 1) and (rig == 1) == (dd == 0) and
                (not rig or con) and fibers >= 0 and 0 <= sec < float("inf")):
            bad.append(l.decode(errors="replace"))
    dup = [k for k, n in keys.items() if n > 1]
    if dup:
        f.append(("perc_duplicate_rows", "samples %s appear more than once" % dup[:3]))
    miss = sorted(PERC_GRID - set(keys))
    if miss:
        f.append(("perc_missing_samples", "samples %s missing after --resume" % miss[:3]))
    if bad:
        f.append(("perc_accepts_invalid_row", "impossible row(s) kept and counted: %s" % bad[:2]))
    t = after.get("t.csv")
    if isinstance(t, bytes):
        for l in t.splitlines()[1:]:
            fl = l.split(b",")
            try:
                P = [float(fl[4]), float(fl[5])]
            except (ValueError, IndexError):
                f.append(("perc_bad_table", "table row %r" % l))
                continue
            if any(not (0 <= p <= 1) for p in P):
                f.append(("perc_bad_table", "P outside [0, 1]: %r" % l.decode(errors="replace")))
    j, _, _ = parse_json(r.out)
    if isinstance(j, dict) and j.get("rows") != parsed:
        f.append(("perc_rows_mismatch", "JSON rows %r, parseable CSV rows %d" % (j.get("rows"), parsed)))
    return f


def sweep_plain_check(case, r, before, after, d):
    """A fresh (non-resume) sweep: CSV rows consistent with the JSON."""
    if r.timed_out or r.rc not in (0, 1):
        return []
    out = next((a for a in case.outputs if a.endswith(".csv")), None)
    csv = after.get(out) if out else None
    if not isinstance(csv, bytes):
        return []
    lines = csv.splitlines()
    f = []
    if not lines or lines[0] != SWEEP_HEADER:
        f.append(("sweep_bad_csv", "header %r" % (lines[0][:60] if lines else b"")))
    j, _, _ = parse_json(r.out)
    if isinstance(j, dict) and j.get("rows") != len(lines) - 1:
        f.append(("sweep_bad_csv", "JSON rows %r, CSV rows %d" % (j.get("rows"), len(lines) - 1)))
    return f


# ----------------------------------------------------------------------------------------------------------------
# seeds


class Seeds:
    def __init__(self, fib, work, timeout):
        self.fib = fib
        self.dir = os.path.join(work, "seeds")
        os.makedirs(self.dir)
        self.files = {}
        self.timeout = timeout
        self.make()

    def cli(self, *args, out=None):
        r = run([self.fib] + list(args), self.dir, max(self.timeout, 60))
        if r.rc != 0:
            sys.exit("fuzz: making seed files failed: fibernet %s -> exit %s\n%s" % (
                " ".join(args), r.rc, r.err.decode(errors="replace")))
        return r

    def read(self, name):
        with open(os.path.join(self.dir, name), "rb") as f:
            self.files[name] = f.read()
        return self.files[name]

    def put(self, name, data):
        with open(os.path.join(self.dir, name), "wb") as f:
            f.write(data)
        self.files[name] = data

    def make(self):
        c = self.cli
        c("generate", "--L", "2.5", "--q", "4", "--seed", "3", "-o", "net_p.txt")
        c("generate", "--L", "2.5", "--q", "4", "--pl", "0.6", "--open", "--seed", "3", "-o", "net_o.txt")
        c("generate", "--L", "3", "--q", "5", "--pl", "0.7", "--seed", "4", "--prune", "dangling", "-o", "net_b.txt")
        for n in ("net_p.txt", "net_o.txt", "net_b.txt"):
            self.read(n)
        c("export", "--L", "2.5", "--q", "4", "--seed", "2", "-o", "model.txt")
        c("relax", "--L", "2.5", "--q", "4", "--seed", "2", "--gamma", "0.01", "-q", "-o", "relax_model.txt")
        self.read("model.txt"), self.read("relax_model.txt")
        self.put("law3.txt", b"# alpha_deg  E/(beta l)\n0    -1.0\n45   -0.5\n90    0.0    # perpendicular: no adhesion\n")
        self.put("law10.txt", b"".join(b"%d %.17g\n" % (a, -__import__("math").cos(a * 3.141592653589793 / 180) ** 2)
                                       for a in range(0, 91, 10)))
        self.put("law2.txt", b"10 -0.9\n80 -0.05\n")
        for p in ("default.toml", "wet.toml", "wet_free.toml"):
            with open(os.path.join(REPO, "problems", p), "rb") as f:
                self.put(p, f.read())
        self.put("tiny.toml", b"""# every key, small
[network]
L = 2.5
q = 4
pl = 0.8
seed = 2
periodic = true

[model]
scheme = "even"
h = 1.0
a = 10
fiber_length = 10
prune = ["dangling"]

[load]
strain = "shear"
gamma = 0.01

[solver]
name = "newton"
tol = 1e-10
max_iter = 200

[wet]
beta = 0.05
crossings = "all"
fraction = 1.0
seed = 1
free_box = false
max_rounds = 100
round_iterations = 10
newton_ldl = true
local_fraction = 0.25
local_threshold = 0.1
local_hops = 3
bundle_partners = 2
""")
        self.put("tiny_file.toml", b"""# a saved network and a law file, both next to the scene
[network]
file = "net_p.txt"

[model]
scheme = "seed"
n_seg = 10

[load]
strain = "uniaxial"
gamma = 0.005

[wet]
beta = 0.1
law = "law3.txt"
crossings = "fraction"
fraction = 0.5
seed = 3
""")
        self.put("tiny_open.toml", b"""[network]
L = 2.5
q = 5
pl = 0.7
seed = 5
periodic = false

[model]
scheme = "seed"

[load]
strain = "isotropic"
gamma = -0.01
""")
        self.put("tiny_free.toml", b"""[network]
L = 2.5
q = 4
pl = 0.5
seed = 1

[wet]
beta = 0.01
free_box = true
free_box_shape = "full"
free_box_tol = 1e-3
""")
        # a partial sweep checkpoint: the completed 0.03 sweep, relabelled as an unfinished 0.06 sweep (fixed step
        # 0.01, so the state is exactly that of a 0.06 sweep stopped after gamma = 0.03)
        c(*SWEEP_DONE[:-1], "-o", "s.csv")
        done_csv, done_ckpt = self.read("s.csv"), self.read("s.csv.ckpt")
        self.files["done_csv"], self.files["done_ckpt"] = done_csv, done_ckpt
        part = done_ckpt.replace(b'"gamma_max":0.03', b'"gamma_max":0.06').replace(b"\ncompleted 1\n", b"\ncompleted 0\n")
        assert part != done_ckpt
        self.put("s.csv.ckpt", part)
        self.files["part_csv"], self.files["part_ckpt"] = done_csv, part
        # check that the base resumes cleanly
        r = run([self.fib] + SWEEP_PARTIAL + ["-o", "s.csv", "--resume"], self.dir, 60)
        if r.rc != 0:
            sys.exit("fuzz: the base sweep checkpoint does not resume: %s" % r.err.decode(errors="replace"))
        self.put("s.csv", done_csv)
        self.put("s.csv.ckpt", part)
        c("percolation", *PERC_ARGS, "--out", "p_full.csv")
        full = self.read("p_full.csv")
        self.put("p.csv", b"".join(_lines(full)[:5]))  # 4 of 6 samples: --resume has 2 to run
        self.put("pts.csv", b"L,q,seed\n2.5,4,1\n3,5,2\n3,5,3\n")
        self.files["pts.csv"] = self.read("pts.csv")
        c("wet", "--L", "2.5", "--q", "4", "--betas", "0,0.1", "-q", "-o", "wetout")
        self.read("wetout/summary.json"), self.read("wetout/sweep.csv"), self.read("wetout/network.svg")


# ----------------------------------------------------------------------------------------------------------------
# case generators: each returns a Case


def scene_companions(seeds):
    return {"net_p.txt": seeds.files["net_p.txt"], "law3.txt": seeds.files["law3.txt"]}


def gen_network(rng, i, seeds):
    base = rng.choice(["net_p.txt", "net_o.txt", "net_b.txt"])
    data, descs = mutate(rng, seeds.files[base], "network")
    files = {"net.txt": data}
    cmd = rng.choice(["info", "info", "modulus", "modulus", "export", "relax", "rigidity", "wet", "sweep", "generate"])
    argv, outputs, checks = [cmd, "--network", "net.txt"], (), []
    if cmd == "export":
        argv += ["-o", "out/model.txt"]
        outputs = ("out/model.txt",)
    elif cmd == "relax":
        argv += ["--gamma", rng.choice(["0", "0.01", "-0.01"]), "-q", "-o", "out/relax.txt"]
    elif cmd == "modulus":
        argv += ["-q"] + rng.choice([[], ["--gamma", "0.02"], ["--scheme", "even"], ["--strain", "uniaxial", "--gamma", "0.01"]])
    elif cmd == "rigidity":
        argv += rng.choice([[], ["--no-clamps"], ["--clusters", "--svg", "out/r.svg"]])
    elif cmd == "wet":
        argv += ["--betas", rng.choice(["0.1", "0,0.05"]), "-q", "-o", "out/wet"] + rng.choice([["--no-moduli"], []])
        outputs = ("out/wet/summary.json",)
    elif cmd == "sweep":
        argv += ["--gamma-max", "0.02", "--step", "0.01", "-q", "-o", "out/s.csv"]
        outputs = ("out/s.csv",)
        checks = [sweep_plain_check]
    elif cmd == "generate":
        argv += ["-o", "out/n.txt"]
        outputs = ("out/n.txt",)
    return Case("network", i, argv, files, ["%s: %s" % (base, d) for d in descs], cmd, checks, outputs=outputs)


SCENES = ["tiny.toml", "tiny.toml", "tiny_file.toml", "tiny_open.toml", "tiny_free.toml", "default.toml", "wet.toml",
          "wet_free.toml"]


def gen_scene(rng, i, seeds):
    base = rng.choice(SCENES)
    data, descs = mutate(rng, seeds.files[base], "scene")
    files = dict(scene_companions(seeds))
    files["scene.toml"] = data
    cmd = rng.choice(["info", "info", "modulus", "modulus", "export", "relax", "rigidity", "wet", "wet", "sweep"])
    big = base in ("default.toml", "wet.toml", "wet_free.toml")
    argv, outputs, checks = [cmd, "scene.toml"], (), []
    override = big and (cmd not in ("info", "export") or rng.random() < 0.3)
    if override:
        argv += TINY
    if cmd == "export":
        argv += ["-o", "out/model.txt"]
        outputs = ("out/model.txt",)
    elif cmd == "relax":
        argv += ["-q", "-o", "out/relax.txt"]
    elif cmd == "modulus":
        argv += ["-q"]
    elif cmd == "wet":
        argv += ["-q", "-o", "out/wet"] + rng.choice([[], ["--no-moduli"], ["--betas", "0,0.05"]])
        outputs = ("out/wet/summary.json",)
    elif cmd == "sweep":
        argv += ["--gamma-max", "0.02", "--step", "0.01", "-q", "-o", "out/s.csv"]
        outputs = ("out/s.csv",)
        checks = [sweep_plain_check]
    return Case("scene", i, argv, files, ["%s: %s" % (base, d) for d in descs], cmd, checks, outputs=outputs)


LAW_KNOWN = [b"# \xff\n0 -1\n90 0\n", b"0 -1 # \xc3\n90 0\n", b"0 -1\n\xff0 0\n"]


def gen_law(rng, i, seeds):
    base = rng.choice(["law3.txt", "law10.txt", "law2.txt"])
    if i < len(LAW_KNOWN):  # the issue report's invalid UTF-8 (in a comment: the table itself is valid) first
        base, data, descs = "hand-made", LAW_KNOWN[i], ["invalid UTF-8: %r" % LAW_KNOWN[i]]
    else:
        data, descs = mutate(rng, seeds.files[base], "law")
    files = {"law.txt": data}
    argv = ["wet"] + TINY + ["--betas", rng.choice(["0.1", "0,0.1"]), "-q", "--law", "law.txt"]
    outputs = ()
    if rng.random() < 0.6:
        argv += ["-o", "out/wet"]
        outputs = ("out/wet/summary.json",)
    if rng.random() < 0.5:
        argv += ["--no-moduli"]
    if rng.random() < 0.2:
        argv += ["--open"]
    return Case("law", i, argv, files, ["%s: %s" % (base, d) for d in descs], "wet", outputs=outputs)


CKPT_KNOWN = [(b"next_step", b"0"), (b"next_step", b"-0.001"), (b"rows", b"-1"), (b"rows", b"0"), (b"step", b"-5")]
CKPT_KEYS = [b"rows", b"step", b"t", b"next_step", b"dofs", b"completed"]
CKPT_VALUES = [b"0", b"-0", b"-1", b"-5", b"1", b"2", b"3", b"5", b"1000", b"-0.001", b"0.001", b"1e-320", b"1e308",
               b"nan", b"inf", b"0.5", b"-0.03", b"0.06", b"0.07", b"2147483648", b"1.5", b""]
CKPT_ENUM = CKPT_KNOWN + [(k, v) for k in CKPT_KEYS for v in CKPT_VALUES if (k, v) not in CKPT_KNOWN]


def gen_sweep_ckpt(rng, i, seeds):
    if i < len(CKPT_ENUM):  # first every header field at every odd value, the issue report's ones first
        key, val = CKPT_ENUM[i]
        ckpt, n = re.subn(rb"(?m)^" + key + rb" [^\n]*$", key + b" " + val, seeds.files["part_ckpt"], count=1)
        c = Case("sweep_ckpt", i, SWEEP_PARTIAL + ["-o", "s.csv", "--resume"],
                 {"s.csv": seeds.files["part_csv"], "s.csv.ckpt": ckpt},
                 ["partial 0.03 of 0.06: ckpt: %s -> %r" % (key.decode(), val)], "sweep",
                 [sweep_resume_check(seeds.files["part_csv"], 0.06, False)], outputs=("s.csv",))
        c.skip_nonfinite = {"s.csv"}
        return c
    partial = rng.random() < 0.8
    csv = seeds.files["part_csv" if partial else "done_csv"]
    ckpt = seeds.files["part_ckpt" if partial else "done_ckpt"]
    r = rng.random()
    descs = []
    csv_mut = False
    if r < 0.75 or i % 4 == 0:
        ckpt, d = mutate(rng, ckpt, "sweep_ckpt")
        descs += ["ckpt: " + x for x in d]
    if r >= 0.75 or r < 0.05:
        csv, d = mutate(rng, csv, "sweep_csv")
        descs += ["csv: " + x for x in d]
        csv_mut = True
    files = {"s.csv": csv, "s.csv.ckpt": ckpt}
    argv = (SWEEP_PARTIAL if partial else SWEEP_DONE) + ["-o", "s.csv", "--resume"]
    gmax = 0.06 if partial else 0.03
    descs = [("partial 0.03 of 0.06: " if partial else "completed 0.03: ") + d for d in descs]
    c = Case("sweep_ckpt", i, argv, files, descs, "sweep",
             [sweep_resume_check(seeds.files["part_csv"], gmax, csv_mut)], outputs=("s.csv",))
    c.skip_nonfinite = {"s.csv"}  # judged by sweep_resume_check (a NaN copied from a mutated CSV is filed apart)
    return c


def gen_percolation(rng, i, seeds):
    base = rng.choice(["p.csv", "p.csv", "p_full.csv"])
    data, descs = mutate(rng, seeds.files[base], "percolation")
    files = {"p.csv": data}
    argv = ["percolation"] + PERC_ARGS + ["--out", "p.csv", "--resume", "--table", "t.csv"]
    c = Case("percolation", i, argv, files, ["%s: %s" % (base, d) for d in descs], "percolation", [perc_check],
             outputs=("p.csv",))
    c.skip_nonfinite = {"p.csv"}  # its rows came from the mutated input; perc_check judges them
    return c


def points_check(case, r, before, after, d):
    """A scan that ran has one samples.csv row per point of its (mutated) list."""
    if r.rc not in (0, 1):
        return []
    pts = [l for l in case.files["pts.csv"].decode(errors="replace").splitlines() if l.strip() and not l.startswith("#")]
    path = os.path.join(d, "out", "samples.csv")
    if not os.path.exists(path):
        return [("missing_output", "out/samples.csv")]
    rows = open(path, "rb").read().splitlines()
    if len(rows) != len(pts):
        return [("points_rows", "%d rows for %d points" % (len(rows) - 1, len(pts) - 1))]
    return []


def gen_points(rng, i, seeds):
    data, descs = mutate(rng, seeds.files["pts.csv"], "points")
    argv = ["scan", "--open", "--points", "pts.csv", "--job", "rigidity", "-q", "-o", "out"]
    return Case("points", i, argv, {"pts.csv": data}, ["pts.csv: %s" % d for d in descs], "scan", [points_check],
                outputs=("out/samples.csv",))


# reader slots: (name, builder(filename) -> (argv, command, extra files, expect_scene_msg, checks, outputs))
def slot_defs(seeds):
    return [
        ("scene:rigidity", lambda f: (["rigidity", f], "rigidity", {}, True, [], ())),
        ("scene:info", lambda f: (["info", f], "info", {}, True, [], ())),
        ("scene:modulus", lambda f: (["modulus", f, "-q"], "modulus", {}, True, [], ())),
        # (small overrides: an empty file is a valid scene of the default, 800-fiber network)
        ("scene:wet", lambda f: (["wet", f] + TINY + ["-q", "--no-moduli", "-o", "out/wet"], "wet", {}, True, [], ())),
        ("scene:sweep", lambda f: (["sweep", f] + TINY + ["--gamma-max", "0.01", "-q", "-o", "out/s.csv"], "sweep", {},
                                   True, [], ())),
        ("network:info", lambda f: (["info", "--network", f], "info", {}, False, [], ())),
        ("network:modulus", lambda f: (["modulus", "--network", f, "-q"], "modulus", {}, False, [], ())),
        ("law:wet", lambda f: (["wet"] + TINY + ["--betas", "0.1", "-q", "--no-moduli", "--law", f, "-o", "out/wet"],
                               "wet", {}, False, [], ())),
        ("ckpt:sweep", lambda f: (SWEEP_PARTIAL + ["-o", "s.csv", "--resume", "--checkpoint", f], "sweep",
                                  {"s.csv": seeds.files["part_csv"]}, False,
                                  [sweep_resume_check(seeds.files["part_csv"], 0.06, False)], ())),
        ("csv:sweep", lambda f: (SWEEP_PARTIAL + ["-o", f, "--resume", "--checkpoint", "c.ckpt"], "sweep",
                                 {"c.ckpt": seeds.files["part_ckpt"]}, False, [], ())),
        ("csv:percolation", lambda f: (["percolation"] + PERC_ARGS + ["--out", f, "--resume"], "percolation", {}, False,
                                       [], ())),
        ("model:export-vtp", lambda f: (["export", "--model", f, "--format", "vtp", "-q", "-o", "out/s.vtp"], "export",
                                        {}, False, [], ())),
        ("model:export-lammps", lambda f: (["export", "--model", f, "--format", "lammps", "-q", "-o", "out/l"],
                                           "export", {}, False, [], ())),
    ]


def foreign_files(seeds):
    s = seeds.files
    scene_utf16 = s["tiny.toml"].decode().encode("utf-16")
    return [
        ("net_p.txt", s["net_p.txt"]), ("net_o.txt", s["net_o.txt"]), ("model.txt", s["model.txt"]),
        ("relax_model.txt", s["relax_model.txt"]), ("scene.toml", s["tiny.toml"]), ("law.txt", s["law3.txt"]),
        ("sweep.ckpt", s["part_ckpt"]), ("sweep.csv", s["part_csv"]), ("perc.csv", s["p.csv"]),
        ("summary.json", s["wetout/summary.json"]), ("wet_sweep.csv", s["wetout/sweep.csv"]),
        ("network.svg", s["wetout/network.svg"]), ("empty.txt", b""), ("newline.txt", b"\n"),
        ("binary.bin", bytes(random.Random(7).randrange(256) for _ in range(300))),
        ("utf16.toml", scene_utf16), ("bom.toml", b"\xef\xbb\xbf" + s["tiny.toml"]),
        ("bom_net.txt", b"\xef\xbb\xbf" + s["net_p.txt"]), ("nul.txt", b"\x00" * 64),
        ("longline.txt", b"a" * 200000 + b"\n"), ("DIR", None), ("/dev/null", None),
    ]


def gen_foreign(rng, i, seeds, mutate_kind=None):
    slots = slot_defs(seeds)
    ff = foreign_files(seeds)
    if mutate_kind == "model":
        fname = rng.choice(["model.txt", "relax_model.txt"])
        content, descs = mutate(rng, seeds.files[fname], "model")
        slot = slots[i % len(slots)]
        descs = ["%s: %s" % (fname, d) for d in descs]
    else:
        combos = [(s, f) for s in slots for f in ff]
        if i < len(combos):
            slot, (fname, content) = combos[i]
            descs = ["%s in slot %s" % (fname, slot[0])]
        else:
            slot = rng.choice(slots)
            fname, content = rng.choice([x for x in ff if x[1] is not None])
            content, d = mutate(rng, content, "foreign")
            descs = ["%s in slot %s: %s" % (fname, slot[0], x) for x in d]
    files = {}
    if fname == "DIR":
        arg = "adir"
        files["adir/"] = None
    elif fname.startswith("/"):
        arg = fname
    else:
        arg = "in_" + os.path.basename(fname)
        files[arg] = content
    argv, command, extra, scene_msg, checks, outputs = slot[1](arg)
    files.update(extra)
    # A file that says what it is (a network, model or checkpoint header) given as the scene must be named as such,
    # not answered with a raw TOML parse error (`fibernet rigidity net.txt`); only unmutated files are held to it.
    expect = (scene_msg and mutate_kind is None and i < len(slots) * len(ff) and content is not None and
              content.lstrip(b"\xef\xbb\xbf").startswith(b"fibernet-"))
    return Case("model" if mutate_kind else "foreign", i, argv, files, descs, command, checks, expect, outputs)


ODD_NAMES = [b"n\xffet.txt", b"\xc3.txt", b"a\nb.txt", b"-dash.txt", b"sp ace.txt", "\u00fc\u00df.txt".encode(),
             b"x" * 200 + b".txt", b"tab\t.txt", b"q'uote\".txt", b"#hash.txt", b"$(x).txt", b"ends.tmp"]


def gen_paths(rng, i, seeds):
    name = ODD_NAMES[i % len(ODD_NAMES)] if i < 4 * len(ODD_NAMES) else rng.choice(ODD_NAMES)
    s = seeds.files
    kinds = ["scene", "network", "law", "out_wet", "out_sweep", "out_export", "ckpt", "perc_out", "perc_table",
             "rigidity_svg", "network_in_scene", "law_in_scene"]
    kind = kinds[(i // len(ODD_NAMES)) % len(kinds)] if i < 4 * len(ODD_NAMES) else rng.choice(kinds)
    files, outputs, checks = {}, (), []
    n = os.fsdecode(name)
    if kind == "scene":
        files[name] = s["tiny.toml"]
        cmd = rng.choice(["modulus", "info"])
        argv = ["modulus", n, "-q"] if cmd == "modulus" else ["info", n]
    elif kind == "network":
        files[name] = s["net_p.txt"]
        cmd = rng.choice(["modulus", "wet", "sweep"])
        argv = {"modulus": ["modulus", "--network", n, "-q"],
                "wet": ["wet", "--network", n, "--betas", "0.1", "--no-moduli", "-q", "-o", "out"],
                "sweep": ["sweep", "--network", n, "--gamma-max", "0.01", "-q", "-o", "out.csv"]}[cmd]
    elif kind == "law":
        files[name] = s["law3.txt"]
        cmd = "wet"
        argv = ["wet"] + TINY + ["--betas", "0.1", "--no-moduli", "-q", "--law", n] + rng.choice([[], ["-o", "out"]])
    elif kind == "out_wet":
        cmd = "wet"
        argv = ["wet"] + TINY + ["--betas", "0.1", "--no-moduli", "-q", "-o", n]
        outputs = (os.path.join(n, "summary.json"),)
    elif kind == "out_sweep":
        cmd = "sweep"
        argv = ["sweep"] + TINY + ["--gamma-max", "0.01", "-q", "-o", n]
        outputs = (n,)
    elif kind == "out_export":
        cmd = rng.choice(["export", "generate", "relax"])
        argv = [cmd] + TINY + ["-o", n] + (["-q"] if cmd == "relax" else [])
        outputs = (n,)
    elif kind == "ckpt":
        cmd = "sweep"
        argv = ["sweep"] + TINY + ["--gamma-max", "0.01", "-q", "-o", "s.csv", "--checkpoint", n]
        outputs = (n,)
    elif kind == "perc_out":
        cmd = "percolation"
        argv = ["percolation"] + PERC_ARGS + ["--out", n]
        outputs = (n,)
    elif kind == "perc_table":
        cmd = "percolation"
        argv = ["percolation"] + PERC_ARGS + ["--out", "p.csv", "--table", n, "--summary", n + b".json".decode()]
        outputs = (n,)
    elif kind == "rigidity_svg":
        cmd = "rigidity"
        argv = ["rigidity"] + TINY + ["--open", "--svg", n, "--out", "r.json"]
        outputs = (n,)
    elif kind == "network_in_scene":
        files[name] = s["net_p.txt"]
        toml_name = name.replace(b"\\", b"\\\\").replace(b'"', b'\\"').replace(b"\n", b"\\n").replace(b"\t", b"\\t")
        files["scene.toml"] = b'[network]\nfile = "' + toml_name + b'"\n'
        cmd = rng.choice(["modulus", "wet"])
        argv = [cmd, "scene.toml", "-q"] + (["--betas", "0.1", "--no-moduli"] if cmd == "wet" else [])
    else:  # law_in_scene
        files[name] = s["law3.txt"]
        toml_name = name.replace(b"\\", b"\\\\").replace(b'"', b'\\"').replace(b"\n", b"\\n").replace(b"\t", b"\\t")
        files["scene.toml"] = s["tiny.toml"].replace(b'crossings = "all"', b'crossings = "all"\nlaw = "' + toml_name + b'"')
        cmd = "wet"
        argv = ["wet", "scene.toml", "--betas", "0.1", "--no-moduli", "-q", "-o", "out"]
    if cmd == "sweep":
        checks = [sweep_plain_check]
    return Case("paths", i, argv, files, ["%r as %s" % (name, kind)], cmd, checks, outputs=outputs)


GENERATORS = {"network": gen_network, "scene": gen_scene, "law": gen_law, "sweep_ckpt": gen_sweep_ckpt,
              "percolation": gen_percolation, "foreign": gen_foreign,
              "model": lambda rng, i, seeds: gen_foreign(rng, i, seeds, "model"), "paths": gen_paths,
              "points": gen_points}


# ----------------------------------------------------------------------------------------------------------------


def shell_quote(a):
    b = os.fsencode(a)
    if re.fullmatch(rb"[A-Za-z0-9_./=,:+-]+", b) and not b.startswith(b"-") or re.fullmatch(rb"-[A-Za-z0-9_.=,:+-]*", b):
        return b.decode()
    if all(32 <= c < 127 and c != 39 for c in b):
        return "'" + b.decode() + "'"
    return "$'" + "".join(chr(c) if 32 <= c < 127 and c not in (39, 92) else "\\x%02x" % c for c in b) + "'"


def write_case_files(d, files):
    for name, data in files.items():
        p = os.path.join(os.fsencode(d), os.fsencode(name))
        if data is None:
            os.makedirs(p, exist_ok=True)
            continue
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "wb") as f:
            f.write(data)


def save_repro(outdir, case, category, detail, r, fib):
    d = os.path.join(outdir, "%s-%s-%04d" % (case.fmt, category, case.index))
    if os.path.exists(d):
        shutil.rmtree(d)
    os.makedirs(d)
    write_case_files(d, case.files)
    cmd = "${FIBERNET:-fibernet} " + " ".join(shell_quote(a) for a in case.argv)
    with open(os.path.join(d, "cmd.sh"), "w") as f:
        f.write("#!/bin/sh\n# %s case %d: %s\n# %s\n# inputs: %s\ncd \"$(dirname \"$0\")\" && %s\necho \"exit $?\"\n" % (
            case.fmt, case.index, category, detail.replace("\n", " ")[:400], "; ".join(case.descs)[:600], cmd))
    os.chmod(os.path.join(d, "cmd.sh"), 0o755)
    with open(os.path.join(d, "stdout"), "wb") as f:
        f.write(r.out[:200000])
    with open(os.path.join(d, "stderr"), "wb") as f:
        f.write(r.err[-200000:])
    with open(os.path.join(d, "meta.json"), "w") as f:
        json.dump({"format": case.fmt, "case": case.index, "category": category, "detail": detail,
                   "mutations": case.descs, "argv": [os.fsdecode(a) for a in case.argv], "exit": r.rc,
                   "timed_out": r.timed_out, "seconds": round(r.seconds, 3)}, f, indent=1)
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=DEFAULT_SEED, help="master seed (default %(default)s)")
    ap.add_argument("--cases", type=int, default=None, help="cases per format (default 200; 30 with --smoke)")
    ap.add_argument("--fibernet", default=os.path.join(REPO, "build", "fibernet"),
                    help="the fibernet executable (default: build/fibernet of the repository)")
    ap.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "fibernet-fuzz-failures"),
                    help="directory for failing reproducers (default %(default)s)")
    ap.add_argument("--timeout", type=float, default=10, help="seconds per case (default %(default)s)")
    ap.add_argument("--formats", default=",".join(FORMATS), help="comma-separated subset of: " + ", ".join(FORMATS))
    ap.add_argument("--smoke", action="store_true", help="30 cases per format (unless --cases says otherwise) and a 5 s timeout: the ctest entry")
    ap.add_argument("--keep", type=int, default=3, help="reproducers kept per (format, category) (default %(default)s)")
    ap.add_argument("--time-budget", type=float, default=0, help="stop starting cases after this many seconds (0: none)")
    ap.add_argument("--start", type=int, default=0, help="first case index (default 0), e.g. to rerun one case")
    ap.add_argument("-v", "--verbose", action="store_true", help="print every failure as it happens")
    a = ap.parse_args()
    if a.smoke:
        a.cases, a.timeout = a.cases if a.cases is not None else 30, min(a.timeout, 5)
    elif a.cases is None:
        a.cases = 200
    formats = [f.strip() for f in a.formats.split(",") if f.strip()]
    for f in formats:
        if f not in FORMATS:
            ap.error("unknown format %r (expected some of %s)" % (f, ", ".join(FORMATS)))
    fib = os.path.abspath(a.fibernet)
    if not os.access(fib, os.X_OK):
        ap.error("--fibernet %s is not an executable" % fib)
    global ASAN
    ASAN = sanitized(fib)
    if ASAN:
        print("fuzz: %s is built with AddressSanitizer: no address-space limit (a cap per allocation instead), "
              "timeouts x%d" % (fib, ASAN_SLOWDOWN), file=sys.stderr)
    outdir = os.path.abspath(a.out)
    work = tempfile.mkdtemp(prefix="fibernet-fuzz-")
    t_start = time.monotonic()
    counts = {}       # (format, category) -> n
    kept = {}
    passed = failed = 0
    first_fail = {}   # (format, category) -> (index, detail)
    try:
        seeds = Seeds(fib, work, a.timeout)
        total = a.cases * len(formats)
        done = 0
        last = 0
        stop = False
        tty = sys.stderr.isatty()
        for fmt in formats:
            for i in range(a.start, a.start + a.cases):
                if a.time_budget and time.monotonic() - t_start > a.time_budget:
                    stop = True
                    break
                rng = random.Random("%d:%s:%d" % (a.seed, fmt, i))
                case = GENERATORS[fmt](rng, i, seeds)
                d = os.path.join(work, "case")
                if os.path.exists(d):
                    shutil.rmtree(d)
                os.makedirs(os.path.join(d, "out"))
                write_case_files(d, case.files)
                before = snapshot(d)
                r = run([fib] + [os.fsencode(x) for x in case.argv], d, a.timeout)
                after = snapshot(d)
                fails, verdict = generic_checks(case, r, before, after, d)
                if verdict is not None or r.timed_out:  # a timed-out resume: its CSV so far is checked too
                    for chk in case.checks:
                        fails += chk(case, r, before, after, d)
                done += 1
                if fails:
                    failed += 1
                    seen = set()
                    for cat, detail in fails:
                        if cat in seen:
                            continue
                        seen.add(cat)
                        counts[(fmt, cat)] = counts.get((fmt, cat), 0) + 1
                        first_fail.setdefault((fmt, cat), (i, detail, case.descs))
                        if kept.get((fmt, cat), 0) < a.keep:
                            kept[(fmt, cat)] = kept.get((fmt, cat), 0) + 1
                            save_repro(outdir, case, cat, detail, r, fib)
                        if a.verbose:
                            sys.stderr.write("\nFAIL %s #%d %s: %s | %s\n" % (fmt, i, cat, detail, "; ".join(case.descs)))
                else:
                    passed += 1
                    counts[(fmt, verdict)] = counts.get((fmt, verdict), 0) + 1
                now = time.monotonic()
                if (tty and now - last > 0.5) or (not tty and now - last > 30) or done == total:
                    last = now
                    sys.stderr.write("%sfuzz: %d/%d [%s #%d] passed %d failed %d, %.0f s%s" % (
                        "\r" if tty else "", done, total, fmt, i, passed, failed, now - t_start, "   " if tty else "\n"))
                    sys.stderr.flush()
            if stop:
                break
        if tty:
            sys.stderr.write("\n")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    # table
    cats = ["ok", "rejected"] + sorted({c for (_, c) in counts} - {"ok", "rejected"})
    w = max(12, max(len(c) for c in cats) + 2)
    fw = max(len(f) for f in formats) + 2
    print("%-*s" % (fw, "format") + "".join("%*s" % (max(len(c) + 2, 8), c) for c in cats))
    for fmt in formats:
        print("%-*s" % (fw, fmt) + "".join("%*d" % (max(len(c) + 2, 8), counts.get((fmt, c), 0)) for c in cats))
    if first_fail:
        print("first case of each failure class (reproducers under %s):" % outdir)
        for (fmt, cat), (i, detail, descs) in sorted(first_fail.items()):
            print("  %s/%s: case %d: %s [%s]" % (fmt, cat, i, detail[:160], "; ".join(descs)[:160]))
    print("elapsed %.0f s, seed %d, %d cases per format, timeout %g s" % (time.monotonic() - t_start, a.seed, a.cases, a.timeout))
    print("fuzz: %d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
