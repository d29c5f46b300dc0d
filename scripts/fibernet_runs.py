"""What scripts/fuzz.py and scripts/soak.py share: how a fibernet child process is run (single-threaded, bounded
memory, no core files) and how its JSON output is read (NaN/Infinity constants noted, not accepted silently)."""
import json
import os
import resource


def sanitized(executable):
    """True when the executable was built with AddressSanitizer (scripts/sanitize.sh): it then calls __asan_init."""
    with open(executable, "rb") as f:
        return b"__asan_init" in f.read()


def child_limits(memory_gib, file_mib=None, asan=False):
    """preexec_fn for a child: address space (huge declared counts fail fast instead of swapping the machine),
    no core dumps, optionally a cap on the size of files it writes. Under AddressSanitizer (asan=True) the address
    space is not limited: its shadow memory reserves terabytes of it at start; child_env(asan=True) bounds each
    allocation instead."""
    if not asan:
        resource.setrlimit(resource.RLIMIT_AS, (memory_gib << 30, memory_gib << 30))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    if file_mib is not None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (file_mib << 20, file_mib << 20))


def child_env(memory_gib=None, asan=False):
    """One thread everywhere (the cases run one at a time and must be comparable), C locale. Under AddressSanitizer
    an allocation above memory_gib returns null (std::bad_alloc), as it would under child_limits' address space."""
    env = dict(os.environ)
    env.update({"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "FIBERNET_THREADS": "1", "LC_ALL": "C"})
    if asan and memory_gib is not None:
        opts = [o for o in env.get("ASAN_OPTIONS", "").split(":") if o]
        opts += ["allocator_may_return_null=1", "max_allocation_size_mb=%d" % (memory_gib << 10)]
        env["ASAN_OPTIONS"] = ":".join(opts)
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
