#pragma once
// CHOLMOD's OpenMP regions on the calling thread.
//
// Debian's CHOLMOD (3.0 of SuiteSparse 5.12) wraps the memory passes of its supernodal factorization (clearing the
// row map, zeroing a supernode, scattering A into it) in OpenMP regions that ask for a fixed 4 threads
// (CHOLMOD_OMP_NUM_THREADS), whatever OMP_NUM_THREADS says. Its arithmetic is in BLAS, outside those regions. On a
// small or medium matrix each region costs more than its loop: 4 threads woken on this 2-core machine, or, with
// OpenMP's teams turned off, still a team built and a futex call per region (docs/benchmarks.md, "OpenBLAS's and
// CHOLMOD's threads"). While an InlineOpenMP lives on a thread, a parallel region opened on that thread runs its body directly
// on it, as a team of one thread would (the regions' loops are static ones over independent entries, so the
// factor is the same bit for bit). Regions opened elsewhere, or on other threads, go to OpenMP as usual.
//
// This works by fibernet defining OpenMP's entry point GOMP_parallel (inline_openmp.cpp), which the dynamic linker
// binds CHOLMOD's calls to; outside a guard it forwards to libgomp's.
namespace fibernet {

class InlineOpenMP {
public:
    InlineOpenMP();
    ~InlineOpenMP();
    InlineOpenMP(const InlineOpenMP&) = delete;
    InlineOpenMP& operator=(const InlineOpenMP&) = delete;

    // Parallel regions run on their calling thread under a guard since the process started (none where a loader
    // bound the libraries' calls to libgomp's entry point instead of fibernet's).
    static long regions_inlined();
};

}  // namespace fibernet
