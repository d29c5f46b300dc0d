// parallel_ranges and parallel_blocks (util/parallel.hpp): every index once; errors reach the caller. One thread keeps
// the OpenMP regions of libraries on the calling thread.
#include <catch2/catch.hpp>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "fibernet/util/parallel.hpp"

// GCC's entry point of `#pragma omp parallel` (these tests are not compiled with OpenMP, so they call it directly).
extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags);

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

namespace {
struct Region {
    std::atomic<int> bodies{0};
};
void count_bodies(void* p) { ++static_cast<Region*>(p)->bodies; }
}  // namespace

TEST_CASE("one thread: an OpenMP region that a library opens runs on one thread", "[util][parallel]") {
    // CHOLMOD asks OpenMP for a fixed 4 threads in its supernodal loops (whatever OMP_NUM_THREADS says). fibernet's
    // own CHOLMOD calls run those regions inline (inline_openmp.hpp); any other region, on one thread, gets a team
    // of one (max-active-levels 0), and with more threads the team it asks for.
    Region one, more;
    set_thread_count(1);
    GOMP_parallel(count_bodies, &one, 4, 0);
    CHECK(one.bodies == 1);
    set_thread_count(2);
    GOMP_parallel(count_bodies, &more, 4, 0);
    CHECK(more.bodies == 4);
    set_thread_count(0);
}
