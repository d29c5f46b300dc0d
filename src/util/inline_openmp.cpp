#include "fibernet/util/inline_openmp.hpp"

#include <dlfcn.h>
#include <omp.h>

#include <atomic>

namespace fibernet {

namespace {
thread_local int guards = 0;
std::atomic<long> inlined{0};
}  // namespace

InlineOpenMP::InlineOpenMP() { ++guards; }
InlineOpenMP::~InlineOpenMP() { --guards; }

long InlineOpenMP::regions_inlined() { return inlined.load(); }

}  // namespace fibernet

// GCC's entry point of `#pragma omp parallel` (libgomp, symbol version GOMP_4.0). Under a guard, on a thread that is
// not one of a team of several, the body runs here: omp_get_num_threads() is 1 and omp_get_thread_num() 0, so a
// static loop's one share is the whole range, exactly as in a team of one. A thread of a larger team (a program that
// calls fibernet from its own parallel region) would hand the body that team's size and give it a share only, so
// there, as everywhere else, libgomp's own entry point runs it.
extern "C" __attribute__((visibility("default"))) void GOMP_parallel(void (*fn)(void*), void* data,
                                                                     unsigned num_threads, unsigned flags) {
    using Entry = void (*)(void (*)(void*), void*, unsigned, unsigned);
    static const Entry gomp = reinterpret_cast<Entry>(dlvsym(RTLD_NEXT, "GOMP_parallel", "GOMP_4.0"));
    if ((fibernet::guards > 0 && omp_get_num_threads() == 1) || !gomp) {
        if (fibernet::guards > 0) fibernet::inlined.fetch_add(1, std::memory_order_relaxed);
        fn(data);
        return;
    }
    gomp(fn, data, num_threads, flags);
}
