// parallel_ranges (util/parallel.hpp): every index once, in contiguous ranges; errors reach the caller.
#include <catch2/catch.hpp>

#include <stdexcept>
#include <vector>

#include "fibernet/util/parallel.hpp"

using namespace fibernet;

TEST_CASE("parallel_ranges: each index exactly once, for any thread count", "[util][parallel]") {
    for (int threads : {1, 2, 3, 8})
        for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{1000}}) {
            std::vector<int> hits(n, 0);  // each range writes only its own slots (Catch2 assertions are not thread safe)
            parallel_ranges(n, threads, [&](std::size_t lo, std::size_t hi) {
                for (std::size_t i = lo; i < hi; ++i) ++hits[i];
            });
            for (std::size_t i = 0; i < n; ++i) CHECK(hits[i] == 1);
        }
}

TEST_CASE("parallel_ranges: an exception in any range is rethrown", "[util][parallel]") {
    CHECK_THROWS_AS(parallel_ranges(100, 2,
                                    [](std::size_t lo, std::size_t) {
                                        if (lo > 0) throw std::runtime_error("second range");
                                    }),
                    std::runtime_error);
    CHECK_THROWS_AS(set_thread_count(-1), std::invalid_argument);
    set_thread_count(3);
    CHECK(thread_count() == 3);
    set_thread_count(0);
    CHECK(thread_count() == thread_count_default());
}
