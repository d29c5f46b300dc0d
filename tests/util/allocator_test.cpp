// keep_freed_memory (allocator.hpp): after it, a large block comes from the heap, not from a mapping of its own, and
// stays in the process when freed, ready for the next allocation of its size (no page faults and zeroing again).
#include <catch2/catch.hpp>
#include <cstdlib>

#include "fibernet/util/allocator.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

using namespace fibernet;

TEST_CASE("allocator: a freed large block stays in the process for reuse", "[util][allocator]") {
#if defined(__SANITIZE_ADDRESS__)
    // AddressSanitizer replaces malloc with its own allocator (scripts/sanitize.sh): glibc's heap, which
    // keep_freed_memory tunes and mallinfo2 counts, is not the one that serves this process.
    WARN("built with AddressSanitizer, whose allocator replaces glibc's heap: not checked");
#elif defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 33)
    if (std::getenv("MALLOC_MMAP_THRESHOLD_") || std::getenv("MALLOC_TRIM_THRESHOLD_")) {
        WARN("glibc's heap is tuned from the environment: not checked");
        return;
    }
    keep_freed_memory();
    const size_t size = 24u << 20;  // above glibc's default mapping threshold, below the 32 MiB we keep
    const struct mallinfo2 before = mallinfo2();
    auto* p = static_cast<volatile char*>(std::malloc(size));
    REQUIRE(p != nullptr);
    p[0] = 1, p[size - 1] = 2;  // used, so the pair is not elided
    const struct mallinfo2 held = mallinfo2();
    CHECK(held.hblkhd == before.hblkhd);  // not a mapping of its own
    std::free(const_cast<char*>(p));
    const struct mallinfo2 after = mallinfo2();
    CHECK(after.fordblks >= size);  // kept as free heap memory, not trimmed
#else
    WARN("not glibc (2.33 or later): not checked");
#endif
}
