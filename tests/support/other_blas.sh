#!/usr/bin/env bash
# Runs a test command with OpenBLAS kernels of another CPU than this one, so that a test asserting round-off fails
# here and not only on a user's machine (issue 21: tests passed on an AVX-512 CPU and failed on an AVX2 one).
# Debian's OpenBLAS picks its kernels at run time (DYNAMIC_ARCH); OPENBLAS_CORETYPE overrides the choice.
#   other_blas.sh <fibernet executable> <command...>
# Prints the kernel used. Also runs OpenBLAS single-threaded: its dpotrf takes another algorithm than the threaded one.
set -euo pipefail
exe=$1; shift
native=$(OPENBLAS_VERBOSE=2 "$exe" --version 2>&1 | sed -n 's/^Core: //p' | head -1)
flags=$(grep -m1 '^flags' /proc/cpuinfo || true)
# Kernels this CPU can run, widest first; the first that is not the native one.
candidates=()
# SkylakeX's double-precision kernels are those of Cooperlake and SapphireRapids: no other rounding there.
[[ $flags == *" avx512f"* && $flags == *" avx512bw"* && $flags == *" avx512vl"* && $flags == *" avx512dq"* &&
   $native != Cooperlake && $native != SapphireRapids ]] && candidates+=(SkylakeX)
[[ $flags == *" avx2"* ]] && candidates+=(Haswell)
[[ $flags == *" avx "* ]] && candidates+=(SandyBridge)
[[ $flags == *" sse4_2"* ]] && candidates+=(Nehalem)
candidates+=(Prescott)
other=""
for c in "${candidates[@]}"; do
  if [ "$c" != "$native" ]; then other=$c; break; fi
done
echo "other_blas: native OpenBLAS kernel '${native:-unknown}', running with '$other', 1 thread" >&2
export OPENBLAS_CORETYPE=$other OPENBLAS_NUM_THREADS=1
exec "$@"
