#include "fibernet/util/allocator.hpp"

#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace fibernet {

void keep_freed_memory() {
#if defined(__GLIBC__)
    // 32 MiB is the largest mmap threshold glibc accepts on 64-bit (DEFAULT_MMAP_THRESHOLD_MAX).
    if (!std::getenv("MALLOC_MMAP_THRESHOLD_")) mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
    // The largest int: the heap's top is not trimmed below 2 GiB.
    if (!std::getenv("MALLOC_TRIM_THRESHOLD_")) mallopt(M_TRIM_THRESHOLD, 2147483647);
    if (!std::getenv("MALLOC_TOP_PAD_")) mallopt(M_TOP_PAD, 256 * 1024 * 1024);
#endif
}

}  // namespace fibernet
