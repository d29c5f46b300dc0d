#!/usr/bin/env bash
# Sets up what is missing (apt-get), builds, and runs the whole test suite (ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --all
ctest --test-dir build --output-on-failure -j"$(nproc)"
