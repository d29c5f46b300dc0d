#!/usr/bin/env bash
# Builds fibernet with AddressSanitizer and UndefinedBehaviorSanitizer into build-sanitize/ and runs the whole test
# suite there (docs/reliability.md). Any report fails the run: ASan aborts on the first error, UBSan is made fatal.
#   scripts/sanitize.sh [ctest args...]      e.g. scripts/sanitize.sh -R mechanics
# Not part of CI (about 25 minutes on 2 cores); run it before a release or after touching memory-heavy code.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --no-build
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g -DNDEBUG" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DFIBERNET_BUILD_BENCH=OFF >&2
cmake --build build-sanitize -j"$(nproc)" >&2
# detect_leaks: CHOLMOD and OpenBLAS keep per-thread buffers for the process's life; leaks of fibernet's own are
# still found (a leak report names the allocating frame). halt_on_error: the first report fails the test.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:abort_on_error=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# The package test builds examples/ against the installed library without the sanitizer runtime: left out here.
ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" --timeout 3000 -E '^package$' "$@"
