// parallel_ranges and parallel_blocks (util/parallel.hpp): every index once; errors reach the caller. One thread keeps
// CHOLMOD's OpenMP regions on the calling thread.
#include <catch2/catch.hpp>

#include <atomic>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include <Eigen/SparseCore>

#include "fibernet/solve/cholmod_llt.hpp"
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

namespace {
int threads_of_this_process() {
    int n = 0;
    for ([[maybe_unused]] const auto& t : std::filesystem::directory_iterator("/proc/self/task")) ++n;
    return n;
}
}  // namespace

TEST_CASE("one thread: CHOLMOD's supernodal factorization starts no OpenMP thread", "[util][parallel]") {
    // CHOLMOD asks OpenMP for a fixed 4 threads in its supernodal loops (whatever OMP_NUM_THREADS says); OpenMP keeps
    // a team's threads alive after its first region, so a region with more than one thread shows in /proc/self/task.
    set_thread_count(1);
    const int before = threads_of_this_process();
    // The 5-point Laplacian of a 150 x 150 grid, shifted: positive definite, with supernodes of hundreds of rows.
    const int m = 150, n = m * m;
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            const int k = i * m + j;
            t.emplace_back(k, k, 4.1);
            if (j + 1 < m) t.emplace_back(k, k + 1, -1.0);
            if (i + 1 < m) t.emplace_back(k, k + m, -1.0);
        }
    Eigen::SparseMatrix<double> H(n, n);
    H.setFromTriplets(t.begin(), t.end());
    CholmodLLT llt;
    llt.analyze(H);
    REQUIRE(llt.factorize(H));
    CHECK(threads_of_this_process() == before);
    set_thread_count(0);
}
