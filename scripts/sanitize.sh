#!/usr/bin/env bash
# Builds fibernet with AddressSanitizer and UndefinedBehaviorSanitizer into build-sanitize/ and runs tests there
# (docs/reliability.md, "Sanitizers"). Any report fails the run: ASan aborts on the first error, UBSan halts on it.
#   scripts/sanitize.sh [ctest args...]   every ctest entry, e.g. scripts/sanitize.sh -R mechanics
#   scripts/sanitize.sh --ci              what .ci/run runs: fibernet and the test binaries of the areas energy,
#                                         model, network, scene, util, solve, mechanics and rigidity only, their
#                                         cases without [slow], and a short fuzz smoke (the entries labelled quick)
# Entries that cannot run as they are under the sanitizers adapt to the build (CMakeLists.txt): the Python test
# preloads the sanitizer runtimes, the fuzz harness bounds allocations instead of the address space, the package
# example is built with the library's flags, and the allocator test skips glibc's counters under ASan's allocator.
set -euo pipefail
cd "$(dirname "$0")/.."
ci=0
if [ "${1:-}" = "--ci" ]; then
  ci=1
  shift
fi
# The whole suite runs LAMMPS, VTK and pytest too: setup.sh --all installs them.
if [ "$ci" = 1 ]; then bash scripts/setup.sh --no-build; else bash scripts/setup.sh --all --no-build; fi
# -g1: line tables for the reports' stack traces, at a fraction of full debug information's compile time.
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DFIBERNET_BUILD_BENCH=OFF >&2
areas=(energy model network scene util solve mechanics rigidity)
if [ "$ci" = 1 ]; then
  cmake --build build-sanitize -j"$(nproc)" --target fibernet "${areas[@]/#/test_}" >&2
else
  cmake --build build-sanitize -j"$(nproc)" >&2
fi
# detect_leaks: CHOLMOD and OpenBLAS keep per-thread buffers for the process's life; leaks of fibernet's own are
# still found (a leak report names the allocating frame). halt_on_error: the first report fails the test.
# scripts/ubsan.supp and scripts/lsan.supp: reports that are not fibernet's to fix (CGAL's, Open MPI's), each with
# its reason.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:abort_on_error=1:check_initialization_order=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$PWD/scripts/ubsan.supp"
if [ "$ci" = 1 ]; then
  only=$(IFS='|'; echo "${areas[*]}")
  ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" --timeout 1200 -L quick -R "^(($only)_quick|fuzz_quick)\$" "$@"
else
  ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" --timeout 3000 -LE quick "$@"
fi
