#!/usr/bin/env bash
# The installed package works for a project of its own: `cmake --install` into a scratch prefix, examples/ built
# against it with find_package(fibernet), and the example's shear and bulk moduli equal to the installed CLI's for the
# same network within the errors they report (both are the library's linear_moduli, same modes and options, at the
# same Newton equilibrium).
#   consumer_test.sh <fibernet build dir> <fibernet source dir>
set -euo pipefail
build=$(cd "$1" && pwd); src=$(cd "$2" && pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log" || { cat "$tmp/install.log"; fail "cmake --install"; }
libdir=$(ls -d "$tmp"/prefix/lib*/cmake/fibernet 2>/dev/null | head -1 || true)
for f in bin/fibernet include/fibernet/mechanics/moduli.hpp include/fibernet/wet/wet_run.hpp; do
  [ -e "$tmp/prefix/$f" ] || fail "not installed: $f"
done
[ -n "$libdir" ] && [ -f "$libdir/fibernetConfig.cmake" ] || fail "no fibernetConfig.cmake under $tmp/prefix/lib*/cmake/fibernet"

# The example is compiled and linked with the flags the library was built with: a library built with sanitizers
# (scripts/sanitize.sh) needs their runtime in the program that links it.
cache() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
cmake -S "$src/examples" -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
      -DCMAKE_CXX_FLAGS="$(cache CMAKE_CXX_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS="$(cache CMAKE_EXE_LINKER_FLAGS)" \
      > "$tmp/configure.log" 2>&1 \
  || { cat "$tmp/configure.log"; fail "find_package(fibernet) from the installed prefix"; }
cmake --build "$tmp/examples" > "$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; fail "building examples/"; }

args=(--L 5 --q 8 --pl 1 --seed 1 --gamma 0.01)
out=$("$tmp/examples/shear_modulus" 5 8 1 1 0.01) || fail "shear_modulus exited $?"
echo "example: $out"
cli=$("$tmp/prefix/bin/fibernet" modulus "${args[@]}" --scheme seed --a 10 --tol 1e-10 -q)
python3 - "$out" "$cli" <<'PY' || fail "the example's moduli differ from the CLI's by more than their errors"
import json, sys
words = sys.argv[1].split()
ex = {words[i]: float(words[i + 1]) for i in range(2, len(words) - 1, 2)}
m = json.loads(sys.argv[2])["moduli"]
print(f"CLI: G {m['G']!r} +- {m['G_error']:.2g}  K {m['K']!r} +- {m['K_error']:.2g}")
# The same library calls with the same options: they agree within the errors both report (on this machine they
# agree bit for bit; the bound is what holds on any CPU).
for name in ("G", "K"):
    tol = ex[name + "_error"] + m[name + "_error"]
    assert abs(ex[name] - m[name]) <= tol, (name, ex[name], m[name], tol)
assert m["G"] > 0
assert abs(ex["G_affine"] - m["G_affine"]) <= 1e-12 * abs(m["G_affine"]), (ex["G_affine"], m["G_affine"])
PY

# Bad input through the library: InputError names the value, the example exits 2.
set +e
msg=$("$tmp/examples/shear_modulus" 5 8 1.5 2>&1); rc=$?
set -e
[ "$rc" = 2 ] || fail "pl = 1.5: exit $rc, expected 2"
echo "$msg" | grep -q "1.5" || fail "pl = 1.5: message does not name the value: $msg"
echo "package test passed"
