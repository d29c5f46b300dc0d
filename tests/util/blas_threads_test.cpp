// BlasThreads (util/blas_threads.hpp): OpenBLAS on one thread for a small factorization and inside a parallel section,
// on fibernet's thread count (at most OpenBLAS's own) for a large one, whatever count was set before.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>

#include "fibernet/util/blas_threads.hpp"
#include "fibernet/util/parallel.hpp"

extern "C" int openblas_get_num_threads(void);
extern "C" void openblas_set_num_threads(int);

using namespace fibernet;

TEST_CASE("BlasThreads: one thread below the threshold, the thread count above it", "[util][blas]") {
    set_thread_count(2);
    const int own = BlasThreads::own();  // the cores, or OPENBLAS_NUM_THREADS
    const int large_count = std::min(2, own);
    for (int before : {1, 2, 3}) {
        openblas_set_num_threads(before);
        {
            const BlasThreads small(0.5 * BlasThreads::kThreadedFlops);
            CHECK(small.threads() == 1);
            CHECK(openblas_get_num_threads() == 1);
        }
        {
            const BlasThreads large(2 * BlasThreads::kThreadedFlops);
            CHECK(large.threads() == large_count);
            CHECK(openblas_get_num_threads() == large_count);
        }
    }
    set_thread_count(1);
    {
        const BlasThreads large(2 * BlasThreads::kThreadedFlops);
        CHECK(large.threads() == 1);  // fibernet's one thread bounds it
        CHECK(openblas_get_num_threads() == 1);
    }
    set_thread_count(0);
    openblas_set_num_threads(own);
}

TEST_CASE("BlasThreads: one thread inside a parallel section, on every thread of it", "[util][blas]") {
    set_thread_count(2);
    std::atomic<int> large_on_one{0}, sections{0};
    for (int repeat = 0; repeat < 20; ++repeat)
        parallel_ranges(2, 2, [&](std::size_t lo, std::size_t hi) {
            for (std::size_t k = lo; k < hi; ++k) {
                sections += in_parallel_section();
                const BlasThreads large(2 * BlasThreads::kThreadedFlops);
                large_on_one += large.threads() == 1;
            }
        });
    CHECK(sections == 40);
    CHECK(large_on_one == 40);
    CHECK(openblas_get_num_threads() == 1);  // no thread of the section left another count behind
    CHECK_FALSE(in_parallel_section());     // over with the section
    set_thread_count(0);
    openblas_set_num_threads(BlasThreads::own());
}
