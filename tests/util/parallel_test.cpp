// parallel_ranges and parallel_blocks (util/parallel.hpp): every index once; errors reach the caller.
#include <catch2/catch.hpp>

#include <atomic>
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

TEST_CASE("parallel_blocks: the first task once, each index exactly once, for any thread count and block", "[util][parallel]") {
    for (int threads : {1, 2, 3})
        for (std::size_t block : {std::size_t{1}, std::size_t{3}, std::size_t{64}})
            for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{1000}}) {
                std::vector<int> hits(n, 0);
                int first = 0;
                std::atomic<int> calls{0}, oversized{0};
                parallel_blocks(n, threads, block, [&] { ++first; }, [&](std::size_t lo, std::size_t hi) {
                    ++calls;
                    if (hi - lo > block) ++oversized;
                    for (std::size_t i = lo; i < hi; ++i) ++hits[i];
                });
                CHECK(first == 1);
                for (std::size_t i = 0; i < n; ++i) CHECK(hits[i] == 1);
                // One thread: the whole range at once; more: blocks as they come.
                if (threads > 1) {
                    CHECK(calls == static_cast<int>((n + block - 1) / block));
                    CHECK(oversized == 0);
                }
            }
}

TEST_CASE("parallel_blocks: an exception in the first task or a block is rethrown", "[util][parallel]") {
    CHECK_THROWS_AS(parallel_blocks(100, 2, 10, [] { throw std::runtime_error("first"); }, [](std::size_t, std::size_t) {}),
                    std::runtime_error);
    CHECK_THROWS_AS(parallel_blocks(100, 3, 10, [] {},
                                    [](std::size_t lo, std::size_t) {
                                        if (lo == 50) throw std::runtime_error("a block");
                                    }),
                    std::runtime_error);
}
