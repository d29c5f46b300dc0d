#pragma once
// A minimal parallel loop for element evaluations. Callers write each element's result to its own slot and sum the
// slots in element order afterwards, so results are bit for bit the same for any number of threads.
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace fibernet {

// Threads for element loops: the environment variable FIBERNET_THREADS if set (>= 1), else the hardware's count.
// A count of 1 (from either) also keeps the OpenMP regions of the libraries (CHOLMOD's supernodal factorization) on
// the calling thread (parallel.cpp).
int thread_count();
// Overrides that count from here on (n >= 1; n = 0 removes the override; tests compare thread counts);
// thread_count_default() is the count without an override.
void set_thread_count(int n);
int thread_count_default();

// Whether the calling thread is inside a parallel section of parallel_ranges or parallel_blocks with more than one
// thread (its calling thread too): work there runs beside other work (blas_threads.hpp).
bool in_parallel_section();
// Marks the calling thread as inside a parallel section while it lives.
class ParallelSection {
public:
    ParallelSection();
    ~ParallelSection();
    ParallelSection(const ParallelSection&) = delete;
    ParallelSection& operator=(const ParallelSection&) = delete;

private:
    bool outer_;
};

// Calls body(lo, hi) on `threads` contiguous ranges covering [0, n), one per thread (the calling thread takes the
// first). The first exception thrown by any range is rethrown here after all threads have finished.
template <class Body>
void parallel_ranges(std::size_t n, int threads, Body body) {
    const std::size_t t = threads < 1 ? 1 : static_cast<std::size_t>(threads) < n ? static_cast<std::size_t>(threads) : n;
    if (t <= 1) {
        if (n > 0) body(std::size_t{0}, n);
        return;
    }
    std::vector<std::exception_ptr> errors(t);
    auto run = [&](std::size_t k) {
        const ParallelSection section;
        try {
            body(n * k / t, n * (k + 1) / t);
        } catch (...) {
            errors[k] = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    pool.reserve(t - 1);
    try {
        for (std::size_t k = 1; k < t; ++k) pool.emplace_back(run, k);
    } catch (...) {  // a thread could not be started: finish the started ones before giving up
        for (auto& th : pool) th.join();
        throw;
    }
    run(0);
    for (auto& th : pool) th.join();
    for (auto& e : errors)
        if (e) std::rethrow_exception(e);
}

// Calls first() and then body(lo, hi) on blocks of `block` items covering [0, n) on the calling thread, while
// threads - 1 more threads take blocks from the start: for a task (first) that runs beside a loop whose items the
// threads share as they come free. Results go to per-item slots, as above. An exception (that of the lowest-numbered
// thread if several threw; the calling thread is number 0) is rethrown here after all threads have finished.
template <class First, class Body>
void parallel_blocks(std::size_t n, int threads, std::size_t block, First first, Body body) {
    if (threads < 2 || n == 0) {
        first();
        if (n > 0) body(std::size_t{0}, n);
        return;
    }
    if (block < 1) block = 1;
    std::atomic<std::size_t> next{0};
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(threads));
    auto take = [&](std::size_t k, bool with_first) {
        const ParallelSection section;
        try {
            if (with_first) first();
            for (;;) {
                const std::size_t lo = next.fetch_add(block);
                if (lo >= n) return;
                body(lo, lo + block < n ? lo + block : n);
            }
        } catch (...) {
            errors[k] = std::current_exception();
            next = n;  // the others stop after their current block
        }
    };
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(threads) - 1);
    try {
        for (int k = 1; k < threads; ++k) pool.emplace_back(take, static_cast<std::size_t>(k), false);
    } catch (...) {
        next = n;
        for (auto& th : pool) th.join();
        throw;
    }
    take(0, true);
    for (auto& th : pool) th.join();
    for (auto& e : errors)
        if (e) std::rethrow_exception(e);
}

}  // namespace fibernet
