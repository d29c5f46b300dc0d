"""What scripts/fuzz.py and scripts/soak.py share: how a fibernet child process is run (single-threaded, bounded
memory, no core files) and how its JSON output is read (NaN/Infinity constants noted, not accepted silently)."""
import json
import os
import resource


def child_limits(memory_gib, file_mib=None):
    """preexec_fn for a child: address space (huge declared counts fail fast instead of swapping the machine),
    no core dumps, optionally a cap on the size of files it writes."""
    resource.setrlimit(resource.RLIMIT_AS, (memory_gib << 30, memory_gib << 30))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    if file_mib is not None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (file_mib << 20, file_mib << 20))


def child_env():
    """One thread everywhere (the cases run one at a time and must be comparable), C locale."""
    env = dict(os.environ)
    env.update({"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "FIBERNET_THREADS": "1", "LC_ALL": "C"})
    return env


def parse_json(text):
    """Returns (object or None, error or None, nonfinite constants found)."""
    bad = []

    def const(c):
        bad.append(c)
        return float("nan")
    try:
        return json.loads(text.decode("utf-8"), parse_constant=const), None, bad
    except (ValueError, UnicodeDecodeError) as e:
        return None, str(e)[:200], bad
