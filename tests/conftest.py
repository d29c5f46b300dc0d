"""The package from the build tree (PYTHONPATH=<build>/python) and the executable it is compared with."""
import json
import os
import subprocess

import pytest


@pytest.fixture(scope="session")
def exe():
    path = os.environ.get("FIBERNET_EXE")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("FIBERNET_EXE must name the fibernet executable (ctest sets it)")
    return path


@pytest.fixture(scope="session")
def cli(exe):
    """Runs the executable: (exit code, parsed JSON or None, stderr)."""
    def run(*args, cwd=None):
        p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, cwd=cwd)
        out = json.loads(p.stdout) if p.stdout.strip().startswith("{") else None
        return p.returncode, out, p.stderr
    return run
