#!/usr/bin/env python3
"""A fibernet JSON result on stdin without what differs between two runs of the same computation: timings (keys that
name seconds), provenance, the command line and the machine load. Printed sorted and indented, for `cmp` and `diff`
(bench/compare_builds.sh, bench/time_builds.sh). Input that is not JSON is printed as it is."""
import json
import sys

DROP = {"timings", "provenance", "command", "load", "out_dir"}


def clean(o):
    if isinstance(o, dict):
        return {k: clean(v) for k, v in o.items() if k not in DROP and "seconds" not in k}
    if isinstance(o, list):
        return [clean(v) for v in o]
    return o


text = sys.stdin.read()
try:
    print(json.dumps(clean(json.loads(text)), indent=1, sort_keys=True))
except ValueError:
    print(text, end="")
