#pragma once
// A minimal parallel loop for element evaluations. Callers write each element's result to its own slot and sum the
// slots in element order afterwards, so results are bit for bit the same for any number of threads.
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace fibernet {

// Threads for element loops: the environment variable FIBERNET_THREADS if set (>= 1), else the hardware's count.
int thread_count();
// Overrides that count from here on (n >= 1; n = 0 removes the override; tests compare thread counts);
// thread_count_default() is the count without an override.
void set_thread_count(int n);
int thread_count_default();

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

}  // namespace fibernet
